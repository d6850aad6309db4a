//! The bake: evaluate f_r on every cell of a (theta_i, phi_i, theta_o, phi_o) grid.
//!
//! * Cell-centred grid (see `clothbake_loader::Grid`); values are f_r = I / (pi cos theta_i) in
//!   1/sr, RGB, from the analytic model (or the ray tracer, for small ground-truth tables).
//! * Symmetry: where the fabric's micro-geometry is invariant under mirror x, mirror y or a
//!   rotation by 180 degrees ([`clothbake_core::symmetry`]), so is its BRDF, exactly. Only one
//!   cell of each orbit of the symmetry group on the (phi_i, phi_o) indices is evaluated; the
//!   others receive a copy of its value.
//! * Deterministic: every cell is a pure function of the inputs; the parallel sweep collects in
//!   cell order, so the table is bit-identical for any number of threads.

use clothbake_core::symmetry::{symmetries, Symmetry};
use clothbake_core::{AnalyticModel, Caps, Fabric, FacetModel, RayTracer, UnitVec3, Variant};
use clothbake_loader::{Grid, Metadata, Table, FORMAT_VERSION};
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The default grid: 32 x 64 x 32 x 64 cells (2.8 degrees in theta, 5.6 in phi).
pub const DEFAULT_GRID: Grid = Grid {
    n_theta_i: 32,
    n_phi_i: 64,
    n_theta_o: 32,
    n_phi_o: 64,
};

/// How each cell is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "lowercase", tag = "method")]
pub enum Method {
    /// The analytic model (thesis ch. 3-4).
    Analytic {
        /// Analytic variant.
        variant: Variant,
    },
    /// The ray-traced ground truth, `samples` rays per cell, seeded per cell.
    Raytrace {
        /// Primary rays per cell.
        samples: usize,
        /// Base seed; cell c uses seed + c.
        seed: u64,
        /// End-cap convention.
        #[serde(skip)]
        caps: Caps,
    },
}

/// Everything that determines a table besides the fabric.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BakeOptions {
    /// The grid.
    pub grid: Grid,
    /// Facet model.
    pub facet: FacetModel,
    /// Evaluation method.
    #[serde(flatten)]
    pub method: Method,
    /// Bounces (1: direct reflection only).
    pub bounces: u32,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            grid: DEFAULT_GRID,
            facet: FacetModel::Huo,
            method: Method::Analytic {
                variant: Variant::default(),
            },
            bounces: 1,
        }
    }
}

/// Why a bake stopped without a table.
#[derive(Debug, Clone, PartialEq)]
pub enum BakeError {
    /// The cancel flag was raised (Ctrl-C).
    Cancelled,
    /// The options cannot be baked (message says why and how to fix it).
    Invalid(String),
}

/// A finished bake.
#[derive(Debug, Clone)]
pub struct Baked {
    /// The table with its metadata.
    pub table: Table,
    /// The symmetries used.
    pub symmetries: Vec<Symmetry>,
    /// Cells actually evaluated (the rest are copies).
    pub evaluated: usize,
}

/// The grid's direction for polar index `k` of `n` and azimuth index `m` of `nm`.
fn direction(k: u32, n: u32, m: u32, nm: u32) -> UnitVec3 {
    let theta = (k as f64 + 0.5) * 90.0 / n as f64;
    let phi = (m as f64 + 0.5) * 360.0 / nm as f64;
    UnitVec3::from_degrees(theta, phi)
}

/// The symmetries usable on this grid: those of the fabric that map azimuth cells onto cells.
fn usable(fabric: &Fabric, g: &Grid) -> Vec<Symmetry> {
    symmetries(fabric)
        .into_iter()
        .filter(|s| {
            s.phi_index(0, g.n_phi_i as usize).is_some()
                && s.phi_index(0, g.n_phi_o as usize).is_some()
        })
        .collect()
}

/// The representative of (pi, po)'s orbit: the smallest pair reachable by the group the
/// symmetries generate (here at most {1, Mx, My, R}, closed under composition).
fn representative(pi: usize, po: usize, syms: &[Symmetry], g: &Grid) -> (usize, usize) {
    let (ni, no) = (g.n_phi_i as usize, g.n_phi_o as usize);
    let mut orbit = vec![(pi, po)];
    let mut k = 0;
    while k < orbit.len() {
        let (a, b) = orbit[k];
        for s in syms {
            let img = (s.phi_index(a, ni).unwrap(), s.phi_index(b, no).unwrap());
            if !orbit.contains(&img) {
                orbit.push(img);
            }
        }
        k += 1;
    }
    orbit.into_iter().min().unwrap()
}

