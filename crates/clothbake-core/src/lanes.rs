//! Lanes of f64. [`F64x2`]: two lanes for the innermost quadrature loop of the secondary
//! reflection, SSE2 on x86-64 (part of the baseline target, so no run-time detection), two
//! plain f64 elsewhere; [`Real`] is the arithmetic the facet terms need, so that
//! [`crate::facet::CosineFacet`] keeps its formulas in one place for one value or two.
//! `F64x4` (crate-private, x86-64): four lanes in an AVX register for the direct model's batch
//! evaluation, and `Lane`, the arithmetic that lets a formula (the inline trigonometry) be
//! written once for one value and for four lanes.

use std::ops::{Add, Div, Mul, Sub};

/// The number type of the facet formulas ([`clothbake_point::facet::Real`]), implemented here
/// for the lanes.
pub use clothbake_point::facet::Real;

#[cfg(target_arch = "x86_64")]
mod imp {
    use std::arch::x86_64::*;

    // SAFETY (every `unsafe` block calling an SSE2 intrinsic below): SSE2 is part of the x86-64
    // baseline, so the instructions exist on every CPU this target runs on.

    /// Two f64 lanes in an SSE2 register.
    #[derive(Clone, Copy, Debug)]
    pub struct F64x2(pub(super) __m128d);

    impl F64x2 {
        /// Lanes `a`, `b`.
        #[inline(always)]
        pub fn new(a: f64, b: f64) -> F64x2 {
            F64x2(unsafe { _mm_set_pd(b, a) })
        }
        /// The two lanes.
        #[inline(always)]
        pub fn lanes(self) -> [f64; 2] {
            let mut out = [0.0; 2];
            // SAFETY: `out` has room for the two f64 an unaligned store writes.
            unsafe { _mm_storeu_pd(out.as_mut_ptr(), self.0) };
            out
        }
        /// Lanes from `a[0]`, `a[1]`.
        #[inline(always)]
        pub fn load(a: &[f64; 2]) -> F64x2 {
            // SAFETY: `a` holds the two f64 an unaligned load reads.
            F64x2(unsafe { _mm_loadu_pd(a.as_ptr()) })
        }
    }

    macro_rules! op {
        ($tr:ident, $f:ident, $intr:ident) => {
            impl std::ops::$tr for F64x2 {
                type Output = F64x2;
                #[inline(always)]
                fn $f(self, o: F64x2) -> F64x2 {
                    F64x2(unsafe { $intr(self.0, o.0) })
                }
            }
        };
    }
    op!(Add, add, _mm_add_pd);
    op!(Sub, sub, _mm_sub_pd);
    op!(Mul, mul, _mm_mul_pd);
    op!(Div, div, _mm_div_pd);

