//! A yarn's facet reflection at one surface point, in the thesis's intensity (pi times
//! radiance, for unit light):
//!
//! * Huo (thesis eqs 4.6, 4.8): I = rho_d N.L + rho_s (N.H)^n, H = (L + E) / |L + E|;
//! * Lewis's modified Phong: I = rho_d N.L + rho_s (n + 2) / 2 (R.E)^n N.L, R = 2 (N.L) N - L.
//!
//! Both are zero unless the point faces the light and the eye. The specular terms are
//! [`crate::facet`]'s, the formulas the analytic model evaluates too.

use crate::facet::CosineFacet;
use clothbake_bsdf::{Rgb, Vec3};
use serde::{Deserialize, Serialize};

/// The facet terms (the model's `FacetModel`, by the same names).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Facet {
    /// The thesis's Phong-like terms (eqs 4.6, 4.8).
    Huo,
    /// Lewis's reciprocal modified Phong.
    Lewis,
}

/// A yarn's facet material.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Finish {
    /// Diffuse albedo rho_d, RGB, each in [0, 1].
    pub albedo: Rgb,
    /// Specular coefficient rho_s in [0, 1].
    pub specular: f64,
    /// Specular exponent n, finite and >= 0.
    pub exponent: f64,
}

impl Finish {
    /// Whether every number is in its range; the message names the field.
    pub fn check(&self) -> Result<(), String> {
        let unit = |x: f64| (0.0..=1.0).contains(&x);
        if !self.albedo.iter().all(|&a| unit(a)) {
            return Err(format!("albedo {:?} is not within [0, 1]", self.albedo));
        }
        if !unit(self.specular) {
            return Err(format!("specular {} is not within [0, 1]", self.specular));
        }
        if !(self.exponent.is_finite() && self.exponent >= 0.0) {
            return Err(format!("exponent {} is not finite and >= 0", self.exponent));
        }
        Ok(())
    }
}

impl Facet {
    /// The intensity a facet of unit normal `n` reflects toward the unit `e` for unit light
    /// from the unit `l`, RGB: the albedo times N.L plus the specular term
    /// ([`CosineFacet`], the model's own formula); zero unless N.L > 0 and N.E > 0.
    #[inline]
    pub fn intensity(self, f: &Finish, n: Vec3, l: Vec3, e: Vec3) -> Rgb {
        let (nl, ne) = (n.dot(l), n.dot(e));
        if nl <= 0.0 || ne <= 0.0 {
            return [0.0; 3];
        }
        let s = CosineFacet::new(self, f.specular, f.exponent).specular(nl, ne, l.dot(e));
        f.albedo.map(|a| a * nl + s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms_in_the_plane() {
        // N = Z, L 40 degrees one side, E 20 degrees the other: H is 10 degrees from N toward
        // L; the mirror of L is 40 degrees toward E, 20 degrees from E.
        let d = |deg: f64| Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
        let (n, l, e) = (Vec3::new(0.0, 0.0, 1.0), d(40.0), d(-20.0));
        let f = Finish {
            albedo: [0.2, 0.4, 0.6],
            specular: 0.3,
            exponent: 7.0,
        };
        let nl = 40f64.to_radians().cos();
        let huo = Facet::Huo.intensity(&f, n, l, e);
        let lewis = Facet::Lewis.intensity(&f, n, l, e);
        for k in 0..3 {
            let hs = 0.3 * 10f64.to_radians().cos().powi(7);
            assert!((huo[k] - (f.albedo[k] * nl + hs)).abs() < 1e-14);
            let ls = 0.3 * 4.5 * 20f64.to_radians().cos().powi(7) * nl;
            assert!((lewis[k] - (f.albedo[k] * nl + ls)).abs() < 1e-14);
        }
        // Facing away from the light or the eye: nothing.
        assert_eq!(Facet::Huo.intensity(&f, n, d(95.0), e), [0.0; 3]);
        assert_eq!(Facet::Lewis.intensity(&f, n, l, d(-91.0)), [0.0; 3]);
    }
}
