//! The lookup on x86-64 processors with AVX2, FMA and F16C (chosen at run time, see
//! [`crate::Kernel`]): the four angles of a pair in one SSE register (the fast `atan2` with
//! fused multiply-adds), the four axes' spans in one register, and the 8 runs of 8 lanes as
//! eight 256-bit fused multiply-adds (F16C widens 8 halves in one instruction).
//!
//! Same rules as the portable path ([`crate::nodes`]) with different arithmetic: `atan2` from
//! squares with Estrin's scheme, fused products (one rounding instead of two), sums in another
//! order. Results agree with the portable kernel within 1e-5 relative (tested), not bit for
//! bit; each kernel is deterministic, and batches give the bits of single lookups.

use std::arch::x86_64::*;

use crate::angles::ATAN_COEFFS;
use crate::lookup::HORIZON_COS;
use crate::nodes::{next_column, Nodes};

/// True when this processor runs the kernel.
pub(crate) fn available() -> bool {
    is_x86_feature_detected!("avx2")
        && is_x86_feature_detected!("fma")
        && is_x86_feature_detected!("f16c")
}

/// `atan2(y, x)` in four lanes from `y^2`, `x^2` and the signs of `x` and `y` (masks), with
/// the polynomial of [`crate::angles::atan2`]: `atan(a) = a P(a^2)` with `a^2 = min / max` of
/// the squares. Starting from squares, the square root (of the ratio) runs beside the
/// polynomial instead of before the division: a shorter dependency chain than `rho =
/// sqrt(x^2 + y^2)` first. 0 for `(0, 0)`.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn atan2_sq(y2: __m128, x2: __m128, x_neg: __m128, y_neg: __m128) -> __m128 {
    let lo = _mm_min_ps(x2, y2);
    let hi = _mm_max_ps(x2, y2);
    let s = _mm_and_ps(_mm_div_ps(lo, hi), _mm_cmpgt_ps(hi, _mm_setzero_ps()));
    let a = _mm_sqrt_ps(s);
    // Estrin's scheme (shorter dependency chain than Horner's):
    // p = (c0 + c1 s) + s^2 (c2 + c3 s) + s^4 (c4 + c5 s).
    let c = ATAN_COEFFS;
    let k = |i: usize| _mm_set1_ps(c[i]);
    let s2 = _mm_mul_ps(s, s);
    let p01 = _mm_fmadd_ps(k(1), s, k(0));
    let p23 = _mm_fmadd_ps(k(3), s, k(2));
    let p45 = _mm_fmadd_ps(k(5), s, k(4));
    let p = _mm_fmadd_ps(_mm_fmadd_ps(p45, s2, p23), s2, p01);
    let mut r = _mm_mul_ps(a, p);
    r = _mm_blendv_ps(
        r,
        _mm_sub_ps(_mm_set1_ps(std::f32::consts::FRAC_PI_2), r),
        _mm_cmpgt_ps(y2, x2),
    );
    r = _mm_blendv_ps(r, _mm_sub_ps(_mm_set1_ps(std::f32::consts::PI), r), x_neg);
    _mm_xor_ps(r, _mm_and_ps(_mm_set1_ps(-0.0), y_neg))
}

/// `[theta_i, phi_i, theta_o, phi_o]` of a pair, and whether the pair has a value (both above
/// the horizon, nothing NaN).
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn angles(wi: [f32; 3], wo: [f32; 3]) -> (__m128, bool) {
    // Lanes: theta_i = atan2(rho_i, z_i), phi_i = atan2(y_i, x_i), and the same for wo.
    let x = _mm_setr_ps(wi[2], wi[0], wo[2], wo[0]);
    let a = _mm_setr_ps(wi[0], wi[1], wo[0], wo[1]);
    let b = _mm_setr_ps(wi[1], 0.0, wo[1], 0.0);
    let y2 = _mm_fmadd_ps(a, a, _mm_mul_ps(b, b)); // rho^2 (lanes 0, 2), y^2 (lanes 1, 3)
    let zero = _mm_setzero_ps();
    let azimuth = _mm_castsi128_ps(_mm_setr_epi32(0, -1, 0, -1));
    let y_neg = _mm_and_ps(_mm_cmplt_ps(a, zero), azimuth); // rho >= 0
                                                            // Lanes 0 and 2 of x are the cosines: not above the horizon (or NaN) there, or NaN in any
                                                            // of the six components (all are in x or a), means no value.
    let below = _mm_cmp_ps::<_CMP_NGT_UQ>(x, _mm_set1_ps(HORIZON_COS));
    let nan = _mm_cmpunord_ps(x, a);
    let bad = _mm_movemask_ps(_mm_or_ps(nan, _mm_andnot_ps(azimuth, below)));
    let ang = atan2_sq(y2, _mm_mul_ps(x, x), _mm_cmplt_ps(x, zero), y_neg);
    (ang, bad == 0)
}

