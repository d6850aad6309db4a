//! The Monte Carlo estimate of the tracers: [`Estimate`], the batch sums and the ratio estimator
//! with its standard error.

use clothbake_fabric::Reflection;

/// Number of independent batches the samples are split into to estimate the standard error.
pub const BATCHES: usize = 16;

/// A Monte Carlo estimate of the reflected intensity.
///
/// The standard error is that of the ratio estimator R = sum(S_b) / sum(H_b) over the batches b
/// (S_b: summed shading, H_b: yarn hits): with B non-empty batches, R_b = S_b / H_b and weights
/// w_b = H_b / mean(H),
/// `std_err^2 = sum_b w_b^2 (R_b - R)^2 / (B (B - 1))`,
/// i.e. the standard error of the mean of the batch ratios, each weighted by its share of the
/// hits (the usual delta-method variance of a ratio estimator; batches without hits contribute
/// their zero weight instead of an undefined ratio). It is infinite when fewer than two batches
/// received rays and zero when there were no yarn hits.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    /// The estimated intensity (diffuse and specular parts).
    pub reflection: Reflection,
    /// Standard error of the total intensity I = I_d + I_s, per channel.
    pub std_err: [f64; 3],
    /// Primary rays whose first hit was a yarn (the denominator).
    pub yarn_hits: usize,
    /// Primary rays traced.
    pub rays: usize,
}

/// Per-batch sums of the ray tracer's estimator.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct BatchSums {
    /// Sum of diffuse factor times albedo, per channel.
    pub(crate) diffuse: [f64; 3],
    /// Sum of the specular intensity.
    pub(crate) specular: f64,
    /// Primary rays whose first hit was counted yarn.
    pub(crate) hits: u64,
    /// Primary rays traced.
    pub(crate) rays: u64,
}

impl BatchSums {
    /// Summed shading of the quantity selected by `f(diffuse, specular)`.
    fn shade(&self, f: impl Fn(&[f64; 3], f64) -> f64) -> f64 {
        f(&self.diffuse, self.specular)
    }
}

/// Ratio estimate and its standard error (see [`Estimate`]) of the per-hit mean of `f`.
pub(crate) fn ratio_and_error(sums: &[BatchSums], f: impl Fn(&[f64; 3], f64) -> f64) -> (f64, f64) {
    let batches: Vec<(f64, u64, u64)> =
        sums.iter().map(|b| (b.shade(&f), b.hits, b.rays)).collect();
    batch_ratio(&batches)
}

/// The ratio estimate (sum of shading) / (yarn hits) over batches given as (sum, hits, rays),
/// and its standard error from the spread of the batches: the estimator of [`Estimate`],
/// shared with the path tracer.
pub(crate) fn batch_ratio(batches: &[(f64, u64, u64)]) -> (f64, f64) {
    let h: u64 = batches.iter().map(|b| b.1).sum();
    if h == 0 {
        return (0.0, 0.0);
    }
    let h = h as f64;
    let r = batches.iter().map(|b| b.0).sum::<f64>() / h;
    let nb = batches.iter().filter(|b| b.2 > 0).count();
    if nb < 2 {
        return (r, f64::INFINITY);
    }
    let mean_h = h / nb as f64;
    // (w_b (R_b - R))^2 = ((S_b - R H_b) / mean(H))^2.
    let ss: f64 = batches
        .iter()
        .filter(|b| b.2 > 0)
        .map(|b| ((b.0 - r * b.1 as f64) / mean_h).powi(2))
        .sum();
    (r, (ss / (nb * (nb - 1)) as f64).sqrt())
}

/// The estimate of the batch sums.
pub(crate) fn estimate(sums: &[BatchSums]) -> Estimate {
    let mut e = Estimate {
        yarn_hits: sums.iter().map(|b| b.hits as usize).sum(),
        rays: sums.iter().map(|b| b.rays as usize).sum(),
        ..Estimate::default()
    };
    for k in 0..3 {
        e.reflection.i_d[k] = ratio_and_error(sums, |d, _| d[k]).0;
        e.std_err[k] = ratio_and_error(sums, |d, s| d[k] + s).1;
    }
    e.reflection.i_s = [ratio_and_error(sums, |_, s| s).0; 3];
    e
}
