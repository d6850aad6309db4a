//! Fitted standard materials: the parametric materials that tools without table lookups
//! render (glTF 2.0 viewers, OpenPBR in MaterialX and USD, Blender's Principled BSDF), with
//! parameters fitted to a cloth's BRDF and, over one weave period, to each crossing cell
//! (docs/guide/export.md, "Fitted materials").
//!
//! A material is a base colour (Lambertian diffuse under a dielectric specular layer of index
//! 1.5, anisotropic GGX) under a sheen layer. The cloth model's non-diffuse reflection is
//! colourless (the facets' specular term), so the sheen colour is grey (one number, `sheen`).
//! How the layers combine differs between the targets' specifications and between renderers;
//! [`Convention`] names each rule set and [`Convention::f`] evaluates it:
//!
//! * [`Convention::GltfSpec`]: glTF 2.0 Appendix B (`fresnel_mix` with Schlick's Fresnel, F0
//!   0.04), KHR_materials_anisotropy, KHR_materials_sheen's Charlie sheen with its visibility
//!   and the albedo scaling of the base, exactly as the specifications state.
//! * [`Convention::ThreeJs`]: three.js's implementation of the same glTF parameters (r187,
//!   pinned in tests/renderers/package.json): Charlie with alpha = sheenRoughness^2 and
//!   Neubelt's visibility, Filament's fit of the sheen albedo, and a multiple-scattering
//!   compensation of the specular.
//! * [`Convention::OpenPbr`]: OpenPBR 1.1 (MaterialX 1.39 `open_pbr_surface`): exact dielectric
//!   Fresnel, the base's diffuse scaled by the specular layer's directional albedo, the fuzz
//!   layer of Zeltner et al. 2022 (LTC sheen) scaling what lies under it.
//! * [`Convention::Cycles`]: Blender's Principled BSDF in Cycles (version pinned where the
//!   tests install `bpy`): OpenPBR's layering with Blender's anisotropy parameter.

pub mod fit;
pub mod material;
pub mod microfacet;
pub mod texture;

use clothbake_core::Vec3;
use microfacet::{Albedos, Ggx};
use std::f64::consts::PI;

/// Linear RGB.
pub type Rgb = [f64; 3];

/// The relative index of refraction of every fitted material's specular layer (glTF's
/// default `ior`, OpenPBR's default `specular_ior`).
pub const IOR: f64 = 1.5;

/// The parameters of a fitted material at one point of the period, in the target's own terms
/// ([`Convention`] says how each maps to the lobes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Base colour, linear RGB in [0, 1].
    pub base: Rgb,
    /// Specular roughness (glTF `roughnessFactor`, OpenPBR `specular_roughness`), in [0, 1].
    pub roughness: f64,
    /// Specular anisotropy in [0, 1) (glTF `anisotropyStrength`, OpenPBR
    /// `specular_roughness_anisotropy`, Blender `Anisotropic`).
    pub anisotropy: f64,
    /// The direction along which the specular lobe is rougher, in degrees from the first
    /// tangent (+X, the weft) toward the second (+Y, the warp).
    pub tangent_deg: f64,
    /// Sheen amount in [0, 1]: glTF's grey `sheenColorFactor`, OpenPBR's `fuzz_weight` (with
    /// a white `fuzz_color`), Blender's `Sheen Weight` (with a white tint).
    pub sheen: f64,
    /// Sheen roughness in [0, 1] (glTF `sheenRoughnessFactor`, OpenPBR `fuzz_roughness`).
    pub sheen_roughness: f64,
    /// Diffuse roughness in [0, 1] (OpenPBR `base_diffuse_roughness`, Blender's `Diffuse
    /// Roughness`: the energy-preserving Oren-Nayar model); glTF has none (always 0).
    pub diffuse_roughness: f64,
}

impl Params {
    /// Every parameter rounded to f32, as a file writes factors and float images.
    pub fn to_f32(&self) -> Params {
        let f = |x: f64| x as f32 as f64;
        Params {
            base: self.base.map(f),
            roughness: f(self.roughness),
            anisotropy: f(self.anisotropy),
            tangent_deg: f(self.tangent_deg),
            sheen: f(self.sheen),
            sheen_roughness: f(self.sheen_roughness),
            diffuse_roughness: f(self.diffuse_roughness),
        }
    }
}