/// The quadrilinear blend at `ang` (radians, as [`Nodes::corner`]) of f16 (`HALF`) or f32
/// values.
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn blend<const HALF: bool, V>(nodes: &Nodes, v: &[V], ang: __m128) -> [f32; 3] {
    gather::<HALF, V>(nodes, v, &corner(nodes, ang))
}

/// Where a lookup falls ([`crate::nodes::Corner`] in registers).
#[derive(Clone, Copy)]
struct Corner {
    /// First lanes of the runs at the low and high `phi_i` columns.
    base: [usize; 2],
    /// Weight of run `r = 4 ia + 2 ib + ic`, lane `r`.
    w: __m256,
    /// `1 - t_po` in lanes 0..4, `t_po` in lanes 4..8.
    d: __m256,
}

/// The corner of a lookup at `ang` (radians, as [`Nodes::corner`]).
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn corner(nodes: &Nodes, ang: __m128) -> Corner {
    // Spans of the four axes in one register, as nodes::polar_axis (lanes 0, 2) and
    // nodes::azimuth_axis (lanes 1, 3): s = c + min(c, 1/2) on polar axes (2c below the first
    // centre, c + 1/2 above), c + n - 1/2 on azimuths; clamped to [0, cap] (NaN -> 0) with
    // cap = n (hold the last ring) or 2n (the azimuth's range).
    let k = &nodes.lanes;
    let c = _mm_mul_ps(ang, _mm_loadu_ps(nodes.scale.as_ptr())); // 4 f32, unaligned loads
    let off = _mm_blend_ps::<0b1010>(
        _mm_min_ps(c, _mm_set1_ps(0.5)),
        _mm_loadu_ps(k.offset.as_ptr()),
    );
    let s = _mm_add_ps(c, off);
    let s = _mm_min_ps(
        _mm_max_ps(s, _mm_setzero_ps()),
        _mm_loadu_ps(k.cap.as_ptr()),
    );
    // 0 <= s <= cap: no overflow. lo <= top = cap - 1, t = s - lo in [0, 1]; azimuths beyond
    // the last column wrap (polar lanes never exceed n - 1 there).
    let ni = _mm_loadu_si128(k.n.as_ptr() as *const __m128i);
    let top = _mm_loadu_si128(k.top.as_ptr() as *const __m128i);
    let l1 = _mm_min_epi32(_mm_cvttps_epi32(s), top);
    let t = _mm_sub_ps(s, _mm_cvtepi32_ps(l1));
    let n1 = _mm_sub_epi32(ni, _mm_set1_epi32(1));
    let lo = _mm_sub_epi32(l1, _mm_and_si128(ni, _mm_cmpgt_epi32(l1, n1)));
    let n = nodes.n;
    let [s_ti, s_pi, s_to] = nodes.strides;
    let mut l = [0i32; 4];
    _mm_storeu_si128(l.as_mut_ptr() as *mut __m128i, lo); // 4 i32, unaligned
    let common = l[0] as usize * s_ti + l[2] as usize * s_to + 4 * l[3] as usize;
    let base = [
        common + l[1] as usize * s_pi,
        common + next_column(l[1] as u32, n[1]) as usize * s_pi,
    ];
    // Weights: T8 = [1 - t, t]; run r = 4 ia + 2 ib + ic weighs wa[ia] wb[ib] wc[ic].
    let t8 = _mm256_set_m128(t, _mm_sub_ps(_mm_set1_ps(1.0), t));
    let wa = _mm256_permutevar8x32_ps(t8, _mm256_setr_epi32(0, 0, 0, 0, 4, 4, 4, 4));
    let wb = _mm256_permutevar8x32_ps(t8, _mm256_setr_epi32(1, 1, 5, 5, 1, 1, 5, 5));
    let wc = _mm256_permutevar8x32_ps(t8, _mm256_setr_epi32(2, 6, 2, 6, 2, 6, 2, 6));
    let d = _mm256_permutevar8x32_ps(t8, _mm256_setr_epi32(3, 3, 3, 3, 7, 7, 7, 7));
    let w = _mm256_mul_ps(_mm256_mul_ps(wa, wb), wc);
    Corner { base, w, d }
}

