//! The orthographic ray caster of the truth's micro-geometry ([`super::yarns`]).
//!
//! [`RayTracer::render`] estimates the thesis's averaged intensity (eq. 4.11 and its pseudocode,
//! `I_total /= S_total`): the facet intensity averaged over the *visible projected area of the
//! yarns* of one weave period, seen from `wo` and lit from `wi`, with exact visibility and exact
//! shadowing by every yarn of the periodic tiling.
//!
//! * Primary rays are parallel to `-wo`. Their origins are spread uniformly (stratified jitter)
//!   over one period `[0, Px) x [0, Py)` of a horizontal plane just above the highest yarn, i.e.
//!   uniformly over the period's projected area seen from `wo`.
//! * A ray's first hit is searched among all segments of all period copies its path crosses
//!   between that plane and the floor z = 0 (a 2-D grid walk over the tiling, see
//!   [`super::cells::CellWalk`]), and the floor itself. Rays whose first hit is the floor are not
//!   counted at all, neither in the numerator nor in the denominator: the thesis averages over
//!   the yarns only.
//! * The surfaces are the cylinder sides (above the floor, within the segment's extent) and the
//!   flat end caps (discs of the cylinder's radius cut by the floor), whose normals are -+ the
//!   axis direction. By default ([`Caps::Excluded`]) rays ending on a cap are not counted either
//!   (caps stand for the thread diving under its crossing thread, which the thesis leaves out);
//!   [`Caps::Shaded`] counts them as shaded yarn.
//! * At a yarn hit with outward normal N, the facet intensity ([`super::facets`]) is taken when
//!   the shadow ray toward `wi` leaves the top plane without hitting anything (zero otherwise):
//!   its diffuse factor times the thread's RGB albedo goes to `i_d`, its specular part to `i_s`.
//! * The estimate is the ratio (sum of shading) / (number of yarn hits). Its standard error comes
//!   from [`BATCHES`] independent batches, each a stratified set of its own, see [`Estimate`].
//!
//! Everything is deterministic for a given seed: no threads, and a SplitMix64 stream
//! ([`crate::rng`]) per batch.

use super::cells::CellIndex;
use super::description::Description;
use super::estimate::{estimate, ratio_and_error, BatchSums, Estimate, BATCHES};
use super::facets::{Shading, Terms};
use super::intersect::{segment_entry, Surface};
use super::yarns::{Cylinder, Yarns};
use clothbake_bsdf::rng::Rng;
use clothbake_bsdf::vec3::{UnitVec3, Vec3};

/// First sample count of [`RayTracer::render_to_error`] (before doubling).
const FIRST_ROUND: usize = 16 * 256;

/// How the flat end caps of the segments count in the average.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Caps {
    /// Caps occlude (they hide and shadow) but, like the floor, rays ending on them are not
    /// counted: they stand for the part of a thread that dives under its crossing thread, which
    /// the thesis does not model and the analytic model does not average over (default).
    #[default]
    Excluded,
    /// Caps are shaded yarn surface with normal along the axis and counted like the sides.
    Shaded,
}

impl Caps {
    /// The setting's name, as the command line and the tables' options spell it.
    pub fn name(self) -> &'static str {
        match self {
            Caps::Excluded => "excluded",
            Caps::Shaded => "shaded",
        }
    }
}

/// A ray's first yarn hit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    /// Ray parameter of the hit.
    pub(crate) t: f64,
    /// The prim hit (an id of [`CellIndex::prims`]).
    pub(crate) prim: u32,
    /// The period copy the hit lies in.
    pub(crate) tile: (i64, i64),
    /// The surface entered.
    pub(crate) surface: Surface,
}

/// A yarn hit resolved to its point, outward normal, segment and physical copy.
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    /// The hit point (unwrapped coordinates).
    pub point: Vec3,
    /// Outward unit normal.
    pub normal: Vec3,
    /// Index of the segment in [`Yarns::cylinders`].
    pub(crate) seg: u32,
    /// Identity of the physical segment copy (to skip it when leaving the surface).
    pub(crate) key: (u32, i64, i64),
    /// The surface the point lies on.
    pub(crate) surface: Surface,
}

/// The exact orthographic ray caster of a fabric's micro-geometry (the ground truth).
#[derive(Clone, Debug)]
pub struct RayTracer {
    pub(crate) yarns: Yarns,
    pub(crate) terms: Terms,
    pub(crate) caps: Caps,
    pub(crate) cells: CellIndex,
    /// Height of the plane the primary rays start from, just above the highest yarn.
    pub(crate) z_top: f64,
    /// The floor z = 0, or on a two-faced cloth a plane just below the lowest yarn.
    pub(crate) z_bottom: f64,
}

