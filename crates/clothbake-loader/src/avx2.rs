//! The lookup on x86-64 processors with AVX2, FMA and F16C (chosen at run time, see
//! [`crate::SimdPath`]): the four angles of a pair in one SSE register, computed straight as
//! positions in cells (the fast `atan2` whose octant fix-ups, cells per radian and polar/azimuth
//! offsets are folded into its last fused multiply-add), the four axes' spans in one register,
//! and the 8 runs of 8 lanes as eight 256-bit fused multiply-adds (F16C widens 8 halves in one
//! instruction).
//!
//! Same rules as the portable path ([`crate::nodes`]) with different arithmetic: `atan2` from
//! squares with Estrin's scheme and scaled coefficients, fused products (one rounding instead
//! of two), sums in another order. Positions agree with the f64 angles within 1.2e-4 cells
//! (tested over the hemisphere), results with the portable kernel within 1e-5 relative
//! (tested), not bit for bit; each kernel is deterministic, and batches give the bits of
//! single lookups.

use std::arch::x86_64::*;

use crate::angles::HORIZON_COS;
use crate::nodes::{
    column_offset, next_column, one_line_tiles, Lane, MirrorLanes, Nodes, SpanLanes,
};

/// True when this processor runs the kernel.
pub(crate) fn available() -> bool {
    is_x86_feature_detected!("avx2")
        && is_x86_feature_detected!("fma")
        && is_x86_feature_detected!("f16c")
}

/// The [`Octant`] parts of `atan2(y, x)` in four lanes, from `y^2`, `x^2` and the signs of
/// `x` and `y` (masks): the polynomial of [`crate::angles::atan2`], `atan(a) = a P(a^2)` with
/// `a^2 = min / max` of the squares, but with the octant fix-ups folded into `atan2 = off +
/// sign atan(a)`, where `off` (0, pi/2, pi, with signs) and `sign` come from the masks beside
/// the division; [`cells`] then maps to cells in one fused multiply-add per candidate, the
/// coefficients pre-multiplied by the cells per radian. Starting from squares, the square root
/// (of the ratio) runs beside the polynomial instead of before the division. `(0, 0)` gives
/// the angle 0.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn atan2_cells(y2: __m128, x2: __m128, x_neg: __m128, y_neg: __m128) -> Octant {
    let lo = _mm_min_ps(x2, y2);
    let hi = _mm_max_ps(x2, y2);
    let s = _mm_and_ps(_mm_div_ps(lo, hi), _mm_cmpgt_ps(hi, _mm_setzero_ps()));
    // Octant: atan2 = s_y (off_x + s_x (off_swap + s_swap atan(a))) with off_swap = pi/2 and
    // s_swap = -1 when |y| > |x|, off_x = pi and s_x = -1 when x < 0, s_y = -1 when y < 0:
    // off = s_y (x < 0 ? pi - off_swap : off_swap), sign = s_y s_x s_swap.
    let neg0 = _mm_set1_ps(-0.0);
    let swap = _mm_cmpgt_ps(y2, x2);
    let off_swap = _mm_and_ps(swap, _mm_set1_ps(std::f32::consts::FRAC_PI_2));
    let off = _mm_blendv_ps(
        off_swap,
        _mm_sub_ps(_mm_set1_ps(std::f32::consts::PI), off_swap),
        x_neg,
    );
    let y_sign = _mm_and_ps(y_neg, neg0);
    let off = _mm_xor_ps(off, y_sign);
    let sign = _mm_and_ps(_mm_xor_ps(_mm_xor_ps(swap, x_neg), y_neg), neg0);
    let a = _mm_xor_ps(_mm_sqrt_ps(s), sign);
    Octant { s, a, off }
}

/// The parts of four `atan2` before the map to cells: `atan2 = off + a P(s)`, `a` signed.
#[derive(Clone, Copy)]
struct Octant {
    s: __m128,
    a: __m128,
    off: __m128,
}

/// The octant parts of the swapped pair (`[theta_o, phi_o, theta_i, phi_i]`): the same
/// lanes, swapped, so the same bits as computing them from `(wo, wi)`.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn swap_octant(o: Octant) -> Octant {
    Octant {
        s: swap(o.s),
        a: swap(o.a),
        off: swap(o.off),
    }
}