    impl super::Real for F64x2 {
        #[inline(always)]
        fn splat(x: f64) -> Self {
            F64x2(unsafe { _mm_set1_pd(x) })
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            F64x2(unsafe { _mm_sqrt_pd(self.0) })
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            F64x2(unsafe { _mm_min_pd(self.0, o.0) })
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            F64x2(unsafe { _mm_max_pd(self.0, o.0) })
        }
        #[inline(always)]
        fn where_positive(self, cond: Self) -> Self {
            F64x2(unsafe { _mm_and_pd(_mm_cmpgt_pd(cond.0, _mm_setzero_pd()), self.0) })
        }
        #[inline(always)]
        fn powf(self, n: f64) -> Self {
            let [a, b] = self.lanes();
            F64x2::new(a.powf(n), b.powf(n))
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod imp {
    /// Two f64 lanes.
    #[derive(Clone, Copy, Debug)]
    pub struct F64x2(pub(super) [f64; 2]);

    impl F64x2 {
        /// Lanes `a`, `b`.
        #[inline(always)]
        pub fn new(a: f64, b: f64) -> F64x2 {
            F64x2([a, b])
        }
        /// The two lanes.
        #[inline(always)]
        pub fn lanes(self) -> [f64; 2] {
            self.0
        }
        /// Lanes from `a[0]`, `a[1]`.
        #[inline(always)]
        pub fn load(a: &[f64; 2]) -> F64x2 {
            F64x2(*a)
        }
    }

    macro_rules! op {
        ($tr:ident, $f:ident, $o:tt) => {
            impl std::ops::$tr for F64x2 {
                type Output = F64x2;
                #[inline(always)]
                fn $f(self, o: F64x2) -> F64x2 {
                    F64x2([self.0[0] $o o.0[0], self.0[1] $o o.0[1]])
                }
            }
        };
    }
    op!(Add, add, +);
    op!(Sub, sub, -);
    op!(Mul, mul, *);
    op!(Div, div, /);

    impl super::Real for F64x2 {
        fn splat(x: f64) -> Self {
            F64x2([x, x])
        }
        fn sqrt(self) -> Self {
            F64x2(self.0.map(f64::sqrt))
        }
        fn min(self, o: Self) -> Self {
            F64x2([self.0[0].min(o.0[0]), self.0[1].min(o.0[1])])
        }
        fn max(self, o: Self) -> Self {
            F64x2([self.0[0].max(o.0[0]), self.0[1].max(o.0[1])])
        }
        fn where_positive(self, cond: Self) -> Self {
            F64x2([0, 1].map(|k| if cond.0[k] > 0.0 { self.0[k] } else { 0.0 }))
        }
        fn powf(self, n: f64) -> Self {
            F64x2(self.0.map(|x| x.powf(n)))
        }
    }
}

pub use imp::F64x2;

/// The arithmetic a formula needs to be written once for one f64 and for four lanes
/// ([`F64x4`]): comparisons give a mask, and branches are selects.
pub(crate) trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + std::ops::Neg<Output = Self>
{
    /// Lane conditions.
    type Mask: Copy;
    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// |x| per lane.
    fn abs(self) -> Self;
    /// `self > o` per lane.
    fn gt(self, o: Self) -> Self::Mask;
    /// `self < o` per lane.
    fn lt(self, o: Self) -> Self::Mask;
    /// `a` where `m` holds, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// The magnitude of `self` with the sign of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// Whether bit `bit` (a mask of one bit) of each lane's representation is set.
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))] // read by the lanes' sin_cos only
    fn has_bit(self, bit: u64) -> Self::Mask;
}

