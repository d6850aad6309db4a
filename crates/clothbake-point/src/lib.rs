//! clothbake-point: woven cloth's reflection at one point of the weave period, from its yarns.
//!
//! The finest of clothbake's three levels of detail (docs/science/spatial.md): a point, the crossing
//! cell (spatial tables) and the period (the averaged table). At a point x of the cloth's
//! reference plane, f(x; wi, wo) is the BTF a camera measures of a cloth sample: the radiance
//! that leaves the yarns along the eye ray crossing the reference plane at x toward `wo`, per
//! unit irradiance from `wi`, shadowed along the light ray through the same yarns. One eye ray
//! and one shadow ray through the period's cylinders ([`Yarns::look`]). Where the eye ray ends
//! on the floor, or on the end cap where a thread dives under its crossing thread, the point
//! shows a gap: coverage 0 (the ground truth leaves both out of its average likewise).
//!
//! The image of a yarn moves with the view (parallax): the eye ray is the one that crosses the
//! reference plane, halfway up the cloth ([`Period::reference_height`]), at x.
//!
//! This crate depends only on `clothbake-bsdf`, so that a renderer linking the loader gets it
//! without the model; clothbake-core converts a fabric's geometry into a [`Period`] in one
//! function, and a test there holds every look against the ground-truth ray tracer, ray for
//! ray. Frame as everywhere in clothbake: +X weft, +Y warp, +Z normal; `wi` toward the light,
//! `wo` toward the eye.

pub mod facet;
mod finish;
mod grid;
mod period;

pub use finish::{Facet, Finish};
pub use grid::Surface;
pub use period::{Along, Period, PeriodError, Yarn, MAX_YARNS};

use clothbake_bsdf::{Rgb, UnitVec3, Vec3};
use grid::Grid;
use std::f64::consts::PI;

/// What a point of the cloth shows toward `wo`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    /// f_r at the point in 1/sr, RGB: the facet intensity at the yarn the eye ray meets (zero
    /// where the light ray is blocked) over pi cos(theta_i); zero over a gap.
    pub f: Rgb,
    /// 1 where the eye ray meets a yarn's side, 0 where it shows a gap (the floor or an end cap).
    pub coverage: f64,
}

impl Look {
    /// Nothing: a gap, or a direction at or below the horizon.
    pub const NONE: Look = Look {
        f: [0.0; 3],
        coverage: 0.0,
    };
}

/// Where the eye ray of a point first meets the yarns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sight {
    /// The point met, in unwrapped period coordinates.
    pub point: Vec3,
    /// The outward unit normal there.
    pub normal: Vec3,
    /// The yarn met (an index of [`Period::yarns`]).
    pub yarn: usize,
    /// The surface met: a side, or an end cap (a gap).
    pub surface: Surface,
    /// The physical copy met, which the light ray leaving it skips.
    key: grid::Key,
}

/// The points a footprint of side `width` periods centred on (u, v) is integrated with:
/// `points` x `points` stratified over the square, each jittered within its stratum by a hash
/// of the centre (so the same footprint gives the same points, and a growing one moves them
/// smoothly); (u, v) alone for one point or a width not above 0.
pub fn footprint_points(
    u: f64,
    v: f64,
    width: f64,
    points: usize,
) -> impl Iterator<Item = (f64, f64)> {
    let one = points <= 1 || width.is_nan() || width <= 0.0;
    let k = if one { 1 } else { points };
    let mut h = u.to_bits() ^ v.to_bits().rotate_left(29);
    let mut jitter = move || {
        // SplitMix64.
        h = h.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = h;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    };
    (0..k * k).map(move |i| {
        if one {
            return (u, v);
        }
        let (a, b) = ((i / k) as f64, (i % k) as f64);
        let kf = k as f64;
        let x = u + width * ((a + jitter()) / kf - 0.5);
        let y = v + width * ((b + jitter()) / kf - 0.5);
        (x, y)
    })
}

/// A [`Period`] ready to trace: its yarns sorted into a grid over the period.
#[derive(Clone, Debug)]
pub struct Yarns {
    period: Period,
    grid: Grid,
    /// The plane the eye rays start from, just above the highest yarn.
    z_top: f64,
}

impl Yarns {
    /// The period's yarns, sorted for tracing.
    pub fn new(period: Period) -> Yarns {
        let top = period.top();
        Yarns {
            grid: Grid::new(&period),
            z_top: top + 1e-6 * top.max(1e-3),
            period,
        }
    }

    /// The period traced.
    pub fn period(&self) -> &Period {
        &self.period
    }

    /// The eye ray of the point (u, v) (period fractions, wrapped) toward `wo`: the line
    /// through the reference plane at the point, as origin (on the plane above every yarn) and
    /// direction (-wo). `None` when wo is at or below the horizon or u, v are not finite.
    pub fn eye_ray(&self, u: f64, v: f64, wo: UnitVec3) -> Option<(Vec3, Vec3)> {
        if !(wo.above_horizon() && u.is_finite() && v.is_finite()) {
            return None;
        }
        let (px, py) = self.period.size();
        let x = Vec3::new(
            u.rem_euclid(1.0) * px,
            v.rem_euclid(1.0) * py,
            self.period.reference_height(),
        );
        let back = (self.z_top - x.z) / wo.z;
        Some((x + wo.get() * back, -wo.get()))
    }