/// Positions in cells of the angles `off + a P(s)` (see [`atan2_cells`]), before clamping.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn cells(k: &SpanLanes, o: Octant) -> __m128 {
    let Octant { s, a, off } = o;
    let ld = |v: &[f32; 4]| _mm_loadu_ps(v.as_ptr()); // 4 f32, unaligned
    let b1 = _mm_fmadd_ps(off, ld(&k.k1), ld(&k.b1));
    let b2 = _mm_fmadd_ps(off, ld(&k.k2), ld(&k.b2));
    // Estrin's scheme (shorter dependency chain than Horner's), both scalings:
    // p = (c0 + c1 s) + s^2 (c2 + c3 s) + s^4 (c4 + c5 s).
    let s2 = _mm_mul_ps(s, s);
    let poly = |c: &[[f32; 4]; 6]| {
        let p01 = _mm_fmadd_ps(ld(&c[1]), s, ld(&c[0]));
        let p23 = _mm_fmadd_ps(ld(&c[3]), s, ld(&c[2]));
        let p45 = _mm_fmadd_ps(ld(&c[5]), s, ld(&c[4]));
        _mm_fmadd_ps(_mm_fmadd_ps(p45, s2, p23), s2, p01)
    };
    let s1 = _mm_fmadd_ps(a, poly(&k.c1), b1);
    let s2 = _mm_fmadd_ps(a, poly(&k.c2), b2);
    _mm_min_ps(s1, s2)
}

/// Positions in cells (before clamping, see [`crate::nodes::SpanLanes::k1`]) of the
/// `[theta_i, phi_i, theta_o, phi_o]` of a pair, and whether the pair has a value (both above
/// the horizon, nothing NaN).
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn positions(nodes: &Nodes, wi: [f32; 3], wo: [f32; 3]) -> (__m128, bool) {
    let (o, ok) = octant(wi, wo);
    (cells(&nodes.lanes, o), ok)
}

/// The octant parts of the four angles of a pair (see [`positions`]) and whether it has a
/// value.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn octant(wi: [f32; 3], wo: [f32; 3]) -> (Octant, bool) {
    // Lanes: theta_i = atan2(rho_i, z_i), phi_i = atan2(y_i, x_i), and the same for wo.
    let x = _mm_setr_ps(wi[2], wi[0], wo[2], wo[0]);
    let a = _mm_setr_ps(wi[0], wi[1], wo[0], wo[1]);
    octant_of(x, a, wi, wo)
}

/// [`octant`] of the pair mirrored by `m`: the same bits as [`octant`] of the directions with
/// x and y multiplied by the mirror's signs (exact), without forming them.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn octant_mirrored(wi: &[f32; 3], wo: &[f32; 3], m: &MirrorLanes) -> (Octant, bool) {
    let ld = |v: &[f32; 4]| _mm_loadu_ps(v.as_ptr()); // 4 f32, unaligned
    let x = _mm_mul_ps(_mm_setr_ps(wi[2], wi[0], wo[2], wo[0]), ld(&m.x));
    let a = _mm_mul_ps(_mm_setr_ps(wi[0], wi[1], wo[0], wo[1]), ld(&m.a));
    // y enters `b` only squared: its sign does not matter there.
    octant_of(x, a, *wi, *wo)
}

/// [`octant`] from its lanes `x` and `a` (the directions' components, as [`octant`] forms
/// them) and `b`'s components from `wi`, `wo`.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn octant_of(x: __m128, a: __m128, wi: [f32; 3], wo: [f32; 3]) -> (Octant, bool) {
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
    let o = atan2_cells(y2, _mm_mul_ps(x, x), _mm_cmplt_ps(x, zero), y_neg);
    (o, bad == 0)
}

/// Positions in cells (before clamping) of angles `[theta_i, phi_i, theta_o, phi_o]`
/// (radians, as [`Nodes::corner`]).
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn positions_of_angles(nodes: &Nodes, ang: __m128) -> __m128 {
    let k = &nodes.lanes;
    let ld = |v: &[f32; 4]| _mm_loadu_ps(v.as_ptr()); // 4 f32, unaligned
    _mm_min_ps(
        _mm_fmadd_ps(ang, ld(&k.k1), ld(&k.b1)),
        _mm_fmadd_ps(ang, ld(&k.k2), ld(&k.b2)),
    )
}

