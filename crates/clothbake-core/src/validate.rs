//! Validation of the analytic model against the ray-traced ground truth: one fixed set of
//! directions, one error measure, shared by the test suite and `cargo xtask validate`.

use crate::analytic::{AnalyticModel, Variant};
use crate::fabric::Fabric;
use crate::facet::FacetModel;
use crate::truth::{Caps, RayTracer};
use crate::vec3::UnitVec3;

/// A direction pair: toward the light, toward the eye.
pub type Pair = (UnitVec3, UnitVec3);

/// The fixed validation set: `n` (wi, wo) pairs with both polar angles at most `max_theta_deg`,
/// spread over the hemisphere by a low-discrepancy (golden-ratio) sequence. Deterministic.
pub fn direction_set(n: usize, max_theta_deg: f64) -> Vec<Pair> {
    let g = |k: usize, a: f64| ((k as f64 + 0.5) * a).fract();
    let cmax = (1.0 - max_theta_deg.to_radians().cos()).max(0.0);
    (0..n)
        .map(|k| {
            // Uniform in solid angle: cos(theta) uniform on [cos max, 1].
            let ti = (1.0 - g(k, 0.618_033_988_749_895) * cmax).acos();
            let pi = g(k, 0.754_877_666_246_693) * 360.0;
            let to = (1.0 - g(k, 0.569_840_290_998_053) * cmax).acos();
            let po = g(k, 0.412_454_033_640_107) * 360.0;
            (
                UnitVec3::from_spherical(ti, pi.to_radians()),
                UnitVec3::from_spherical(to, po.to_radians()),
            )
        })
        .collect()
}

/// Pairs on which the model's special branches are taken: normal incidence, the symmetry
/// planes (phi a multiple of 90 degrees: a projection's zero component), a diagonal and near
/// grazing (89.99 degrees), for tests that compare two evaluations of the model.
pub fn edge_pairs() -> Vec<Pair> {
    [
        (0.0, 0.0, 0.0, 0.0),
        (30.0, 0.0, 45.0, 180.0),
        (60.0, 90.0, 20.0, 270.0),
        (89.99, 0.0, 89.99, 90.0),
        (45.0, 45.0, 45.0, 225.0),
        (0.0, 0.0, 70.0, 180.0),
    ]
    .map(|(ti, pi, to, po)| {
        (
            UnitVec3::from_degrees(ti, pi),
            UnitVec3::from_degrees(to, po),
        )
    })
    .to_vec()
}

/// The direction set of the secondary-reflection accuracy table and benchmarks
/// (`cargo xtask ir-accuracy`, `cargo bench -p clothbake-core -- secondary`): 40 pairs of
/// [`direction_set`] up to 85 degrees, and 4 grazing pairs whose light and eye run along the
/// +Y threads (the axial lobes' hard case).
pub fn secondary_direction_set() -> Vec<Pair> {
    let mut v = direction_set(40, 85.0);
    for ((ti, pi), (to, po)) in [
        ((60.0, 90.0), (60.0, 270.0)),
        ((80.0, 85.0), (70.0, 275.0)),
        ((45.0, 80.0), (75.0, 260.0)),
        ((85.0, 90.0), (85.0, 90.0)),
    ] {
        v.push((
            UnitVec3::from_degrees(ti, pi),
            UnitVec3::from_degrees(to, po),
        ));
    }
    v
}

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
    let model = AnalyticModel::with_variant(fabric, facet, variant);
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
