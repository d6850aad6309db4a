//! Comparing two tables of the same grid (`clothbake diff`, the golden-table test).
//!
//! Every value (cell and channel) of table A is compared with the same value of table B. A value
//! is within tolerance when `|a - b| <= abs + rel * |a|`.

use clothbake_loader::{Faces, Grid, Metadata, Spatial, Table};

/// Default relative tolerance of `clothbake diff`: about 8 units in the last place of an f32,
/// so that two bakes of the same model agree even across platforms whose maths libraries round
/// differently in the last bit.
pub const DEFAULT_REL: f64 = 1e-6;
/// Default absolute tolerance of `clothbake diff`, in 1/sr: a million times below a typical
/// cloth BRDF (0.1 /sr); it only matters for values that are (nearly) zero.
pub const DEFAULT_ABS: f64 = 1e-7;
/// The tolerance that covers the rounding of an f32 table to half floats (EXR `--precision
/// f16`): relative 2^-11 (half floats' rounding error, 4.88e-4) and, for the half subnormals
/// below 6.1e-5, absolute 2^-25 (3.0e-8).
pub const F16_TOLERANCE: Tolerance = Tolerance {
    rel: 4.9e-4,
    abs: 3e-8,
};

/// `|a - b| <= abs + rel * |a|`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Relative part, times |a|.
    pub rel: f64,
    /// Absolute part, 1/sr.
    pub abs: f64,
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance {
            rel: DEFAULT_REL,
            abs: DEFAULT_ABS,
        }
    }
}

/// A cell of a grid with its direction in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    /// Cell number ([`Grid::index`]).
    pub index: usize,
    /// Indices (ti, pi, to, po).
    pub indices: [u32; 4],
    /// Cell centre (theta_i, phi_i, theta_o, phi_o), degrees.
    pub degrees: [f64; 4],
}

impl Cell {
    /// The cell numbered `index` of `g`.
    pub fn of(g: &Grid, index: usize) -> Cell {
        let po = (index % g.n_phi_o as usize) as u32;
        let rest = index / g.n_phi_o as usize;
        let to = (rest % g.n_theta_o as usize) as u32;
        let rest = rest / g.n_theta_o as usize;
        let pi = (rest % g.n_phi_i as usize) as u32;
        let ti = (rest / g.n_phi_i as usize) as u32;
        Cell {
            index,
            indices: [ti, pi, to, po],
            degrees: [
                g.theta_i_deg(ti),
                g.phi_i_deg(pi),
                g.theta_o_deg(to),
                g.phi_o_deg(po),
            ],
        }
    }
}

impl std::fmt::Display for Cell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [ti, pi, to, po] = self.degrees;
        write!(
            f,
            "theta_i {ti:.2} phi_i {pi:.2} theta_o {to:.2} phi_o {po:.2} (cell {})",
            self.index
        )
    }
}

/// The value that is furthest beyond (or closest to) the tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Worst {
    /// Where.
    pub cell: Cell,
    /// Channel, in `clothbake_loader::spatial::channel_names` order of table A: 0 R, 1 G, 2 B,
    /// then a spatial table's class values.
    pub channel: usize,
    /// Value of A.
    pub a: f32,
    /// Value of B.
    pub b: f32,
    /// `|a - b| / (abs + rel |a|)`: above 1 means beyond the tolerance (infinite for a
    /// difference where the tolerance is 0).
    pub ratio: f64,
}

/// What `clothbake diff` reports.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Number of values compared (3 per cell).
    pub values: usize,
    /// Largest |a - b|.
    pub max_abs: f64,
    /// Mean |a - b|.
    pub mean_abs: f64,
    /// Largest |a - b| / |a| over the values with a != 0 (0 if there are none).
    pub max_rel: f64,
    /// Mean |a - b| / |a| over the values with a != 0.
    pub mean_rel: f64,
    /// Largest value of A (the PSNR's peak).
    pub peak: f64,
    /// Mean squared difference.
    pub mse: f64,
    /// Number of values beyond the tolerance.
    pub beyond: usize,
    /// The value furthest beyond the tolerance (the largest `ratio`, ties to the largest
    /// difference); `None` when the tables are identical.
    pub worst: Option<Worst>,
    /// The tolerance used.
    pub tolerance: Tolerance,
}