/// The quadrilinear blend at positions `pos` (cells, before clamping) of f16 or f32 values.
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn blend<V: Lane>(nodes: &Nodes, v: &[V], pos: __m128) -> [f32; 3] {
    gather(nodes, v, &corner(nodes, pos))
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

/// The corner of a lookup at positions `pos` (cells, before clamping: see
/// [`crate::nodes::SpanLanes::k1`]).
///
/// # Safety
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn corner(nodes: &Nodes, pos: __m128) -> Corner {
    // As Axis::lookup_node of the polar (lanes 0, 2) and azimuth axes (lanes 1, 3), in the
    // form of Axis::lookup_lines: the positions clamped to [0, cap] (NaN -> 0) with cap = n (hold the last ring) or 2n (the azimuth's
    // range).
    let k = &nodes.lanes;
    let s = _mm_min_ps(
        _mm_max_ps(pos, _mm_setzero_ps()),
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
    let common = l[0] as usize * s_ti + l[2] as usize * s_to + column_offset(l[3] as usize);
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
/// The processor must have AVX2, FMA and F16C.
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn gather<V: Lane>(nodes: &Nodes, v: &[V], k: &Corner) -> [f32; 3] {
    let [r, g, b, _] = gather4(nodes, v, k);
    [r, g, b]
}

/// [`gather`] of all four lanes.
///
/// # Safety
/// As [`gather`].
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn gather4<V: Lane>(nodes: &Nodes, v: &[V], k: &Corner) -> [f32; 4] {
    let Corner { base, w, d } = *k;
    let sum = nodes.with_runs(
        v,
        base,
        #[inline(always)]
        |runs| {
            // Each run widened to 8 f32 as its lane type loads it (F16C for halves).
            let load = |r: usize| V::load8(runs[r]);
            // Run r weighs w_r (a broadcast from memory: a load, not a shuffle); (1 - t_po, t_po)
            // by D is common to all runs and applied once to the sum; the weights do not wait for
            // the loads, and the sum is a tree (short chain after them).
            let mut wr = [0f32; 8];
            _mm256_storeu_ps(wr.as_mut_ptr(), w); // 8 f32, unaligned
            let lane = |r: usize| _mm256_broadcast_ss(&wr[r]);
            let y0 = _mm256_fmadd_ps(load(1), lane(1), _mm256_mul_ps(load(0), lane(0)));
            let y1 = _mm256_fmadd_ps(load(3), lane(3), _mm256_mul_ps(load(2), lane(2)));
            let y2 = _mm256_fmadd_ps(load(5), lane(5), _mm256_mul_ps(load(4), lane(4)));
            let y3 = _mm256_fmadd_ps(load(7), lane(7), _mm256_mul_ps(load(6), lane(6)));
            _mm256_add_ps(_mm256_add_ps(y0, y1), _mm256_add_ps(y2, y3))
        },
    );
    let Some(sum) = sum else {
        return [0.0; 4];
    };
    let acc = _mm256_mul_ps(sum, d);
    let rgb = _mm_add_ps(_mm256_castps256_ps128(acc), _mm256_extractf128_ps::<1>(acc));
    let mut out = [0f32; 4];
    _mm_storeu_ps(out.as_mut_ptr(), rgb); // 4 f32, unaligned
    out
}

/// The four lanes of one pair's lookup (no symmetrising): a spatial table's two classes.
///
/// # Safety
/// The processor must have AVX2, FMA and F16C ([`available`]).
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn eval4<V: Lane>(
    nodes: &Nodes,
    v: &[V],
    wi: [f32; 3],
    wo: [f32; 3],
) -> [f32; 4] {
    let (pos, ok) = positions(nodes, wi, wo);
    if !ok {
        return [0.0; 4];
    }
    gather4(nodes, v, &corner(nodes, pos))
}

/// [`eval4`] at the pair mirrored by `m` (the same bits as [`eval4`] of the mirrored
/// directions).
///
/// # Safety
/// The processor must have AVX2, FMA and F16C ([`available`]).
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn eval4_mirrored<V: Lane>(
    nodes: &Nodes,
    v: &[V],
    wi: &[f32; 3],
    wo: &[f32; 3],
    m: &MirrorLanes,
) -> [f32; 4] {
    let (o, ok) = octant_mirrored(wi, wo, m);
    if !ok {
        return [0.0; 4];
    }
    gather4(nodes, v, &corner(nodes, cells(&nodes.lanes, o)))
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
/// The processor must have AVX2, FMA and F16C ([`available`]).
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn eval<V: Lane>(
    nodes: &Nodes,
    v: &[V],
    reciprocal: bool,
    wi: [f32; 3],
    wo: [f32; 3],
) -> [f32; 3] {
    if reciprocal {
        return eval_reciprocal(nodes, v, wi, wo);
    }
    let (pos, ok) = positions(nodes, wi, wo);
    if !ok {
        return [0.0; 3];
    }
    blend(nodes, v, pos)
}

/// The symmetrised lookup of one pair, out of line (so that the plain lookup keeps its
/// values in registers).
///
/// # Safety
/// As [`eval`].
#[inline(never)]
#[target_feature(enable = "avx2,fma,f16c")]
unsafe fn eval_reciprocal<V: Lane>(nodes: &Nodes, v: &[V], wi: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
    let (o, ok) = octant(wi, wo);
    if !ok {
        return [0.0; 3];
    }
    let f = blend(nodes, v, cells(&nodes.lanes, o));
    // The swapped pair: its octant parts swap, its positions do not (the axes' scales differ).
    let r = blend(nodes, v, cells(&nodes.lanes, swap_octant(o)));
    mean(f, r)
}

/// `(f + r) / 2` per channel (the same bits for `(r + f) / 2`).
#[inline(always)]
fn mean(f: [f32; 3], r: [f32; 3]) -> [f32; 3] {
    [
        0.5 * (f[0] + r[0]),
        0.5 * (f[1] + r[1]),
        0.5 * (f[2] + r[2]),
    ]
}

/// The lookup at angles `[theta_i, phi_i, theta_o, phi_o]`, radians.
///
/// # Safety
/// As [`eval`].
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn at_angles<V: Lane>(
    nodes: &Nodes,
    v: &[V],
    reciprocal: bool,
    ang: __m128,
) -> [f32; 3] {
    let f = blend(nodes, v, positions_of_angles(nodes, ang));
    if !reciprocal {
        return f;
    }
    let r = blend(nodes, v, positions_of_angles(nodes, swap(ang)));
    mean(f, r)
}

/// [`at_angles`] at `[theta_i, phi_i, theta_o, phi_o]` in an array.
///
/// # Safety
/// As [`eval`].
#[inline]
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn at_angles_of<V: Lane>(
    nodes: &Nodes,
    v: &[V],
    reciprocal: bool,
    ang: [f32; 4],
) -> [f32; 3] {
    at_angles(nodes, v, reciprocal, _mm_loadu_ps(ang.as_ptr()))
}

/// [`eval`] of every pair, into `out` (same lengths, checked by the caller).
///
/// # Safety
/// As [`eval`].
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn batch<V: Lane>(
    nodes: &Nodes,
    v: &[V],
    reciprocal: bool,
    wi: &[[f32; 3]],
    wo: &[[f32; 3]],
    out: &mut [[f32; 3]],
) {
    // `GROUP` pairs at a time: all corners before all gathers, so that the next pairs' angle
    // arithmetic overlaps the loads of the first (same operations as `eval`: the same bits).
    // Pipelined for half floats: the next group's corners are found and their lines
    // prefetched before this group's gathers, so that random pairs' memory reads overlap (a
    // hint: no effect on the values). Measured on f32 tables (two lines a tile), the pipeline
    // made random batches 1.1x faster but batches in cache 1.12x slower (the held corners),
    // so f32 batches are not pipelined (docs/reference/benchmarks.md).
    const GROUP: usize = 4;
    /// The corners of pairs `k..k + GROUP`, or `None` when one is off the table's domain or the
    /// lookup is symmetrised (then each pair goes through `eval`).
    #[inline]
    #[target_feature(enable = "avx2,fma,f16c")]
    unsafe fn corners(
        nodes: &Nodes,
        reciprocal: bool,
        wi: &[[f32; 3]],
        wo: &[[f32; 3]],
        k: usize,
    ) -> Option<[Corner; GROUP]> {
        let ang: [(__m128, bool); GROUP] = [
            positions(nodes, wi[k], wo[k]),
            positions(nodes, wi[k + 1], wo[k + 1]),
            positions(nodes, wi[k + 2], wo[k + 2]),
            positions(nodes, wi[k + 3], wo[k + 3]),
        ];
        (!reciprocal && ang.iter().all(|a| a.1)).then(|| {
            [
                corner(nodes, ang[0].0),
                corner(nodes, ang[1].0),
                corner(nodes, ang[2].0),
                corner(nodes, ang[3].0),
            ]
        })
    }
    /// Group `k..k + GROUP` into `o`, from its corners or, without them, pair by pair.
    #[inline]
    #[target_feature(enable = "avx2,fma,f16c")]
    unsafe fn finish<V: Lane>(
        nodes: &Nodes,
        v: &[V],
        reciprocal: bool,
        (wi, wo): (&[[f32; 3]], &[[f32; 3]]),
        k: usize,
        corners: Option<[Corner; GROUP]>,
        o: &mut [[f32; 3]],
    ) {
        match corners {
            Some(c) => {
                for (o, c) in o.iter_mut().zip(&c) {
                    *o = gather(nodes, v, c);
                }
            }
            None => {
                for (i, o) in o.iter_mut().enumerate() {
                    *o = eval(nodes, v, reciprocal, wi[k + i], wo[k + i]);
                }
            }
        }
    }
    let n = wi.len().min(wo.len()).min(out.len());
    let (wi, wo, out) = (&wi[..n], &wo[..n], &mut out[..n]);
    let groups = n / GROUP;
    let pipelined = one_line_tiles::<V>();
    let mut next = if groups > 0 && pipelined {
        corners(nodes, reciprocal, wi, wo, 0)
    } else {
        None
    };
    for j in 0..groups {
        let k = j * GROUP;
        let cur = if pipelined {
            let cur = next;
            if j + 1 < groups {
                next = corners(nodes, reciprocal, wi, wo, k + GROUP);
                if let Some(c) = &next {
                    for c in c {
                        nodes.prefetch(v, c.base);
                    }
                }
            }
            cur
        } else {
            corners(nodes, reciprocal, wi, wo, k)
        };
        finish(
            nodes,
            v,
            reciprocal,
            (wi, wo),
            k,
            cur,
            &mut out[k..k + GROUP],
        );
    }
    let k = groups * GROUP;
    for (i, o) in out[k..].iter_mut().enumerate() {
        *o = eval(nodes, v, reciprocal, wi[k + i], wo[k + i]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::Span;
    use crate::grid::Grid;

    /// The probes of the build script, to fail with its message when run without AVX2.
    mod probe {
        include!("../build/probe.rs");
    }

    #[test]
    #[cfg_attr(
        missing_avx2,
        ignore = "needs an x86-64 processor with AVX2, FMA and F16C: nothing to install, run on such a processor"
    )]
    fn positions_match_f64_angles_over_the_hemisphere() {
        probe::AVX2.require();
        assert!(available());
        let g = Grid::new(32, 64, 90, 360);
        // The positions need the lookup's constants only.
        let nodes = Nodes::empty(&g);
        // The documented position in cells of an angle on each axis, in f64.
        let axes = g.axes();
        // A grid over the hemisphere (and lengths other than 1: only directions matter),
        // with the axes, the pole and the horizon.
        let mut dirs = vec![
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1e-6],
            [0.0, -1.0, 1e-6],
            [-1.0, -0.0, 0.5],
        ];
        for i in 0..=300 {
            for j in 0..300 {
                let theta = Span::Hemisphere.radians() * f64::from(i) / 300.0;
                let phi = std::f64::consts::TAU * f64::from(j) / 300.0 - 3.0;
                let len = 1.0 + f64::from((i * j) % 3);
                dirs.push([
                    (len * theta.sin() * phi.cos()) as f32,
                    (len * theta.sin() * phi.sin()) as f32,
                    (len * theta.cos()).max(1e-6) as f32,
                ]);
            }
        }
        let mut worst = [0f64; 4];
        for w in dirs.windows(2) {
            let (wi, wo) = (w[0], w[1]);
            // SAFETY: AVX2, FMA and F16C were detected.
            let (pos, ok) = unsafe { positions(&nodes, wi, wo) };
            assert!(ok);
            let mut got = [0f32; 4];
            unsafe { _mm_storeu_ps(got.as_mut_ptr(), pos) };
            let f = |v: [f32; 3]| v.map(f64::from);
            let (a, b) = (f(wi), f(wo));
            let want = [
                a[0].hypot(a[1]).atan2(a[2]),
                a[1].atan2(a[0]),
                b[0].hypot(b[1]).atan2(b[2]),
                b[1].atan2(b[0]),
            ];
            for k in 0..4 {
                let v = if k < 2 { a } else { b };
                if k % 2 == 1 && v[0] == 0.0 && v[1] == 0.0 {
                    continue; // no azimuth at the pole (std gives pi for x = -0, the kernel 0)
                }
                let e = (f64::from(got[k]) - axes[k].lookup_position(want[k])).abs();
                // Azimuths: modulo a turn (f64 gives -pi for y = -0, the kernel +pi).
                let e = if k % 2 == 1 {
                    e.min((e - f64::from(axes[k].count())).abs())
                } else {
                    e
                };
                worst[k] = worst[k].max(e);
            }
        }
        // atan within 2e-6 rad (angles::atan2's test) times at most 2 scale cells per radian,
        // plus f32 rounding of positions below 2 n = 720 (ulp 6e-5).
        for (k, (w, k1)) in worst.iter().zip(nodes.lanes.k1).enumerate() {
            let bound = 2e-6 * f64::from(k1) + 2.0 * 6.1e-5;
            assert!(*w < bound, "axis {k}: worst {w} cells");
        }
        eprintln!("worst position errors (cells): {worst:?}");
        // Signed zeros and the origin, as the scalar atan2 (y = -0 is not negative there).
        for (w, phi) in [
            ([-1.0, -0.0, 1.0], std::f64::consts::PI),
            ([0.0, 0.0, 1.0], 0.0),
        ] {
            // SAFETY: as above.
            let (pos, _) = unsafe { positions(&nodes, w, w) };
            let mut got = [0f32; 4];
            unsafe { _mm_storeu_ps(got.as_mut_ptr(), pos) };
            assert!(
                (f64::from(got[1]) - axes[1].lookup_position(phi)).abs() < 1e-4,
                "{w:?} {got:?}"
            );
        }
    }

    #[test]
    #[cfg_attr(
        missing_avx2,
        ignore = "needs an x86-64 processor with AVX2, FMA and F16C: nothing to install, run on such a processor"
    )]
    fn a_mirrored_octant_is_the_octant_of_the_mirrored_pair() {
        probe::AVX2.require();
        let bits = |v: __m128| {
            let mut out = [0f32; 4];
            // SAFETY: SSE is part of x86-64.
            unsafe { _mm_storeu_ps(out.as_mut_ptr(), v) };
            out.map(f32::to_bits)
        };
        let mut dirs: Vec<[f32; 3]> = vec![
            [0.0, 0.0, 1.0],
            [-0.0, 0.0, 1.0],
            [0.0, -0.0, 1.0],
            [0.6, -0.0, 0.8],
            [-0.6, 0.0, 0.8],
            [0.3, 0.4, -0.2],
            [f32::NAN, 0.1, 0.9],
            [0.1, f32::NAN, 0.9],
        ];
        for k in 0..200 {
            let (t, p) = (0.0077 * k as f32, 0.37 * k as f32);
            dirs.push([t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]);
        }
        for m in [[1.0f32, 1.0], [-1.0, 1.0], [1.0, -1.0], [-1.0, -1.0]] {
            let lanes = MirrorLanes::new(m);
            let flip = |w: [f32; 3]| [w[0] * m[0], w[1] * m[1], w[2]];
            for w in dirs.windows(2) {
                let (wi, wo) = (w[0], w[1]);
                // SAFETY: AVX2, FMA and F16C were detected.
                let (got, ok) = unsafe { octant_mirrored(&wi, &wo, &lanes) };
                let (want, want_ok) = unsafe { octant(flip(wi), flip(wo)) };
                assert_eq!(ok, want_ok, "{wi:?} {wo:?} {m:?}");
                for (g, w) in [(got.s, want.s), (got.a, want.a), (got.off, want.off)] {
                    assert_eq!(bits(g), bits(w), "{wi:?} {wo:?} {m:?}");
                }
            }
        }
    }
}