impl Lane for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(x: f64) -> f64 {
        x
    }
    #[inline(always)]
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    #[inline(always)]
    fn gt(self, o: f64) -> bool {
        self > o
    }
    #[inline(always)]
    fn lt(self, o: f64) -> bool {
        self < o
    }
    #[inline(always)]
    fn select(m: bool, a: f64, b: f64) -> f64 {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn copysign(self, sign: f64) -> f64 {
        f64::copysign(self, sign)
    }
    #[inline(always)]
    fn has_bit(self, bit: u64) -> bool {
        self.to_bits() & bit != 0
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::{F64x4, Mask4};

/// Four f64 lanes in an AVX register, for the direct model's batch evaluation.
#[cfg(target_arch = "x86_64")]
mod avx {
    use std::arch::x86_64::*;

    /// Four f64 lanes in one AVX register: each operation the IEEE operation of each lane (no
    /// fused multiply-add), so a lane gives the bits the same scalar arithmetic gives.
    ///
    /// Only for code that runs on a processor with AVX2: every function here compiles to AVX
    /// instructions, and is meant to be inlined into a function compiled for AVX2 after
    /// `is_x86_feature_detected!("avx2")` (the direct model's batch). Values cannot be created
    /// outside this crate (the type is crate-private).
    #[derive(Clone, Copy, Debug)]
    pub struct F64x4(__m256d);

    /// Four lane conditions (all bits set or clear per lane).
    #[derive(Clone, Copy, Debug)]
    pub struct Mask4(__m256d);

    // SAFETY (every `unsafe` block below): AVX instructions, which the callers' contract
    // (AVX2 detected) provides; loads and stores are of whole local arrays.
    impl F64x4 {
        /// Every lane `x`.
        #[inline(always)]
        pub fn splat(x: f64) -> F64x4 {
            F64x4(unsafe { _mm256_set1_pd(x) })
        }
        /// The lanes of `a`, lane 0 first.
        #[inline(always)]
        pub fn from_array(a: [f64; 4]) -> F64x4 {
            F64x4(unsafe { _mm256_loadu_pd(a.as_ptr()) })
        }
        /// The lanes as an array, lane 0 first.
        #[inline(always)]
        pub fn to_array(self) -> [f64; 4] {
            let mut a = [0.0; 4];
            unsafe { _mm256_storeu_pd(a.as_mut_ptr(), self.0) };
            a
        }
        /// Square root per lane.
        #[inline(always)]
        pub fn sqrt(self) -> F64x4 {
            F64x4(unsafe { _mm256_sqrt_pd(self.0) })
        }
        /// |x| per lane.
        #[inline(always)]
        pub fn abs(self) -> F64x4 {
            F64x4(unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0) })
        }
        #[inline(always)]
        fn cmp<const P: i32>(self, o: F64x4) -> Mask4 {
            Mask4(unsafe { _mm256_cmp_pd::<P>(self.0, o.0) })
        }
        /// `self < o` per lane (false where either is NaN).
        #[inline(always)]
        pub fn lt(self, o: F64x4) -> Mask4 {
            self.cmp::<_CMP_LT_OQ>(o)
        }
        /// `self <= o` per lane.
        #[inline(always)]
        pub fn le(self, o: F64x4) -> Mask4 {
            self.cmp::<_CMP_LE_OQ>(o)
        }
        /// `self > o` per lane.
        #[inline(always)]
        pub fn gt(self, o: F64x4) -> Mask4 {
            self.cmp::<_CMP_GT_OQ>(o)
        }
        /// `self >= o` per lane.
        #[inline(always)]
        pub fn ge(self, o: F64x4) -> Mask4 {
            self.cmp::<_CMP_GE_OQ>(o)
        }
        /// Lanes where `self` is NaN.
        #[inline(always)]
        fn nan(self) -> Mask4 {
            self.cmp::<_CMP_UNORD_Q>(self)
        }
        /// `f64::max` per lane (the other lane where one is NaN).
        #[inline(always)]
        pub fn max(self, o: F64x4) -> F64x4 {
            // max_pd(a, b) gives b where either is NaN.
            o.nan()
                .select(self, F64x4(unsafe { _mm256_max_pd(self.0, o.0) }))
        }
        /// `f64::min` per lane (the other lane where one is NaN).
        #[inline(always)]
        pub fn min(self, o: F64x4) -> F64x4 {
            o.nan()
                .select(self, F64x4(unsafe { _mm256_min_pd(self.0, o.0) }))
        }
        /// `f64::clamp` per lane (NaN stays NaN).
        #[inline(always)]
        pub fn clamp(self, lo: f64, hi: f64) -> F64x4 {
            self.clamp_to(F64x4::splat(lo), F64x4::splat(hi))
        }
        /// `f64::clamp` per lane with bounds per lane (NaN stays NaN).
        #[inline(always)]
        pub fn clamp_to(self, lo: F64x4, hi: F64x4) -> F64x4 {
            self.lt(lo).select(lo, self.gt(hi).select(hi, self))
        }
    }

    impl Mask4 {
        /// Every lane `m`.
        #[inline(always)]
        pub fn splat(m: bool) -> Mask4 {
            Mask4(unsafe { _mm256_castsi256_pd(_mm256_set1_epi64x(-i64::from(m))) })
        }
        /// `a` in the lanes where the mask holds, `b` elsewhere.
        #[inline(always)]
        pub fn select(self, a: F64x4, b: F64x4) -> F64x4 {
            F64x4(unsafe { _mm256_blendv_pd(b.0, a.0, self.0) })
        }
        /// The lanes as booleans, lane 0 first.
        #[inline(always)]
        pub fn to_array(self) -> [bool; 4] {
            let bits = unsafe { _mm256_movemask_pd(self.0) };
            [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0, bits & 8 != 0]
        }
        /// Whether any lane holds.
        #[inline(always)]
        pub fn any(self) -> bool {
            unsafe { _mm256_movemask_pd(self.0) != 0 }
        }
    }

    macro_rules! lane_op {
        ($tr:ident, $f:ident, $intr:ident) => {
            impl std::ops::$tr for F64x4 {
                type Output = F64x4;
                #[inline(always)]
                fn $f(self, o: F64x4) -> F64x4 {
                    F64x4(unsafe { $intr(self.0, o.0) })
                }
            }
            impl std::ops::$tr<f64> for F64x4 {
                type Output = F64x4;
                #[inline(always)]
                fn $f(self, o: f64) -> F64x4 {
                    std::ops::$tr::$f(self, F64x4::splat(o))
                }
            }
            impl std::ops::$tr<F64x4> for f64 {
                type Output = F64x4;
                #[inline(always)]
                fn $f(self, o: F64x4) -> F64x4 {
                    std::ops::$tr::$f(F64x4::splat(self), o)
                }
            }
        };
    }
    lane_op!(Add, add, _mm256_add_pd);
    lane_op!(Sub, sub, _mm256_sub_pd);
    lane_op!(Mul, mul, _mm256_mul_pd);
    lane_op!(Div, div, _mm256_div_pd);

    impl std::ops::Neg for F64x4 {
        type Output = F64x4;
        #[inline(always)]
        fn neg(self) -> F64x4 {
            F64x4(unsafe { _mm256_xor_pd(_mm256_set1_pd(-0.0), self.0) })
        }
    }

    macro_rules! mask_op {
        ($tr:ident, $f:ident, $intr:ident) => {
            impl std::ops::$tr for Mask4 {
                type Output = Mask4;
                #[inline(always)]
                fn $f(self, o: Mask4) -> Mask4 {
                    Mask4(unsafe { $intr(self.0, o.0) })
                }
            }
        };
    }
    mask_op!(BitAnd, bitand, _mm256_and_pd);
    mask_op!(BitOr, bitor, _mm256_or_pd);

    impl std::ops::Not for Mask4 {
        type Output = Mask4;
        #[inline(always)]
        fn not(self) -> Mask4 {
            Mask4(unsafe { _mm256_xor_pd(self.0, _mm256_castsi256_pd(_mm256_set1_epi64x(-1))) })
        }
    }

    impl super::Lane for F64x4 {
        type Mask = Mask4;
        #[inline(always)]
        fn splat(x: f64) -> F64x4 {
            F64x4::splat(x)
        }
        #[inline(always)]
        fn abs(self) -> F64x4 {
            F64x4::abs(self)
        }
        #[inline(always)]
        fn gt(self, o: F64x4) -> Mask4 {
            F64x4::gt(self, o)
        }
        #[inline(always)]
        fn lt(self, o: F64x4) -> Mask4 {
            F64x4::lt(self, o)
        }
        #[inline(always)]
        fn select(m: Mask4, a: F64x4, b: F64x4) -> F64x4 {
            m.select(a, b)
        }
        #[inline(always)]
        fn copysign(self, sign: F64x4) -> F64x4 {
            unsafe {
                let s = _mm256_set1_pd(-0.0);
                F64x4(_mm256_or_pd(
                    _mm256_andnot_pd(s, self.0),
                    _mm256_and_pd(s, sign.0),
                ))
            }
        }
        #[inline(always)]
        fn has_bit(self, bit: u64) -> Mask4 {
            unsafe {
                let b = _mm256_set1_epi64x(bit as i64);
                let set = _mm256_and_si256(_mm256_castpd_si256(self.0), b);
                Mask4(_mm256_castsi256_pd(_mm256_cmpeq_epi64(set, b)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_match_scalar_arithmetic() {
        let (a, b) = (F64x2::new(1.5, -2.0), F64x2::new(0.25, 3.0));
        assert_eq!((a + b).lanes(), [1.75, 1.0]);
        assert_eq!((a - b).lanes(), [1.25, -5.0]);
        assert_eq!((a * b).lanes(), [0.375, -6.0]);
        assert_eq!((a / b).lanes(), [6.0, -2.0 / 3.0]);
        assert_eq!(F64x2::new(4.0, 2.25).sqrt().lanes(), [2.0, 1.5]);
        assert_eq!(a.min(b).lanes(), [0.25, -2.0]);
        assert_eq!(a.max(b).lanes(), [1.5, 3.0]);
        assert_eq!(b.where_positive(a).lanes(), [0.25, 0.0]);
        assert_eq!(
            F64x2::new(2.0, 3.0).powf(1.5).lanes(),
            [2f64.powf(1.5), 3f64.powf(1.5)]
        );
        assert_eq!(F64x2::load(&[7.0, 8.0]).lanes(), [7.0, 8.0]);
        assert_eq!(<F64x2 as Real>::splat(0.5).lanes(), [0.5, 0.5]);
        let nan = F64x2::new(f64::NAN, 1.0);
        assert_eq!(b.where_positive(nan).lanes(), [0.0, 3.0]);
    }
}