impl Comparison {
    /// Peak signal-to-noise ratio in dB, peak = max of A: infinite for identical tables, `None`
    /// when A has no positive value.
    pub fn psnr(&self) -> Option<f64> {
        if self.peak <= 0.0 {
            None
        } else if self.mse == 0.0 {
            Some(f64::INFINITY)
        } else {
            Some(10.0 * (self.peak * self.peak / self.mse).log10())
        }
    }

    /// True when every value is within the tolerance.
    pub fn within(&self) -> bool {
        self.beyond == 0
    }
}

/// The two grids differ.
#[derive(Clone, Debug, PartialEq)]
pub struct GridMismatch {
    /// Grid of A.
    pub a: Grid,
    /// Grid of B.
    pub b: Grid,
}

impl std::fmt::Display for GridMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (a, b) = (self.a, self.b);
        let differ: Vec<String> = [
            ("n_theta_i", a.n_theta_i, b.n_theta_i),
            ("n_phi_i", a.n_phi_i, b.n_phi_i),
            ("n_theta_o", a.n_theta_o, b.n_theta_o),
            ("n_phi_o", a.n_phi_o, b.n_phi_o),
        ]
        .iter()
        .filter(|(_, x, y)| x != y)
        .map(|(n, x, y)| format!("{n} {x} vs {y}"))
        .chain((a.faces != b.faces).then(|| {
            let name = |f: Faces| match f {
                Faces::One => "one",
                Faces::Two => "two",
            };
            format!("faces {} vs {}", name(a.faces), name(b.faces))
        }))
        .collect();
        write!(
            f,
            "different grids ({}): A is {a}, B is {b}",
            differ.join(", ")
        )
    }
}

/// What else a table carries that changes what it renders, field by field: one line for each
/// field of `a` and `b` that differs, naming it and saying how (empty when they agree): the
/// two-faced cloth's openness, a spatial table's cells, classes, albedos and visible areas, and
/// the yarns of its point level. The values themselves are [`compare`]'s. A spatial table
/// against an averaged one is compared by its averaged values, as [`compare`] does: the cells
/// and yarns only one of them has are not named.
pub fn carried_differences(a: &Metadata, b: &Metadata) -> Vec<String> {
    let mut out = Vec::new();
    let presence = |out: &mut Vec<String>, field: &str, x: bool, y: bool| -> bool {
        match (x, y) {
            (true, false) => out.push(format!("{field}: A has it, B has none")),
            (false, true) => out.push(format!("{field}: B has it, A has none")),
            _ => return x,
        }
        false
    };
    if presence(
        &mut out,
        "openness",
        a.openness.is_some(),
        b.openness.is_some(),
    ) {
        let wide = |m: &Metadata| -> Vec<f64> {
            let v = m.openness.as_deref().unwrap_or_default();
            v.iter().map(|&o| f64::from(o)).collect()
        };
        out.extend(values_differ("openness", &wide(a), &wide(b), "values"));
    }
    // A spatial table against an averaged one: their averaged values are what is compared
    // (a spatial table begins with them), and the cells one of them lacks are not a difference.
    match (&a.spatial, &b.spatial) {
        (Some(x), Some(y)) => out.extend(spatial_differences(x, y)),
        (None, None) => {}
        _ => return out,
    }
    if presence(&mut out, "yarns", a.yarns.is_some(), b.yarns.is_some()) && a.yarns != b.yarns {
        out.push("yarns: the point level's yarns or finishes differ".into());
    }
    out
}

