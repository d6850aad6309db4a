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
//!   Where a footprint is under a crossing cell, the model with one bounce answers the point
//!   level (docs/spatial.md): a sample whose eye ray meets a gap has c = 0; without `--gaps`
//!   a pixel averages the samples that meet yarn (times the share of its samples that meet
//!   the surface), so the gaps close up within a pixel and show black only where a pixel
//!   sees nothing but gap.

pub use clothbake_core::Component;
use clothbake_core::{
    AnalyticBsdf, AnalyticModel, Bsdf, Fabric, FacetModel, Footprint, Local, RayTracer,
    SecondaryOptions, UnitVec3, Variant,
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
    /// and [`Component::SecondarySpecular`] need `secondary`. With one bounce the model carries
    /// the fabric's yarns, so footprints under a crossing cell show the point level
    /// (docs/spatial.md); with two, the crossing cell is the finest level (a single trace has
    /// no I_2).
    pub fn model(
        fabric: &Fabric,
        facet: FacetModel,
        variant: Variant,
        secondary: Option<SecondaryOptions>,
        component: Component,
    ) -> Result<Shader, String> {
        let one_bounce = secondary.is_none();
        let mut bsdf = AnalyticBsdf::new(
            AnalyticModel::with_variant(fabric, facet, variant),
            secondary,
        )
        .with_component(component)
        .ok_or("the secondary reflection's components need two bounces")?;
        if one_bounce {
            if let Some(y) = clothbake_core::point::yarns(fabric, facet) {
                bsdf = bsdf.with_yarns(y);
            }
        }
        Ok(Shader::new(Box::new(bsdf), fabric_tint(fabric)))
    }

    /// The ground truth of `fabric` (`render --truth`): the ray tracer's looks
    /// (`RayTracer::look_at`), each eye ray continuing into the explicit yarns tiled over the
    /// surface, with a shadow ray through the same yarns. A sample's footprint is integrated by
    /// [`truth_points`] stratified jittered points in it (one for a footprint under an eighth
    /// of a crossing cell), so that distant truth converges instead of aliasing; `seed` picks
    /// the jitter. With `paths`, each point is one path with every bounce up to its
    /// `max_bounces` (`RayTracer::look_paths_at`, radiometric kernel) instead of one bounce.
    /// Without a footprint, the period's average is ray-traced with 16 384 rays per pair (one
    /// bounce).
    pub fn truth(
        fabric: &Fabric,
        facet: FacetModel,
        seed: u64,
        paths: Option<clothbake_core::PathOptions>,
    ) -> Shader {
        Shader::new(
            Box::new(Truth {
                rt: RayTracer::new(fabric, facet),
                seed,
                paths,
                cell: 1.0 / fabric.weave().n_warp().max(fabric.weave().n_weft()) as f64,
            }),
            fabric_tint(fabric),
        )
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

    /// Whether each value is scaled by its footprint's coverage (`render --gaps`).
    pub fn shows_gaps(&self) -> bool {
        self.gaps
    }

    /// The cloth's colour for the ambient term: the diffuse colour over its largest channel.
    pub fn tint(&self) -> [f32; 3] {
        self.tint
    }
}

/// The ground truth as a [`Bsdf`]: looks integrated over each footprint, a ray-traced
/// average for the period.
struct Truth {
    rt: RayTracer,
    seed: u64,
    /// Every bounce up to its `max_bounces`, a path a point; `None`: one bounce.
    paths: Option<clothbake_core::PathOptions>,
    /// The smallest crossing cell's side, about, in periods.
    cell: f64,
}

/// The points [`Shader::truth`] integrates a footprint of side `width` periods with on a weave
/// of crossing cells `cell` periods wide: k x k, k = ceil(8 width / cell) from 1 to 16.
pub fn truth_points(width: f64, cell: f64) -> usize {
    let k = (8.0 * width / cell).ceil();
    let k = if k.is_nan() { 1.0 } else { k.clamp(1.0, 16.0) };
    (k * k) as usize
}

impl Bsdf for Truth {
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> clothbake_core::Rgb {
        let e = self.rt.render(wi, wo, 1 << 14, self.seed);
        clothbake_core::intensity_to_brdf(e.reflection.total(), wi)
    }

    fn f_at(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> clothbake_core::Rgb {
        self.local(at, wi, wo).f
    }

    fn coverage_at(&self, at: Footprint, wo: UnitVec3) -> f64 {
        self.local(at, UnitVec3::Z, wo).coverage
    }

    fn local(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> Local {
        // The light's direction does not change what the eye meets: below the horizon, look
        // with an overhead light for the coverage alone.
        let lit = wi.above_horizon();
        let light = if lit { wi } else { UnitVec3::Z };
        let width = if at.width.is_finite() {
            at.width.max(0.0)
        } else {
            1.0
        };
        let n = truth_points(width, self.cell);
        let k = (n as f64).sqrt() as usize;
        // The jitter is a pure function of the footprint's point and the seed.
        let mut rng = clothbake_core::rng::Rng::new(
            self.seed ^ at.u.to_bits().rotate_left(17) ^ at.v.to_bits().rotate_left(41),
        );
        let (mut sum, mut hits) = ([0.0; 3], 0usize);
        for a in 0..k {
            for b in 0..k {
                let (u, v) = if n == 1 {
                    (at.u, at.v)
                } else {
                    (
                        at.u + width * ((a as f64 + rng.next_f64()) / k as f64 - 0.5),
                        at.v + width * ((b as f64 + rng.next_f64()) / k as f64 - 0.5),
                    )
                };
                let seen = match self.paths {
                    None => self.rt.look_at(u, v, light, wo),
                    Some(o) => self.rt.look_paths_at(u, v, light, wo, o, &mut rng),
                };
                if let Some(f) = seen {
                    hits += 1;
                    for c in 0..3 {
                        sum[c] += f[c];
                    }
                }
            }
        }
        Local {
            f: if lit && hits > 0 {
                sum.map(|x| x / hits as f64)
            } else {
                [0.0; 3]
            },
            coverage: hits as f64 / n as f64,
        }
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
    let (v, c) = shade_at(shader, lighting, wi, wo, at);
    if shader.gaps {
        v.map(|x| x * c)
    } else {
        v
    }
}

/// The value of a surface point and the coverage of its footprint, from one lookup
/// ([`Bsdf::local`]): the value unscaled, and the share of the footprint that is yarn (0 where
/// a point shows a gap; without a footprint, the directional coverage C(wo)). [`radiance_at`]
/// scales by it with `--gaps`; the picture's pixels leave gap points out of their yarns'
/// mean without it (`render_weave`).
pub fn shade_at(
    shader: &Shader,
    lighting: &Lighting,
    wi: clothbake_core::Vec3,
    wo: clothbake_core::Vec3,
    at: Option<Footprint>,
) -> ([f64; 3], f64) {
    let Some(wo) = UnitVec3::new(wo).filter(|w| w.above_horizon()) else {
        return ([0.0; 3], 0.0);
    };
    let tint = shader.tint();
    let mut v: [f64; 3] = std::array::from_fn(|k| lighting.ambient * f64::from(tint[k]));
    let wi = UnitVec3::new(wi).filter(|w| w.above_horizon());
    let local = match (at, wi) {
        (Some(at), Some(wi)) => shader.bsdf.local(at, wi, wo),
        (Some(at), None) => Local {
            f: [0.0; 3],
            coverage: shader.bsdf.coverage_at(at, wo),
        },
        (None, wi) => {
            // The whole period's coverage, asked only where it is used.
            let c = if shader.gaps {
                shader.bsdf.coverage_at(
                    Footprint {
                        u: 0.0,
                        v: 0.0,
                        width: f64::INFINITY,
                    },
                    wo,
                )
            } else {
                1.0
            };
            Local {
                f: wi.map_or([0.0; 3], |wi| shader.bsdf.f(wi, wo)),
                coverage: c,
            }
        }
    };
    if let Some(wi) = wi {
        let f = local.f.map(|x| x as f32);
        let ce = wi.cos_theta() * lighting.irradiance;
        for k in 0..3 {
            v[k] += f64::from(f[k]) * ce;
        }
    }
    (v, local.coverage)
}
