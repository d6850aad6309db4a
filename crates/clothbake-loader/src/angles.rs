//! Directions to table angles, fast: polar angle and azimuth of a local-frame vector.
//!
//! The lookup needs four angles per call; the standard library's `acos`/`atan2` alone would
//! cost more than the whole interpolation. [`atan2`] here is a degree-11 odd polynomial on
//! [0, 1] (coefficients fitted by iteratively reweighted least squares toward the minimax
//! fit) with octant reduction: absolute error under 2e-6 rad (1e-4 degrees, a
//! thirty-thousandth of a default grid cell), tested against `f64::atan2`.

use std::f32::consts::{FRAC_PI_2, PI};

/// Directions with `cos theta` at or below this are on or below the horizon: zero. The one
/// horizon of every reflectance, [`clothbake_bsdf::HORIZON_COS`], in the f32 the lookups
/// compare their f32 directions with (1e-9 rounded to f32 once: widening each `z` to compare
/// it in f64 would move the horizon by the difference of the two roundings, about 3e-17, and
/// cost a conversion per direction on the render path).
pub const HORIZON_COS: f32 = clothbake_bsdf::HORIZON_COS as f32;

/// True when a unit vector is above the horizon (`z > 1e-9`); false for NaN.
#[inline(always)]
pub fn above_horizon(w: [f32; 3]) -> bool {
    w[2] > HORIZON_COS
}

/// True when a pair has a value: both directions above the horizon, no component NaN.
#[inline(always)]
pub(crate) fn has_value(wi: [f32; 3], wo: [f32; 3]) -> bool {
    let nan = wi.iter().chain(&wo).any(|x| x.is_nan());
    !nan && above_horizon(wi) && above_horizon(wo)
}

/// Coefficients `c_j` of `atan(a) ~ a * sum_j c_j a^(2j)` on `0 <= a <= 1`.
pub(crate) const ATAN_COEFFS: [f32; 6] = [
    0.999_977_2,
    -0.332_622_83,
    0.193_540_4,
    -0.116_426_51,
    0.052_647_36,
    -0.011_719_135,
];

/// `atan(a)` for `0 <= a <= 1`.
#[inline(always)]
fn atan_unit(a: f32) -> f32 {
    let s = a * a;
    let c = &ATAN_COEFFS;
    // Horner; plain products and sums (`mul_add` is a slow library call without FMA hardware).
    let p = ((((c[5] * s + c[4]) * s + c[3]) * s + c[2]) * s + c[1]) * s + c[0];
    a * p
}

/// `atan2(y, x)` in radians, in `[-pi, pi]`; 0 for `(0, 0)`.
#[inline(always)]
pub fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = if ax < ay { (ax, ay) } else { (ay, ax) };
    let a = if hi > 0.0 { lo / hi } else { 0.0 };
    let mut r = atan_unit(a);
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 {
        -r
    } else {
        r
    }
}

/// Polar angle from +Z and azimuth from +X toward +Y (in `[-pi, pi]`), radians, of a vector
/// (any length: only its direction matters).
#[inline(always)]
pub fn theta_phi(v: [f32; 3]) -> (f32, f32) {
    let rho = (v[0] * v[0] + v[1] * v[1]).sqrt();
    (atan2(rho, v[2]), atan2(v[1], v[0]))
}

/// The unit vector of polar angle `theta` and azimuth `phi` (radians).
pub fn direction(theta: f32, phi: f32) -> [f32; 3] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * cp, st * sp, ct]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_horizon_is_the_bsdf_crates_rounded_to_f32() {
        assert_eq!(HORIZON_COS.to_bits(), 1e-9f32.to_bits());
        assert_eq!(f64::from(HORIZON_COS) as f32, HORIZON_COS);
        assert!((f64::from(HORIZON_COS) - clothbake_bsdf::HORIZON_COS).abs() < 1e-16);
    }

    #[test]
    fn atan2_is_within_2e6_rad_of_the_standard_library_everywhere() {
        let mut worst = 0f64;
        for i in 0..=2000 {
            for j in 0..=2000 {
                let (x, y) = ((i as f32 - 1000.0) / 997.0, (j as f32 - 1000.0) / 991.0);
                let e = (f64::from(atan2(y, x)) - f64::from(y).atan2(f64::from(x))).abs();
                worst = worst.max(e);
            }
        }
        assert!(worst < 2e-6, "worst error {worst} rad");
        assert_eq!(atan2(0.0, 0.0), 0.0);
    }

    #[test]
    fn theta_phi_inverts_direction() {
        for k in 0..100 {
            let theta = 0.01 + 1.55 * k as f32 / 100.0;
            let phi = -3.1 + 6.2 * ((k * 37) % 100) as f32 / 100.0;
            let (t, p) = theta_phi(direction(theta, phi));
            assert!(
                (t - theta).abs() < 1e-5 && (p - phi).abs() < 1e-5,
                "{theta} {phi}"
            );
        }
    }
}