    /// Where the eye ray of the point (u, v) toward `wo` first meets a yarn; `None` where it
    /// reaches the floor (or for the cases [`Yarns::eye_ray`] refuses).
    pub fn sight(&self, u: f64, v: f64, wo: UnitVec3) -> Option<Sight> {
        let (o, d) = self.eye_ray(u, v, wo)?;
        self.first_sight(o, d)
    }

    /// Where the ray from `o` (on or above the top plane) along the downward `d` first meets a
    /// yarn; `None` when it reaches the floor.
    pub fn first_sight(&self, o: Vec3, d: Vec3) -> Option<Sight> {
        if d.z >= 0.0 || !o.is_finite() {
            return None;
        }
        let e = self.grid.first(o, d, o.z / -d.z, false, None)?;
        let c = &self.grid.copies[e.copy as usize];
        let (px, py) = self.period.size();
        let point = o + d * e.t;
        let local = Vec3::new(
            point.x - e.tile.0 as f64 * px,
            point.y - e.tile.1 as f64 * py,
            point.z,
        );
        Some(Sight {
            point,
            normal: c.normal(local, e.surface, d),
            yarn: c.yarn as usize,
            surface: e.surface,
            key: c.key(e.tile),
        })
    }

    /// Whether the light from `wi` reaches the point `s` met by an eye ray: the ray toward
    /// `wi` leaves the top plane without meeting another yarn.
    pub fn lit(&self, s: &Sight, wi: UnitVec3) -> bool {
        if !wi.above_horizon() {
            return false;
        }
        let t_out = (self.z_top - s.point.z) / wi.z;
        self.grid
            .first(s.point, wi.get(), t_out, true, Some(s.key))
            .is_none()
    }

    /// What the point (u, v) (period fractions, wrapped) shows toward `wo` lit from `wi`
    /// (docs/science/spatial.md, "The point level").
    pub fn look(&self, u: f64, v: f64, wi: UnitVec3, wo: UnitVec3) -> Look {
        if !wi.above_horizon() {
            return Look::NONE;
        }
        let Some(s) = self.sight(u, v, wo) else {
            return Look::NONE;
        };
        self.shade(&s, wi, wo)
    }

    /// The mean look over the square of side `width` periods centred on (u, v): the
    /// [`footprint_points`] of the square. Coverage is the share of the points that meet a
    /// yarn; f_r the mean over those (zero where none does). One point (or a width of 0) is
    /// [`Yarns::look`] at the centre.
    pub fn look_within(
        &self,
        u: f64,
        v: f64,
        width: f64,
        points: usize,
        wi: UnitVec3,
        wo: UnitVec3,
    ) -> Look {
        let (mut sum, mut hits, mut n) = ([0.0; 3], 0usize, 0usize);
        for (x, y) in footprint_points(u, v, width, points) {
            n += 1;
            let l = self.look(x, y, wi, wo);
            if l.coverage > 0.0 {
                hits += 1;
                for (s, f) in sum.iter_mut().zip(l.f) {
                    *s += f;
                }
            }
        }
        Look {
            f: if hits > 0 {
                sum.map(|s| s / hits as f64)
            } else {
                [0.0; 3]
            },
            coverage: hits as f64 / n as f64,
        }
    }

    /// The coverage of [`Yarns::look_within`] (under any light above the horizon), from the
    /// eye rays alone: the share of the same points whose eye ray meets a yarn's side.
    pub fn coverage_within(&self, u: f64, v: f64, width: f64, points: usize, wo: UnitVec3) -> f64 {
        let (mut hits, mut n) = (0usize, 0usize);
        for (x, y) in footprint_points(u, v, width, points) {
            n += 1;
            let side = self
                .sight(x, y, wo)
                .is_some_and(|s| s.surface == Surface::Side);
            hits += usize::from(side);
        }
        hits as f64 / n as f64
    }

    /// The look of a point met by an eye ray toward `wo`, lit from `wi`.
    pub fn shade(&self, s: &Sight, wi: UnitVec3, wo: UnitVec3) -> Look {
        if s.surface == Surface::Cap || !wi.above_horizon() {
            return Look::NONE;
        }
        let finish = &self.period.finishes()[self.period.yarns()[s.yarn].finish as usize];
        let i = self
            .period
            .facet()
            .intensity(finish, s.normal, wi.get(), wo.get());
        if i == [0.0; 3] || !self.lit(s, wi) {
            return Look {
                f: [0.0; 3],
                coverage: 1.0,
            };
        }
        let k = 1.0 / (PI * wi.cos_theta());
        Look {
            f: i.map(|x| x * k),
            coverage: 1.0,
        }
    }
}
