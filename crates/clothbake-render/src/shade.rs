//! Shading: the BRDF behind one small trait ([`ModelShader`]: the analytic model;
//! [`TableShader`]: a baked table), and the pixel value of a lit surface point.
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

use clothbake_core::{
    intensity_to_brdf, AnalyticModel, Fabric, FacetModel, SecondaryOptions, UnitVec3, Variant,
};

/// A BRDF in the fabric's local frame.
pub trait Shader: Sync {
    /// f_r(wi, wo) in 1/sr, RGB; zero when either direction is at or below the horizon.
    fn f_r(&self, wi: UnitVec3, wo: UnitVec3) -> [f32; 3];
    /// The cloth's colour for the ambient term: the diffuse colour over its largest channel.
    fn tint(&self) -> [f32; 3];
}

/// Which part of the model's reflection a [`ModelShader`] shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Component {
    /// Everything computed: I_1, plus I_2 with two bounces.
    #[default]
    Total,
    /// The direct reflection I_1 = I_d + I_s (thesis eq. 4.11).
    Direct,
    /// The secondary reflection I_2 = I_ss + I_sd + I_ds + I_dd alone (eq. 5.15).
    Secondary,
    /// The specular-specular secondary reflection I_ss alone (eq. 5.11).
    SecondarySpecular,
}

/// The analytic model evaluated directly at every shading point.
pub struct ModelShader {
    model: AnalyticModel,
    secondary: Option<SecondaryOptions>,
    component: Component,
    tint: [f32; 3],
}

impl ModelShader {
    /// The model of `fabric`; `secondary` adds I_2 (two bounces). [`Component::Secondary`]
    /// and [`Component::SecondarySpecular`] need `secondary`.
    pub fn new(
        fabric: &Fabric,
        facet: FacetModel,
        variant: Variant,
        secondary: Option<SecondaryOptions>,
        component: Component,
    ) -> Result<ModelShader, String> {
        if secondary.is_none()
            && matches!(
                component,
                Component::Secondary | Component::SecondarySpecular
            )
        {
            return Err("the secondary reflection's components need two bounces".into());
        }
        let a: [f64; 3] = std::array::from_fn(|k| {
            0.5 * (fabric.warp().material.albedo[k] + fabric.weft().material.albedo[k])
        });
        Ok(ModelShader {
            model: AnalyticModel::with_variant(fabric, facet, variant),
            secondary,
            component,
            tint: tint_of(a),
        })
    }
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

impl Shader for ModelShader {
    fn f_r(&self, wi: UnitVec3, wo: UnitVec3) -> [f32; 3] {
        let r = self.model.eval_with(wi, wo, self.secondary.as_ref());
        let s = r.secondary.unwrap_or_default();
        let i = match self.component {
            Component::Total => r.total(),
            Component::Direct => r.direct(),
            Component::Secondary => s.total(),
            Component::SecondarySpecular => s.ss,
        };
        intensity_to_brdf(i, wi).map(|x| x as f32)
    }

    fn tint(&self) -> [f32; 3] {
        self.tint
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
    shader: &dyn Shader,
    lighting: &Lighting,
    wi: clothbake_core::Vec3,
    wo: clothbake_core::Vec3,
) -> [f64; 3] {
    let Some(wo) = UnitVec3::new(wo).filter(|w| w.above_horizon()) else {
        return [0.0; 3];
    };
    let tint = shader.tint();
    let mut v: [f64; 3] = std::array::from_fn(|k| lighting.ambient * f64::from(tint[k]));
    if let Some(wi) = UnitVec3::new(wi).filter(|w| w.above_horizon()) {
        let f = shader.f_r(wi, wo);
        let ce = wi.cos_theta() * lighting.irradiance;
        for k in 0..3 {
            v[k] += f64::from(f[k]) * ce;
        }
    }
    v
}

/// A baked table, looked up with the loader's interpolation (`clothbake_loader::Brdf::eval`).
pub struct TableShader {
    brdf: clothbake_loader::Brdf,
    tint: [f32; 3],
}

impl TableShader {
    /// Opens the table at `path` (either format). The tint comes from the fabric file stored in
    /// the table's metadata ((1, 1, 1) if it cannot be read).
    pub fn open(path: &std::path::Path) -> Result<TableShader, clothbake_loader::TableError> {
        let options = clothbake_loader::Options {
            sampling: false,
            ..Default::default()
        };
        let brdf = clothbake_loader::Brdf::open(path, options)?;
        let tint = Fabric::from_json_str(&brdf.meta().fabric_json, "table metadata").map_or(
            [1.0; 3],
            |f| {
                tint_of(std::array::from_fn(|k| {
                    0.5 * (f.warp().material.albedo[k] + f.weft().material.albedo[k])
                }))
            },
        );
        Ok(TableShader { brdf, tint })
    }
}

impl Shader for TableShader {
    fn f_r(&self, wi: UnitVec3, wo: UnitVec3) -> [f32; 3] {
        let v = |u: UnitVec3| [u.x as f32, u.y as f32, u.z as f32];
        self.brdf.eval(v(wi), v(wo))
    }

    fn tint(&self) -> [f32; 3] {
        self.tint
    }
}
