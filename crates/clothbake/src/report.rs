//! Output of `clothbake eval`: one JSON object (`--json`) or a short table.

use crate::cli::{Direction, Method};
use clothbake_core::{Cell, FacetModel, PeriodPoint, Reflection};
use serde_json::json;
use std::fmt::Write as _;
use std::path::Path;

/// Ray-tracer extras.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Raytrace {
    /// Standard error of the estimate of I, per channel (infinite, printed as JSON `null`, when
    /// too few samples to estimate it).
    pub std_err: [f64; 3],
    /// Number of samples asked for.
    pub samples: usize,
}

/// Coverage of the analytic model (docs/science/spatial.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Local {
    /// C(wo): the visible yarn's projected area per unit projected area of the period.
    pub directional_coverage: f64,
    /// With `--at`: the point, its crossing cell and the coverage c(x; wo) there.
    pub at: Option<(PeriodPoint, Cell, f64)>,
    /// With `--at`: whether the warp thread lies on top at that crossing.
    pub warp_on_top: bool,
}

/// What `--at` reports: the footprint's reflection through the BSDF (`Bsdf::local`), one value
/// per level of detail, so without the split into I_d and I_s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtFootprint {
    /// The footprint's side in periods.
    pub width: f64,
    /// The level of detail that answered, in words.
    pub level: &'static str,
    /// The reflected intensity I = pi cos(theta_i) f_r.
    pub i: [f64; 3],
    /// With two bounces: its I_2 (the crossing cells' or the period's).
    pub i2: Option<[f64; 3]>,
}

/// Full transport (`--bounces N > 2`, `all`): the energy of every order and the split of I_2.
#[derive(Clone, Debug, PartialEq)]
pub struct Transport {
    /// I_1, I_2, ... (I_1 the direct term of the method, the rest path-traced), RGB.
    pub orders: Vec<[f64; 3]>,
    /// Their standard errors (I_1's: zero for the analytic model).
    pub std_err: Vec<[f64; 3]>,
    /// I_2 by the yarn the light met first: parallel, perpendicular to the visible one.
    pub i2_split: [[f64; 3]; 2],
    /// Standard errors of `i2_split`.
    pub i2_split_err: [[f64; 3]; 2],
    /// The multiple-bounce part, orders 2 to N, and its standard error.
    pub multiple: ([f64; 3], [f64; 3]),
    /// The total I = I_1 + the multiple-bounce part.
    pub total: [f64; 3],
    /// Paths per direction pair and the base seed.
    pub paths: usize,
    /// Base seed (the pair's seed is hashed from it and the directions).
    pub seed: u64,
}

impl Transport {
    /// Whether the orders die out: orders 16 and up carry at most 0.1% of I_1 (channel means).
    /// Facets that reflect more than they receive (the thesis's sec. 5.4 material at n = 1,
    /// docs/science/transport.md) make the series diverge, and the truncated sum means little.
    pub fn converged(&self) -> bool {
        let m = |v: &[f64; 3]| (v[0] + v[1] + v[2]) / 3.0;
        let tail: f64 = self.orders.iter().skip(15).map(m).sum();
        tail <= 1e-3 * m(&self.orders[0])
    }
}

/// Everything one evaluation prints.
#[derive(Debug)]
pub struct Report<'a> {
    /// Fabric display name.
    pub fabric_name: &'a str,
    /// Fabric file.
    pub file: &'a Path,
    /// What reading the file did to it (a WIF draft's packed yarns), one line each.
    pub notes: &'a [String],
    /// Method used.
    pub method: Method,
    /// Facet model used.
    pub facet: FacetModel,
    /// The rest of the model's settings in words (variant or caps, bounces), e.g.
    /// `variant refined, 1 bounce`.
    pub settings: String,
    /// With two bounces: how I_2 was computed (solution, orders or sampling, kernel).
    pub secondary: Option<String>,
    /// Toward the light.
    pub wi: Direction,
    /// Toward the eye.
    pub wo: Direction,
    /// True when wi or wo lies at the horizon (the result is zero by definition).
    pub horizon: bool,
    /// I_d and I_s.
    pub reflection: Reflection,
    /// f_r in 1/sr.
    pub brdf: [f64; 3],
    /// Present for `--method raytrace`.
    pub raytrace: Option<Raytrace>,
    /// Present for the analytic model.
    pub local: Option<Local>,
    /// Present with --bounces N > 2 or all.
    pub transport: Option<Transport>,
    /// Present with --at: the footprint's reflection, which replaces `reflection`'s rows.
    pub footprint: Option<AtFootprint>,
}

