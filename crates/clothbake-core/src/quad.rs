//! Numerical quadrature: adaptive Gauss-Kronrod (G7/K15), accurate where the thesis used
//! adaptive Simpson.

pub(crate) const XK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
pub(crate) const WK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
pub(crate) const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// One G7/K15 panel: (Kronrod estimate, |Kronrod - Gauss| error estimate).
pub fn gk15(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut k = WK[7] * fc;
    let mut g = WG[3] * fc;
    for i in 0..7 {
        let x = h * XK[i];
        let s = f(c - x) + f(c + x);
        k += WK[i] * s;
        if i % 2 == 1 {
            g += WG[i / 2] * s;
        }
    }
    (k * h, ((k - g) * h).abs())
}

/// Adaptive Gauss-Kronrod integral of `f` over [a, b] to absolute tolerance `tol`
/// (bisecting panels whose error estimate exceeds their share, at most `depth` levels).
pub fn integrate(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    fn rec(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64, tol: f64, depth: u32) -> f64 {
        let (v, e) = gk15(f, a, b);
        if e <= tol || depth == 0 || (b - a).abs() < 1e-12 {
            return v;
        }
        let m = 0.5 * (a + b);
        rec(f, a, m, 0.5 * tol, depth - 1) + rec(f, m, b, 0.5 * tol, depth - 1)
    }
    if a == b {
        return 0.0;
    }
    rec(f, a, b, tol, 20)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomials_and_peaks() {
        let v = integrate(&mut |x| x.powi(6) - 2.0 * x, 0.0, 2.0, 1e-12);
        assert!((v - (128.0 / 7.0 - 4.0)).abs() < 1e-12);
        // A sharp cosine lobe: int_{-pi/2}^{pi/2} cos^200 = pi * C(200,100) / 2^200.
        let mut c = 1.0f64;
        for k in 1..=100 {
            c *= (100 + k) as f64 / k as f64 / 4.0;
        }
        let want = std::f64::consts::PI * c;
        let v = integrate(
            &mut |x: f64| x.cos().powi(200),
            -std::f64::consts::FRAC_PI_2,
            std::f64::consts::FRAC_PI_2,
            1e-13,
        );
        assert!((v - want).abs() < 1e-10, "{v} {want}");
    }
}
