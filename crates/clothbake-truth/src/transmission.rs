//! Light through the two-faced cloth (docs/science/transmission.md): the ground truth of its openness,
//! of its reflection from either face and of its transmission.
//!
//! The cloth is [`RayTracer::two_faced`]'s: the front floats above z = 0, the inverted weave's
//! floats mirrored below it, no floor, every surface shaded. A facet of a translucent yarn
//! reflects by its facet terms and transmits the share t = tau (1 - rho_d - rho_s) of the light
//! it receives ([`Finish::transmittance`](super::Finish)): the light that enters at a point
//! leaves the yarn diffusely (Lambertian about the outward normal) from the other end of the
//! chord of the yarn's cross-section through that point and the cross-section's middle, the
//! chord's *partner* ([`RayTracer::partner`]); an end cap is its own partner. The pairing of a
//! point with its partner is an involution and t is a constant, so the transport is
//! reciprocal.
//!
//! Every quantity is per unit area of the cloth (the macro surface), with unit irradiance from
//! `wi` on it, and counts every ray, including those that pass through the gaps:
//! * [`RayTracer::openness`]: the share of parallel rays that meet no yarn (a delta toward
//!   `-wi`);
//! * [`RayTracer::scatter`]: where the light from `wi` goes, traced from the light (every
//!   bounce up to a bound): reflected to `wi`'s side, transmitted to the other, through the
//!   gaps, absorbed;
//! * [`RayTracer::render_sphere`]: f(wi, wo) in 1/sr over the whole sphere, traced from the eye
//!   with the light sampled at every vertex (reflection and transmission by the partner).

use super::estimate::BATCHES;
use super::intersect::Surface;
use super::pathtracer::uniform_hemisphere;
use super::raytracer::{Contact, RayTracer};
use super::yarns::Face;
use clothbake_bsdf::rng::Rng;
use clothbake_bsdf::vec3::{UnitVec3, Vec3};
use std::f64::consts::PI;

/// Where the light from one direction goes on the two-faced cloth, per unit irradiance: each
/// share with its standard error (over [`BATCHES`] independent batches).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Scattering {
    /// Scattered back to the light's side (reflectance R), RGB.
    pub reflected: [f64; 3],
    /// Scattered to the other side (diffuse transmittance T, the gaps' part excluded), RGB.
    pub transmitted: [f64; 3],
    /// Passed straight through the gaps (the openness).
    pub through: f64,
    /// Standard errors of `reflected`, `transmitted` and `through`.
    pub std_err: ([f64; 3], [f64; 3], f64),
}

/// Mean and standard error of per-batch means.
fn mean_err(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let m = xs.iter().sum::<f64>() / n;
    let v = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, (v / n).sqrt())
}

