//! The analytic model against the ray-traced ground truth: one error measure on the fixed
//! direction sets of `clothbake_core::directions`, shared by the test suite and `cargo xtask
//! validate`. It lives here, beside the tests, because only they may see both the model
//! (clothbake-core) and the truth (clothbake-truth).

use clothbake_core::directions::Pair;
use clothbake_core::{AnalyticModel, Fabric, FacetModel, Variant};
use clothbake_truth::{Caps, RayTracer};

/// One compared direction pair (channel-mean totals).
#[derive(Clone, Copy, Debug)]
pub struct Comparison {
    /// The directions.
    pub pair: Pair,
    /// Analytic total intensity (mean of R, G, B).
    pub analytic: f64,
    /// Ray-traced total intensity (mean of R, G, B).
    pub traced: f64,
    /// Its standard error.
    pub std_err: f64,
}

impl Comparison {
    /// |analytic - traced| / traced (0 when both vanish).
    pub fn rel_err(&self) -> f64 {
        if self.traced <= 0.0 {
            return if self.analytic <= 0.0 { 0.0 } else { 1.0 };
        }
        (self.analytic - self.traced).abs() / self.traced
    }
}

/// Statistics of a set of comparisons.
#[derive(Clone, Debug)]
pub struct Report {
    /// Every pair compared.
    pub rows: Vec<Comparison>,
}

impl Report {
    /// Mean relative error.
    pub fn mean_rel_err(&self) -> f64 {
        self.rows.iter().map(Comparison::rel_err).sum::<f64>() / self.rows.len().max(1) as f64
    }
    /// Largest relative error.
    pub fn max_rel_err(&self) -> f64 {
        self.rows
            .iter()
            .map(Comparison::rel_err)
            .fold(0.0, f64::max)
    }
    /// Mean signed relative difference (analytic - traced) / traced: the bias.
    pub fn mean_bias(&self) -> f64 {
        let v: Vec<f64> = self
            .rows
            .iter()
            .filter(|c| c.traced > 0.0)
            .map(|c| (c.analytic - c.traced) / c.traced)
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    }
    /// Mean relative standard error of the ground truth (its own noise).
    pub fn mean_noise(&self) -> f64 {
        self.rows
            .iter()
            .filter(|c| c.traced > 0.0)
            .map(|c| c.std_err / c.traced)
            .sum::<f64>()
            / self.rows.len().max(1) as f64
    }
}

/// Compares the analytic model with the ray tracer on `pairs`, `samples` primary rays each.
pub fn compare(
    fabric: &Fabric,
    facet: FacetModel,
    pairs: &[Pair],
    samples: usize,
    seed: u64,
) -> Report {
    compare_with(
        fabric,
        facet,
        Variant::default(),
        Caps::default(),
        pairs,
        samples,
        seed,
    )
}

/// As [`compare`] with a chosen variant rule.
pub fn compare_with(
    fabric: &Fabric,
    facet: FacetModel,
    variant: Variant,
    caps: Caps,
    pairs: &[Pair],
    samples: usize,
    seed: u64,
) -> Report {
    let model = AnalyticModel::with_variant(fabric, facet, variant)
        .expect("the fabrics compared are within every variant's limits");
    let tracer = RayTracer::new(fabric, facet).with_caps(caps);
    let mean = |v: [f64; 3]| (v[0] + v[1] + v[2]) / 3.0;
    let rows = pairs
        .iter()
        .enumerate()
        .map(|(k, &(wi, wo))| {
            let est = tracer.render(wi, wo, samples, seed.wrapping_add(k as u64));
            Comparison {
                pair: (wi, wo),
                analytic: mean(model.intensity(wi, wo).total()),
                traced: mean(est.reflection.total()),
                std_err: mean(est.std_err),
            }
        })
        .collect();
    Report { rows }
}
