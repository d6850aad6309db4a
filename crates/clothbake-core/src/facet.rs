//! Facet (microscopic) reflection models behind one trait (thesis sec. 4.2, eqs 4.6 and 4.8).
//!
//! Every model returns the thesis's *intensity* for unit incident intensity, i.e. pi times the
//! reflected radiance: I = pi f(l, e) (n.l) for a facet BRDF f. It is split into a part that
//! scales with the diffuse albedo (returned without the albedo) and a specular part (white).

use crate::fabric::Material;
use crate::vec3::Vec3;
use serde::{Deserialize, Serialize};

/// The intensity a facet reflects: `diffuse` times the RGB albedo, plus `specular`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FacetIntensity {
    /// Diffuse factor, to be multiplied by the albedo rho_d (per channel).
    pub diffuse: f64,
    /// Specular intensity (already includes rho_s).
    pub specular: f64,
}

/// A facet reflection model.
pub trait Facet: Send + Sync {
    /// Intensity reflected toward `e` by a facet of normal `n` lit by unit light from `l`.
    /// All three are unit vectors; zero when `n.l <= 0` or `n.e <= 0`.
    fn intensity(&self, m: &Material, n: Vec3, l: Vec3, e: Vec3) -> FacetIntensity;
}

/// The selectable facet models.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum FacetModel {
    /// The thesis's Phong-like terms: I_d = rho_d N.L (eq. 4.6), I_s = rho_s (N.H)^n (eq. 4.8).
    /// Neither reciprocal nor energy conserving (Lewis 1993).
    #[default]
    Huo,
    /// Lewis's modified Phong (the thesis's future-work item): f = rho_d / pi +
    /// rho_s (n + 2) / (2 pi) (R.E)^n, reciprocal, and energy conserving when rho_d + rho_s <= 1.
    Lewis,
}

impl FacetModel {
    /// Name as used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            FacetModel::Huo => "huo",
            FacetModel::Lewis => "lewis",
        }
    }
}

impl Facet for FacetModel {
    fn intensity(&self, m: &Material, n: Vec3, l: Vec3, e: Vec3) -> FacetIntensity {
        let nl = n.dot(l);
        let ne = n.dot(e);
        if nl <= 0.0 || ne <= 0.0 {
            return FacetIntensity::default();
        }
        match self {
            FacetModel::Huo => {
                let h = l + e;
                let hl = h.length();
                let nh = if hl > 0.0 {
                    (n.dot(h) / hl).max(0.0)
                } else {
                    0.0
                };
                FacetIntensity {
                    diffuse: nl,
                    specular: m.specular * pow(nh, m.exponent),
                }
            }
            FacetModel::Lewis => {
                // R = 2 (N.L) N - L;  R.E = 2 (N.L)(N.E) - L.E
                let re = (2.0 * nl * ne - l.dot(e)).max(0.0);
                FacetIntensity {
                    diffuse: nl,
                    specular: m.specular * 0.5 * (m.exponent + 2.0) * pow(re, m.exponent) * nl,
                }
            }
        }
    }
}

/// x^n for x >= 0: repeated multiplication for small integer n (several times faster than
/// `powf`, which the hot loops of the secondary reflection feel), `powf` otherwise.
#[inline]
fn pow(x: f64, n: f64) -> f64 {
    if n.fract() == 0.0 && (0.0..=64.0).contains(&n) {
        // Square-and-multiply, inlined (the `powi` intrinsic is an out-of-line call).
        let (mut acc, mut base, mut k) = (1.0, x, n as u32);
        while k > 0 {
            if k & 1 == 1 {
                acc *= base;
            }
            base *= base;
            k >>= 1;
        }
        acc
    } else {
        x.powf(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vec3::UnitVec3;

    #[test]
    fn lambertian_part_is_rho_cos() {
        let m = Material::default();
        let n = Vec3::new(0.0, 0.0, 1.0);
        let l = UnitVec3::from_degrees(60.0, 10.0).get();
        let e = UnitVec3::from_degrees(20.0, 200.0).get();
        for f in [FacetModel::Huo, FacetModel::Lewis] {
            let i = f.intensity(&m, n, l, e);
            assert!((i.diffuse - 0.5).abs() < 1e-12);
        }
    }

    #[test]
    fn lewis_specular_lobe_is_normalised() {
        // Directional albedo of the specular lobe at normal incidence is exactly rho_s.
        let m = Material {
            albedo: [0.0; 3],
            specular: 1.0,
            exponent: 7.0,
        };
        let n = Vec3::new(0.0, 0.0, 1.0);
        let (nt, np) = (400, 64);
        let mut sum = 0.0;
        for it in 0..nt {
            let t = (it as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
            for ip in 0..np {
                let p = (ip as f64 + 0.5) / np as f64 * 2.0 * std::f64::consts::PI;
                let e = UnitVec3::from_spherical(t, p).get();
                // intensity / pi = radiance; albedo = int radiance cos dw for unit irradiance.
                let i = FacetModel::Lewis.intensity(&m, n, n, e).specular / std::f64::consts::PI;
                sum += i * t.cos() * t.sin();
            }
        }
        sum *= std::f64::consts::FRAC_PI_2 / nt as f64 * 2.0 * std::f64::consts::PI / np as f64;
        assert!((sum - 1.0).abs() < 1e-3, "{sum}");
    }
}
