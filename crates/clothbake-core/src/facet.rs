//! Facet (microscopic) reflection models behind one trait (thesis sec. 4.2, eqs 4.6 and 4.8).
//!
//! Every model returns the thesis's *intensity* for unit incident intensity, i.e. pi times the
//! reflected radiance: I = pi f(l, e) (n.l) for a facet BRDF f. It is split into a part that
//! scales with the diffuse albedo (returned without the albedo) and a specular part (white).

use crate::vec3::Vec3;
use crate::yarn::Material;
pub use clothbake_point::facet::CosineFacet;

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

/// The selectable facet models (the selector the ground truth reads too).
pub use clothbake_fabric::FacetModel;

/// [`Facet::intensity`] of `model` from the three cosines N.L, N.E and L.E of unit vectors
/// alone, for integrands that have them at hand (the secondary reflection's axial lines).
#[inline]
pub fn intensity_cos(model: FacetModel, m: &Material, nl: f64, ne: f64, le: f64) -> FacetIntensity {
    if nl <= 0.0 || ne <= 0.0 {
        return FacetIntensity::default();
    }
    FacetIntensity {
        diffuse: nl,
        specular: cosine_facet(model, m).specular(nl, ne, le),
    }
}

impl Facet for FacetModel {
    fn intensity(&self, m: &Material, n: Vec3, l: Vec3, e: Vec3) -> FacetIntensity {
        intensity_cos(*self, m, n.dot(l), n.dot(e), l.dot(e))
    }
}

/// The specular term of `model` bound to material `m` ([`CosineFacet`], the one place of the
/// formulas, in clothbake-point: the point level shares it).
pub fn cosine_facet(model: FacetModel, m: &Material) -> CosineFacet {
    CosineFacet::new(point_facet(model), m.specular, m.exponent)
}

/// The point level's name of a facet model.
pub fn point_facet(model: FacetModel) -> clothbake_point::Facet {
    match model {
        FacetModel::Huo => clothbake_point::Facet::Huo,
        FacetModel::Lewis => clothbake_point::Facet::Lewis,
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
    fn huo_half_vector_from_cosines_matches_the_explicit_half_vector() {
        // N.H computed from the normalised vector L + E, independently of intensity_cos; an odd
        // exponent (square root of (N.H)^2), an even one (none) and a real one (powf).
        for (exponent, (n, l, e)) in [9.0, 10.0, 7.5].into_iter().flat_map(|x| {
            [
                ((10.0, 30.0), (40.0, 200.0), (35.0, 10.0)),
                ((0.0, 0.0), (60.0, 0.0), (60.0, 180.0)),
                ((25.0, 90.0), (5.0, 45.0), (80.0, 300.0)),
            ]
            .map(|d| (x, d))
        }) {
            let m = Material {
                albedo: [0.5; 3],
                specular: 0.7,
                exponent,
                translucency: 0.0,
            };
            let n = UnitVec3::from_degrees(n.0, n.1).get();
            let l = UnitVec3::from_degrees(l.0, l.1).get();
            let e = UnitVec3::from_degrees(e.0, e.1).get();
            let h = l + e;
            let nh = (n.dot(h) / h.length()).max(0.0);
            let i = FacetModel::Huo.intensity(&m, n, l, e);
            if n.dot(l) > 0.0 && n.dot(e) > 0.0 {
                assert!((i.specular - 0.7 * nh.powf(exponent)).abs() < 1e-12);
                assert!((i.diffuse - n.dot(l)).abs() < 1e-15);
            } else {
                assert_eq!(i, FacetIntensity::default());
            }
        }
    }

    #[test]
    fn lewis_specular_lobe_is_normalised() {
        // Directional albedo of the specular lobe at normal incidence is exactly rho_s.
        let m = Material {
            albedo: [0.0; 3],
            specular: 1.0,
            exponent: 7.0,
            translucency: 0.0,
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
