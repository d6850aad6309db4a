//! clothbake-bsdf: the one BSDF interface of clothbake, after pbrt-v4's BxDF, and the vector
//! maths it is written in.
//!
//! Every reflectance clothbake computes or loads — the analytic model (any facet, variant and
//! bounce setting, `clothbake_core::AnalyticBsdf`) and a baked table (`clothbake_loader::Brdf`)
//! — implements [`Bsdf`]; baking, export, pictures and Python use only this trait. It lives in
//! a crate of its own, below both the model and the loader, so that renderers that link the
//! loader alone get it without the model.
//!
//! Conventions: local frame with +X the weft direction, +Y the warp direction, +Z the macro
//! normal; `wi` points toward the light, `wo` toward the eye, both unit vectors
//! ([`UnitVec3`]); values are linear RGB. A one-faced cloth (the thesis's, over its floor)
//! reflects nothing at or below the horizon (cos theta <= [`HORIZON_COS`]); a two-faced one
//! (docs/science/transmission.md) also reflects from its back (-Z) and transmits, and passes light
//! straight through its gaps ([`Bsdf::openness`]); within [`HORIZON_COS`] of the plane every
//! direction gives zero.
//!
//! [`rng`] is the deterministic random stream (SplitMix64) the model's samplers and the ground
//! truth both draw from, so that a seed gives the same numbers everywhere.

pub mod rng;
pub mod vec3;

pub use vec3::{half_vector, UnitVec3, Vec3, HORIZON_COS};

use std::f64::consts::PI;

/// Linear RGB.
pub type Rgb = [f64; 3];

/// An incident direction drawn by [`Bsdf::sample`], with f_r and the density there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled incident direction (toward the light): above the horizon, or on either
    /// side for a two-faced cloth.
    pub wi: UnitVec3,
    /// f_r(wi, wo) in 1/sr.
    pub f: Rgb,
    /// Its density per unit solid angle, > 0.
    pub pdf: f64,
}

impl BsdfSample {
    /// The estimator's weight f(wi, wo) |cos(theta_i)| / pdf.
    pub fn weight(&self) -> Rgb {
        let c = self.wi.cos_theta().abs() / self.pdf;
        self.f.map(|f| f * c)
    }
}

/// Where on the cloth a reflectance is looked up: a point of the weave period and the part of
/// the period one pixel covers (docs/science/spatial.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// Fraction of the period along the weft (+X); any finite value, wrapped.
    pub u: f64,
    /// Fraction of the period along the warp (+Y); any finite value, wrapped.
    pub v: f64,
    /// Side of the square the pixel covers, in periods: 0 (or NaN) for a point, 1 or more for
    /// the whole period (the averaged reflectance).
    pub width: f64,
}

/// Footprint widths, in crossing cells, below which a footprint is answered by the point
/// level alone (`POINT_UNTIL`) and from which by the cells alone (`CELLS_FROM`); between,
/// the two blend smoothly (docs/science/spatial.md, "Levels of detail").
pub const POINT_UNTIL: f64 = 1.0;
/// See [`POINT_UNTIL`].
pub const CELLS_FROM: f64 = 2.0;
/// The most points across a footprint that the point level integrates ([`Level::Local`]).
pub const MAX_POINTS_ACROSS: usize = 8;

/// The level of detail a footprint asks for: the one rule every spatially varying
/// reflectance follows ([`Footprint::level`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Level {
    /// Inside the period: the point level with weight `point` in [0, 1], blended with the box
    /// filter of side `width` periods (in [0, 1)) over the crossing cells with weight
    /// `1 - point`. The point level integrates the footprint's square with `points` x
    /// `points` stratified points (1: the point itself), about eight to a cell across, so that
    /// a footprint of a cell or two converges instead of aliasing. A reflectance without a
    /// point level uses the cells alone.
    Local {
        /// Weight of the point level.
        point: f64,
        /// Side of the footprint's square, in periods (0: the point; the cell at the point).
        width: f64,
        /// Points across the square that the point level integrates, 1 to
        /// [`MAX_POINTS_ACROSS`].
        points: usize,
    },
    /// The whole period: the averaged reflectance.
    Period,
}