impl RayTracer {
    /// The other end of the chord of the contact's cross-section through the contact and the
    /// cross-section's middle (on the axis's vertical, halfway between the yarn's top and the
    /// plane z = 0; the same distance along the axis), where the light a translucent yarn lets
    /// in at the contact leaves it. Its normal is the outward one there: on the round
    /// side, or on the flat face in z = 0 where the chord meets that first. An end cap is its
    /// own partner (the chord would stay in the cap's disc): what a cap lets in leaves the cap.
    pub(crate) fn partner(&self, c: &Contact) -> Option<Contact> {
        if matches!(c.surface, Surface::CapLo | Surface::CapHi) {
            return Some(*c);
        }
        let cyl = self.cylinder(c);
        let warp = cyl.group == clothbake_fabric::weave::Group::Warp;
        let (pa, period) = if warp {
            (c.point.x, self.yarns.period.0)
        } else {
            (c.point.y, self.yarns.period.1)
        };
        // Across the axis, relative to the axis of this copy (|du| <= r < half the period).
        let off = pa - cyl.axis;
        let du = off - period * (off / period).round();
        // z measured so that the solid keeps zz >= 0 (the back is mirrored).
        let flip = cyl.face == Face::Back;
        let zz = if flip { -c.point.z } else { c.point.z };
        let hh = if flip { -cyl.height } else { cyl.height };
        let r = cyl.radius;
        // The line through the point and the middle of the cross-section: on the axis's
        // vertical, halfway between the top (h + r) and the plane z = 0, strictly inside.
        let mid = 0.5 * (hh + r);
        let (dx, dz) = (-du, mid - zz);
        let a = dx * dx + dz * dz;
        if a == 0.0 {
            return None;
        }
        // Leaving the circle: the larger root of |e + s d|^2 = r^2 with e = p - axis.
        let (ex, ez) = (du, zz - hh);
        let b = ex * dx + ez * dz;
        let disc = (b * b - a * (ex * ex + ez * ez - r * r)).max(0.0);
        let s_circle = (-b + disc.sqrt()) / a;
        // Leaving through the plane z = 0, when the chord goes down to it first.
        let s_plane = if dz < 0.0 { -zz / dz } else { f64::INFINITY };
        let (s, cut) = if s_plane < s_circle {
            (s_plane, true)
        } else {
            (s_circle, false)
        };
        let (qu, qz) = (du + s * dx, if cut { 0.0 } else { zz + s * dz });
        let (nu, nz) = if cut {
            (0.0, -1.0)
        } else {
            (qu / r, (qz - hh) / r)
        };
        let (qz, nz) = if flip { (-qz, -nz) } else { (qz, nz) };
        let shift = qu - du;
        let (point, normal) = if warp {
            (
                Vec3::new(c.point.x + shift, c.point.y, qz),
                Vec3::new(nu, 0.0, nz),
            )
        } else {
            (
                Vec3::new(c.point.x, c.point.y + shift, qz),
                Vec3::new(0.0, nu, nz),
            )
        };
        let len = normal.length();
        Some(Contact {
            point,
            normal: normal * (1.0 / len),
            seg: c.seg,
            key: c.key,
            surface: if cut { Surface::Cut } else { Surface::Side },
        })
    }

    /// Where the light a translucent yarn lets in at `c` leaves the cloth's yarns, and the
    /// share of it that does (per RGB channel): the contact's [`RayTracer::partner`] and its
    /// transmittance t, or, where the partner lies on a flat face in z = 0 that touches a yarn
    /// of the other face (at a crossing, or where a thread passes between the faces), the
    /// light goes on through that yarn too and leaves from its partner, with the smaller of
    /// the two transmittances (what one yarn lets through, when both are alike). The pairing
    /// stays an involution and the share symmetric, so the transport stays reciprocal, and it
    /// is at most the entry yarn's, so no energy is made. `None` for an opaque yarn.
    pub(crate) fn passage(&self, c: &Contact) -> Option<(Contact, [f64; 3])> {
        let t = self.cylinder(c).finish.transmittance;
        if t == [0.0; 3] {
            return None;
        }
        let y = self.partner(c)?;
        if y.surface != Surface::Cut {
            return Some((y, t));
        }
        // A yarn touching the flat face: a short ray from just inside it, outward.
        let scale = 1e-9 * (self.z_top - self.z_bottom);
        let o = y.point - y.normal * scale;
        let Some(h) = self.trace(o, y.normal, 0.0, 2.0 * scale, false, Some(y.key)) else {
            return Some((y, t));
        };
        let mut other = self.contact(o, y.normal, &h);
        if other.surface != Surface::Cut {
            return Some((y, t));
        }
        other.point = y.point;
        let u = self.cylinder(&other).finish.transmittance;
        let z = self.partner(&other)?;
        Some((z, [0, 1, 2].map(|k| t[k].min(u[k]))))
    }

    /// Origins of `m` stratified rays over one period on the plane a ray along `d` enters
    /// the cloth through (the top plane when `d` points down).
    fn entry_origins(&self, d: Vec3, m: usize, rng: &mut Rng) -> Vec<Vec3> {
        let z = if d.z < 0.0 { self.z_top } else { self.z_bottom };
        self.origins(m, rng)
            .map(|o| Vec3::new(o.x, o.y, z))
            .collect()
    }

