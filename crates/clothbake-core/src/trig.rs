//! Inline trigonometry: sine and cosine together, for the quadrature loops of the secondary
//! reflection (the library's `sin_cos` is an out-of-line call that dominated them), and
//! `atan2`/`asin` for the direct model's arcs (issue 22: the library's calls were half its time).
//!
//! `atan2`: octant reduction to t = min(|x|, |y|) / max(|x|, |y|) in [0, 1], then once more by
//! tan(pi/8) (t > tan(pi/8): atan t = pi/4 + atan((t - 1)/(t + 1))) onto |t| <= 0.4143, where
//! FDLIBM's `s_atan.c` polynomial (11 terms, < 1 ulp on |t| < 7/16) gives atan t; the quadrant
//! fix-ups subtract from pi/2 and pi with their low parts. `asin x = atan2(x, sqrt((1-x)(1+x)))`.
//! Both within 5e-16 (two units in the last place near pi) of the standard library's, tested.
//!
//! Quadrant reduction x = k pi/2 + r with |r| <= pi/4 (pi/2 split in two parts, Cody & Waite, so
//! r keeps full precision for the |x| of a few turns these loops use), then the Taylor series of
//! sin r and cos r up to r^17 and r^16: the first omitted terms are below 1e-17 on |r| <= pi/4.
//! Absolute error under 1e-15 for |x| <= 100, tested against the standard library.
//!
//! The reductions and polynomials are written once over `Lane` (one f64, or four in an AVX
//! register: `atan2_x4`, `sin_cos_x4` for the direct model's batch), so the lanes give the
//! scalar functions' bits.

#[cfg(target_arch = "x86_64")]
use crate::lanes::F64x4;
use crate::lanes::Lane;

/// 1.5 * 2^52: x + SHIFT rounds x to an integer for |x| < 2^51 ([`round_nearest`]).
const SHIFT: f64 = 6_755_399_441_055_744.0;

/// pi/2 in two parts: the high part has 33 significant bits, so k * PI_2_HI is exact for
/// |k| < 2^20.
const PI_2_HI: f64 = 1.570_796_326_734_125_6;
/// pi/2 - PI_2_HI.
const PI_2_LO: f64 = 6.077_100_506_506_192e-11;

/// 1 / (2j + 1)! for j = 1..=8 (sine) and 1 / (2j)! for j = 1..=8 (cosine).
const SIN: [f64; 8] = [
    1.0 / 6.0,
    1.0 / 120.0,
    1.0 / 5040.0,
    1.0 / 362_880.0,
    1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];
const COS: [f64; 8] = [
    1.0 / 2.0,
    1.0 / 24.0,
    1.0 / 720.0,
    1.0 / 40_320.0,
    1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
];

/// `(sin x, cos x)`; for |x| > 1e6 or non-finite x the standard library's.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if !in_range(x) {
        return x.sin_cos();
    }
    sin_cos_reduced(x)
}

/// Whether [`sin_cos_reduced`] holds for `x`: not NaN, |x| <= 1e6.
#[inline(always)]
fn in_range(x: f64) -> bool {
    x.abs() <= 1e6
}

/// x = k pi/2 + r, |r| <= pi/4, for |x| <= 1e6 (one f64 or four lanes): (sin r, cos r) and
/// k + 1.5 * 2^52, whose low bits are k mod 4 (the sum's unit is 1, so they are k's two's
/// complement).
#[inline(always)]
fn reduced<L: Lane>(x: L) -> ((L, L), L) {
    let shifted = x * L::splat(std::f64::consts::FRAC_2_PI) + L::splat(SHIFT);
    let kf = shifted - L::splat(SHIFT);
    let r = (x - kf * L::splat(PI_2_HI)) - kf * L::splat(PI_2_LO);
    let z = r * r;
    // Alternating series by Horner in z.
    let mut ps = L::splat(SIN[7]);
    let mut pc = L::splat(COS[7]);
    for j in (0..7).rev() {
        ps = L::splat(SIN[j]) - z * ps;
        pc = L::splat(COS[j]) - z * pc;
    }
    ((r - r * z * ps, L::splat(1.0) - z * pc), shifted)
}

/// [`sin_cos`] for |x| <= 1e6: quadrants 0..3 give (s, c), (c, -s), (-s, -c), (-c, s).
#[inline(always)]
fn sin_cos_reduced(x: f64) -> (f64, f64) {
    let ((s, c), shifted) = reduced(x);
    match shifted.to_bits() & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// [`sin_cos`] of four lanes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn sin_cos_x4(x: F64x4) -> (F64x4, F64x4) {
    let a = x.to_array();
    if a.iter().all(|&x| in_range(x)) {
        // The quadrants of sin_cos_reduced as selects.
        let ((s, c), shifted) = reduced(x);
        let (odd, negated) = (shifted.has_bit(1), shifted.has_bit(2));
        let (sin, cos) = (odd.select(c, s), odd.select(-s, c));
        return (negated.select(-sin, sin), negated.select(-cos, cos));
    }
    let sc = a.map(sin_cos);
    (
        F64x4::from_array(sc.map(|p| p.0)),
        F64x4::from_array(sc.map(|p| p.1)),
    )
}