/// The fields of two spatial layouts that differ ([`carried_differences`]).
fn spatial_differences(x: &Spatial, y: &Spatial) -> Vec<String> {
    let mut out = Vec::new();
    if x.classes != y.classes {
        out.push(format!("spatial.classes: {} vs {}", x.classes, y.classes));
    }
    if x.secondary != y.secondary {
        out.push(format!(
            "spatial.secondary: {} vs {} (the classes hold the second bounce)",
            x.secondary, y.secondary
        ));
    }
    type Field = (&'static str, &'static str, fn(&Spatial) -> Vec<f64>);
    let fields: [Field; 6] = [
        ("spatial.u_edges", "edges", |s| s.u_edges.clone()),
        ("spatial.v_edges", "edges", |s| s.v_edges.clone()),
        ("spatial.cell_class", "cells", |s| {
            s.cell_class.iter().map(|&c| f64::from(c)).collect()
        }),
        ("spatial.cell_albedo", "values", |s| {
            s.cell_albedo
                .iter()
                .flatten()
                .map(|&a| f64::from(a))
                .collect()
        }),
        ("spatial.visible", "values", |s| {
            s.visible.iter().map(|&v| f64::from(v)).collect()
        }),
        ("spatial.cell_neighbours", "values", |s| {
            let flat = s.cell_neighbours.iter().flatten().flatten();
            flat.map(|&a| f64::from(a)).collect()
        }),
    ];
    for (field, what, get) in fields {
        out.extend(values_differ(field, &get(x), &get(y), what));
    }
    out
}

/// `field: N of M <what> differ (max |a - b| D)`, or a count mismatch; `None` when equal (bit
/// for bit: the stored f32 and u32 values are exact in f64).
fn values_differ(field: &str, a: &[f64], b: &[f64], what: &str) -> Option<String> {
    if a.len() != b.len() {
        return Some(format!("{field}: {} vs {} {what}", a.len(), b.len()));
    }
    let (mut n, mut max) = (0usize, 0.0f64);
    for (&x, &y) in a.iter().zip(b) {
        if x.to_bits() != y.to_bits() {
            n += 1;
            max = max.max((x - y).abs());
        }
    }
    (n > 0).then(|| {
        format!(
            "{field}: {n} of {} {what} differ (max |a - b| {max:.3e})",
            a.len()
        )
    })
}

/// Compares every value of `a` with the same value of `b` (only the averaged RGB values when
/// one is a spatial table and the other not, or their classes differ).
pub fn compare(a: &Table, b: &Table, tol: Tolerance) -> Result<Comparison, GridMismatch> {
    if a.meta.grid != b.meta.grid {
        return Err(GridMismatch {
            a: a.meta.grid,
            b: b.meta.grid,
        });
    }
    let g = a.meta.grid;
    // A spatial table begins with its averaged values: against an averaged table, or a
    // spatial one of other classes, the averaged parts are compared.
    let classes = |t: &Table| t.meta.spatial.as_ref().map(|s| (s.classes, s.secondary));
    let n = if a.values.len() == b.values.len() && classes(a) == classes(b) {
        a.values.len()
    } else {
        3 * g.len()
    };
    let (mut sum_abs, mut sum_sq, mut sum_rel, mut n_rel) = (0.0, 0.0, 0.0, 0usize);
    let (mut max_abs, mut max_rel, mut peak) = (0.0f64, 0.0f64, f64::NEG_INFINITY);
    let mut beyond = 0;
    let mut worst: Option<(f64, f64, usize)> = None; // (ratio, diff, value index)
    for (k, (&x, &y)) in a.values[..n].iter().zip(&b.values[..n]).enumerate() {
        let (x64, y64) = (f64::from(x), f64::from(y));
        let d = (x64 - y64).abs();
        peak = peak.max(x64);
        sum_abs += d;
        sum_sq += d * d;
        max_abs = max_abs.max(d);
        if x != 0.0 {
            let r = d / x64.abs();
            sum_rel += r;
            n_rel += 1;
            max_rel = max_rel.max(r);
        }
        let t = tol.abs + tol.rel * x64.abs();
        if d > t {
            beyond += 1;
        }
        if d > 0.0 {
            let ratio = if t > 0.0 { d / t } else { f64::INFINITY };
            let better = match worst {
                None => true,
                Some((wr, wd, _)) => (ratio, d) > (wr, wd),
            };
            if better {
                worst = Some((ratio, d, k));
            }
        }
    }
    let nf = n.max(1) as f64;
    Ok(Comparison {
        values: n,
        max_abs,
        mean_abs: sum_abs / nf,
        max_rel,
        mean_rel: if n_rel > 0 {
            sum_rel / n_rel as f64
        } else {
            0.0
        },
        peak: if n > 0 { peak } else { 0.0 },
        mse: sum_sq / nf,
        beyond,
        worst: worst.map(|(ratio, _, k)| {
            let (cell, channel) = cell_channel(a, k);
            Worst {
                cell: Cell::of(&g, cell),
                channel,
                a: a.values[k],
                b: b.values[k],
                ratio,
            }
        }),
        tolerance: tol,
    })
}