impl Report<'_> {
    /// One JSON object: `I_d`, `I_s`, `I`, `brdf`, for the ray tracer `std_err`, `samples`, and
    /// `notes` where reading the fabric left any.
    pub fn json(&self) -> String {
        let mut v = json!({
            "I_d": self.reflection.i_d,
            "I_s": self.reflection.i_s,
            "I": self.reflection.total(),
            "brdf": self.brdf,
        });
        if let Some(f) = &self.footprint {
            v = json!({
                "I": f.i,
                "brdf": self.brdf,
                "width": f.width,
                "level": f.level,
            });
            if let Some(i2) = f.i2 {
                v["I_2"] = json!(i2);
            }
        } else if let Some(s2) = &self.reflection.secondary {
            v["I_ss"] = json!(s2.ss);
            v["I_sd"] = json!(s2.sd);
            v["I_ds"] = json!(s2.ds);
            v["I_dd"] = json!(s2.dd);
            v["I_2"] = json!(s2.total());
        }
        if let Some(rt) = &self.raytrace {
            v["std_err"] = json!(rt.std_err);
            v["samples"] = json!(rt.samples);
        }
        if let Some(t) = &self.transport {
            v["I"] = json!(t.total);
            v["orders"] = json!(t.orders);
            v["orders_std_err"] = json!(t.std_err);
            v["I_2"] = json!(t.orders.get(1).copied().unwrap_or_default());
            v["I_2_parallel"] = json!(t.i2_split[0]);
            v["I_2_perpendicular"] = json!(t.i2_split[1]);
            v["I_2_split_std_err"] = json!(t.i2_split_err);
            v["I_multiple"] = json!(t.multiple.0);
            v["I_multiple_std_err"] = json!(t.multiple.1);
            v["paths"] = json!(t.paths);
            v["seed"] = json!(t.seed);
            v["converged"] = json!(t.converged());
        }
        if let Some(l) = &self.local {
            v["directional_coverage"] = json!(l.directional_coverage);
            if let Some((p, cell, c)) = l.at {
                v["at"] = json!([p.u(), p.v()]);
                v["cell"] = json!([cell.warp, cell.weft]);
                v["on_top"] = json!(if l.warp_on_top { "warp" } else { "weft" });
                v["coverage"] = json!(c);
            }
        }
        if !self.notes.is_empty() {
            v["notes"] = json!(self.notes);
        }
        let mut s = v.to_string();
        s.push('\n');
        s
    }

    /// A short human-readable table.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "fabric  {} ({})\nmethod  {}, {} facets, {}",
            self.fabric_name,
            self.file.display(),
            self.method.name(),
            self.facet.name(),
            self.settings
        );
        if let Some(how) = &self.secondary {
            let _ = writeln!(s, "I_2 by  {how}");
        }
        let _ = writeln!(
            s,
            "wi      theta {:6.2}  phi {:7.2}  (toward the light, degrees)",
            self.wi.theta, self.wi.phi
        );
        let _ = writeln!(
            s,
            "wo      theta {:6.2}  phi {:7.2}  (toward the eye, degrees)",
            self.wo.theta, self.wo.phi
        );
        if let Some(l) = self.local {
            if let Some((p, cell, _)) = l.at {
                let (top, under) = if l.warp_on_top {
                    (format!("warp {}", cell.warp), format!("weft {}", cell.weft))
                } else {
                    (format!("weft {}", cell.weft), format!("warp {}", cell.warp))
                };
                let _ = writeln!(
                    s,
                    "at      u {:.6}  v {:.6}  (period fractions): {top} over {under}",
                    p.u(),
                    p.v(),
                );
            }
        }
        for n in self.notes {
            let _ = writeln!(s, "note    {n}");
        }
        if self.horizon {
            let _ = writeln!(
                s,
                "note    a direction lies at the horizon: nothing is reflected"
            );
        }
        if self.transport.as_ref().is_some_and(|t| !t.converged()) {
            let _ = writeln!(
                s,
                "note    the orders do not die out (orders 16 and up carry over 0.1% of I_1): these \
                 facets reflect more than they receive, the sum is truncated (docs/science/transport.md)"
            );
        }
        let _ = writeln!(s, "{:8}{:>12} {:>12} {:>12}", "", "R", "G", "B");
        let row = |s: &mut String, name: &str, v: [f64; 3], unit: &str| {
            let _ = writeln!(
                s,
                "{name:8}{:>12.6} {:>12.6} {:>12.6}{unit}",
                v[0], v[1], v[2]
            );
        };
        if let Some(f) = &self.footprint {
            if let Some(i2) = f.i2 {
                row(&mut s, "I_2", i2, "");
            }
            row(&mut s, "I", f.i, "");
        } else {
            row(&mut s, "I_d", self.reflection.i_d, "");
            row(&mut s, "I_s", self.reflection.i_s, "");
        }
        if let (None, Some(s2)) = (&self.footprint, &self.reflection.secondary) {
            row(&mut s, "I_ss", s2.ss, "");
            row(&mut s, "I_sd", s2.sd, "");
            row(&mut s, "I_ds", s2.ds, "");
            row(&mut s, "I_dd", s2.dd, "");
            row(&mut s, "I_2", s2.total(), "");
        }
        if let Some(t) = &self.transport {
            for (k, (o, e)) in t.orders.iter().zip(&t.std_err).enumerate() {
                let err = format!("  +- {:.6} {:.6} {:.6}", e[0], e[1], e[2]);
                row(&mut s, &format!("I_{}", k + 1), *o, &err);
            }
            let err = |e: [f64; 3]| format!("  +- {:.6} {:.6} {:.6}", e[0], e[1], e[2]);
            row(&mut s, "I_2 par", t.i2_split[0], &err(t.i2_split_err[0]));
            row(&mut s, "I_2 perp", t.i2_split[1], &err(t.i2_split_err[1]));
            row(&mut s, "I_2..", t.multiple.0, &err(t.multiple.1));
            row(&mut s, "I", t.total, "");
        } else if self.footprint.is_none() {
            row(&mut s, "I", self.reflection.total(), "");
        }
        row(&mut s, "brdf", self.brdf, "  1/sr");
        if let Some(l) = &self.local {
            if let (Some((_, _, c)), Some(f)) = (l.at, &self.footprint) {
                let _ = writeln!(
                    s,
                    "coverage {c:.6}  (visible yarn over the footprint, {} periods wide: {})",
                    f.width, f.level
                );
            }
            let _ = writeln!(
                s,
                "coverage {:.6}  (directional: visible yarn over the period)",
                l.directional_coverage
            );
        }
        if let Some(rt) = &self.raytrace {
            row(
                &mut s,
                "std_err",
                rt.std_err,
                &format!("  (of I, {} samples)", rt.samples),
            );
        }
        s
    }
}
