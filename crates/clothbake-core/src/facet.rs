//! Facet (microscopic) reflection models behind one trait (thesis sec. 4.2, eqs 4.6 and 4.8).
//!
//! Every model returns the thesis's *intensity* for unit incident intensity, i.e. pi times the
//! reflected radiance: I = pi f(l, e) (n.l) for a facet BRDF f. It is split into a part that
//! scales with the diffuse albedo (returned without the albedo) and a specular part (white).

use crate::lanes::Real;
use crate::vec3::Vec3;
use crate::yarn::Material;

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
        specular: CosineFacet::new(model, m).specular(nl, ne, le),
    }
}

impl Facet for FacetModel {
    fn intensity(&self, m: &Material, n: Vec3, l: Vec3, e: Vec3) -> FacetIntensity {
        intensity_cos(*self, m, n.dot(l), n.dot(e), l.dot(e))
    }
}

/// The specular term of a facet model bound to one material, from cosines: the one place of the
/// facet formulas. Huo (eq. 4.8): rho_s (N.H)^n with N.H = (N.L + N.E) / |L + E| and
/// |L + E|^2 = 2 + 2 L.E. Lewis: rho_s (n + 2) / 2 (R.E)^n N.L with R.E = 2 (N.L)(N.E) - L.E.
/// Built once per material so that loops evaluating it many times skip the set-up.
#[derive(Clone, Copy, Debug)]
pub struct CosineFacet {
    model: FacetModel,
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
    /// The specular term of `model` for material `m`.
    pub fn new(model: FacetModel, m: &Material) -> CosineFacet {
        let scale = match model {
            FacetModel::Huo => m.specular,
            FacetModel::Lewis => m.specular * 0.5 * (m.exponent + 2.0),
        };
        CosineFacet {
            model,
            scale,
            power: Power::new(m.exponent),
        }
    }

    /// True when the specular term is zero everywhere (rho_s = 0).
    pub fn is_zero(&self) -> bool {
        self.scale == 0.0
    }

    /// Specular intensity for unit light, from N.L > 0 and N.E > 0 (the caller checks them: the
    /// term is zero otherwise) and L.E; for one value (`f64`) or two lanes
    /// ([`crate::lanes::F64x2`]) alike.
    #[inline(always)]
    pub fn specular<T: Real>(&self, nl: T, ne: T, le: T) -> T {
        let scale = T::splat(self.scale);
        match self.model {
            FacetModel::Huo => {
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
            FacetModel::Lewis => {
                let re = (T::splat(2.0) * nl * ne - le).max(T::splat(0.0));
                scale * self.power.of(re) * nl
            }
        }
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