    /// The first contact of the ray `o + t d` inside the cloth, any surface.
    fn first_any(&self, o: Vec3, d: Vec3, skip: Option<(u32, i64, i64)>) -> Option<Contact> {
        let h = self.trace(o, d, 0.0, self.t_out(o, d), false, skip)?;
        Some(self.contact(o, d, &h))
    }

    /// The openness along `w` (either side): the share of `samples` stratified rays parallel
    /// to `-w`, spread over one period, that cross the cloth without meeting a yarn.
    /// Deterministic for a seed; 0 within [`clothbake_bsdf::vec3::HORIZON_COS`] of the plane.
    pub fn openness(&self, w: UnitVec3, samples: usize, seed: u64) -> f64 {
        if !(w.above_horizon() || w.below_horizon()) || samples == 0 {
            return 0.0;
        }
        let d = -w.get();
        let mut rng = Rng::stream(seed, 0);
        let origins = self.entry_origins(d, samples, &mut rng);
        let open = origins
            .into_iter()
            .filter(|&o| self.first_any(o, d, None).is_none())
            .count();
        open as f64 / samples as f64
    }

    /// Where the light from `wi` goes: `samples` rays from the light's side, each followed
    /// through up to `max_bounces` scattering events (reflection drawn uniformly over the
    /// normal's hemisphere; on a translucent facet, reflection or transmission with even odds).
    /// A path still inside after `max_bounces` is dropped (counted as absorbed). Deterministic
    /// for a seed.
    pub fn scatter(
        &self,
        wi: UnitVec3,
        samples: usize,
        seed: u64,
        max_bounces: usize,
    ) -> Scattering {
        if !(wi.above_horizon() || wi.below_horizon()) || samples == 0 {
            return Scattering::default();
        }
        let d = -wi.get();
        let mut per = vec![([0.0; 3], [0.0; 3], 0.0); BATCHES];
        let mut counts = [0usize; BATCHES];
        for (b, acc) in per.iter_mut().enumerate() {
            let m = samples / BATCHES + usize::from(b < samples % BATCHES);
            counts[b] = m;
            let mut rng = Rng::stream(seed, (2 << 32) + b as u64);
            for o in self.entry_origins(d, m, &mut rng) {
                let Some(mut at) = self.first_any(o, d, None) else {
                    acc.2 += 1.0;
                    continue;
                };
                let mut inc = wi.get();
                let mut thr = [1.0; 3];
                for _ in 0..max_bounces.max(1) {
                    let Some((from, w)) = self.scatter_once(&at, inc, &mut thr, &mut rng) else {
                        break;
                    };
                    match self.first_any(from.point, w, Some(from.key)) {
                        Some(next) => {
                            at = next;
                            inc = -w;
                        }
                        None => {
                            let out = if (w.z > 0.0) == (wi.z > 0.0) {
                                &mut acc.0
                            } else {
                                &mut acc.1
                            };
                            for c in 0..3 {
                                out[c] += thr[c];
                            }
                            break;
                        }
                    }
                }
            }
        }
        let share = |f: &dyn Fn(usize) -> f64| {
            let xs: Vec<f64> = (0..BATCHES)
                .map(|b| f(b) / counts[b].max(1) as f64)
                .collect();
            mean_err(&xs)
        };
        let mut s = Scattering::default();
        for c in 0..3 {
            (s.reflected[c], s.std_err.0[c]) = share(&|b| per[b].0[c]);
            (s.transmitted[c], s.std_err.1[c]) = share(&|b| per[b].1[c]);
        }
        (s.through, s.std_err.2) = share(&|b| per[b].2);
        s
    }

