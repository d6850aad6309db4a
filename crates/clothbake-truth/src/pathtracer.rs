//! Ground truth beyond the thesis: a path tracer with any number of bounces over the explicit
//! micro-geometry, reporting the energy of each bounce order (thesis ch. 6 leaves the
//! convergence of inter-reflection open).
//!
//! Primary rays are those of [`RayTracer::render`] (uniform over one period's projected area,
//! floor hits and, with [`Caps::Excluded`], cap hits not counted). At every path vertex the
//! directional light is added by a shadow ray (next-event estimation), then a direction is drawn
//! uniformly over the hemisphere of the normal and traced on; the floor, excluded caps and the sky
//! absorb. In thesis intensities (pi times radiance) the throughput of a transition toward `w`
//! is `I_F(w -> out) / (pi pdf) = 2 I_F(w -> out)` (the facet intensity, bounded, so the
//! estimator has finite variance). With [`Kernel::Thesis`] the transition at the visible point
//! carries the thesis's extra factor pi (N . w) (see `clothbake_core::interreflection`), and only the
//! first two orders are meaningful. Russian roulette from order `roulette_from` on.
//!
//! Besides the orders it reports their sum from the second on, estimated jointly
//! ([`PathEstimate::multiple`], what `--bounces all` adds to the analytic direct term, see
//! `clothbake_bake::transport`), and I_2 split by the yarn the light met first: parallel to the visible
//! segment (same group) or perpendicular (the crossing group). `first_order: 2` skips the
//! shadow rays of the direct reflection when another method supplies it.

use super::estimate::{batch_ratio, BATCHES};
use super::intersect::Surface;
use super::raytracer::{Caps, RayTracer};
use clothbake_bsdf::rng::Rng;
use clothbake_bsdf::vec3::{UnitVec3, Vec3};
use clothbake_fabric::{Kernel, Secondary};
use std::f64::consts::PI;

/// Path-tracing options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathOptions {
    /// Highest bounce order estimated (1 = direct only).
    pub max_bounces: usize,
    /// Weight of the transition at the visible point (affects orders >= 2).
    pub kernel: Kernel,
    /// First order at which Russian roulette may end a path.
    pub roulette_from: usize,
    /// First order whose light is gathered (orders below it report zero): 2 leaves out the
    /// direct reflection when another method supplies it and saves its shadow rays.
    pub first_order: usize,
}

impl PathOptions {
    /// The brute-force reference of the full-transport validation: 64 bounces, radiometric
    /// kernel, no Russian roulette (every order gathered).
    pub fn brute_force() -> PathOptions {
        PathOptions {
            max_bounces: 64,
            kernel: Kernel::Radiometric,
            roulette_from: 65,
            first_order: 1,
        }
    }
}

impl Default for PathOptions {
    fn default() -> Self {
        PathOptions {
            max_bounces: 8,
            kernel: Kernel::Radiometric,
            roulette_from: 4,
            first_order: 1,
        }
    }
}

/// Per-order estimates of a path-traced direction pair.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PathEstimate {
    /// I_k for k = 1..=max_bounces (index 0 is the direct reflection), RGB.
    pub orders: Vec<[f64; 3]>,
    /// Standard error of each I_k, RGB.
    pub std_err: Vec<[f64; 3]>,
    /// I_2 split into I_ss, I_sd, I_ds, I_dd.
    pub secondary: Secondary,
    /// I_2 split by the yarn the light met first (the first bounce seen from the eye's side):
    /// `[parallel, perpendicular]` to the visible segment (same group, or the crossing group).
    pub i2_split: [[f64; 3]; 2],
    /// Standard errors of `i2_split`.
    pub i2_split_err: [[f64; 3]; 2],
    /// The sum of every order from 2 to `max_bounces` (the multiple-bounce part), estimated
    /// jointly, so that its standard error accounts for the orders' correlation.
    pub multiple: [f64; 3],
    /// Standard error of `multiple`.
    pub multiple_err: [f64; 3],
    /// Primary rays that hit (counted) yarn.
    pub yarn_hits: usize,
    /// Primary rays traced.
    pub rays: usize,
}

#[derive(Clone, Debug, Default)]
struct Acc {
    hits: u64,
    rays: u64,
    orders: Vec<[f64; 3]>,
    split: [[f64; 3]; 4],
    pp: [[f64; 3]; 2],
    multi: [f64; 3],
}

/// A direction uniform over the hemisphere around `n`.
pub(crate) fn uniform_hemisphere(n: Vec3, u1: f64, u2: f64) -> Vec3 {
    let z = u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u2;
    // Orthonormal basis around n.
    let a = if n.x.abs() > 0.9 {
        Vec3::new(0.0, 1.0, 0.0)
    } else {
        Vec3::new(1.0, 0.0, 0.0)
    };
    let t = UnitVec3::new(a.cross(n)).expect("non-parallel").get();
    let b = n.cross(t);
    t * (r * phi.cos()) + b * (r * phi.sin()) + n * z
}