/// A family of targets whose files share one parameterisation (and so one fit).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// glTF 2.0 with KHR_materials_sheen and KHR_materials_anisotropy.
    Gltf,
    /// OpenPBR (MaterialX, USD) and Blender's Principled BSDF.
    OpenPbr,
}

impl Family {
    /// The rule set a family is fitted with: its specification's.
    pub fn convention(self) -> Convention {
        match self {
            Family::Gltf => Convention::GltfSpec,
            Family::OpenPbr => Convention::OpenPbr,
        }
    }

    /// Its name in messages and docs.
    pub fn name(self) -> &'static str {
        match self {
            Family::Gltf => "glTF",
            Family::OpenPbr => "OpenPBR",
        }
    }
}

/// A rule set that turns [`Params`] into f_r (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Convention {
    /// The glTF 2.0 specification with KHR_materials_sheen and KHR_materials_anisotropy.
    GltfSpec,
    /// three.js's implementation of the glTF material.
    ThreeJs,
    /// OpenPBR 1.1 / MaterialX 1.39 `open_pbr_surface`.
    OpenPbr,
    /// Blender's Principled BSDF in Cycles, given OpenPBR-fitted parameters converted by
    /// [`cycles_params`].
    Cycles,
}

/// The GGX roughnesses (along the rough direction, across it) a convention gives `p`.
pub fn alphas(conv: Convention, p: &Params) -> (f64, f64) {
    // three.js raises the roughness to 0.045 at least.
    let r = match conv {
        Convention::ThreeJs => p.roughness.max(0.045),
        _ => p.roughness,
    };
    let a = (r * r).max(microfacet::ALPHA_MIN);
    let s = p.anisotropy.clamp(0.0, 1.0);
    match conv {
        // KHR_materials_anisotropy: alpha_t = mix(alpha, 1, s^2), alpha_b = alpha.
        Convention::GltfSpec | Convention::ThreeJs => (a + (1.0 - a) * s * s, a),
        // OpenPBR: alpha_t = alpha sqrt(2 / (1 + (1 - s)^2)), alpha_b = (1 - s) alpha_t.
        Convention::OpenPbr => {
            let t = a * (2.0 / (1.0 + (1.0 - s) * (1.0 - s))).sqrt();
            (t.min(1.0), ((1.0 - s) * t).max(microfacet::ALPHA_MIN))
        }
        // Principled BSDF: aspect = sqrt(1 - 0.9 s), alpha_x = alpha / aspect, alpha_y =
        // alpha aspect.
        Convention::Cycles => {
            let aspect = (1.0 - 0.9 * s).sqrt();
            ((a / aspect).min(1.0), a * aspect)
        }
    }
}

/// OpenPBR-fitted parameters as Blender's Principled BSDF takes them: the same mean alpha
/// and the same ratio of the two alphas (as far as Blender's range, a ratio of 0.1, allows).
pub fn cycles_params(p: &Params) -> Params {
    let (t, b) = alphas(Convention::OpenPbr, p);
    let ratio = (b / t).clamp(0.1, 1.0);
    // aspect^2 = 1 - 0.9 s = ratio.
    let anisotropy = ((1.0 - ratio) / 0.9).clamp(0.0, 1.0);
    Params {
        roughness: (t * b).sqrt().sqrt(),
        anisotropy,
        ..*p
    }
}

/// The normal-incidence reflectance of a dielectric of index `eta`: ((eta - 1) / (eta + 1))^2.
pub fn f0(eta: f64) -> f64 {
    ((eta - 1.0) / (eta + 1.0)).powi(2)
}

/// `w` in the frame whose +X is the rough direction `deg` degrees from +X.
fn rotate(w: Vec3, deg: f64) -> Vec3 {
    let (s, c) = deg.to_radians().sin_cos();
    Vec3::new(c * w.x + s * w.y, -s * w.x + c * w.y, w.z)
}

impl Convention {
    /// f_r(l, v) in 1/sr of the material `p` under this rule set; `l` toward the light, `v`
    /// toward the eye, local frame (+X the weft, +Z the normal); zero at or below the horizon.
    pub fn f(self, p: &Params, tables: &Albedos, l: Vec3, v: Vec3) -> Rgb {
        let t = self.terms(p, tables, l, v);
        p.base.map(|b| t.of(b))
    }

