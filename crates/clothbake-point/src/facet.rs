//! The facet formulas of a yarn surface point from the cosines of its directions, in the
//! thesis's intensity (pi times radiance, for unit light): the one place they are written for
//! the analytic model (clothbake-core, which evaluates them on one value or on SIMD lanes) and
//! the point level ([`crate::Facet::intensity`]). The ground truth (clothbake-truth) keeps its
//! own copy on purpose; a test of the model's holds the two against each other.
//!
//! * Huo (thesis eqs 4.6, 4.8): I_s = rho_s (N.H)^n with N.H = (N.L + N.E) / |L + E| and
//!   |L + E|^2 = 2 + 2 L.E;
//! * Lewis's modified Phong: I_s = rho_s (n + 2) / 2 (R.E)^n N.L with R.E = 2 (N.L)(N.E) - L.E.

use crate::Facet;
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

/// The specular term of a facet model bound to one material, from cosines: the one place of the
/// facet formulas. Huo (eq. 4.8): rho_s (N.H)^n with N.H = (N.L + N.E) / |L + E| and
/// |L + E|^2 = 2 + 2 L.E. Lewis: rho_s (n + 2) / 2 (R.E)^n N.L with R.E = 2 (N.L)(N.E) - L.E.
/// Built once per material so that loops evaluating it many times skip the set-up.
#[derive(Clone, Copy, Debug)]
pub struct CosineFacet {
    model: Facet,
    /// rho_s (Huo) or rho_s (n + 2) / 2 (Lewis).
    scale: f64,
    power: Power,
}

/// x^n: square-and-multiply for integer 0 <= n <= 64 (several times faster than `powf`, which
/// the hot loops of the secondary reflection feel), `powf` otherwise.
#[derive(Clone, Copy, Debug)]
enum Power {
    Int(u32),
    Real(f64),
}

impl Power {
    fn new(n: f64) -> Power {
        if n.fract() == 0.0 && (0.0..=64.0).contains(&n) {
            Power::Int(n as u32)
        } else {
            Power::Real(n)
        }
    }

    #[inline(always)]
    fn of<T: Real>(self, x: T) -> T {
        match self {
            Power::Int(n) => {
                let (mut acc, mut base, mut k) = (T::splat(1.0), x, n);
                while k > 0 {
                    if k & 1 == 1 {
                        acc = acc * base;
                    }
                    base = base * base;
                    k >>= 1;
                }
                acc
            }
            Power::Real(n) => x.powf(n),
        }
    }
}

impl CosineFacet {
    /// The specular term of `model` for specular coefficient rho_s `specular` and exponent n
    /// `exponent`.
    pub fn new(model: Facet, specular: f64, exponent: f64) -> CosineFacet {
        let scale = match model {
            Facet::Huo => specular,
            Facet::Lewis => specular * 0.5 * (exponent + 2.0),
        };
        CosineFacet {
            model,
            scale,
            power: Power::new(exponent),
        }
    }

    /// True when the specular term is zero everywhere (rho_s = 0).
    pub fn is_zero(&self) -> bool {
        self.scale == 0.0
    }

    /// Specular intensity for unit light, from N.L > 0 and N.E > 0 (the caller checks them: the
    /// term is zero otherwise) and L.E; for one value (`f64`) or two lanes
    /// (the model's SSE2 lanes) alike.
    #[inline(always)]
    pub fn specular<T: Real>(&self, nl: T, ne: T, le: T) -> T {
        let scale = T::splat(self.scale);
        match self.model {
            Facet::Huo => {
                // (N.H)^2 = (N.L + N.E)^2 / (2 + 2 L.E): an even integer exponent needs no
                // square root. |L + E| = 0 (L = -E) gives 0.
                let two = T::splat(2.0);
                let hh = two + two * le;
                let s = nl + ne;
                let nh2 = (s * s / hh.max(T::splat(f64::MIN_POSITIVE))).min(T::splat(1.0));
                let v = match self.power {
                    Power::Int(n) if n % 2 == 0 => scale * Power::Int(n / 2).of(nh2),
                    p => scale * p.of(nh2.sqrt()),
                };
                v.where_positive(hh)
            }
            Facet::Lewis => {
                let re = (T::splat(2.0) * nl * ne - le).max(T::splat(0.0));
                scale * self.power.of(re) * nl
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_powers_by_squaring_agree_with_powf() {
        for n in 0..=64u32 {
            for x in [0.0, 1e-3, 0.3, 0.77, 0.99, 1.0] {
                let (a, b) = (Power::new(f64::from(n)).of(x), x.powf(f64::from(n)));
                assert!(
                    (a - b).abs() <= 1e-13 * b.max(1e-300),
                    "{x}^{n}: {a} vs {b}"
                );
            }
        }
        // Past 64, or not whole: powf itself.
        assert_eq!(Power::new(2.5).of(0.5), 0.5f64.powf(2.5));
        assert_eq!(Power::new(65.0).of(0.9), 0.9f64.powf(65.0));
    }

    #[test]
    fn the_specular_terms_are_their_closed_forms_in_the_plane() {
        // N = Z, L 40 degrees one side, E 20 degrees the other: N.H = cos 10 degrees, R.E =
        // cos 20 degrees.
        let (nl, ne) = (40f64.to_radians().cos(), 20f64.to_radians().cos());
        let le = 60f64.to_radians().cos();
        for n in [7.0, 8.0, 2.5] {
            let huo = CosineFacet::new(Facet::Huo, 0.3, n).specular(nl, ne, le);
            let lewis = CosineFacet::new(Facet::Lewis, 0.3, n).specular(nl, ne, le);
            let want_huo = 0.3 * 10f64.to_radians().cos().powf(n);
            let want_lewis = 0.3 * (n + 2.0) / 2.0 * 20f64.to_radians().cos().powf(n) * nl;
            assert!((huo - want_huo).abs() < 1e-14, "{n}: {huo} vs {want_huo}");
            assert!(
                (lewis - want_lewis).abs() < 1e-14,
                "{n}: {lewis} vs {want_lewis}"
            );
        }
        assert!(CosineFacet::new(Facet::Huo, 0.0, 10.0).is_zero());
        // L = -E: no half vector, nothing.
        assert_eq!(
            CosineFacet::new(Facet::Huo, 0.5, 3.0).specular(1.0, 1.0, -1.0),
            0.0
        );
    }
}