impl RayTracer {
    /// Path-traces `samples` primary rays for the pair (`wi`, `wo`) and estimates the intensity
    /// of every bounce order up to `opts.max_bounces`. Deterministic for a seed.
    pub fn render_paths(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        samples: usize,
        seed: u64,
        opts: PathOptions,
    ) -> PathEstimate {
        let k_max = opts.max_bounces.max(1);
        if !(wi.above_horizon() && wo.above_horizon()) {
            return PathEstimate {
                orders: vec![[0.0; 3]; k_max],
                std_err: vec![[0.0; 3]; k_max],
                ..Default::default()
            };
        }
        let mut accs = vec![
            Acc {
                orders: vec![[0.0; 3]; k_max],
                ..Default::default()
            };
            BATCHES
        ];
        for (b, acc) in accs.iter_mut().enumerate() {
            let m = samples / BATCHES + usize::from(b < samples % BATCHES);
            let mut rng = Rng::stream(seed, (1 << 32) + b as u64);
            let origins: Vec<Vec3> = self.origins(m, &mut rng).collect();
            for o in origins {
                acc.rays += 1;
                self.path(o, wi, wo, k_max, opts, &mut rng, acc);
            }
        }
        summarise(&accs, k_max)
    }

    /// f_r at the point (u, v) of the reference plane with every bounce up to
    /// `opts.max_bounces`: one path from the eye ray that crosses the plane there toward `wo`
    /// (as [`RayTracer::render_paths`] traces them: light sampled at each bounce, the path
    /// continued uniformly over the hemisphere), so one unbiased, noisy sample. `None` where
    /// the eye ray shows a gap or a direction is at or below the horizon. With one bounce it is
    /// [`RayTracer::look_at`].
    pub fn look_paths_at(
        &self,
        u: f64,
        v: f64,
        wi: UnitVec3,
        wo: UnitVec3,
        opts: PathOptions,
        rng: &mut Rng,
    ) -> Option<[f64; 3]> {
        if !(wi.above_horizon() && wo.above_horizon() && u.is_finite() && v.is_finite()) {
            return None;
        }
        let k_max = opts.max_bounces.max(1);
        let mut acc = Acc {
            orders: vec![[0.0; 3]; k_max],
            ..Default::default()
        };
        self.path(
            self.eye_origin(u, v, wo),
            wi,
            wo,
            k_max,
            opts,
            rng,
            &mut acc,
        );
        if acc.hits == 0 {
            return None;
        }
        let k = 1.0 / (PI * wi.cos_theta());
        Some(std::array::from_fn(|c| {
            acc.orders.iter().map(|o| o[c]).sum::<f64>() * k
        }))
    }

    #[allow(clippy::too_many_arguments)]
    fn path(
        &self,
        o: Vec3,
        wi: UnitVec3,
        wo: UnitVec3,
        k_max: usize,
        opts: PathOptions,
        rng: &mut Rng,
        acc: &mut Acc,
    ) {
        let d = -wo.get();
        let Some(mut at) = self.first_contact(o, d) else {
            return;
        };
        acc.hits += 1;
        let mut out = wo.get();
        let mut thr = [1.0; 3];
        let mut first: ([f64; 3], f64) = ([0.0; 3], 0.0);
        let visible = self.cylinder(&at).group;
        for k in 1..=k_max {
            let n = at.normal;
            let cyl = self.cylinder(&at);
            let mat = cyl.finish;
            // Next-event estimation toward the light.
            let f = if k >= opts.first_order {
                self.terms.shade(&mat, n, wi.get(), out)
            } else {
                Default::default()
            };
            if (f.diffuse > 0.0 || f.specular > 0.0) && self.lit(&at, wi) {
                let fd: [f64; 3] = std::array::from_fn(|c| f.diffuse * mat.albedo[c]);
                for c in 0..3 {
                    let x = thr[c] * (fd[c] + f.specular);
                    acc.orders[k - 1][c] += x;
                    if k >= 2 {
                        acc.multi[c] += x;
                    }
                }
                if k == 2 {
                    let side = usize::from(cyl.group != visible);
                    for c in 0..3 {
                        acc.pp[side][c] += thr[c] * (fd[c] + f.specular);
                    }
                    let (d0, s0) = first;
                    for c in 0..3 {
                        acc.split[0][c] += s0 * f.specular;
                        acc.split[1][c] += d0[c] * f.specular;
                        acc.split[2][c] += s0 * fd[c];
                        acc.split[3][c] += d0[c] * fd[c];
                    }
                }
            }
            if k == k_max {
                break;
            }
            // Continue the path: uniform over the hemisphere, weight 2 I_F (thesis units).
            let w = uniform_hemisphere(n, rng.next_f64(), rng.next_f64());
            let g = self.terms.shade(&mat, n, w, out);
            let mut tw = 2.0;
            if k == 1 && opts.kernel == Kernel::Thesis {
                tw *= PI * n.dot(w);
            }
            let gd: [f64; 3] = std::array::from_fn(|c| g.diffuse * mat.albedo[c] * tw);
            if k == 1 {
                first = (gd, g.specular * tw);
            }
            for c in 0..3 {
                thr[c] *= gd[c] + g.specular * tw;
            }
            if k + 1 >= opts.roulette_from {
                let p = thr.iter().cloned().fold(0.0, f64::max).clamp(0.05, 1.0);
                if rng.next_f64() >= p {
                    break;
                }
                thr = thr.map(|x| x / p);
            }
            if thr.iter().all(|&x| x == 0.0) {
                break;
            }
            let pos = at.point;
            let t_max = self.t_out(pos, w);
            let Some(h) = self.trace(pos, w, 0.0, t_max, false, Some(at.key)) else {
                break;
            };
            if self.caps == Caps::Excluded && h.surface != Surface::Side {
                break;
            }
            at = self.contact(pos, w, &h);
            out = -w;
        }
    }
}

