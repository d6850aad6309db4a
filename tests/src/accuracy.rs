//! The loader's interpolation error against direct evaluation of the analytic model.
//!
//! A fabric is baked on a grid (the baker's direct reflection, Huo facets), loaded as a
//! [`Brdf`] at a chosen precision, and looked up at random direction pairs drawn uniformly in
//! solid angle over both hemispheres; each pair's error is the largest over R, G, B of
//! `|f_table - f_model| / f_model` (as `cos theta_i` multiplies both, this is also the relative
//! error of `f_r cos theta_i`). Pairs where the model gives 0 in some channel are counted apart.

use std::sync::atomic::AtomicBool;

use clothbake_bake::{bake, BakeOptions};
use clothbake_core::{AnalyticModel, Fabric, FacetModel, UnitVec3};
use clothbake_loader::{Brdf, Grid, Options, Precision, StoredTable};

/// Error statistics of one grid.
#[derive(Clone, Copy, Debug)]
pub struct Accuracy {
    /// The grid.
    pub grid: Grid,
    /// Direction pairs compared.
    pub pairs: usize,
    /// Pairs left out because the model gives 0 in some channel.
    pub zero: usize,
    /// Mean relative error.
    pub mean: f64,
    /// 99th-percentile relative error.
    pub p99: f64,
    /// Largest relative error.
    pub max: f64,
}

/// Random direction pairs, uniform in solid angle on the upper hemisphere (SplitMix64 from
/// `seed`), strictly above the horizon.
pub fn random_pairs(n: usize, seed: u64) -> Vec<(UnitVec3, UnitVec3)> {
    let mut rng = clothbake_core::rng::Rng::new(seed);
    let mut next = move || rng.next_f64();
    let mut dir = move || {
        let mu = 1e-6 + (1.0 - 1e-6) * next();
        UnitVec3::from_spherical(mu.acos(), std::f64::consts::TAU * next())
    };
    (0..n).map(|_| (dir(), dir())).collect()
}

/// The single-precision local-frame vector of a direction.
pub fn to_f32(w: UnitVec3) -> [f32; 3] {
    let v = w.get();
    [v.x as f32, v.y as f32, v.z as f32]
}

/// Bakes `fabric` on `grid` (direct reflection, analytic model, Huo facets) into a lookup whose
/// values are held at `precision` (f16: as a default EXR table holds them).
pub fn baked_brdf(fabric: &Fabric, grid: Grid, precision: Precision) -> Brdf {
    let opts = BakeOptions {
        grid,
        ..BakeOptions::default()
    };
    let baked = bake(fabric, &opts, &|_| {}, &AtomicBool::new(false)).expect("bake");
    let stored = StoredTable::from_table(baked.table, precision).expect("half-float range");
    let opts = Options {
        sampling: false,
        ..Options::default()
    };
    Brdf::from_stored(stored, opts).expect("valid table")
}

/// The error statistics of the lookup `brdf` of `fabric` against the analytic model at `pairs`
/// random direction pairs.
pub fn measure(fabric: &Fabric, brdf: &Brdf, pairs: usize, seed: u64) -> Accuracy {
    let model = AnalyticModel::new(fabric, FacetModel::Huo);
    let mut errors = Vec::with_capacity(pairs);
    let mut zero = 0;
    for (wi, wo) in random_pairs(pairs, seed) {
        let want = model.intensity(wi, wo).brdf(wi);
        let got = brdf.eval(to_f32(wi), to_f32(wo));
        if want.iter().any(|&w| w <= 0.0) {
            zero += 1;
            continue;
        }
        let e = (0..3)
            .map(|k| (f64::from(got[k]) - want[k]).abs() / want[k])
            .fold(0.0, f64::max);
        errors.push(e);
    }
    errors.sort_by(f64::total_cmp);
    let n = errors.len().max(1);
    Accuracy {
        grid: *brdf.grid(),
        pairs: errors.len(),
        zero,
        mean: errors.iter().sum::<f64>() / n as f64,
        p99: errors
            .get(((n as f64 * 0.99).ceil() as usize).saturating_sub(1))
            .copied()
            .unwrap_or(0.0),
        max: errors.last().copied().unwrap_or(0.0),
    }
}