/// The grid cell and the channel (in `channel_names` order) of value `k` of table `t`.
fn cell_channel(t: &Table, k: usize) -> (usize, usize) {
    clothbake_loader::spatial::value_cell_channel(k, t.meta.grid.len(), t.meta.class_lanes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_loader::Metadata;

    fn table(g: Grid, f: impl Fn(usize) -> f32) -> Table {
        let meta = Metadata::new("t", g, "{}", "{}", "none");
        Table::new(meta, (0..3 * g.len()).map(f).collect()).unwrap()
    }

    const G: Grid = Grid::new(2, 3, 4, 5);

    #[test]
    fn identical_tables() {
        let a = table(G, |k| k as f32 * 0.1);
        let c = compare(&a, &a, Tolerance { rel: 0.0, abs: 0.0 }).unwrap();
        assert!(c.within());
        assert_eq!((c.max_abs, c.mean_abs, c.max_rel), (0.0, 0.0, 0.0));
        assert_eq!(c.worst, None);
        assert_eq!(c.psnr(), Some(f64::INFINITY));
        assert_eq!(c.values, 360);
    }

    #[test]
    fn a_class_value_is_named_by_its_channel_and_cell() {
        // A spatial table of 2 classes with the second bounce (6 values each): value k of
        // class 1, lane 3 (plus_both), grid cell 17 is 3 n + 6 (n + 17) + 3.
        let spatial = |g: Grid| Spatial {
            classes: 2,
            u_edges: vec![0.0, 1.0],
            v_edges: vec![0.0, 1.0],
            cell_class: vec![0],
            cell_albedo: vec![[0.5; 3]],
            visible: vec![0.0; 2 * (g.n_theta_o * g.n_phi_o) as usize],
            secondary: true,
            cell_neighbours: vec![[[0.0; 3]; 2]],
        };
        let n = G.len();
        let make = |bump: bool| {
            let meta = Metadata {
                spatial: Some(spatial(G)),
                ..Metadata::new("t", G, "{}", "{}", "none")
            };
            let k = 3 * n + 6 * (n + 17) + 3;
            let values = (0..15 * n)
                .map(|i| if bump && i == k { 2.0 } else { 1.0 })
                .collect();
            Table::new(meta, values).unwrap()
        };
        let c = compare(&make(false), &make(true), Tolerance::default()).unwrap();
        let w = c.worst.unwrap();
        assert_eq!((w.cell.index, w.channel), (17, 3 + 6 + 3));
        let names = clothbake_loader::spatial::channel_names(2, 6);
        assert_eq!(names[w.channel], "class1.plus_both");
    }

    #[test]
    fn one_value_differs() {
        let a = table(G, |k| 1.0 + k as f32);
        let b = table(G, |k| {
            if k == 100 {
                101.0 + 0.5
            } else {
                1.0 + k as f32
            }
        });
        let c = compare(&a, &b, Tolerance::default()).unwrap();
        assert!(!c.within());
        assert_eq!(c.beyond, 1);
        assert_eq!(c.max_abs, 0.5);
        assert!((c.max_rel - 0.5 / 101.0).abs() < 1e-12);
        let w = c.worst.unwrap();
        assert_eq!((w.cell.index, w.channel, w.a, w.b), (33, 1, 101.0, 101.5));
        assert_eq!(Cell::of(&G, 33).indices, [0, 1, 2, 3]);
        assert_eq!(G.index(0, 1, 2, 3), 33);
        let psnr = c.psnr().unwrap();
        let want = 10.0 * (360.0f64 * 360.0 / (0.25 / 360.0)).log10();
        assert!((psnr - want).abs() < 1e-9, "{psnr} {want}");
        // A loose tolerance accepts it.
        let c = compare(
            &a,
            &b,
            Tolerance {
                rel: 0.01,
                abs: 0.0,
            },
        )
        .unwrap();
        assert!(c.within());
        assert!(c.worst.unwrap().ratio < 1.0);
    }

    #[test]
    fn zeros_use_the_absolute_tolerance() {
        let a = table(G, |_| 0.0);
        let b = table(G, |k| if k == 7 { 5e-8 } else { 0.0 });
        assert!(compare(&a, &b, Tolerance::default()).unwrap().within());
        let c = compare(&a, &b, Tolerance { rel: 1.0, abs: 0.0 }).unwrap();
        assert!(!c.within());
        assert_eq!(c.worst.unwrap().ratio, f64::INFINITY);
        assert_eq!(c.max_rel, 0.0);
        assert_eq!(c.psnr(), None);
    }

    #[test]
    fn grids_must_match() {
        let a = table(G, |_| 1.0);
        let b = table(
            Grid {
                n_phi_o: 6,
                n_theta_i: 3,
                ..G
            },
            |_| 1.0,
        );
        let e = compare(&a, &b, Tolerance::default()).unwrap_err();
        let s = e.to_string();
        assert!(s.contains("n_theta_i 2 vs 3, n_phi_o 5 vs 6"), "{s}");
    }

    /// A spatial table of the gingham's period (8 x 8 threads of two colours), one bounce.
    fn spatial_gingham() -> Table {
        let f = clothbake_core::Fabric::from_path(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/gingham.wif"),
        )
        .unwrap();
        let opts = crate::BakeOptions {
            grid: Grid::new(2, 4, 2, 4),
            spatial: true,
            ..crate::BakeOptions::default()
        };
        crate::bake(
            &f,
            &opts,
            &|_| {},
            &std::sync::atomic::AtomicBool::new(false),
        )
        .unwrap()
        .table
    }

    #[test]
    fn what_a_table_carries_is_compared_field_by_field() {
        let a = spatial_gingham();
        assert!(carried_differences(&a.meta, &a.meta).is_empty());
        let sp = a.meta.spatial.as_ref().unwrap();
        assert!(a.meta.yarns.is_some() && sp.classes > 1);
        // Each field changed alone is named, with how much.
        let changed = |edit: &dyn Fn(&mut Metadata)| {
            let mut m = a.meta.clone();
            edit(&mut m);
            carried_differences(&a.meta, &m)
        };
        let d = changed(&|m| m.spatial.as_mut().unwrap().cell_albedo[3][1] += 0.25);
        let cells = sp.cell_albedo.len();
        assert_eq!(
            d,
            [format!(
                "spatial.cell_albedo: 1 of {} values differ (max |a - b| 2.500e-1)",
                3 * cells
            )]
        );
        let d = changed(&|m| {
            let s = m.spatial.as_mut().unwrap();
            s.cell_class[0] = (s.cell_class[0] + 1) % s.classes;
        });
        assert!(d[0].starts_with("spatial.cell_class: 1 of "), "{d:?}");
        let d = changed(&|m| m.spatial.as_mut().unwrap().visible[5] *= 0.5);
        assert!(d[0].starts_with("spatial.visible: 1 of "), "{d:?}");
        let d = changed(&|m| m.yarns = None);
        assert_eq!(d, ["yarns: A has it, B has none"]);
        // Against an averaged table, the averages are what is compared.
        let d = changed(&|m| {
            m.spatial = None;
            m.yarns = None;
        });
        assert!(d.is_empty(), "{d:?}");
        // The two-faced cloth's openness: present in one, and one value of it different.
        let open = |m: &mut Metadata| m.openness = Some(vec![0.5; 8]);
        let d = changed(&open);
        assert_eq!(d, ["openness: B has it, A has none"]);
        let mut b = a.meta.clone();
        open(&mut b);
        let mut c = b.clone();
        c.openness.as_mut().unwrap()[2] = 1.0;
        assert_eq!(
            carried_differences(&b, &c),
            ["openness: 1 of 8 values differ (max |a - b| 5.000e-1)"]
        );
    }

    #[test]
    fn a_grid_of_another_face_count_is_named() {
        let one = Grid::new(2, 4, 2, 4);
        let e = GridMismatch {
            a: one,
            b: one.two_faced(),
        };
        let msg = e.to_string();
        assert!(
            msg.starts_with("different grids (") && msg.contains("faces one vs two"),
            "{msg}"
        );
    }
}
