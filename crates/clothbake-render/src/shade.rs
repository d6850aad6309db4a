//! Shading: a [`Shader`] (any [`Bsdf`]: the analytic model or a baked table) and the pixel
//! value of a lit surface point.
//!
//! Pixel value (linear, per RGB channel), for a surface point seen from the eye:
//!
//! `V = rho_a * tint + f_r(wi, wo) * cos(theta_i) * E`
//!
//! * `wi` (toward the light) and `wo` (toward the eye) are expressed in the point's tangent
//!   frame (local +X weft, +Y warp, +Z normal) before f_r is looked up;
//! * `f_r` is the BRDF in 1/sr (thesis: f_r = I / (pi cos theta_i));
//! * `E` is the irradiance of the directional light on a surface facing it (default pi, so that
//!   the directional term equals the thesis's intensity I for unit light, and a white Lambertian
//!   surface facing the light shows 1);
//! * `rho_a * tint` is the thesis's ambient term rho_a I_a with unit ambient light I_a = 1,
//!   coloured by the cloth's tint (its diffuse colour divided by its largest channel: (1, 1, 1)
//!   for grey cloth);
//! * where `wo` is at or below the local horizon (the back of the surface) V = 0; where `wi`
//!   is, only the ambient term remains. There are no cast shadows between parts of the scene.
//! * with `render --periods N`, f_r is looked up through the pixel's footprint of the weave
//!   period (`Bsdf::f_at`, docs/spatial.md): a spatial table or the model shows the weave where
//!   a pixel covers less than a period, and the average beyond. The cloth is drawn opaque (the
//!   coverage of the gaps is not applied), so a distant render equals the averaged one; with
//!   `--gaps` every value is scaled by the coverage c of its footprint (the cloth over black:
//!   `V c`), the directional coverage C(wo) without `--periods` (1 for an averaged table).

pub use clothbake_core::Component;
use clothbake_core::{
    AnalyticBsdf, AnalyticModel, Bsdf, Fabric, FacetModel, Footprint, SecondaryOptions, UnitVec3,
    Variant,
};

/// What a picture shades with: a [`Bsdf`] (the analytic model or a baked table, through the
/// one interface) and the cloth's tint for the ambient term.
pub struct Shader {
    bsdf: Box<dyn Bsdf>,
    tint: [f32; 3],
    /// Whether the gaps between the yarns show: the value is scaled by the coverage.
    gaps: bool,
}

impl Shader {
    /// Any BSDF with the tint of its ambient term.
    pub fn new(bsdf: Box<dyn Bsdf>, tint: [f32; 3]) -> Shader {
        Shader {
            bsdf,
            tint,
            gaps: false,
        }
    }

    /// The same shader showing the gaps between the yarns (`render --gaps`): each value is
    /// scaled by the coverage of its footprint (`Bsdf::coverage_at`), as if the cloth lay
    /// over black.
    pub fn with_gaps(self) -> Shader {
        Shader { gaps: true, ..self }
    }

    /// The analytic model of `fabric`; `secondary` adds I_2 (two bounces). [`Component::Secondary`]
    /// and [`Component::SecondarySpecular`] need `secondary`.
    pub fn model(
        fabric: &Fabric,
        facet: FacetModel,
        variant: Variant,
        secondary: Option<SecondaryOptions>,
        component: Component,
    ) -> Result<Shader, String> {
        let bsdf = AnalyticBsdf::new(
            AnalyticModel::with_variant(fabric, facet, variant),
            secondary,
        )
        .with_component(component)
        .ok_or("the secondary reflection's components need two bounces")?;
        Ok(Shader::new(Box::new(bsdf), fabric_tint(fabric)))
    }