impl Footprint {
    /// The level of detail of this footprint on a weave whose crossing cells are `cell`
    /// periods wide: [`Level::Period`] for a width of 1 or more or a point not finite; else
    /// the point level alone up to [`POINT_UNTIL`] cells, the cells alone from [`CELLS_FROM`],
    /// and a smoothstep between; the point level's points across are ceil(8 width / cell),
    /// from 1 to [`MAX_POINTS_ACROSS`]. A NaN width is a point.
    #[inline]
    pub fn level(&self, cell: f64) -> Level {
        if !self.within_period() {
            return Level::Period;
        }
        let width = if self.width.is_nan() {
            0.0
        } else {
            self.width.max(0.0)
        };
        let x = ((width / cell - POINT_UNTIL) / (CELLS_FROM - POINT_UNTIL)).clamp(0.0, 1.0);
        let point = if x.is_nan() {
            1.0
        } else {
            1.0 - x * x * (3.0 - 2.0 * x)
        };
        let across = (8.0 * width / cell).ceil();
        let points = if across.is_nan() {
            1
        } else {
            across.clamp(1.0, MAX_POINTS_ACROSS as f64) as usize
        };
        Level::Local {
            point,
            width,
            points,
        }
    }
}

impl Footprint {
    /// Whether the footprint asks for less than the whole period (a point of finite u and v,
    /// a width under one period or NaN): the first test of [`Footprint::level`], for lookups
    /// that need only it.
    #[inline(always)]
    pub fn within_period(&self) -> bool {
        self.u.is_finite() && self.v.is_finite() && (self.width < 1.0 || self.width.is_nan())
    }
}

/// What a footprint of the cloth shows: f_r and the share of it that is yarn, from one call
/// ([`Bsdf::local`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Local {
    /// f_r in 1/sr, RGB, the coverage-weighted mean over the footprint.
    pub f: Rgb,
    /// The share of the footprint's projected area seen from `wo` where the eye meets yarn.
    pub coverage: f64,
}

impl Local {
    /// The blend of two levels' answers for one footprint ([`Level::Local`]): `a` with weight
    /// `wa` and `b` with weight 1 - `wa`, each f_r weighted by its coverage (so that the
    /// blend's f c is the weighted mean of the levels' f c).
    pub fn blend(wa: f64, a: Local, b: Local) -> Local {
        let (ca, cb) = (wa * a.coverage, (1.0 - wa) * b.coverage);
        let c = ca + cb;
        Local {
            f: if c > 0.0 {
                [0, 1, 2].map(|k| (ca * a.f[k] + cb * b.f[k]) / c)
            } else {
                [0.0; 3]
            },
            coverage: c,
        }
    }
}

/// A bidirectional reflectance distribution: f_r, a sampler of incident directions and its
/// density, on local-frame unit directions. Every method that takes both directions takes
/// them in one order, `(wi, wo)`: toward the light, then toward the eye (`f`, `pdf`, `f_at`);
/// `sample` takes `wo` and returns a `wi`.
pub trait Bsdf: Sync {
    /// f(wi, wo) in 1/sr, RGB, over the whole sphere: reflection where `wi` and `wo` are on
    /// the same side of the cloth, transmission where they are on opposite sides (the
    /// straight-through part excluded: [`Bsdf::openness`]). A one-faced reflectance gives zero
    /// unless both are above the horizon. For cloth, the average over the weave period
    /// (eq. 4.11).
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb;

    /// The share of the light arriving from `wi` (from either side) that passes through the
    /// cloth's gaps without meeting a yarn and leaves toward `-wi`: a delta lobe beside
    /// [`Bsdf::f`]. The default is opaque: 0.
    fn openness(&self, wi: UnitVec3) -> f64 {
        let _ = wi;
        0.0
    }

    /// [`Bsdf::f`] of each pair (light, eye): `out[k]` is `f(pairs[k])`, bit for bit. The
    /// default evaluates them one by one; a BSDF that evaluates several pairs faster at once
    /// (the analytic model, four pairs in AVX2 lanes) overrides it.
    ///
    /// # Panics
    /// If `out` and `pairs` differ in length.
    fn f_batch(&self, pairs: &[(UnitVec3, UnitVec3)], out: &mut [Rgb]) {
        assert_eq!(pairs.len(), out.len(), "one output per pair");
        for (o, &(wi, wo)) in out.iter_mut().zip(pairs) {
            *o = self.f(wi, wo);
        }
    }