impl RayTracer {
    /// Builds the tracer of a fabric description.
    pub(crate) fn from_description(d: &Description, terms: Terms) -> RayTracer {
        RayTracer::from_yarns(Yarns::build(d), terms)
    }

    /// Builds the tracer of an explicit micro-geometry. The segments must be disjoint solids and
    /// the period positive.
    pub(crate) fn from_yarns(yarns: Yarns, terms: Terms) -> RayTracer {
        let cells = CellIndex::new(&yarns);
        let top = yarns.top();
        let z_top = top + 1e-6 * top.max(1e-3);
        let z_bottom = if yarns.two_faced() {
            let b = -yarns.bottom();
            -(b + 1e-6 * b.max(1e-3))
        } else {
            0.0
        };
        RayTracer {
            yarns,
            terms,
            caps: Caps::default(),
            cells,
            z_top,
            z_bottom,
        }
    }

    /// The same tracer with end caps counted as `caps` says.
    pub fn with_caps(mut self, caps: Caps) -> Self {
        self.caps = caps;
        self
    }

    /// How end caps count.
    pub fn caps(&self) -> Caps {
        self.caps
    }

    /// The period (Px, Py) of the micro-geometry.
    pub fn period(&self) -> (f64, f64) {
        self.yarns.period
    }

    /// The first yarn surface the ray `o + t d` enters with `t_min < t < t_max`; with `any`, the
    /// first one found (for shadow rays). `skip` excludes one physical segment copy.
    pub(crate) fn trace(
        &self,
        o: Vec3,
        d: Vec3,
        t_min: f64,
        t_max: f64,
        any: bool,
        skip: Option<(u32, i64, i64)>,
    ) -> Option<Hit> {
        let cells = &self.cells;
        let mut best: Option<Hit> = None;
        let mut best_t = t_max;
        for cell in cells.walk(o, d, t_max) {
            let (ol, items) = cells.visit(&cell, o);
            let (tx, ty) = cell.tile;
            for &id in items {
                let p = &cells.prims[id as usize];
                if let Some((t, surface)) = segment_entry(&p.local(ol, d), &p.shape, t_min, best_t)
                {
                    if skip.is_some_and(|k| k == p.copy_key(tx, ty)) {
                        continue;
                    }
                    best_t = t;
                    best = Some(Hit {
                        t,
                        prim: id,
                        tile: (tx, ty),
                        surface,
                    });
                    if any {
                        return best;
                    }
                }
            }
            if best_t <= cell.t_exit {
                break;
            }
        }
        best
    }

    /// The point, normal and segment of the hit `h` of the ray `o + t d`.
    pub(crate) fn contact(&self, o: Vec3, d: Vec3, h: &Hit) -> Contact {
        let p = &self.cells.prims[h.prim as usize];
        let (px, py) = self.yarns.period;
        let point = o + d * h.t;
        let local = Vec3::new(
            point.x - h.tile.0 as f64 * px,
            point.y - h.tile.1 as f64 * py,
            point.z,
        );
        Contact {
            point,
            normal: p.normal(local, h.surface),
            seg: p.seg,
            key: p.copy_key(h.tile.0, h.tile.1),
            surface: h.surface,
        }
    }

    /// The segment a contact lies on.
    pub fn cylinder(&self, c: &Contact) -> &Cylinder {
        &self.yarns.cylinders[c.seg as usize]
    }

    /// Whether the ray from the contact toward the light `wi` leaves the cloth unblocked
    /// (through the top plane, or the bottom one on a two-faced cloth lit from below).
    pub(crate) fn lit(&self, c: &Contact, wi: UnitVec3) -> bool {
        let t_out = self.t_out(c.point, wi.get());
        self.trace(c.point, wi.get(), 0.0, t_out, true, Some(c.key))
            .is_none()
    }

    /// The ray parameter at which `o + t d` leaves the slab between the bottom plane (the
    /// floor, or below the two-faced cloth) and the top plane.
    #[inline]
    pub(crate) fn t_out(&self, o: Vec3, d: Vec3) -> f64 {
        if d.z > 0.0 {
            (self.z_top - o.z) / d.z
        } else {
            (o.z - self.z_bottom) / -d.z
        }
    }

    /// The counted yarn hit of a ray from the top plane at `o` along `d`: `None` for the floor
    /// and, with [`Caps::Excluded`], for a cap.
    pub(crate) fn first_contact(&self, o: Vec3, d: Vec3) -> Option<Contact> {
        let hit = self.trace(o, d, 0.0, self.t_out(o, d), false, None)?;
        if self.caps == Caps::Excluded && hit.surface != Surface::Side {
            return None;
        }
        Some(self.contact(o, d, &hit))
    }

