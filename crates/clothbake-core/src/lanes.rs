//! Two f64 lanes for the innermost quadrature loop of the secondary reflection: SSE2 on x86-64
//! (part of the baseline target, so no run-time detection), two plain f64 elsewhere. [`Real`]
//! is the arithmetic the facet terms need, so that [`crate::facet::CosineFacet`] keeps its
//! formulas in one place for one value or two.

use std::ops::{Add, Div, Mul, Sub};

/// The arithmetic of the facet terms, for `f64` and [`F64x2`].
pub trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// Square root per lane.
    fn sqrt(self) -> Self;
    /// Lane-wise minimum (`o` where either is NaN).
    fn min(self, o: Self) -> Self;
    /// Lane-wise maximum (`o` where either is NaN).
    fn max(self, o: Self) -> Self;
    /// `self` where `cond > 0`, else 0 (also for a NaN `cond`).
    fn where_positive(self, cond: Self) -> Self;
    /// `self^n` per lane (`powf`).
    fn powf(self, n: f64) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        if self < o {
            self
        } else {
            o
        }
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        if self > o {
            self
        } else {
            o
        }
    }
    #[inline(always)]
    fn where_positive(self, cond: Self) -> Self {
        if cond > 0.0 {
            self
        } else {
            0.0
        }
    }
    #[inline(always)]
    fn powf(self, n: f64) -> Self {
        f64::powf(self, n)
    }
}

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
