//! Shading: a [`Shader`] (any [`Bsdf`]: the analytic model or a baked table) and the pixel
//! value of a lit surface point under a sun and a sky.
//!
//! Pixel value (linear, per RGB channel), for a surface point seen from the eye:
//!
//! `V = E f_r(w_s, wo) C(e) + rho_a s(N) pi f_r(w_k, wo)`
//!
//! * all directions in the point's tangent frame (local +X weft, +Y warp, +Z normal) before f_r
//!   is looked up; `wo` toward the eye; f_r in 1/sr (thesis: f_r = I / (pi cos theta_i));
//! * **the sun**: a disk of angular radius [`SUN_RADIUS`] toward `wi`, of irradiance `E` on a
//!   surface facing it (default pi: a white Lambertian surface facing it shows 1). With its
//!   centre at elevation e above the local horizon, C(e) is the mean of the cosine over the part
//!   of the disk above the horizon, times its share of the disk (exactly cos(theta_i) = sin e
//!   for e >= [`SUN_RADIUS`], 0 for e <= -[`SUN_RADIUS`], and in between a closed form that joins
//!   both with a continuous slope: the sun sets over a penumbra instead of at a line), and `w_s`
//!   is `wi` itself where the whole disk is up, else the direction of the same azimuth at
//!   elevation (e + [`SUN_RADIUS`]) / 2, the middle of the part that is up;
//! * **the sky**: a uniform sky over the world's upper hemisphere (+Z up) above a ground of
//!   [`GROUND`] times its radiance, scaled so that a white Lambertian surface facing up shows
//!   `rho_a` (the thesis's ambient coefficient); s(N) = (1 + N_z) / 2 + [`GROUND`] (1 - N_z) / 2
//!   is the share of that irradiance a surface of normal N receives (exact for a horizon plane),
//!   and the light it receives is looked up in one direction, `w_k` = the normal tilted toward
//!   the brighter sky, normalize(N + k up) with k = (1 - [`GROUND`]) / (1 + [`GROUND`]), always
//!   above the horizon. So the sky is coloured by the cloth's own reflectance, varies smoothly
//!   over a curved surface, and lights what the sun does not reach;
//! * where `wo` is at or below the local horizon (the back of the surface) V = 0. There are no
//!   cast shadows between parts of the scene.
//! * with `render --periods N`, f_r is looked up through the pixel's footprint of the weave
//!   period (`Bsdf::local`, docs/science/spatial.md), for the sun and the sky alike: a spatial table or
//!   the model shows the weave where a pixel covers less than a period, and the average beyond.
//!   The cloth is drawn opaque (the coverage of the gaps is not applied), so a distant render
//!   equals the averaged one; with `--gaps` every value is scaled by the coverage c of its
//!   footprint (the cloth over black: `V c`), the directional coverage C(wo) without `--periods`
//!   (1 for an averaged table). Where a footprint is under a crossing cell, the model with one
//!   bounce answers the point level (docs/science/spatial.md): a sample whose eye ray meets a gap has
//!   c = 0; without `--gaps` a pixel averages the samples that meet yarn (times the share of its
//!   samples that meet the surface), so the gaps close up within a pixel and show black only
//!   where a pixel sees nothing but gap.

pub use clothbake_core::Component;
use clothbake_core::{
    AnalyticBsdf, AnalyticModel, Bsdf, Fabric, FacetModel, Footprint, Local, SecondaryOptions,
    UnitVec3, Variant,
};
use clothbake_truth::RayTracer;

/// What a picture shades with: a [`Bsdf`] (the analytic model or a baked table, through the
/// one interface).
pub struct Shader {
    bsdf: Box<dyn Bsdf>,
    /// Whether the gaps between the yarns show: the value is scaled by the coverage.
    gaps: bool,
    /// Whether the BSDF is a two-faced cloth's (docs/science/transmission.md): lit and seen from
    /// either side, transmitting, and showing what lies behind it through its openness.
    two_faced: bool,
}