/// FDLIBM `s_atan.c`'s coefficients: atan t = t - t (s1 + s2) with s1 the even-indexed terms
/// in w = t^4 times z = t^2, s2 the odd-indexed ones times w.
const AT: [f64; 11] = [
    f64::from_bits(0x3FD5_5555_5555_550D), //  3.33333333333329318027e-01
    f64::from_bits(0xBFC9_9999_9998_EBC4), // -1.99999999998764832476e-01
    f64::from_bits(0x3FC2_4924_9200_83FF), //  1.42857142725034663711e-01
    f64::from_bits(0xBFBC_71C6_FE23_1671), // -1.11111104054623557880e-01
    f64::from_bits(0x3FB7_45CD_C54C_206E), //  9.09088713343650656196e-02
    f64::from_bits(0xBFB3_B0F2_AF74_9A6D), // -7.69187620504482999495e-02
    f64::from_bits(0x3FB1_0D66_A0D0_3D51), //  6.66107313738753120669e-02
    f64::from_bits(0xBFAD_DE2D_52DE_FD9A), // -5.83357013379057348645e-02
    f64::from_bits(0x3FA9_7B4B_2476_0DEB), //  4.97687799461593236017e-02
    f64::from_bits(0xBFA2_B444_2C6A_6C2F), // -3.65315727442169155270e-02
    f64::from_bits(0x3F90_AD3A_E322_DA11), //  1.62858201153657823623e-02
];
/// pi/4 in two parts (high part the nearest double, low part the rest); pi/2 and pi's low parts.
const PI_4_HI: f64 = std::f64::consts::FRAC_PI_4;
const PI_4_LO: f64 = f64::from_bits(0x3C81_A626_3314_5C07);
const PI_2_LO_FULL: f64 = f64::from_bits(0x3C91_A626_3314_5C07);
const PI_LO: f64 = f64::from_bits(0x3CA1_A626_3314_5C07);

/// atan(t) for |t| <= 0.4375 (FDLIBM's kernel, no reduction).
#[inline(always)]
fn atan_kernel<L: Lane>(t: L) -> L {
    // Not a closure for the coefficients: a closure here would have this function's target
    // features (none), not the AVX2 of the lanes' callers, and, left out of line, its splats
    // would be calls.
    let c = [
        L::splat(AT[0]),
        L::splat(AT[1]),
        L::splat(AT[2]),
        L::splat(AT[3]),
        L::splat(AT[4]),
        L::splat(AT[5]),
        L::splat(AT[6]),
        L::splat(AT[7]),
        L::splat(AT[8]),
        L::splat(AT[9]),
        L::splat(AT[10]),
    ];
    let z = t * t;
    let w = z * z;
    let s1 = z * (c[0] + w * (c[2] + w * (c[4] + w * (c[6] + w * (c[8] + w * c[10])))));
    let s2 = w * (c[1] + w * (c[3] + w * (c[5] + w * (c[7] + w * c[9]))));
    t * (s1 + s2)
}

/// `y.atan2(x)` within 5e-16; the standard library's for non-finite input or the origin. Out of
/// line: inlined at every call of the direct model, the model measured 10% slower.
#[inline(never)]
pub fn atan2(y: f64, x: f64) -> f64 {
    if !reduces(y, x) {
        return y.atan2(x);
    }
    atan2_reduced(y, x)
}

/// Whether [`atan2_reduced`] holds for (`y`, `x`): the larger of |x| and |y| positive and
/// finite (the one `atan2_reduced` divides by).
#[inline(always)]
fn reduces(y: f64, x: f64) -> bool {
    let (ax, ay) = (x.abs(), y.abs());
    let den = if ay > ax { ay } else { ax };
    den > 0.0 && den < f64::INFINITY
}

/// [`atan2`] where [`reduces`] holds, one f64 or four lanes.
#[inline(always)]
fn atan2_reduced<L: Lane>(y: L, x: L) -> L {
    // Written as selects, not branches (random directions mispredict them): one division.
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay.gt(ax);
    let (num, den) = (L::select(swap, ax, ay), L::select(swap, ay, ax));
    // atan(num / den) in [0, pi/4]: above tan(pi/8), pi/4 + atan((num - den) / (num + den)).
    let big = num.gt(L::splat(0.414_213_562_373_095_03) * den);
    let (n2, d2) = (
        L::select(big, num - den, num),
        L::select(big, num + den, den),
    );
    let zero = L::splat(0.0);
    let (hi, lo) = (
        L::select(big, L::splat(PI_4_HI), zero),
        L::select(big, L::splat(PI_4_LO), zero),
    );
    let t = n2 / d2;
    let a = hi - ((atan_kernel(t) - lo) - t);
    let a = L::select(
        swap,
        (L::splat(std::f64::consts::FRAC_PI_2) - a) + L::splat(PI_2_LO_FULL),
        a,
    );
    let a = L::select(
        x.lt(zero),
        (L::splat(std::f64::consts::PI) - a) + L::splat(PI_LO),
        a,
    );
    a.copysign(y)
}