fn summarise(accs: &[Acc], k_max: usize) -> PathEstimate {
    let hits: u64 = accs.iter().map(|a| a.hits).sum();
    let mut est = PathEstimate {
        orders: vec![[0.0; 3]; k_max],
        std_err: vec![[0.0; 3]; k_max],
        yarn_hits: hits as usize,
        rays: accs.iter().map(|a| a.rays).sum::<u64>() as usize,
        ..Default::default()
    };
    if hits == 0 {
        return est;
    }
    let ratio = |f: &dyn Fn(&Acc) -> f64| -> (f64, f64) {
        let batches: Vec<(f64, u64, u64)> = accs.iter().map(|a| (f(a), a.hits, a.rays)).collect();
        batch_ratio(&batches)
    };
    for k in 0..k_max {
        for c in 0..3 {
            let (m, e) = ratio(&|a: &Acc| a.orders[k][c]);
            est.orders[k][c] = m;
            est.std_err[k][c] = e;
        }
    }
    for c in 0..3 {
        (est.multiple[c], est.multiple_err[c]) = ratio(&|a: &Acc| a.multi[c]);
        for side in 0..2 {
            (est.i2_split[side][c], est.i2_split_err[side][c]) = ratio(&|a: &Acc| a.pp[side][c]);
        }
        est.secondary.ss[c] = ratio(&|a: &Acc| a.split[0][c]).0;
        est.secondary.sd[c] = ratio(&|a: &Acc| a.split[1][c]).0;
        est.secondary.ds[c] = ratio(&|a: &Acc| a.split[2][c]).0;
        est.secondary.dd[c] = ratio(&|a: &Acc| a.split[3][c]).0;
    }
    est
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_fabric::fabric::Fabric;
    use clothbake_fabric::FacetModel;

    fn pf() -> Fabric {
        Fabric::from_json_str(
            r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 2,
                "material": {"albedo": 0.4, "specular": 0.7, "exponent": 4}},
                "weft": {"radius": 1, "spacing": 2}}"#,
            "pf",
        )
        .unwrap()
    }

    #[test]
    fn a_points_path_of_one_bounce_is_its_look_and_more_bounces_add_light() {
        let f = Fabric::from_path(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/twill.json"),
        )
        .unwrap();
        let rt = RayTracer::new(&f, FacetModel::Huo);
        let (wi, wo) = (
            UnitVec3::from_degrees(40.0, 20.0),
            UnitVec3::from_degrees(30.0, 200.0),
        );
        let one = PathOptions {
            max_bounces: 1,
            ..PathOptions::default()
        };
        let mut rng = Rng::new(3);
        let (mut direct, mut all) = (0.0, 0.0);
        for k in 0..4000 {
            let (u, v) = (k as f64 * 0.618_034 % 1.0, k as f64 * 0.414_214 % 1.0);
            let look = rt.look_at(u, v, wi, wo);
            assert_eq!(rt.look_paths_at(u, v, wi, wo, one, &mut rng), look);
            direct += look.map_or(0.0, |f| f[0]);
            all += rt
                .look_paths_at(u, v, wi, wo, PathOptions::default(), &mut rng)
                .map_or(0.0, |f| f[0]);
        }
        // The later orders add light (albedo 0.4: some percent), not more than the direct.
        assert!(
            all > 1.01 * direct && all < 2.0 * direct,
            "{all} vs {direct}"
        );
    }

    #[test]
    fn first_order_is_the_direct_render() {
        let rt = RayTracer::new(&pf(), FacetModel::Huo);
        let (wi, wo) = (
            UnitVec3::from_degrees(40.0, 10.0),
            UnitVec3::from_degrees(30.0, 200.0),
        );
        let p = rt.render_paths(wi, wo, 20_000, 3, PathOptions::default());
        let d = rt.render(wi, wo, 20_000, 3);
        let (a, b) = (p.orders[0][0], d.reflection.total()[0]);
        assert!(
            (a - b).abs() < 4.0 * (p.std_err[0][0] + d.std_err[0]),
            "{a} vs {b}"
        );
    }
}