/// The blend of the 8 runs of a corner.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C; `V` is `u16` (half bits) when `HALF`, else
/// `f32`.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn gather<const HALF: bool, V>(nodes: &Nodes, v: &[V], k: &Corner) -> [f32; 3] {
    let Corner { base, w, d } = *k;
    let Some(p) = nodes.runs(v, base) else {
        return [0.0; 3];
    };
    // `runs` gives pointers valid for 8 reads of V (u16 halves when HALF).
    let load = |r: usize| {
        if HALF {
            _mm256_cvtph_ps(_mm_loadu_si128(p[r] as *const __m128i))
        } else {
            _mm256_loadu_ps(p[r] as *const f32)
        }
    };
    // Run r's lane weights: w_r for the low phi_o node, times (1 - t_po, t_po) by D; the
    // weights do not wait for the loads, and the sum is a tree (short chain after them).
    let lane = |r: i32| _mm256_mul_ps(_mm256_permutevar8x32_ps(w, _mm256_set1_epi32(r)), d);
    let y0 = _mm256_fmadd_ps(load(1), lane(1), _mm256_mul_ps(load(0), lane(0)));
    let y1 = _mm256_fmadd_ps(load(3), lane(3), _mm256_mul_ps(load(2), lane(2)));
    let y2 = _mm256_fmadd_ps(load(5), lane(5), _mm256_mul_ps(load(4), lane(4)));
    let y3 = _mm256_fmadd_ps(load(7), lane(7), _mm256_mul_ps(load(6), lane(6)));
    let acc = _mm256_add_ps(_mm256_add_ps(y0, y1), _mm256_add_ps(y2, y3));
    let rgb = _mm_add_ps(_mm256_castps256_ps128(acc), _mm256_extractf128_ps::<1>(acc));
    let mut out = [0f32; 4];
    _mm_storeu_ps(out.as_mut_ptr(), rgb); // 4 f32, unaligned
    [out[0], out[1], out[2]]
}

/// Swaps the incident and outgoing angles: `[theta_o, phi_o, theta_i, phi_i]`.
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn swap(ang: __m128) -> __m128 {
    _mm_shuffle_ps::<0b01_00_11_10>(ang, ang)
}

/// The lookup of one pair (see [`crate::Brdf::eval`]), symmetrised when `reciprocal`.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C ([`available`]); `v` must be `u16` half bits
/// when `HALF`, else `f32`.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn eval<const HALF: bool, V>(
    nodes: &Nodes,
    v: &[V],
    reciprocal: bool,
    wi: [f32; 3],
    wo: [f32; 3],
) -> [f32; 3] {
    let (ang, ok) = angles(wi, wo);
    if !ok {
        return [0.0; 3];
    }
    at_angles::<HALF, V>(nodes, v, reciprocal, ang)
}

/// The lookup at angles `[theta_i, phi_i, theta_o, phi_o]`, radians.
///
/// # Safety
/// As [`eval`].
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn at_angles<const HALF: bool, V>(
    nodes: &Nodes,
    v: &[V],
    reciprocal: bool,
    ang: __m128,
) -> [f32; 3] {
    let f = blend::<HALF, V>(nodes, v, ang);
    if !reciprocal {
        return f;
    }
    let r = blend::<HALF, V>(nodes, v, swap(ang));
    [
        0.5 * (f[0] + r[0]),
        0.5 * (f[1] + r[1]),
        0.5 * (f[2] + r[2]),
    ]
}