/// Bakes `fabric` on `opts.grid`. `progress` receives the number of cells finished so far (it
/// is called from worker threads); raising `cancel` stops the sweep with [`BakeError::Cancelled`].
/// Runs on the current rayon pool (use `ThreadPool::install` to choose the thread count).
pub fn bake(
    fabric: &Fabric,
    opts: &BakeOptions,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) -> Result<Baked, BakeError> {
    let g = opts.grid;
    g.validate()
        .map_err(|e| BakeError::Invalid(e.to_string()))?;
    if opts.bounces != 1 {
        return Err(BakeError::Invalid(format!(
            "--bounces {} is not available yet (inter-reflection, thesis ch. 5, is not built); use --bounces 1",
            opts.bounces
        )));
    }
    let syms = usable(fabric, &g);
    let eval: Box<dyn Fn(usize, UnitVec3, UnitVec3) -> [f64; 3] + Sync> = match opts.method {
        Method::Analytic { variant } => {
            let m = AnalyticModel::with_variant(fabric, opts.facet, variant);
            Box::new(move |_, wi, wo| m.eval(wi, wo).brdf(wi))
        }
        Method::Raytrace {
            samples,
            seed,
            caps,
        } => {
            let rt = RayTracer::new(fabric, opts.facet).with_caps(caps);
            Box::new(move |c, wi, wo| {
                rt.render(wi, wo, samples, seed.wrapping_add(c as u64))
                    .reflection
                    .brdf(wi)
            })
        }
    };
    let (nti, npi, nto, npo) = (g.n_theta_i, g.n_phi_i, g.n_theta_o, g.n_phi_o);
    let row_len = (nto * npo) as usize;
    let done = AtomicU64::new(0);
    // One row per (theta_i, phi_i): its canonical cells' values, in cell order.
    let rows: Vec<Vec<[f32; 3]>> = (0..(nti * npi) as usize)
        .into_par_iter()
        .map(|row| {
            if cancel.load(Ordering::Relaxed) {
                return Vec::new();
            }
            let (ti, pi) = ((row / npi as usize) as u32, (row % npi as usize) as u32);
            let wi = direction(ti, nti, pi, npi);
            let mut out = Vec::new();
            for to in 0..nto {
                for po in 0..npo {
                    if representative(pi as usize, po as usize, &syms, &g)
                        != (pi as usize, po as usize)
                    {
                        continue;
                    }
                    let c = g.index(ti, pi, to, po);
                    let v = eval(c, wi, direction(to, nto, po, npo));
                    out.push(v.map(|x| x as f32));
                }
            }
            progress(done.fetch_add(row_len as u64, Ordering::Relaxed) + row_len as u64);
            out
        })
        .collect();
    if cancel.load(Ordering::Relaxed) {
        return Err(BakeError::Cancelled);
    }
    // Scatter: canonical cells first, then copies from their representatives.
    let mut values = vec![f32::NAN; g.len() * 3];
    let mut evaluated = 0;
    for (row, vals) in rows.iter().enumerate() {
        let (ti, pi) = (row / npi as usize, row % npi as usize);
        let mut it = vals.iter();
        for to in 0..nto as usize {
            for po in 0..npo as usize {
                if representative(pi, po, &syms, &g) == (pi, po) {
                    let v = it.next().expect("one value per canonical cell");
                    values[3 * g.index(ti as u32, pi as u32, to as u32, po as u32)..][..3]
                        .copy_from_slice(v);
                    evaluated += 1;
                }
            }
        }
    }
    for ti in 0..nti as usize {
        for pi in 0..npi as usize {
            for to in 0..nto as usize {
                for po in 0..npo as usize {
                    let (ri, ro) = representative(pi, po, &syms, &g);
                    if (ri, ro) != (pi, po) {
                        let src = 3 * g.index(ti as u32, ri as u32, to as u32, ro as u32);
                        let dst = 3 * g.index(ti as u32, pi as u32, to as u32, po as u32);
                        values.copy_within(src..src + 3, dst);
                    }
                }
            }
        }
    }
    let symmetry = if syms.is_empty() {
        "none".to_string()
    } else {
        syms.iter().map(|s| s.name()).collect::<Vec<_>>().join(", ")
    };
    let meta = Metadata {
        format_version: FORMAT_VERSION,
        tool: format!("clothbake {}", env!("CARGO_PKG_VERSION")),
        grid: g,
        centring: "cell".into(),
        quantity: "f_r".into(),
        units: "1/sr".into(),
        fabric_json: fabric.to_json().to_string(),
        options_json: serde_json::to_string(opts).expect("options serialise"),
        symmetry,
    };
    let table = Table::new(meta, values).map_err(|e| BakeError::Invalid(e.to_string()))?;
    Ok(Baked {
        table,
        symmetries: syms,
        evaluated,
    })
}