    /// One scattering event of light arriving at `at` from the direction `inc` (toward where
    /// it came from): the vertex it leaves from (`at`, or its partner through the yarn) and the
    /// direction, with the event's weight multiplied into `thr`; `None` when nothing leaves.
    fn scatter_once(
        &self,
        at: &Contact,
        inc: Vec3,
        thr: &mut [f64; 3],
        rng: &mut Rng,
    ) -> Option<(Contact, Vec3)> {
        let fin = self.cylinder(at).finish;
        let n = at.normal;
        let ni = n.dot(inc);
        if ni <= 0.0 {
            return None;
        }
        let through = self.passage(at);
        let p_reflect = if through.is_some() { 0.5 } else { 1.0 };
        if rng.next_f64() < p_reflect {
            // f = I_F(inc -> w) / (pi n.inc); weight f (n.w) / (pdf = 1 / 2 pi) / p.
            let w = uniform_hemisphere(n, rng.next_f64(), rng.next_f64());
            let g = self.terms.shade(&fin, n, inc, w);
            let k = 2.0 * n.dot(w) / ni / p_reflect;
            for (x, a) in thr.iter_mut().zip(fin.albedo) {
                *x *= (g.diffuse * a + g.specular) * k;
            }
            Some((*at, w))
        } else {
            // Lambertian out of the partner: (t / pi) (n_y.w) / (1 / 2 pi) / (1 - p).
            let (y, t) = through?;
            let w = uniform_hemisphere(y.normal, rng.next_f64(), rng.next_f64());
            let k = 2.0 * y.normal.dot(w) / (1.0 - p_reflect);
            for c in 0..3 {
                thr[c] *= t[c] * k;
            }
            Some((y, w))
        }
    }

    /// f(wi, wo) in 1/sr, RGB, of the two-faced cloth over the whole sphere (reflection where
    /// `wi` and `wo` are on the same side, transmission where they are not; the straight path
    /// through the gaps is [`RayTracer::openness`], not in it), per unit area of the cloth:
    /// `samples` eye rays along `-wo` over one period, each followed through up to
    /// `max_bounces` events with the light `wi` sampled at every vertex (by a shadow ray from
    /// the vertex, and on a translucent yarn from its partner). Returns the mean and its
    /// standard error. Deterministic for a seed.
    pub fn render_sphere(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        samples: usize,
        seed: u64,
        max_bounces: usize,
    ) -> ([f64; 3], [f64; 3]) {
        self.sphere_paths(wi, wo, samples, seed, max_bounces, false)
    }

    /// [`RayTracer::render_sphere`] without what the analytic model gives of it: the direct
    /// reflection (first event, light by its shadow ray) off the round sides of the yarns of
    /// the face the eye looks at, when the light is on that side too. The rest of the
    /// two-faced cloth's f: the caps' and flat faces' direct light, what is seen of the other
    /// face through the gaps, every later bounce, and the transmission.
    pub fn render_sphere_rest(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        samples: usize,
        seed: u64,
        max_bounces: usize,
    ) -> ([f64; 3], [f64; 3]) {
        self.sphere_paths(wi, wo, samples, seed, max_bounces, true)
    }

    fn sphere_paths(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        samples: usize,
        seed: u64,
        max_bounces: usize,
        rest: bool,
    ) -> ([f64; 3], [f64; 3]) {
        let sided = |w: UnitVec3| w.above_horizon() || w.below_horizon();
        if !(sided(wi) && sided(wo)) || samples == 0 {
            return ([0.0; 3], [0.0; 3]);
        }
        let d = -wo.get();
        let k = 1.0 / (PI * wi.cos_theta().abs());
        let mut means = vec![[0.0; 3]; BATCHES];
        for (b, mean) in means.iter_mut().enumerate() {
            let m = samples / BATCHES + usize::from(b < samples % BATCHES);
            let mut rng = Rng::stream(seed, (3 << 32) + b as u64);
            for o in self.entry_origins(d, m, &mut rng) {
                let x = self.eye_path(o, d, wi, max_bounces, rest, &mut rng);
                for c in 0..3 {
                    mean[c] += x[c] * k / m.max(1) as f64;
                }
            }
        }
        let mut f = [0.0; 3];
        let mut err = [0.0; 3];
        for c in 0..3 {
            let xs: Vec<f64> = means.iter().map(|m| m[c]).collect();
            (f[c], err[c]) = mean_err(&xs);
        }
        (f, err)
    }