/// [`at_angles`] at `[theta_i, phi_i, theta_o, phi_o]` in an array.
///
/// # Safety
/// As [`eval`].
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn at_angles_of<const HALF: bool, V>(
    nodes: &Nodes,
    v: &[V],
    reciprocal: bool,
    ang: [f32; 4],
) -> [f32; 3] {
    at_angles::<HALF, V>(nodes, v, reciprocal, _mm_loadu_ps(ang.as_ptr()))
}

/// [`eval`] of every pair, into `out` (same lengths, checked by the caller).
///
/// # Safety
/// As [`eval`].
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn batch<const HALF: bool, V>(
    nodes: &Nodes,
    v: &[V],
    reciprocal: bool,
    wi: &[[f32; 3]],
    wo: &[[f32; 3]],
    out: &mut [[f32; 3]],
) {
    // `GROUP` pairs at a time: all corners before all gathers, so that the next pairs' angle
    // arithmetic overlaps the loads of the first (same operations as `eval`: the same bits).
    const GROUP: usize = 4;
    let n = wi.len().min(wo.len()).min(out.len());
    let (wi, wo, out) = (&wi[..n], &wo[..n], &mut out[..n]);
    let mut chunks = out.chunks_exact_mut(GROUP);
    for (j, o) in (&mut chunks).enumerate() {
        let k = j * GROUP;
        let ang: [(__m128, bool); GROUP] = [
            angles(wi[k], wo[k]),
            angles(wi[k + 1], wo[k + 1]),
            angles(wi[k + 2], wo[k + 2]),
            angles(wi[k + 3], wo[k + 3]),
        ];
        if !reciprocal && ang.iter().all(|a| a.1) {
            let c = [
                corner(nodes, ang[0].0),
                corner(nodes, ang[1].0),
                corner(nodes, ang[2].0),
                corner(nodes, ang[3].0),
            ];
            for (o, c) in o.iter_mut().zip(&c) {
                *o = gather::<HALF, V>(nodes, v, c);
            }
        } else {
            for (i, o) in o.iter_mut().enumerate() {
                *o = eval::<HALF, V>(nodes, v, reciprocal, wi[k + i], wo[k + i]);
            }
        }
    }
    let rest = chunks.into_remainder();
    let k = n - rest.len();
    for (i, o) in rest.iter_mut().enumerate() {
        *o = eval::<HALF, V>(nodes, v, reciprocal, wi[k + i], wo[k + i]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angles::{atan2, theta_phi};

    #[test]
    fn four_lane_angles_match_the_scalar_ones() {
        if !available() {
            return;
        }
        let mut worst = 0f32;
        for k in 0..5000 {
            let u = |j: u32| ((k * 7919 + j * 104_729) % 10_007) as f32 / 10_007.0 * 2.0 - 1.0;
            let wi = [u(1), u(2), u(3).abs() + 1e-3];
            let wo = [u(4), u(5), u(6).abs() + 1e-3];
            // SAFETY: AVX2, FMA and F16C were detected.
            let (ang, ok) = unsafe { angles(wi, wo) };
            assert!(ok);
            let mut got = [0f32; 4];
            unsafe { _mm_storeu_ps(got.as_mut_ptr(), ang) };
            let ((a, b), (c, d)) = (theta_phi(wi), theta_phi(wo));
            for (g, w) in got.iter().zip([a, b, c, d]) {
                worst = worst.max((g - w).abs());
            }
        }
        assert!(worst < 1e-6, "worst {worst}");
        // Signed zeros and axes, as the scalar atan2 (y = -0 is not negative there).
        let ys = [0.0f32, -0.0, 1.0, -1.0];
        let xs = [0.0f32, -1.0, 0.0, 2.0];
        let mut got = [0f32; 4];
        // SAFETY: as above (SSE is baseline on x86-64).
        unsafe {
            let sq = |v: [f32; 4]| _mm_setr_ps(v[0] * v[0], v[1] * v[1], v[2] * v[2], v[3] * v[3]);
            let neg = |v: [f32; 4]| _mm_cmplt_ps(_mm_loadu_ps(v.as_ptr()), _mm_setzero_ps());
            let r = atan2_sq(sq(ys), sq(xs), neg(xs), neg(ys));
            _mm_storeu_ps(got.as_mut_ptr(), r);
        }
        for k in 0..4 {
            assert!((got[k] - atan2(ys[k], xs[k])).abs() < 1e-6, "{k} {got:?}");
        }
    }
}