    /// f_r seen through a footprint of the weave period: the coverage-weighted mean of the
    /// local f_r over the footprint, which is [`Bsdf::f`] once the footprint spans the period
    /// ([`Footprint::level`]). The default is spatially uniform.
    fn f_at(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        let _ = at;
        self.f(wi, wo)
    }

    /// The share of the footprint's projected area seen from `wo` in which the eye meets yarn
    /// (the rest shows what lies behind the cloth). The default is opaque: 1.
    fn coverage_at(&self, at: Footprint, wo: UnitVec3) -> f64 {
        let _ = (at, wo);
        1.0
    }

    /// [`Bsdf::f_at`] and [`Bsdf::coverage_at`] in one call, which a reflectance that traces
    /// its yarns answers with one eye ray. The default calls the two.
    fn local(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> Local {
        Local {
            f: self.f_at(at, wi, wo),
            coverage: self.coverage_at(at, wo),
        }
    }

    /// Draws an incident direction for the outgoing `wo` from `u` in [0, 1)^2; `None` when
    /// there is none (`wo` below the horizon). The default draws cos(theta_i)-weighted
    /// directions ([`cosine_sample`]), valid for any f_r.
    fn sample(&self, wo: UnitVec3, u: [f64; 2]) -> Option<BsdfSample> {
        default_sample(self, wo, u)
    }

    /// The density per unit solid angle with which [`Bsdf::sample`] draws `wi` for `wo`. The
    /// default is that of [`cosine_sample`], cos(theta_i) / pi.
    fn pdf(&self, wi: UnitVec3, wo: UnitVec3) -> f64 {
        default_pdf(wi, wo)
    }
}

/// A function f_r(wi, wo) as a [`Bsdf`] (with the default sampling): for a user's own
/// reflectance and for tests. The function must return zero at and below the horizon.
pub struct FromFn<F>(pub F);

impl<F: Fn(UnitVec3, UnitVec3) -> Rgb + Sync> Bsdf for FromFn<F> {
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        (self.0)(wi, wo)
    }
}

/// The default [`Bsdf::sample`]: a [`cosine_sample`] with f_r from `b` and [`default_pdf`].
pub fn default_sample<B: Bsdf + ?Sized>(b: &B, wo: UnitVec3, u: [f64; 2]) -> Option<BsdfSample> {
    if !wo.above_horizon() {
        return None;
    }
    let wi = cosine_sample(u);
    let pdf = default_pdf(wi, wo);
    (pdf > 0.0).then(|| BsdfSample {
        wi,
        f: b.f(wi, wo),
        pdf,
    })
}

/// The default [`Bsdf::pdf`]: cos(theta_i) / pi above the horizon, else 0.
pub fn default_pdf(wi: UnitVec3, wo: UnitVec3) -> f64 {
    if !(wo.above_horizon() && wi.above_horizon()) {
        return 0.0;
    }
    wi.cos_theta() / PI
}

/// The cosine sampling of a BSDF over the whole sphere (reflection and transmission): `wi`
/// drawn cos-weighted on `wo`'s side or on the other with even odds (`u[0] < 1/2`: `wo`'s
/// side), f from `b`, density [`two_sided_pdf`]; `None` for `wo` in the cloth's plane.
pub fn two_sided_sample<B: Bsdf + ?Sized>(b: &B, wo: UnitVec3, u: [f64; 2]) -> Option<BsdfSample> {
    if !(wo.above_horizon() || wo.below_horizon()) {
        return None;
    }
    let same = u[0] < 0.5;
    let w = cosine_sample([if same { 2.0 * u[0] } else { 2.0 * u[0] - 1.0 }, u[1]]);
    let wi = if same == (wo.z > 0.0) {
        w
    } else {
        w.mirror_z()
    };
    let pdf = two_sided_pdf(wi, wo);
    (pdf > 0.0).then(|| BsdfSample {
        wi,
        f: b.f(wi, wo),
        pdf,
    })
}

/// The density of [`two_sided_sample`]: |cos(theta_i)| / (2 pi) on either side, 0 for a
/// direction in the plane.
pub fn two_sided_pdf(wi: UnitVec3, wo: UnitVec3) -> f64 {
    let sided = |w: UnitVec3| w.above_horizon() || w.below_horizon();
    if !(sided(wi) && sided(wo)) {
        return 0.0;
    }
    wi.cos_theta().abs() / (2.0 * PI)
}