    /// The intensity (pi times radiance, unit light from `wi`) one eye ray from `o` along `d`
    /// carries back: every event up to `max_bounces`, the light sampled at each vertex; with
    /// `rest`, without the direct reflection [`RayTracer::render_sphere_rest`] leaves out.
    fn eye_path(
        &self,
        o: Vec3,
        d: Vec3,
        wi: UnitVec3,
        max_bounces: usize,
        rest: bool,
        rng: &mut Rng,
    ) -> [f64; 3] {
        let mut sum = [0.0; 3];
        let Some(mut at) = self.first_any(o, d, None) else {
            return sum;
        };
        let mut out = -d;
        let mut thr = [1.0; 3];
        let l = wi.get();
        // The face the eye looks at: the front from above.
        let seen = if out.z > 0.0 { Face::Front } else { Face::Back };
        for k in 1..=max_bounces.max(1) {
            let fin = self.cylinder(&at).finish;
            let n = at.normal;
            if n.dot(out) <= 0.0 {
                break;
            }
            let modelled = rest
                && k == 1
                && at.surface == Surface::Side
                && self.cylinder(&at).face == seen
                && (l.z > 0.0) == (out.z > 0.0);
            let s = self.terms.shade(&fin, n, l, out);
            if !modelled && (s.diffuse > 0.0 || s.specular > 0.0) && self.lit(&at, wi) {
                for c in 0..3 {
                    sum[c] += thr[c] * (s.diffuse * fin.albedo[c] + s.specular);
                }
            }
            let through = self.passage(&at);
            if let Some((y, t)) = through {
                let e = y.normal.dot(l);
                if e > 0.0 && self.lit(&y, wi) {
                    for c in 0..3 {
                        sum[c] += thr[c] * t[c] * e;
                    }
                }
            }
            if k == max_bounces.max(1) {
                break;
            }
            // Where the light reaching `at` toward `out` came from: the adjoint of
            // `scatter_once`, reflection at `at` or transmission from the partner.
            let p_reflect = if through.is_some() { 0.5 } else { 1.0 };
            let (from, w) = if rng.next_f64() < p_reflect {
                let w = uniform_hemisphere(n, rng.next_f64(), rng.next_f64());
                let g = self.terms.shade(&fin, n, w, out);
                for (x, a) in thr.iter_mut().zip(fin.albedo) {
                    *x *= 2.0 * (g.diffuse * a + g.specular) / p_reflect;
                }
                (at, w)
            } else {
                let Some((y, t)) = through else { break };
                let w = uniform_hemisphere(y.normal, rng.next_f64(), rng.next_f64());
                let kt = 2.0 * y.normal.dot(w) / (1.0 - p_reflect);
                for c in 0..3 {
                    thr[c] *= t[c] * kt;
                }
                (y, w)
            };
            if thr.iter().all(|&x| x == 0.0) {
                break;
            }
            let Some(next) = self.first_any(from.point, w, Some(from.key)) else {
                break;
            };
            at = next;
            out = -w;
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_fabric::fabric::Fabric;
    use clothbake_fabric::FacetModel;

    /// An open plain weave: threads of radius r at spacing s both ways, axes at height h,
    /// Lewis facets with the given diffuse albedo, specular share and translucency.
    fn open_plain(r: f64, s: f64, h: f64, rho: f64, spec: f64, tau: f64) -> RayTracer {
        let json = format!(
            r#"{{"pattern": [[1,0],[0,1]],
                "warp": {{"radius": {r}, "spacing": {s}, "height": {h},
                  "material": {{"albedo": {rho}, "specular": {spec}, "exponent": 8, "translucency": {tau}}}}},
                "weft": {{"radius": {r}, "spacing": {s}, "height": {h},
                  "material": {{"albedo": {rho}, "specular": {spec}, "exponent": 8, "translucency": {tau}}}}}}}"#
        );
        RayTracer::two_faced(
            &Fabric::from_json_str(&json, "test").unwrap(),
            FacetModel::Lewis,
        )
    }