impl Shader {
    /// Any BSDF.
    pub fn new(bsdf: Box<dyn Bsdf>) -> Shader {
        Shader {
            bsdf,
            gaps: false,
            two_faced: false,
        }
    }

    /// The two-faced cloth of `fabric` (`render --faces two`; docs/science/transmission.md): its
    /// model (`clothbake_bake::two_faced::TwoFaced`, the rest's nodes path-traced now, in
    /// parallel), lit and seen from either side. An error where the fabric's back is not a
    /// valid fabric.
    pub fn two_faced(
        fabric: &Fabric,
        facet: FacetModel,
        variant: Variant,
    ) -> Result<Shader, String> {
        let tf = clothbake_bake::two_faced::TwoFaced::new(fabric, facet, variant)
            .map_err(|e| e.to_string())?;
        tf.prepare();
        Ok(Shader::two_sided(Box::new(tf)))
    }

    /// Any BSDF of a two-faced cloth (f over the whole sphere, `openness`), lit and seen from
    /// either side.
    pub fn two_sided(bsdf: Box<dyn Bsdf>) -> Shader {
        Shader {
            two_faced: true,
            ..Shader::new(bsdf)
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
    /// (docs/science/spatial.md); with two, the crossing cell is the finest level (a single trace has
    /// no I_2).
    pub fn model(
        fabric: &Fabric,
        facet: FacetModel,
        variant: Variant,
        secondary: Option<SecondaryOptions>,
        component: Component,
    ) -> Result<Shader, String> {
        let one_bounce = secondary.is_none();
        let model = AnalyticModel::with_variant(fabric, facet, variant).map_err(|e| e.line())?;
        let mut bsdf = AnalyticBsdf::new(model, secondary)
            .with_component(component)
            .ok_or("the secondary reflection's components need two bounces")?;
        if one_bounce {
            if let Some(y) = clothbake_core::point::yarns(fabric, facet) {
                bsdf = bsdf.with_yarns(y);
            }
        }
        Ok(Shader::new(Box::new(bsdf)))
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
        paths: Option<clothbake_truth::PathOptions>,
    ) -> Shader {
        Shader::new(Box::new(Truth {
            rt: RayTracer::new(fabric, facet),
            seed,
            paths,
            cell: 1.0 / fabric.weave().n_warp().max(fabric.weave().n_weft()) as f64,
        }))
    }

    /// Whether the BSDF is a two-faced cloth's, lit and seen from either side.
    pub fn is_two_faced(&self) -> bool {
        self.two_faced
    }

    /// The baked table at `path` (either format, either kind: a two-faced table is lit and
    /// seen from either side), looked up with the loader's interpolation.
    pub fn table(path: &std::path::Path) -> Result<Shader, clothbake_loader::TableError> {
        let options = clothbake_loader::Options {
            sampling: false,
            ..Default::default()
        };
        Ok(match clothbake_loader::Lookup::open(path, options)? {
            clothbake_loader::Lookup::One(brdf) => Shader::new(brdf),
            // A two-faced table: lit and seen from either side.
            clothbake_loader::Lookup::Two(t) => Shader::two_sided(t),
        })
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
}

/// The ground truth as a [`Bsdf`]: looks integrated over each footprint, a ray-traced
/// average for the period.
struct Truth {
    rt: RayTracer,
    seed: u64,
    /// Every bounce up to its `max_bounces`, a path a point; `None`: one bounce.
    paths: Option<clothbake_truth::PathOptions>,
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

/// The sun's angular radius, radians: 6 degrees, wider than the real sun's 0.27 on purpose (a
/// hazy sun with its aureole), so that the penumbra where it sets spans several pixels of a
/// picture's curved surfaces and the terminator is soft instead of a crease (docs/guide/render.md).
pub const SUN_RADIUS: f64 = 6.0 * std::f64::consts::PI / 180.0;

/// The ground's radiance as a share of the sky's (a ground of albedo about 0.2).
pub const GROUND: f64 = 0.2;

/// Lighting of a render: the sun and the sky (module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Unit direction toward the sun's centre (world frame).
    pub light: clothbake_core::Vec3,
    /// Irradiance E of the sun on a surface facing it.
    pub irradiance: f64,
    /// The sky's strength rho_a: what a white Lambertian surface facing up shows in the sky's
    /// light alone.
    pub ambient: f64,
}

/// The share C(e) of the sun's irradiance (on a surface facing it) that reaches a surface over
/// whose horizon its centre stands at elevation `e` (radians): sin e while the whole disk is up,
/// 0 once it has set, and between the two the mean over the disk of max(elevation, 0) (the
/// cosine taken as linear across the small disk), scaled by sin(r) / r so that both ends join.
pub fn sun_share(e: f64) -> f64 {
    let r = SUN_RADIUS;
    if e >= r {
        return e.sin();
    }
    if e <= -r {
        return 0.0;
    }
    // The chord at height -e cuts the disk; the part above it is up.
    let c = -e;
    let h = (r * r - c * c).max(0.0);
    let segment = r * r * (c / r).clamp(-1.0, 1.0).acos() - c * h.sqrt();
    let mean = (e * segment + 2.0 / 3.0 * h * h.sqrt()) / (std::f64::consts::PI * r * r);
    mean * r.sin() / r
}

/// The direction the sun's light is looked up in for local `wi` at elevation `e`
/// (`wi` itself while the whole disk is up), and its share [`sun_share`]; `None` once it has set.
fn sun(wi: clothbake_core::Vec3) -> Option<(UnitVec3, f64)> {
    let w = UnitVec3::new(wi)?;
    let e = w.z.clamp(-1.0, 1.0).asin();
    if e >= SUN_RADIUS {
        return Some((w, w.cos_theta()));
    }
    if e <= -SUN_RADIUS {
        return None;
    }
    let mid = 0.5 * (e + SUN_RADIUS);
    let flat = (w.x * w.x + w.y * w.y).sqrt();
    let (x, y) = if flat > 0.0 {
        (w.x / flat, w.y / flat)
    } else {
        (1.0, 0.0)
    };
    let dir = UnitVec3::new(clothbake_core::Vec3::new(
        x * mid.cos(),
        y * mid.cos(),
        mid.sin(),
    ))?;
    Some((dir, sun_share(e)))
}

/// The sky's lookup direction w_k and weight rho_a s(N) pi for a surface whose local frame sees
/// the world's up as `up` (module documentation).
fn sky(ambient: f64, up: clothbake_core::Vec3) -> Option<(UnitVec3, f64)> {
    if ambient <= 0.0 {
        return None;
    }
    let k = (1.0 - GROUND) / (1.0 + GROUND);
    // |Z + k up| >= 1 - k > 0, and its z is at least 1 - k: above the horizon.
    let dir = UnitVec3::new(clothbake_core::Vec3::new(
        k * up.x,
        k * up.y,
        1.0 + k * up.z,
    ))?;
    let nz = up.z.clamp(-1.0, 1.0);
    let share = 0.5 * (1.0 + nz) + GROUND * 0.5 * (1.0 - nz);
    Some((dir, ambient * share * std::f64::consts::PI))
}

/// The pixel value of a surface point with local sun and eye directions `wi`, `wo` (not
/// necessarily above the horizon) and the world's up `up` in the same local frame: see the
/// module documentation.
pub fn radiance(
    shader: &Shader,
    lighting: &Lighting,
    wi: clothbake_core::Vec3,
    wo: clothbake_core::Vec3,
    up: clothbake_core::Vec3,
) -> [f64; 3] {
    radiance_at(shader, lighting, wi, wo, up, None)
}

/// As [`radiance`], with f_r seen through footprint `at` of the weave period where one is
/// given ([`Bsdf::f_at`]; `render --periods`).
pub fn radiance_at(
    shader: &Shader,
    lighting: &Lighting,
    wi: clothbake_core::Vec3,
    wo: clothbake_core::Vec3,
    up: clothbake_core::Vec3,
    at: Option<Footprint>,
) -> [f64; 3] {
    let (v, c) = shade_at(shader, lighting, wi, wo, up, at);
    if shader.gaps {
        v.map(|x| x * c)
    } else {
        v
    }
}

/// The value of a surface point and the coverage of its footprint, from one lookup per light
/// ([`Bsdf::local`]; the coverage depends on the eye's direction alone): the value unscaled,
/// and the share of the footprint that is yarn (0 where a point shows a gap; without a
/// footprint, the directional coverage C(wo)). [`radiance_at`] scales by it with `--gaps`; the
/// picture's pixels leave gap points out of their yarns' mean without it (`render_weave`).
pub fn shade_at(
    shader: &Shader,
    lighting: &Lighting,
    wi: clothbake_core::Vec3,
    wo: clothbake_core::Vec3,
    up: clothbake_core::Vec3,
    at: Option<Footprint>,
) -> ([f64; 3], f64) {
    if shader.two_faced {
        return (shade_two_faced(shader, lighting, wi, wo, up), 1.0);
    }
    let Some(wo) = UnitVec3::new(wo).filter(|w| w.above_horizon()) else {
        return ([0.0; 3], 0.0);
    };
    // The whole period's coverage, asked only where it is used.
    let period_coverage = || {
        if shader.gaps {
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
        }
    };
    let look = |dir: UnitVec3| -> Local {
        match at {
            Some(at) => shader.bsdf.local(at, dir, wo),
            None => Local {
                f: shader.bsdf.f(dir, wo),
                coverage: 1.0,
            },
        }
    };
    let mut v = [0.0f64; 3];
    let mut coverage = None;
    for (dir, weight) in [
        sun(wi).map(|(d, c)| (d, c * lighting.irradiance)),
        sky(lighting.ambient, up),
    ]
    .into_iter()
    .flatten()
    {
        let local = look(dir);
        coverage.get_or_insert(local.coverage);
        let f = local.f.map(|x| x as f32);
        for k in 0..3 {
            v[k] += f64::from(f[k]) * weight;
        }
    }
    let coverage = match (at, coverage) {
        (None, _) => period_coverage(),
        (Some(_), Some(c)) => c,
        (Some(at), None) => shader.bsdf.coverage_at(at, wo),
    };
    (v, coverage)
}

/// The pixel value of a point of a two-faced cloth (`render --faces two`): the sun lights the
/// side it stands over (its share [`sun_share`] of the elevation over that side), the sky lights
/// the side facing up and the ground the other (each side's share s(N) of module
/// documentation), each looked up as reflection or transmission by the sides of the light and
/// the eye; and through the gaps the eye sees what lies behind the cloth along its ray, the
/// openness O(wo) times the sky's radiance (rho_a; the ground's, [`GROUND`] rho_a) or, within
/// the sun's disk, the sun's (E over the disk's solid angle) as well.
fn shade_two_faced(
    shader: &Shader,
    lighting: &Lighting,
    wi: clothbake_core::Vec3,
    wo: clothbake_core::Vec3,
    up: clothbake_core::Vec3,
) -> [f64; 3] {
    let Some(wo) = UnitVec3::new(wo).filter(|w| w.above_horizon() || w.below_horizon()) else {
        return [0.0; 3];
    };
    let mirror = |v: clothbake_core::Vec3| clothbake_core::Vec3::new(v.x, v.y, -v.z);
    // The sun over the side it stands on: computed as over the front, mirrored for the back.
    let sun_side = if wi.z >= 0.0 {
        sun(wi)
    } else {
        sun(mirror(wi)).map(|(d, c)| (d.mirror_z(), c))
    };
    // The sky over the side facing up, the ground (and the sky's rest) over the other.
    let front_sky = sky(lighting.ambient, up);
    let back_sky = sky(lighting.ambient, mirror(up)).map(|(d, w)| (d.mirror_z(), w));
    let mut v = [0.0f64; 3];
    for (dir, weight) in [
        sun_side.map(|(d, c)| (d, c * lighting.irradiance)),
        front_sky,
        back_sky,
    ]
    .into_iter()
    .flatten()
    {
        let f = shader.bsdf.f(dir, wo);
        for k in 0..3 {
            v[k] += f[k] * weight;
        }
    }
    // Behind the cloth, along the eye's ray.
    let behind = wo.reverse();
    let open = shader.bsdf.openness(wo);
    if open > 0.0 {
        let mut l = if behind.get().dot(up) > 0.0 {
            lighting.ambient
        } else {
            GROUND * lighting.ambient
        };
        let to_sun = UnitVec3::new(wi).map_or(-1.0, |s| s.get().dot(behind.get()));
        if to_sun >= SUN_RADIUS.cos() {
            let disk = 2.0 * std::f64::consts::PI * (1.0 - SUN_RADIUS.cos());
            l += lighting.irradiance / disk;
        }
        v = v.map(|x| x + open * l);
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_core::{Rgb, Vec3};
    use std::f64::consts::PI;

    /// A Lambertian sheet: reflects rho / pi on either side, transmits t / pi across, and
    /// passes `open` straight through.
    struct Sheet {
        rho: f64,
        t: f64,
        open: f64,
    }

    impl Bsdf for Sheet {
        fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
            let sided = |w: UnitVec3| w.above_horizon() || w.below_horizon();
            if !(sided(wi) && sided(wo)) {
                return [0.0; 3];
            }
            let same = (wi.z > 0.0) == (wo.z > 0.0);
            [if same { self.rho } else { self.t } / PI; 3]
        }
        fn openness(&self, _: UnitVec3) -> f64 {
            self.open
        }
    }

    #[test]
    fn a_backlit_sheet_shows_its_transmission_and_what_lies_behind() {
        // A flat sheet facing up, the sun behind it at elevation e below, the eye above: the
        // sun transmitted, E sin(e) t / pi; the sky on the front, rho_a rho; the ground's light
        // on the back, transmitted, rho_a GROUND t; through the gaps the ground, O GROUND rho_a.
        let (rho, t, open) = (0.4, 0.3, 0.2);
        let shader = Shader::two_sided(Box::new(Sheet { rho, t, open }));
        let lighting = Lighting {
            light: Vec3::new(0.0, 0.0, -1.0),
            irradiance: PI,
            ambient: 0.3,
        };
        let e = 40f64.to_radians();
        let wi = Vec3::new(e.cos(), 0.0, -e.sin());
        let up = Vec3::new(0.0, 0.0, 1.0);
        let wo = UnitVec3::from_degrees(30.0, 200.0).get();
        let v = shade_at(&shader, &lighting, wi, wo, up, None).0[0];
        let want = PI * e.sin() * t / PI + 0.3 * rho + 0.3 * GROUND * t + open * GROUND * 0.3;
        assert!((v - want).abs() < 1e-12, "{v} vs {want}");
        // The eye looking through the sheet at the sun sees it through the gaps too.
        let v_sun = shade_at(&shader, &lighting, wi, -wi, up, None).0[0];
        let disk = 2.0 * PI * (1.0 - SUN_RADIUS.cos());
        let want_sun = want + open * PI / disk;
        assert!(
            (v_sun - want_sun).abs() < 1e-9 * want_sun,
            "{v_sun} vs {want_sun}"
        );
        // A one-faced shader shows nothing of a cloth seen from below (the eye at wi).
        let opaque = Shader::new(Box::new(Sheet { rho, t, open }));
        assert_eq!(shade_at(&opaque, &lighting, wi, wi, up, None).0, [0.0; 3]);
    }
}