    /// The baked table at `path` (either format), looked up with the loader's interpolation.
    /// The tint comes from the fabric file stored in the table's metadata ((1, 1, 1) if it
    /// cannot be read).
    pub fn table(path: &std::path::Path) -> Result<Shader, clothbake_loader::TableError> {
        let options = clothbake_loader::Options {
            sampling: false,
            ..Default::default()
        };
        let brdf = clothbake_loader::Brdf::open(path, options)?;
        let tint = Fabric::from_json_str(&brdf.meta().fabric_json, "table metadata")
            .map_or([1.0; 3], |f| fabric_tint(&f));
        Ok(Shader::new(Box::new(brdf), tint))
    }

    /// f_r(wi, wo) in 1/sr, RGB, in the render's f32; zero when either direction is at or
    /// below the horizon.
    pub fn f_r(&self, wi: UnitVec3, wo: UnitVec3) -> [f32; 3] {
        self.bsdf.f(wi, wo).map(|x| x as f32)
    }

    /// f_r through a footprint of the weave period ([`Bsdf::f_at`]).
    pub fn f_r_at(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> [f32; 3] {
        self.bsdf.f_at(at, wi, wo).map(|x| x as f32)
    }

    /// The cloth's colour for the ambient term: the diffuse colour over its largest channel.
    pub fn tint(&self) -> [f32; 3] {
        self.tint
    }
}

/// A fabric's tint: the mean of its two groups' diffuse colours over its largest channel.
pub fn fabric_tint(fabric: &Fabric) -> [f32; 3] {
    tint_of(std::array::from_fn(|k| {
        0.5 * (fabric.warp().material.albedo[k] + fabric.weft().material.albedo[k])
    }))
}

/// A colour divided by its largest channel ((1, 1, 1) for black or grey).
pub fn tint_of(c: [f64; 3]) -> [f32; 3] {
    let m = c[0].max(c[1]).max(c[2]);
    if m.is_finite() && m > 0.0 {
        std::array::from_fn(|k| (c[k] / m) as f32)
    } else {
        [1.0; 3]
    }
}

/// Lighting of a render: the directional light and the ambient term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Unit direction toward the light (world frame).
    pub light: clothbake_core::Vec3,
    /// Irradiance E of the light on a surface facing it.
    pub irradiance: f64,
    /// Ambient coefficient rho_a.
    pub ambient: f64,
}

/// The pixel value of a surface point with local light and eye directions `wi`, `wo` (not
/// necessarily above the horizon): see the module documentation.
pub fn radiance(
    shader: &Shader,
    lighting: &Lighting,
    wi: clothbake_core::Vec3,
    wo: clothbake_core::Vec3,
) -> [f64; 3] {
    radiance_at(shader, lighting, wi, wo, None)
}

/// As [`radiance`], with f_r seen through footprint `at` of the weave period where one is
/// given ([`Bsdf::f_at`]; `render --periods`).
pub fn radiance_at(
    shader: &Shader,
    lighting: &Lighting,
    wi: clothbake_core::Vec3,
    wo: clothbake_core::Vec3,
    at: Option<Footprint>,
) -> [f64; 3] {
    let Some(wo) = UnitVec3::new(wo).filter(|w| w.above_horizon()) else {
        return [0.0; 3];
    };
    let tint = shader.tint();
    let mut v: [f64; 3] = std::array::from_fn(|k| lighting.ambient * f64::from(tint[k]));
    if let Some(wi) = UnitVec3::new(wi).filter(|w| w.above_horizon()) {
        let f = match at {
            Some(at) => shader.f_r_at(at, wi, wo),
            None => shader.f_r(wi, wo),
        };
        let ce = wi.cos_theta() * lighting.irradiance;
        for k in 0..3 {
            v[k] += f64::from(f[k]) * ce;
        }
    }
    if shader.gaps {
        // Without a footprint, the whole period's (the directional coverage).
        let at = at.unwrap_or(Footprint {
            u: 0.0,
            v: 0.0,
            width: f64::INFINITY,
        });
        let c = shader.bsdf.coverage_at(at, wo);
        v = v.map(|x| x * c);
    }
    v
}