    fn dir(theta: f64, phi: f64) -> UnitVec3 {
        UnitVec3::from_degrees(theta, phi)
    }

    #[test]
    fn the_openness_at_normal_incidence_is_the_open_area() {
        // Seen straight through, a thread covers its diameter d = 2 r, on the front where it
        // floats and on the back where it passes under: open share (1 - d/s)^2.
        for (r, s, h) in [(0.5, 2.0, 0.0), (0.6, 2.0, 0.3), (0.3, 1.5, 0.1)] {
            let rt = open_plain(r, s, h, 0.5, 0.0, 0.0);
            let want = (1.0 - 2.0 * r / s).powi(2);
            for (w, seed) in [(UnitVec3::Z, 1), (UnitVec3::Z.reverse(), 2)] {
                let n = 40_000;
                let got = rt.openness(w, n, seed);
                let sigma = (want * (1.0 - want) / n as f64).sqrt();
                assert!(
                    (got - want).abs() < 4.0 * sigma,
                    "r {r} s {s} h {h}: openness {got}, closed form {want}"
                );
            }
        }
    }

    #[test]
    fn the_openness_falls_as_the_incidence_grows() {
        let rt = open_plain(0.5, 2.0, 0.0, 0.5, 0.0, 0.0);
        for phi in [0.0, 30.0, 45.0, 90.0] {
            let mut last = 1.0;
            for theta in [0.0, 15.0, 30.0, 45.0, 60.0, 75.0] {
                let o = rt.openness(dir(theta, phi), 20_000, 7);
                assert!(
                    o <= last + 0.005,
                    "phi {phi} theta {theta}: {o} after {last}"
                );
                last = o;
            }
            assert!(last < 0.05, "phi {phi}: still {last} open at 75 degrees");
        }
    }