    /// Shading of one primary ray from `o` along `-wo`: `None` for an uncounted hit, otherwise
    /// the facet intensity at the first yarn hit (zero when shadowed) and the hit.
    pub fn shade(&self, o: Vec3, wi: UnitVec3, wo: UnitVec3) -> Option<(Shading, Contact)> {
        let c = self.first_contact(o, -wo.get())?;
        let s = self
            .terms
            .shade(&self.cylinder(&c).finish, c.normal, wi.get(), wo.get());
        if s == Shading::default() || !self.lit(&c, wi) {
            return Some((Shading::default(), c));
        }
        Some((s, c))
    }

    /// The origins of `m` stratified primary rays over one period (jittered with `rng`).
    pub(crate) fn origins(&self, m: usize, rng: &mut Rng) -> impl Iterator<Item = Vec3> + '_ {
        let (px, py) = self.yarns.period;
        // sx * sy <= m strata of aspect ~ Px:Py, the remaining (< sx) samples uniform.
        let sx = ((m as f64 * px / py).sqrt().round() as usize).clamp(1, m.max(1));
        let sy = (m / sx).max(1);
        let strata = (sx * sy).min(m);
        let jitter: Vec<(f64, f64)> = (0..m).map(|_| (rng.next_f64(), rng.next_f64())).collect();
        jitter.into_iter().enumerate().map(move |(k, (u, v))| {
            let (x, y) = if k < strata {
                (
                    ((k % sx) as f64 + u) / sx as f64,
                    ((k / sx) as f64 + v) / sy as f64,
                )
            } else {
                (u, v)
            };
            Vec3::new(x * px, y * py, self.z_top)
        })
    }

    /// The reference plane's height, where a renderer's mesh of the cloth lies (docs/science/spatial.md,
    /// "The reference plane"): halfway between the floor and the top of the highest yarn.
    pub fn reference_height(&self) -> f64 {
        0.5 * self.yarns.top()
    }

    /// f_r at the point (u, v) of the reference plane (period fractions, wrapped): the facet
    /// intensity over pi cos(theta_i) where the eye ray crossing the plane there toward `wo`
    /// meets a yarn (zero where the light is blocked), `None` where it shows a gap (the floor,
    /// or a cap with [`Caps::Excluded`]) or a direction is at or below the horizon. The
    /// ground-truth picture of `render --truth` is made of these.
    pub fn look_at(&self, u: f64, v: f64, wi: UnitVec3, wo: UnitVec3) -> Option<[f64; 3]> {
        if !(wi.above_horizon() && wo.above_horizon() && u.is_finite() && v.is_finite()) {
            return None;
        }
        let o = self.eye_origin(u, v, wo);
        let (s, c) = self.shade(o, wi, wo)?;
        let albedo = self.cylinder(&c).finish.albedo;
        let k = 1.0 / (std::f64::consts::PI * wi.cos_theta());
        Some(albedo.map(|a| (s.diffuse * a + s.specular) * k))
    }

    /// Where the eye ray through the point (u, v) of the reference plane (period fractions,
    /// wrapped) toward `wo` starts on the top plane (`wo` above the horizon).
    pub(crate) fn eye_origin(&self, u: f64, v: f64, wo: UnitVec3) -> Vec3 {
        let (px, py) = self.yarns.period;
        let z_ref = self.reference_height();
        // Back along the eye ray from the plane to the top plane.
        let back = (self.z_top - z_ref) / wo.z;
        Vec3::new(u.rem_euclid(1.0) * px, v.rem_euclid(1.0) * py, z_ref) + wo.get() * back
    }

    /// The masking and shadowing shares of the period seen from `wo` (docs/science/model.md, "Where
    /// the error comes from"): the fraction of its projected area where the eye meets counted
    /// yarn (the coverage), and where that yarn also faces the light `wi` and is lit. From
    /// `samples` stratified rays, deterministic for a given `seed`; zeros when a direction is
    /// at or below the horizon.
    pub fn visible_and_lit(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        samples: usize,
        seed: u64,
    ) -> (f64, f64) {
        if !(wi.above_horizon() && wo.above_horizon()) || samples == 0 {
            return (0.0, 0.0);
        }
        let mut rng = Rng::stream(seed, 0);
        let (mut seen, mut lit) = (0usize, 0usize);
        for o in self.origins(samples, &mut rng) {
            if let Some(c) = self.first_contact(o, -wo.get()) {
                seen += 1;
                if c.normal.dot(wi.get()) > 0.0 && self.lit(&c, wi) {
                    lit += 1;
                }
            }
        }
        let n = samples as f64;
        (seen as f64 / n, lit as f64 / n)
    }

    /// Traces `m` stratified primary rays over one period into `sums`.
    fn batch(&self, wi: UnitVec3, wo: UnitVec3, m: usize, rng: &mut Rng, sums: &mut BatchSums) {
        for o in self.origins(m, rng) {
            sums.rays += 1;
            if let Some((s, c)) = self.shade(o, wi, wo) {
                sums.hits += 1;
                let albedo = self.cylinder(&c).finish.albedo;
                for (d, a) in sums.diffuse.iter_mut().zip(albedo) {
                    *d += s.diffuse * a;
                }
                sums.specular += s.specular;
            }
        }
    }

    /// Adds round `round` of `samples` rays (spread over the batches) to `sums`.
    fn accumulate(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        samples: usize,
        seed: u64,
        round: u64,
        sums: &mut [BatchSums; BATCHES],
    ) {
        for (b, s) in sums.iter_mut().enumerate() {
            let m = samples / BATCHES + usize::from(b < samples % BATCHES);
            let mut rng = Rng::stream(seed, round * BATCHES as u64 + b as u64);
            self.batch(wi, wo, m, &mut rng, s);
        }
    }

    /// The height of the plane the primary rays start from, just above the highest yarn.
    pub fn top(&self) -> f64 {
        self.z_top
    }

    /// Estimates the intensity reflected toward `wo` (unit vector toward the eye) for unit light
    /// from `wi` with `samples` primary rays; deterministic for a given `seed`. Zero, with no
    /// rays, when either direction is at or below the horizon.
    pub fn render(&self, wi: UnitVec3, wo: UnitVec3, samples: usize, seed: u64) -> Estimate {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return Estimate::default();
        }
        let mut sums = [BatchSums::default(); BATCHES];
        self.accumulate(wi, wo, samples, seed, 0, &mut sums);
        estimate(&sums)
    }

    /// As [`RayTracer::render`], doubling the number of samples (each round adds as many fresh
    /// rays as all the rounds before it) until the standard error of the channel-mean total
    /// intensity is at most `rel_err` times that mean, or `max_samples` rays have been traced.
    pub fn render_to_error(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        rel_err: f64,
        max_samples: usize,
        seed: u64,
    ) -> Estimate {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return Estimate::default();
        }
        let mut sums = [BatchSums::default(); BATCHES];
        let mut total = 0usize;
        let mut next = FIRST_ROUND.min(max_samples);
        for round in 0.. {
            self.accumulate(wi, wo, next, seed, round, &mut sums);
            total += next;
            let hits: u64 = sums.iter().map(|b| b.hits).sum();
            let (mean, se) = ratio_and_error(&sums, |d, s| (d[0] + d[1] + d[2]) / 3.0 + s);
            if (hits > 0 && se <= rel_err * mean) || total >= max_samples {
                break;
            }
            next = total.min(max_samples - total);
        }
        estimate(&sums)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Face;

    /// Asserts that `got`, channel `c` of `est`, is `want` within four standard errors plus
    /// 0.2% of `want` (the closed forms' own rounding is far below); returns that tolerance.
    fn within_error(est: &Estimate, c: usize, got: f64, want: f64, what: &str) -> f64 {
        let tol = 4.0 * est.std_err[c] + 0.002 * want;
        assert!(
            (got - want).abs() < tol,
            "{what}: got {got}, want {want}, tol {tol}, {est:?}"
        );
        tol
    }
    use crate::description::Finish;
    use crate::intersect::{LocalRay, SegmentShape};
    use clothbake_fabric::fabric::Fabric;
    use clothbake_fabric::weave::Group;
    use clothbake_fabric::FacetModel;
    use std::f64::consts::PI;

    fn fabric(json: &str) -> Fabric {
        Fabric::from_json_str(json, "test").unwrap()
    }

    /// One endless warp cylinder (radius 1, axis on the floor), neighbours 1000 away.
    fn lone(material: &str) -> RayTracer {
        let json = format!(
            r#"{{"pattern": [[1]], "warp": {{"radius": 1, "spacing": 1000, "material": {material}}},
                "weft": {{"radius": 0.5, "spacing": 1}}}}"#
        );
        RayTracer::new(&fabric(&json), FacetModel::Huo)
    }

    fn twill() -> RayTracer {
        RayTracer::new(
            &fabric(
                r#"{"pattern": [[1,1,0],[0,1,1],[1,0,1]],
                    "warp": {"radius": 1.5, "spacing": 3.1}, "weft": {"radius": 1.5, "spacing": 3.1}}"#,
            ),
            FacetModel::Huo,
        )
    }

    fn dir(theta_deg: f64, phi_deg: f64) -> UnitVec3 {
        UnitVec3::from_degrees(theta_deg, phi_deg)
    }

    /// Thesis eqs 4.7 / 4.10 for one cylinder cross-section in the XZ plane: the average of
    /// `f(theta)` over the visible upper half circle, points N = (cos t, 0, sin t) with
    /// cos(t - tE) > 0, weighted by the correction factor cos(t - tE). Midpoint quadrature.
    fn arc_average(e_angle: f64, f: impl Fn(f64) -> f64) -> f64 {
        let n = 200_000;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            let t = (i as f64 + 0.5) / n as f64 * PI;
            let w = (t - e_angle).cos();
            if w > 0.0 {
                num += f(t) * w;
                den += w;
            }
        }
        num / den
    }

    /// Elevation angle, measured from +X in the XZ plane, of a direction in that plane.
    fn xz_angle(d: UnitVec3) -> f64 {
        assert!(d.y.abs() < 1e-12);
        d.z.atan2(d.x)
    }

    const XZ_CASES: [(f64, f64, f64, f64); 7] = [
        // (theta_i, phi_i, theta_o, phi_o), degrees; phi 0 or 180 keeps both in the XZ plane.
        (30.0, 0.0, 50.0, 180.0),
        (0.0, 0.0, 60.0, 0.0),
        (70.0, 180.0, 20.0, 0.0),
        (45.0, 0.0, 45.0, 0.0),
        (60.0, 0.0, 85.0, 180.0),
        (85.0, 0.0, 30.0, 180.0),
        (80.0, 180.0, 85.0, 0.0),
    ];

    #[test]
    fn lone_cylinder_diffuse_matches_quadrature() {
        let albedo = [0.2, 0.5, 0.8];
        let rt = lone(r#"{"albedo": [0.2, 0.5, 0.8], "specular": 0}"#);
        for (k, &(ti, pi, to, po)) in XZ_CASES.iter().enumerate() {
            let (wi, wo) = (dir(ti, pi), dir(to, po));
            let (tl, te) = (xz_angle(wi), xz_angle(wo));
            let want = arc_average(te, |t| (t - tl).cos().max(0.0));
            let est = rt.render(wi, wo, 1 << 22, k as u64);
            assert!(est.yarn_hits > 5000, "{est:?}");
            for (c, rho) in albedo.into_iter().enumerate() {
                let what = format!("case {k} channel {c}");
                within_error(&est, c, est.reflection.i_d[c], rho * want, &what);
                assert_eq!(est.reflection.i_s[c], 0.0);
            }
        }
    }

    #[test]
    fn lone_cylinder_specular_matches_quadrature() {
        let rt = lone(r#"{"albedo": 0, "specular": 1, "exponent": 10}"#);
        for (k, &(ti, pi, to, po)) in XZ_CASES.iter().enumerate() {
            let (wi, wo) = (dir(ti, pi), dir(to, po));
            let (tl, te) = (xz_angle(wi), xz_angle(wo));
            // Half vector angle in the XZ plane: bisector of the light and eye angles.
            let th = 0.5 * (tl + te);
            let want = arc_average(te, |t| {
                if (t - tl).cos() > 0.0 {
                    (t - th).cos().powi(10)
                } else {
                    0.0
                }
            });
            let est = rt.render(wi, wo, 1 << 22, 100 + k as u64);
            within_error(&est, 0, est.reflection.i_s[0], want, &format!("case {k}"));
        }
    }

    #[test]
    fn overhead_light_and_eye_give_pi_over_four() {
        // I_d = rho_d int_0^pi sin^2 / int_0^pi sin = rho_d pi / 4; with the axis at height h the
        // floor cuts the visible arc to [a, pi - a], sin a = max(0, -h) / r.
        for (h, seed) in [(0.0, 1), (0.5, 2), (-0.5, 3)] {
            let json = format!(
                r#"{{"pattern": [[1]], "warp": {{"radius": 1, "height": {h}, "spacing": 1000,
                    "material": {{"albedo": 0.4, "specular": 0}}}}, "weft": {{"radius": 0.5, "spacing": 1}}}}"#
            );
            let rt = RayTracer::new(&fabric(&json), FacetModel::Huo);
            let a = f64::max(-h, 0.0).asin();
            let want = 0.4 * (PI / 2.0 - a + a.sin() * a.cos()) / (2.0 * a.cos());
            if h == 0.0 {
                assert!((want - 0.4 * PI / 4.0).abs() < 1e-15);
            }
            let est = rt.render(UnitVec3::Z, UnitVec3::Z, 1 << 22, seed);
            within_error(&est, 1, est.reflection.i_d[1], want, &format!("h {h}"));
        }
    }

    #[test]
    fn end_cap_is_seen_and_shaded() {
        // A lone finite warp segment, axis on the floor along y in [0, 4], seen (and lit) from
        // (0, -sin t, cos t): the side contributes int (N.E)^2 = r L cos^2 t pi / 2 over
        // projected area 2 r L cos t, the low cap (half disc, normal -y) (pi r^2 / 2) sin^2 t
        // over (pi r^2 / 2) sin t.
        let (r, len) = (1.0, 4.0);
        let yarns = Yarns {
            period: (20.0, 20.0),
            threads: (vec![10.0], vec![0.0]),
            cylinders: vec![Cylinder {
                group: Group::Warp,
                thread: 0,
                axis: 10.0,
                radius: r,
                height: 0.0,
                extent: Some((8.0, 8.0 + len)),
                finish: Finish {
                    albedo: [0.4; 3],
                    specular: 0.0,
                    exponent: 10.0,
                    transmittance: [0.0; 3],
                },
                face: Face::OverFloor,
            }],
        };
        let rt = RayTracer::from_yarns(yarns, Terms::Huo).with_caps(Caps::Shaded);
        let excluded = rt.clone().with_caps(Caps::Excluded);
        for (t_deg, seed) in [(30.0, 1), (60.0, 2), (80.0, 3)] {
            let t = f64::to_radians(t_deg);
            let e = dir(t_deg, 270.0);
            let half_disc = PI * r * r / 2.0;
            let num = r * len * t.cos().powi(2) * PI / 2.0 + half_disc * t.sin().powi(2);
            let den = 2.0 * r * len * t.cos() + half_disc * t.sin();
            let want = 0.4 * num / den;
            let est = rt.render(e, e, 1 << 20, seed);
            let what = format!("theta {t_deg}");
            let tol = within_error(&est, 0, est.reflection.i_d[0], want, &what);
            // Without the cap the answer would differ by far more than the tolerance.
            let no_cap = 0.4 * (r * len * t.cos().powi(2) * PI / 2.0) / (2.0 * r * len * t.cos());
            if t_deg >= 60.0 {
                assert!((no_cap - want).abs() > 5.0 * tol);
            }
            // With caps excluded (the default) only the side is averaged.
            let est = excluded.render(e, e, 1 << 18, seed);
            let what = format!("excluded, theta {t_deg}");
            within_error(&est, 0, est.reflection.i_d[0], no_cap, &what);
        }
    }

    #[test]
    fn packed_cylinders_cover_the_projected_period_at_grazing_angles() {
        // Endless cylinders of radius r, axis on the floor, spacing s. Seen along d, the
        // cross-section sees the ray at tan t' = |d_across| / |d_z|; each half cylinder covers
        // r (1 + sec t') of the floor, so the yarn-hit fraction is min(1, r (1 + sec t') / s).
        // A grazing ray crosses several periods, testing the period-copy enumeration.
        let warp = RayTracer::new(
            &fabric(
                r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 4}, "weft": {"radius": 0.5, "spacing": 1.3}}"#,
            ),
            FacetModel::Huo,
        );
        let weft = RayTracer::new(
            &fabric(
                r#"{"pattern": [[0]], "warp": {"radius": 0.5, "spacing": 1.3}, "weft": {"radius": 1, "spacing": 4}}"#,
            ),
            FacetModel::Huo,
        );
        let n = 1 << 16;
        for (t, p) in [
            (0.0, 0.0),
            (45.0, 10.0),
            (60.0, 0.0),
            (60.0, 200.0),
            (75.0, 60.0),
            (85.0, 85.0),
            (85.0, 0.0),
            (89.0, 45.0),
        ] {
            for (rt, across) in [(&warp, 0usize), (&weft, 1)] {
                let wo = dir(t, p + 90.0 * across as f64);
                let d = [wo.x, wo.y];
                let tan = d[across].abs() / wo.z;
                let want = ((1.0 + (1.0 + tan * tan).sqrt()) / 4.0).min(1.0);
                let est = rt.render(dir(30.0, 40.0), wo, n, 9);
                let got = est.yarn_hits as f64 / est.rays as f64;
                let tol = 4.0 * (want * (1.0 - want) / n as f64).sqrt() + 1e-4;
                assert!(
                    (got - want).abs() <= tol,
                    "theta {t} phi {p} across {across}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn neighbours_cast_shadows() {
        // Endless warp half cylinders (r = 1, spacing s = 2.5), eye overhead: the whole upper
        // half circle N = (cos p, 0, sin p) is visible with weight sin p. Light at angle a from
        // the zenith toward +x: the point P = r (cos p, sin p) is lit when N.L > 0 and the ray
        // P + t L (t > 0) passes no neighbour centre C_k = (k s, 0) closer than r, i.e.
        // |(C_k - P) x L| = |k s cos a - r cos(p + a)| >= r or C_k lies behind.
        let (r, s) = (1.0, 2.5);
        let rt = RayTracer::new(
            &fabric(
                r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 2.5, "material": {"specular": 0}},
                    "weft": {"radius": 0.5, "spacing": 1}}"#,
            ),
            FacetModel::Huo,
        );
        for (a_deg, seed) in [(40.0, 1), (65.0, 2), (85.0, 3)] {
            let a = f64::to_radians(a_deg);
            let l = [a.sin(), a.cos()];
            let n = 100_000;
            let (mut num, mut den, mut free) = (0.0, 0.0, 0.0);
            for i in 0..n {
                let p = (i as f64 + 0.5) / n as f64 * PI;
                let pt = [r * p.cos(), r * p.sin()];
                let nl = p.cos() * l[0] + p.sin() * l[1];
                let lit = nl > 0.0
                    && (1..200).all(|k| {
                        let c = [k as f64 * s - pt[0], -pt[1]];
                        let ahead = c[0] * l[0] + c[1] * l[1] > 0.0;
                        !ahead || (c[0] * l[1] - c[1] * l[0]).abs() >= r
                    });
                den += p.sin();
                free += nl.max(0.0) * p.sin();
                if lit {
                    num += nl * p.sin();
                }
            }
            let want = 0.4 * num / den;
            let est = rt.render(dir(a_deg, 0.0), UnitVec3::Z, 1 << 18, seed);
            let what = format!("light {a_deg}");
            let tol = within_error(&est, 0, est.reflection.i_d[0], want, &what);
            // The neighbours' shadows matter far beyond the tolerance at oblique light.
            if a_deg > 60.0 {
                assert!(0.4 * free / den - want > 5.0 * tol, "{}", 0.4 * free / den);
            }
        }
    }

    /// Brute force first hit: every segment of every period copy within `k` periods.
    fn brute_first_hit(rt: &RayTracer, o: Vec3, d: Vec3, t_max: f64, k: i64) -> Option<f64> {
        let (px, py) = rt.yarns.period;
        let mut best: Option<f64> = None;
        for s in &rt.yarns.cylinders {
            let shape = SegmentShape {
                axis: s.axis,
                height: s.height,
                radius: s.radius,
                extent: s.extent,
                face: s.face,
            };
            for i in -k..=k {
                for j in -k..=k {
                    let ol = Vec3::new(o.x - i as f64 * px, o.y - j as f64 * py, o.z);
                    let ray = LocalRay::in_frame(s.group == Group::Warp, ol, d);
                    if let Some((t, _)) = segment_entry(&ray, &shape, 0.0, best.unwrap_or(t_max)) {
                        best = Some(t);
                    }
                }
            }
        }
        best
    }

    #[test]
    fn grid_walk_finds_the_same_first_hit_as_brute_force() {
        let rt = twill();
        let mut rng = Rng::new(5);
        let (px, py) = rt.yarns.period;
        for i in 0..4000 {
            let theta = if i % 2 == 0 {
                85.0
            } else {
                90.0 * rng.next_f64()
            };
            let wo = dir(theta, 360.0 * rng.next_f64());
            let o = Vec3::new(rng.next_f64() * px, rng.next_f64() * py, rt.z_top);
            let d = -wo.get();
            let t_floor = o.z / -d.z;
            let fast = rt.trace(o, d, 0.0, t_floor, false, None).map(|h| h.t);
            let brute = brute_first_hit(&rt, o, d, t_floor, 4);
            let same = match (fast, brute) {
                (Some(a), Some(b)) => (a - b).abs() < 1e-9,
                (None, None) => true,
                _ => false,
            };
            assert!(
                same,
                "ray {i}: theta {theta} {o:?} {d:?}: {fast:?} vs {brute:?}"
            );
        }
    }

    #[test]
    fn zero_below_horizon_and_deterministic() {
        let rt = twill();
        let below = UnitVec3::from_degrees(95.0, 20.0);
        let up = dir(40.0, 30.0);
        let horizon = UnitVec3::new(Vec3::new(1.0, 0.0, 0.0)).unwrap();
        for (wi, wo) in [(below, up), (up, below), (horizon, up), (up, horizon)] {
            let e = rt.render(wi, wo, 1000, 1);
            assert_eq!(e, Estimate::default());
            assert_eq!(
                rt.render_to_error(wi, wo, 0.01, 1000, 1),
                Estimate::default()
            );
        }
        let a = rt.render(dir(30.0, 80.0), dir(50.0, 200.0), 20_000, 42);
        let b = rt.render(dir(30.0, 80.0), dir(50.0, 200.0), 20_000, 42);
        let c = rt.render(dir(30.0, 80.0), dir(50.0, 200.0), 20_000, 43);
        assert_eq!(a, b);
        assert_eq!(format!("{a:?}"), format!("{b:?}")); // bit-identical, NaN-free
        assert_ne!(a.reflection, c.reflection);
        assert_eq!(a.rays, 20_000);
        for e in [a, c] {
            for k in 0..3 {
                for v in [e.reflection.i_d[k], e.reflection.i_s[k], e.std_err[k]] {
                    assert!(v.is_finite() && v >= 0.0, "{e:?}");
                }
            }
            assert!(e.yarn_hits > 0 && e.yarn_hits <= e.rays);
        }
    }

    #[test]
    fn std_err_shrinks_like_inverse_sqrt_and_is_honest() {
        let rt = twill();
        let (wi, wo) = (dir(40.0, 30.0), dir(60.0, 250.0));
        // Quadrupling the samples 4x (16x samples) should shrink the error ~4x (stratification
        // may do somewhat better); a broken or constant error estimate fails.
        let small = rt.render(wi, wo, 4096, 1).std_err[0];
        let large = rt.render(wi, wo, 65_536, 1).std_err[0];
        let ratio = small / large;
        assert!((2.5..12.0).contains(&ratio), "{small} / {large} = {ratio}");
        // The reported error matches the actual scatter of independent estimates.
        let runs: Vec<Estimate> = (0..24).map(|s| rt.render(wi, wo, 4096, 1000 + s)).collect();
        let m = runs.iter().map(|e| e.reflection.total()[0]).sum::<f64>() / runs.len() as f64;
        let sd = (runs
            .iter()
            .map(|e| (e.reflection.total()[0] - m).powi(2))
            .sum::<f64>()
            / (runs.len() - 1) as f64)
            .sqrt();
        let se = runs.iter().map(|e| e.std_err[0]).sum::<f64>() / runs.len() as f64;
        assert!(
            (0.5..2.0).contains(&(sd / se)),
            "scatter {sd} vs reported {se}"
        );
    }

    #[test]
    fn render_to_error_reaches_target() {
        let rt = twill();
        let (wi, wo) = (dir(20.0, 0.0), dir(35.0, 120.0));
        let e = rt.render_to_error(wi, wo, 0.002, 1 << 24, 3);
        let t = e.reflection.total();
        let mean = (t[0] + t[1] + t[2]) / 3.0;
        assert!(e.std_err[0] <= 0.002 * mean * 1.0001, "{e:?}");
        assert!(e.rays > FIRST_ROUND && e.rays < 1 << 24, "{e:?}");
        assert!(e.rays.is_power_of_two());
        let capped = rt.render_to_error(wi, wo, 1e-9, 3 * FIRST_ROUND, 3);
        assert_eq!(capped.rays, 3 * FIRST_ROUND);
    }

    #[test]
    fn plain_weave_is_mirror_symmetric() {
        let rt = RayTracer::new(
            &fabric(
                r#"{"pattern": [[1,0],[0,1]],
                    "warp": {"radius": 1.5, "spacing": 3.1}, "weft": {"radius": 1.5, "spacing": 3.1}}"#,
            ),
            FacetModel::Huo,
        );
        for (k, (wi, wo)) in [
            (dir(30.0, 20.0), dir(50.0, 200.0)),
            (dir(60.0, 45.0), dir(20.0, 135.0)),
            (dir(10.0, 300.0), dir(75.0, 10.0)),
            (dir(80.0, 170.0), dir(40.0, 60.0)),
        ]
        .into_iter()
        .enumerate()
        {
            let a = rt.render(wi, wo, 1 << 18, 2 * k as u64);
            let b = rt.render(wi.mirror_x(), wo.mirror_x(), 1 << 18, 2 * k as u64 + 1);
            let (ta, tb) = (a.reflection.total()[0], b.reflection.total()[0]);
            let tol = 4.0 * a.std_err[0].hypot(b.std_err[0]);
            assert!((ta - tb).abs() < tol, "case {k}: {ta} vs {tb} (tol {tol})");
        }
    }
}