/// [`atan2`] of four lanes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn atan2_x4(y: F64x4, x: F64x4) -> F64x4 {
    let (ya, xa) = (y.to_array(), x.to_array());
    if (0..4).all(|k| reduces(ya[k], xa[k])) {
        atan2_reduced(y, x)
    } else {
        F64x4::from_array([0, 1, 2, 3].map(|k| atan2(ya[k], xa[k])))
    }
}

/// `x.asin()` within 5e-16 for |x| <= 1, inline (NaN outside).
#[inline]
pub fn asin(x: f64) -> f64 {
    if x.is_nan() || x.abs() > 1.0 {
        return f64::NAN;
    }
    atan2(x, ((1.0 - x) * (1.0 + x)).sqrt())
}

/// The integer nearest `x` (ties to even) for |x| < 2^51, by the 1.5 * 2^52 shift: no `round`
/// library call on baseline x86-64.
#[inline(always)]
pub fn round_nearest(x: f64) -> f64 {
    (x + SHIFT) - SHIFT
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_standard_library() {
        let mut worst = 0f64;
        for i in -200_000..=200_000 {
            let x = i as f64 * 5e-4 + 1e-7 * (i % 7) as f64;
            let (s, c) = sin_cos(x);
            worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
        }
        assert!(worst < 1e-15, "worst {worst:e}");
        for x in [0.0, -0.0, 1e-300, std::f64::consts::FRAC_PI_4, 1e5 + 0.3] {
            let (s, c) = sin_cos(x);
            assert!(
                (s - x.sin()).abs() < 1e-15 && (c - x.cos()).abs() < 1e-15,
                "{x}"
            );
        }
        let (s, c) = sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }

    #[test]
    fn atan2_and_asin_match_the_standard_library() {
        let mut rng = crate::rng::Rng::new(7);
        let mut worst = 0f64;
        for i in 0..400_000 {
            // Every octant, both signs of zero, magnitudes far apart and on the reduction's
            // break points (|t| = tan(pi/8), 1).
            let (y, x) = match i % 4 {
                0 => {
                    let t = std::f64::consts::TAU * rng.next_f64();
                    let r = 1e-3 + rng.next_f64();
                    (r * t.sin(), r * t.cos())
                }
                1 => (rng.next_f64() - 0.5, 1e-12 * (rng.next_f64() - 0.5)),
                2 => {
                    let s = if rng.next_u64().is_multiple_of(2) {
                        1.0
                    } else {
                        -1.0
                    };
                    let t = 0.414_213_562_373_095 * (1.0 + 1e-9 * (rng.next_f64() - 0.5));
                    (s * t, -s * (1.0 + 1e-15 * (rng.next_f64() - 0.5)))
                }
                _ => {
                    let x = 2.0 * rng.next_f64() - 1.0;
                    worst = worst.max((asin(x) - x.asin()).abs());
                    (x, 1.0 - x)
                }
            };
            worst = worst.max((atan2(y, x) - y.atan2(x)).abs());
        }
        assert!(worst < 5e-16, "worst {worst:e}");
        for (y, x) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (0.0, 0.0),
            (-0.0, -0.0),
            (1.0, f64::INFINITY),
            (f64::INFINITY, -1.0),
        ] {
            let (a, b) = (atan2(y, x), y.atan2(x));
            assert!(
                (a - b).abs() < 5e-16 && a.is_sign_negative() == b.is_sign_negative(),
                "{y} {x}: {a} {b}"
            );
        }
        assert!(atan2(f64::NAN, 1.0).is_nan() && atan2(1.0, f64::NAN).is_nan());
        for x in [-1.0, -0.5, 0.0, 0.5, 1.0, 1e-300, 0.999_999_999_999] {
            assert!((asin(x) - x.asin()).abs() < 5e-16, "{x}");
        }
        assert!(asin(1.5).is_nan() && asin(f64::NAN).is_nan());
    }

    #[test]
    fn round_nearest_matches_the_standard_library_off_ties() {
        for x in [-3.7, -2.2, -0.4, 0.0, 0.49, 1.5000001, 12345.6] {
            assert_eq!(round_nearest(x), x.round(), "{x}");
        }
        assert_eq!(round_nearest(2.5), 2.0);
    }
}