    #[test]
    fn the_back_of_a_twill_is_the_inverted_twill_mirrored() {
        // Built from the inverted pattern by the front's rules, then mirrored below z = 0.
        let twill = r#"{"pattern": [[1,1,0],[0,1,1],[1,0,1]], "warp": {"radius": 1.5, "spacing": 3.1, "height": 0.4},
                        "weft": {"radius": 1.5, "spacing": 3.1, "height": 0.2}}"#;
        let inverted = twill.replace("[[1,1,0],[0,1,1],[1,0,1]]", "[[0,0,1],[1,0,0],[0,1,0]]");
        let two = RayTracer::two_faced(
            &Fabric::from_json_str(twill, "t").unwrap(),
            FacetModel::Lewis,
        );
        let inv = RayTracer::new(
            &Fabric::from_json_str(&inverted, "i").unwrap(),
            FacetModel::Lewis,
        );
        let back: Vec<_> = two
            .yarns
            .cylinders
            .iter()
            .filter(|c| c.face == Face::Back)
            .collect();
        assert_eq!(back.len(), inv.yarns.cylinders.len());
        for (b, f) in back.iter().zip(&inv.yarns.cylinders) {
            assert_eq!(
                (b.group, b.thread, b.axis, b.extent),
                (f.group, f.thread, f.axis, f.extent)
            );
            assert_eq!(b.height, -f.height);
        }
        assert!(
            two.yarns
                .cylinders
                .iter()
                .filter(|c| c.face == Face::Front)
                .count()
                > 0
        );
        assert!(
            (two.z_bottom + two.z_top).abs() < 1e-3,
            "{} {}",
            two.z_bottom,
            two.z_top
        );
    }

    #[test]
    fn a_partner_is_on_the_surface_and_its_partner_is_the_start() {
        let rt = open_plain(0.6, 2.0, 0.3, 0.5, 0.0, 1.0);
        let mut rng = Rng::new(11);
        let mut seen = [0usize; 2];
        for _ in 0..4000 {
            let w = dir(80.0 * rng.next_f64(), 360.0 * rng.next_f64());
            let w = if rng.next_f64() < 0.5 {
                w
            } else {
                w.mirror_z()
            };
            let d = -w.get();
            let z = if d.z < 0.0 { rt.z_top } else { rt.z_bottom };
            let o = Vec3::new(2.0 * rng.next_f64(), 2.0 * rng.next_f64(), z);
            let Some(c) = rt.first_any(o, d, None) else {
                continue;
            };
            if matches!(c.surface, Surface::CapLo | Surface::CapHi) {
                continue;
            }
            let Some(p) = rt.partner(&c) else { continue };
            seen[usize::from(p.surface == Surface::Cut)] += 1;
            // On the surface: a ray from just outside along -normal enters at the partner.
            let start = p.point + p.normal * 1e-3;
            let h = rt.trace(start, -p.normal, 0.0, 1.0, false, None).unwrap();
            let back = rt.contact(start, -p.normal, &h);
            assert_eq!(back.key, c.key);
            assert!(
                (back.point - p.point).length() < 1e-9,
                "{:?} {:?}",
                back.point,
                p.point
            );
            // An involution.
            let q = rt.partner(&p).unwrap();
            assert!(
                (q.point - c.point).length() < 1e-9,
                "{:?} {:?}",
                q.point,
                c.point
            );
            assert!((q.normal - c.normal).length() < 1e-9);
        }
        assert!(seen[0] > 100 && seen[1] > 100, "{seen:?}");
    }

    #[test]
    fn without_absorption_the_light_is_reflected_transmitted_or_through() {
        // Lambertian facets rho_d = 0.6, translucency 1: t = 0.4, nothing absorbed.
        let rt = open_plain(0.6, 2.0, 0.2, 0.5, 0.0, 1.0);
        for (w, seed) in [
            (dir(0.0, 0.0), 1),
            (dir(50.0, 20.0), 2),
            (dir(30.0, 70.0).mirror_z(), 3),
        ] {
            let s = rt.scatter(w, 8000, seed, 400);
            let total = s.reflected[0] + s.transmitted[0] + s.through;
            let err = s.std_err.0[0] + s.std_err.1[0] + s.std_err.2;
            assert!((total - 1.0).abs() < 4.0 * err + 1e-3, "{w:?}: {s:?}");
            assert!(s.transmitted[0] > 0.1 && s.reflected[0] > 0.1, "{s:?}");
        }
        // Absorbing yarn (tau = 0.5) and Lewis specular lobes keep the sum under 1.
        let rt = open_plain(0.6, 2.0, 0.2, 0.4, 0.3, 0.5);
        let s = rt.scatter(dir(40.0, 10.0), 8000, 4, 400);
        let total = s.reflected[0] + s.transmitted[0] + s.through;
        assert!(total < 1.0 - 0.05, "{s:?}");
    }

    #[test]
    fn eye_paths_and_light_paths_agree_on_reflectance_and_transmittance() {
        // The hemispherical R and T of the light paths against the eye paths' f integrated
        // over wo (wo cosine-distributed on each side): two estimators of the same transport.
        let rt = open_plain(0.6, 2.0, 0.2, 0.4, 0.2, 0.8);
        let wi = dir(35.0, 25.0);
        let s = rt.scatter(wi, 20_000, 5, 64);
        let mut rng = Rng::new(9);
        let n = 20_000;
        let (mut r, mut t) = (Vec::new(), Vec::new());
        for k in 0..n {
            let w = clothbake_bsdf::cosine_sample([rng.next_f64(), rng.next_f64()]);
            let (wo, into) = if k % 2 == 0 {
                (w, &mut r)
            } else {
                (w.mirror_z(), &mut t)
            };
            // pi f cos(theta_o) / (cos / pi) / pi ... the mean of pi f over cosine-drawn wo.
            let (f, _) = rt.render_sphere(wi, wo, BATCHES, k as u64, 64);
            into.push(PI * f[1]);
        }
        let (rm, re) = mean_err(&r);
        let (tm, te) = mean_err(&t);
        assert!(
            (rm - s.reflected[1]).abs() < 4.0 * (re + s.std_err.0[1]),
            "R {rm} +- {re} vs {s:?}"
        );
        assert!(
            (tm - s.transmitted[1]).abs() < 4.0 * (te + s.std_err.1[1]),
            "T {tm} +- {te} vs {s:?}"
        );
    }

    #[test]
    fn what_the_model_gives_is_the_floors_direct_reflection() {
        // The part `render_sphere_rest` leaves out (first event off the round sides of the
        // face seen, light on that side) is, per unit area, what the thesis's cloth over its
        // floor reflects directly: the front's, and the back's through the inverted fabric
        // seen from below. Same rays for both sphere estimates, so their difference has no
        // noise from the later bounces.
        let json = r#"{"pattern": [[1,1,0],[0,1,1],[1,0,1]],
            "warp": {"radius": 0.6, "spacing": 2, "height": 0.2,
              "material": {"albedo": 0.4, "specular": 0.2, "exponent": 8, "translucency": 0.8}},
            "weft": {"radius": 0.5, "spacing": 1.8,
              "material": {"albedo": 0.3, "specular": 0.2, "exponent": 8, "translucency": 0.5}}}"#;
        let fabric = Fabric::from_json_str(json, "t").unwrap();
        let two = RayTracer::two_faced(&fabric, FacetModel::Lewis);
        let back = fabric.back().unwrap();
        for (f, wi, wo) in [
            (&fabric, dir(22.5, 45.0), dir(67.5, 225.0)),
            (&fabric, dir(50.0, 100.0), dir(10.0, 0.0)),
            (&back, dir(67.5, 315.0), dir(22.5, 45.0)),
            (&back, dir(30.0, 0.0), dir(40.0, 180.0)),
        ] {
            let floor = RayTracer::new(f, FacetModel::Lewis);
            let e = floor.render(wi, wo, 200_000, 1);
            let (seen, _) = floor.visible_and_lit(wi, wo, 200_000, 2);
            let want = e.reflection.total()[1] * seen / (PI * wi.z);
            let (wi2, wo2) = if std::ptr::eq(f, &fabric) {
                (wi, wo)
            } else {
                (wi.mirror_z(), wo.mirror_z())
            };
            let full = two.render_sphere(wi2, wo2, 65_536, 7, 16).0[1];
            let rest = two.render_sphere_rest(wi2, wo2, 65_536, 7, 16).0[1];
            assert!(
                (full - rest - want).abs() < 0.015 * want,
                "{wi2:?} {wo2:?}: two-faced direct {} vs floor {want}",
                full - rest
            );
        }
    }

    #[test]
    fn transmission_and_reflection_are_reciprocal() {
        let rt = open_plain(0.6, 2.0, 0.2, 0.4, 0.2, 0.8);
        for (wi, wo) in [
            (dir(20.0, 10.0), dir(50.0, 200.0)),
            (dir(30.0, 40.0), dir(60.0, 100.0).mirror_z()),
            (dir(10.0, 0.0).mirror_z(), dir(45.0, 80.0)),
        ] {
            let (a, ea) = rt.render_sphere(wi, wo, 60_000, 1, 32);
            let (b, eb) = rt.render_sphere(wo, wi, 60_000, 2, 32);
            assert!(a[0] > 0.0);
            assert!(
                (a[0] - b[0]).abs() < 4.0 * (ea[0] + eb[0]),
                "{a:?} +- {ea:?} vs {b:?} +- {eb:?}"
            );
        }
    }
}