    /// f_r per channel as base A + h(base) M + K ([`Terms`]): every layer but the base colour
    /// is grey, so each channel is the same function of its base colour (the fit solves the
    /// base per channel with these numbers).
    pub fn terms(self, p: &Params, tables: &Albedos, l: Vec3, v: Vec3) -> Terms {
        if l.z <= 1e-9 || v.z <= 1e-9 {
            return Terms::default();
        }
        let (at, ab) = alphas(self, p);
        let g = Ggx { ax: at, ay: ab };
        let (lt, vt) = (rotate(l, p.tangent_deg), rotate(v, p.tangent_deg));
        let h = l + v;
        let vh = (v.dot(h) / h.length()).clamp(0.0, 1.0);
        let lobe = g.lobe(lt, vt);
        let s = p.sheen.clamp(0.0, 1.0);
        let mut sigma = 0.0;
        let ((diffuse, multi), specular, sheen, scale) = match self {
            Convention::GltfSpec => {
                // fresnel_mix(ior, diffuse, specular) under the sheen's albedo scaling.
                let f = microfacet::fresnel_schlick(f0(tables.eta()), vh);
                let a = p.sheen_roughness.max(microfacet::ALPHA_MIN);
                let scale =
                    (1.0 - s * tables.charlie(v.z, a)).min(1.0 - s * tables.charlie(l.z, a));
                (
                    ((1.0 - f) / PI, 0.0),
                    f * lobe,
                    s * microfacet::charlie_lobe(l, v, a),
                    scale,
                )
            }
            Convention::ThreeJs => {
                // three.js r187 (src/renderers/shaders/ShaderChunk, lights_physical_*):
                // Epic's exp2 form of Schlick's Fresnel, the diffuse scaled by 1 - F
                // (fresnel_mix), the specular times the multiple-scattering compensation
                // 1 + F0 (1 / E_ss - 1), Charlie with alpha = roughness^2 and sin^2 >= 2^-7,
                // Neubelt's visibility clamped to 1, and the base scaled by
                // 1 - max(sheen) max(E(v), E(l)) with Filament's fit of E.
                let x = vh;
                let phi = 2f64.powf((-5.55473 * x - 6.98316) * x);
                let f0 = f0(tables.eta());
                let f = f0 * (1.0 - phi) + phi;
                let comp = 1.0 + f0 * (1.0 / tables.white_specular(v.z, g.ay).max(1e-3) - 1.0);
                let r = p.sheen_roughness;
                let scale = 1.0
                    - s * microfacet::filament_sheen_albedo(v.z, r)
                        .max(microfacet::filament_sheen_albedo(l.z, r));
                (
                    ((1.0 - f) / PI, 0.0),
                    f * lobe * comp,
                    s * microfacet::charlie_lobe_threejs(l, v, r * r),
                    scale,
                )
            }
            Convention::OpenPbr | Convention::Cycles => {
                let f = microfacet::fresnel_dielectric(vh, tables.eta());
                let e = match self {
                    // Cycles layers by the albedo of the specular lobe with its
                    // multiple scattering restored (measured: the single-scattering
                    // albedo over the white furnace's).
                    Convention::Cycles => {
                        tables.specular(v.z, g.mean_alpha())
                            / tables.white_specular(v.z, g.mean_alpha()).max(1e-3)
                    }
                    _ => tables.specular(v.z, g.mean_alpha()),
                };
                let r = p.sheen_roughness.clamp(0.01, 1.0);
                sigma = p.diffuse_roughness.clamp(0.0, 1.0);
                let (d1, dm) = microfacet::eon_terms(l, v, sigma);
                (
                    ((1.0 - e) * d1, (1.0 - e) * dm),
                    f * lobe,
                    s * microfacet::zeltner_lobe_cos(l, v, r) / l.z,
                    1.0 - s * microfacet::zeltner_albedo(v.z, r),
                )
            }
        };
        Terms {
            a: diffuse * scale,
            m: multi * scale,
            k: specular * scale + sheen,
            sigma,
            colour_twice: self == Convention::Cycles,
        }
    }
}

/// f_r of one channel of base colour c: c a + h(c) m + k, h the colour of the diffuse's
/// multiple scattering ([`Terms::h`]; zero `m` without diffuse roughness).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Terms {
    /// The coefficient of the base colour.
    pub a: f64,
    /// The coefficient of h(base colour).
    pub m: f64,
    /// The grey rest (specular and sheen).
    pub k: f64,
    /// The Oren-Nayar roughness of the diffuse (what h depends on).
    pub sigma: f64,
    /// Whether the multiple scattering's colour is weighted by the base colour again (Cycles).
    pub colour_twice: bool,
}