/// A direction of the upper hemisphere with density cos(theta) / pi, from `u` in [0, 1)^2
/// (Malley's method: a uniform point of the unit disc lifted to the hemisphere).
pub fn cosine_sample(u: [f64; 2]) -> UnitVec3 {
    let r = u[0].clamp(0.0, 1.0).sqrt();
    let phi = 2.0 * PI * u[1];
    let z = (1.0 - r * r).max(0.0).sqrt().max(2.0 * HORIZON_COS);
    UnitVec3::new(Vec3::new(r * phi.cos(), r * phi.sin(), z)).unwrap_or(UnitVec3::Z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Lambertian reflector of albedo rho: f_r = rho / pi.
    struct Lambert(f64);
    impl Bsdf for Lambert {
        fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
            if wi.above_horizon() && wo.above_horizon() {
                [self.0 / PI; 3]
            } else {
                [0.0; 3]
            }
        }
    }

    #[test]
    fn the_default_sampler_gives_a_lambertian_its_albedo_as_weight() {
        // Closed form: f cos / pdf = (rho / pi) cos / (cos / pi) = rho for every sample.
        let b = Lambert(0.7);
        let wo = UnitVec3::from_degrees(40.0, 10.0);
        for k in 0..64 {
            let u = [(k as f64 + 0.5) / 64.0, ((k * 37) % 64) as f64 / 64.0];
            let s = b.sample(wo, u).unwrap();
            assert!(s.wi.above_horizon());
            assert!((s.pdf - b.pdf(s.wi, wo)).abs() < 1e-15);
            for w in s.weight() {
                assert!((w - 0.7).abs() < 1e-12, "{w}");
            }
        }
        assert!(b
            .sample(UnitVec3::from_degrees(90.0, 0.0), [0.5; 2])
            .is_none());
    }

    #[test]
    fn the_level_rule_hands_over_smoothly_and_monotonically() {
        let at = |u, v, width| Footprint { u, v, width };
        let cell = 1.0 / 3.0;
        assert_eq!(at(0.2, 0.3, 1.0).level(cell), Level::Period);
        assert_eq!(at(f64::NAN, 0.3, 0.1).level(cell), Level::Period);
        assert_eq!(at(0.2, f64::INFINITY, 0.0).level(cell), Level::Period);
        let point = |w: f64| match at(0.2, 0.3, w).level(cell) {
            Level::Local {
                point,
                width,
                points,
            } => {
                assert!(width == w.max(0.0) || (w.is_nan() && width == 0.0));
                assert!((1..=MAX_POINTS_ACROSS).contains(&points));
                assert_eq!(points == 1, width <= 0.125 * cell, "{w}");
                point
            }
            Level::Period => panic!("{w}"),
        };
        assert_eq!(point(f64::NAN), 1.0);
        assert_eq!(point(-1.0), 1.0);
        assert_eq!(point(POINT_UNTIL * cell), 1.0);
        assert_eq!(point(CELLS_FROM * cell), 0.0);
        assert_eq!(point(0.9), 0.0);
        // Halfway between the two widths, halfway between the levels (smoothstep's middle).
        assert!((point(0.5 * (POINT_UNTIL + CELLS_FROM) * cell) - 0.5).abs() < 1e-12);
        // Continuous and monotone: no step larger than the slope allows.
        let mut last = 1.0;
        for k in 0..=1000 {
            let p = point(k as f64 / 1000.0 * 0.9);
            assert!(p <= last && last - p < 0.01, "{k}: {p} after {last}");
            last = p;
        }
    }

    #[test]
    fn the_default_density_integrates_to_one() {
        // Midpoint rule over the hemisphere: int pdf dw = 1.
        let (nt, np) = (400, 64);
        let mut s = 0.0;
        for i in 0..nt {
            let t = (i as f64 + 0.5) * (PI / 2.0) / nt as f64;
            for j in 0..np {
                let p = (j as f64 + 0.5) * 2.0 * PI / np as f64;
                let wi = UnitVec3::from_spherical(t, p);
                s += Lambert(1.0).pdf(wi, UnitVec3::Z) * t.sin();
            }
        }
        s *= (PI / 2.0 / nt as f64) * (2.0 * PI / np as f64);
        assert!((s - 1.0).abs() < 1e-5, "{s}");
    }
}