impl Terms {
    /// The channel's f_r for base colour `c`.
    pub fn of(&self, c: f64) -> f64 {
        c * self.a + self.h(c) * self.m + self.k
    }

    /// The colour of the diffuse's multiple scattering for base colour `c`: EON's
    /// c^2 E / (1 - c (1 - E)) ([`microfacet::eon_colour`]), times c once more in Cycles,
    /// which weights the Oren-Nayar closure (multiple scattering included) by the base
    /// colour (Blender 5.0 `svm_closure.h`, `bsdf_oren_nayar.h`; measured).
    pub fn h(&self, c: f64) -> f64 {
        if self.m == 0.0 {
            return 0.0;
        }
        let h = microfacet::eon_colour(c, self.sigma);
        if self.colour_twice {
            c * h
        } else {
            h
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> Params {
        Params {
            base: [0.5, 0.3, 0.2],
            roughness: 0.6,
            anisotropy: 0.5,
            tangent_deg: 0.0,
            sheen: 0.4,
            sheen_roughness: 0.5,
            diffuse_roughness: 0.3,
        }
    }

    fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
        let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }

    #[test]
    fn every_specified_convention_conserves_energy() {
        // three.js is left out: its Lambert term is not scaled by the Fresnel factor, and its
        // sheen's Neubelt visibility is not energy conserving (the KHR_materials_sheen
        // specification says so).
        let t = Albedos::new(IOR);
        let p = Params {
            base: [1.0; 3],
            sheen: 1.0,
            ..params()
        };
        for conv in [
            Convention::GltfSpec,
            Convention::OpenPbr,
            Convention::Cycles,
        ] {
            for tv in [0.0f64, 45.0, 80.0] {
                let c = tv.to_radians().cos();
                let e = microfacet::hemisphere_albedo(c, |l, v| conv.f(&p, &t, l, v)[0]);
                assert!(e < 1.02, "{conv:?} at {tv}: albedo {e}");
            }
        }
    }

    #[test]
    fn a_lambertian_material_is_base_over_pi_where_the_layers_vanish() {
        // No sheen and the roughest GGX: OpenPBR's base is (1 - E_spec) base / pi + F D G.
        let t = Albedos::new(IOR);
        let p = Params {
            sheen: 0.0,
            anisotropy: 0.0,
            diffuse_roughness: 0.0,
            ..params()
        };
        let (l, v) = (dir(20.0, 0.0), dir(30.0, 150.0));
        let f = Convention::OpenPbr.f(&p, &t, l, v);
        let g = Ggx { ax: 0.36, ay: 0.36 };
        let h = l + v;
        let vh = v.dot(h) / h.length();
        let spec = microfacet::fresnel_dielectric(vh, IOR) * g.lobe(l, v);
        let e = microfacet::ggx_albedo(v.z, 0.36, IOR);
        let want = 0.5 * (1.0 - e) / PI + spec;
        assert!((f[0] - want).abs() < 2e-3 * want, "{} vs {want}", f[0]);
    }

    #[test]
    fn the_tangent_turns_the_lobe() {
        let t = Albedos::new(IOR);
        let p = params();
        let q = Params {
            tangent_deg: 90.0,
            ..p
        };
        let (l, v) = (dir(40.0, 0.0), dir(40.0, 180.0));
        let sw = |w: Vec3| Vec3::new(-w.y, w.x, w.z);
        for conv in [Convention::GltfSpec, Convention::OpenPbr] {
            let a = conv.f(&p, &t, l, v);
            let b = conv.f(&q, &t, sw(l), sw(v));
            assert!((a[1] - b[1]).abs() < 1e-9 * a[1], "{conv:?}");
            // And the anisotropy matters: the turned lobe differs at the same directions.
            assert!(
                (a[1] - conv.f(&q, &t, l, v)[1]).abs() > 1e-3 * a[1],
                "{conv:?}"
            );
        }
    }

    #[test]
    fn cycles_parameters_keep_the_alphas() {
        let p = Params {
            anisotropy: 0.4,
            ..params()
        };
        let (t, b) = alphas(Convention::OpenPbr, &p);
        let (tc, bc) = alphas(Convention::Cycles, &cycles_params(&p));
        assert!(
            (t - tc).abs() < 1e-12 && (b - bc).abs() < 1e-12,
            "{t} {b} {tc} {bc}"
        );
    }
}
