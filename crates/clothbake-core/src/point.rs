//! The one door from a fabric to the point level (`clothbake-point`): the model's micro-geometry
//! ([`Geometry`]) and each thread's material as a [`Period`] a renderer can trace. The ground
//! truth builds its own geometry (`truth::yarns`); the tests below hold the point level against
//! it ray for ray.

use crate::fabric::Fabric;
use crate::facet::FacetModel;
use crate::geometry::Geometry;
use crate::weave::Group;
use clothbake_point::{Along, Facet, Finish, Period, Yarn, Yarns};

/// The point level's name for a facet model.
pub fn facet(model: FacetModel) -> Facet {
    match model {
        FacetModel::Huo => Facet::Huo,
        FacetModel::Lewis => Facet::Lewis,
    }
}

/// The most yarn segments a spatial table carries (`Metadata::yarns`), so that its header stays
/// well under the container's 16 MiB: larger periods' tables show their crossing cells.
pub const TABLE_YARNS: usize = 4096;
const _: () = assert!(TABLE_YARNS <= clothbake_point::MAX_YARNS);

/// The period of a validated fabric, its segments shaded with `model`'s facet terms: one
/// finish per distinct thread material; `None` for a period of more than
/// [`clothbake_point::MAX_YARNS`] segments (no point level: the crossing cells are the finest).
pub fn period(fabric: &Fabric, model: FacetModel) -> Option<Period> {
    let geo = Geometry::new(fabric);
    if geo.segments.len() > clothbake_point::MAX_YARNS {
        return None;
    }
    let mut finishes: Vec<Finish> = Vec::new();
    let mut yarns = Vec::with_capacity(geo.segments.len());
    for s in &geo.segments {
        let m = fabric.thread_material(s.group, s.thread);
        let finish = Finish {
            albedo: m.albedo,
            specular: m.specular,
            exponent: m.exponent,
        };
        let k = match finishes.iter().position(|f| *f == finish) {
            Some(k) => k,
            None => {
                finishes.push(finish);
                finishes.len() - 1
            }
        };
        yarns.push(Yarn {
            along: match s.group {
                Group::Warp => Along::Y,
                Group::Weft => Along::X,
            },
            across: s.axis,
            height: s.height,
            radius: s.radius,
            extent: s.extent,
            finish: k as u32,
        });
    }
    Some(
        Period::new(geo.period, yarns, finishes, facet(model))
            .expect("a validated fabric's geometry is a valid period"),
    )
}

/// [`period`], sorted for tracing.
pub fn yarns(fabric: &Fabric, model: FacetModel) -> Option<Yarns> {
    period(fabric, model).map(Yarns::new)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facet::Facet as _;
    use crate::rng::Rng;
    use crate::vec3::UnitVec3;
    use clothbake_truth::RayTracer;
    use std::path::Path;

    fn shipped() -> Vec<(String, Fabric)> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables");
        let mut out = Vec::new();
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_file() {
                out.push((
                    p.file_name().unwrap().to_string_lossy().into_owned(),
                    Fabric::from_path(&p).unwrap(),
                ));
            }
        }
        assert!(out.len() >= 9, "{} shipped fabrics", out.len());
        out
    }

    /// A random direction above the horizon, a tenth of them within 5 degrees of it.
    fn direction(rng: &mut Rng) -> UnitVec3 {
        let theta = if rng.next_f64() < 0.1 {
            85.0 + 4.9 * rng.next_f64()
        } else {
            85.0 * rng.next_f64()
        };
        UnitVec3::from_degrees(theta, 360.0 * rng.next_f64())
    }

    #[test]
    fn every_look_agrees_with_the_ground_truth_ray_for_ray() {
        // The same eye ray through the point level and through the truth's independent tracer:
        // the same yarn, point and normal, the same shadowing, the same f_r.
        for facet_model in [FacetModel::Huo, FacetModel::Lewis] {
            for (name, fabric) in shipped() {
                let y = yarns(&fabric, facet_model).unwrap();
                let rt = RayTracer::new(&fabric, facet_model);
                let mut rng = Rng::new(7);
                let (mut hits, mut shadowed) = (0, 0);
                for k in 0..3000 {
                    let (u, v) = (rng.next_f64(), rng.next_f64());
                    let (wi, wo) = (direction(&mut rng), direction(&mut rng));
                    let (o, d) = y.eye_ray(u, v, wo).unwrap();
                    // The truth starts its rays on its own top plane: move along the same line.
                    let o = o + d * ((o.z - rt.top()) / -d.z);
                    assert_eq!(d, -wo.get());
                    let look = y.look(u, v, wi, wo);
                    let truth = rt.shade(o, wi, wo);
                    // The truth's own point lookup (its own reference plane) says the same.
                    match rt.look_at(u, v, wi, wo) {
                        None => assert_eq!(look.coverage, 0.0),
                        Some(f) => {
                            for (a, b) in f.iter().zip(look.f) {
                                assert!((a - b).abs() <= 1e-9 * a.max(1e-3), "{f:?} {look:?}");
                            }
                        }
                    }
                    let what = format!("{name} {facet_model:?} ray {k}: {look:?} {truth:?}");
                    match truth {
                        None => assert_eq!(look.coverage, 0.0, "{what}"),
                        Some((s, c)) => {
                            assert_eq!(look.coverage, 1.0, "{what}");
                            let sight = y.sight(u, v, wo).unwrap();
                            assert!((sight.point - c.point).length() < 1e-9, "{what}");
                            assert!((sight.normal - c.normal).length() < 1e-9, "{what}");
                            let albedo = rt.cylinder(&c).finish.albedo;
                            let k_f = 1.0 / (std::f64::consts::PI * wi.cos_theta());
                            for (got, a) in look.f.iter().zip(albedo) {
                                let want = (s.diffuse * a + s.specular) * k_f;
                                let tol = 1e-9 * want.max(1e-3);
                                assert!((got - want).abs() <= tol, "{what}");
                            }
                            hits += 1;
                            shadowed += usize::from(s.diffuse == 0.0);
                        }
                    }
                }
                assert!(hits > 1000, "{name}: {hits} hits");
                if name != "parallel.json" {
                    assert!(shadowed > 30, "{name}: only {shadowed} shadowed hits");
                }
            }
        }
    }

    /// The point level's period mean over an n x n grid of points (midpoints of a jittered
    /// grid): the coverage-weighted mean f_r, the mean coverage, and the standard error of the
    /// mean f_r's channel 0 from 16 interleaved sub-grids.
    fn period_mean(y: &Yarns, wi: UnitVec3, wo: UnitVec3, n: usize) -> ([f64; 3], f64, f64) {
        let mut rng = Rng::new(11);
        let (mut num, mut den) = ([0.0; 3], 0.0);
        let mut parts = [(0.0, 0.0); 16];
        for i in 0..n {
            for j in 0..n {
                let u = (i as f64 + rng.next_f64()) / n as f64;
                let v = (j as f64 + rng.next_f64()) / n as f64;
                let l = y.look(u, v, wi, wo);
                for (n, f) in num.iter_mut().zip(l.f) {
                    *n += l.coverage * f;
                }
                den += l.coverage;
                let p = &mut parts[(i % 4) * 4 + j % 4];
                p.0 += l.coverage * l.f[0];
                p.1 += l.coverage;
            }
        }
        let mean = num.map(|x| x / den);
        let m: Vec<f64> = parts.iter().map(|p| p.0 / p.1).collect();
        let var = m.iter().map(|x| (x - mean[0]).powi(2)).sum::<f64>() / (15.0 * 16.0);
        (mean, den / (n * n) as f64, var.sqrt())
    }

    const PAIRS: [(f64, f64, f64, f64); 6] = [
        (0.0, 0.0, 30.0, 180.0),
        (30.0, 0.0, 30.0, 180.0),
        (60.0, 45.0, 20.0, 200.0),
        (45.0, 90.0, 60.0, 270.0),
        (70.0, 10.0, 50.0, 100.0),
        (20.0, 300.0, 75.0, 30.0),
    ];

    #[test]
    fn the_period_mean_of_the_points_is_the_closed_form_on_parallel_cylinders() {
        // Parallel cylinders are where the thesis's construction is exact (docs/results/validation.md:
        // the model within 0.01% of the ray tracer): the point level's coverage-weighted period
        // mean must be the analytic average, and its mean coverage the model's C(wo).
        let f = Fabric::from_path(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/parallel.json"),
        )
        .unwrap();
        let y = yarns(&f, FacetModel::Huo).unwrap();
        let b = crate::AnalyticBsdf::new(crate::AnalyticModel::new(&f, FacetModel::Huo), None);
        for (ti, pi, to, po) in PAIRS {
            let (wi, wo) = (
                UnitVec3::from_degrees(ti, pi),
                UnitVec3::from_degrees(to, po),
            );
            let (mean, cov, se) = period_mean(&y, wi, wo, 400);
            let want = clothbake_bsdf::Bsdf::f(&b, wi, wo);
            let c = b.model().coverage(wo);
            for k in 0..3 {
                let tol = 4.0 * se + 2e-3 * want[k];
                assert!(
                    (mean[k] - want[k]).abs() < tol,
                    "{ti} {to}: {mean:?} {want:?} {se}"
                );
            }
            assert!((cov - c).abs() < 2e-3, "{ti} {to}: coverage {cov} vs {c}");
        }
    }

    #[test]
    fn the_period_mean_of_the_points_is_the_ground_truths_average_on_woven_cloth() {
        // The invariant that ties the levels together: the coverage-weighted mean of f over the
        // period is the averaged BRDF. Held against the truth's own estimate (its own rays,
        // its own sampling), within the two estimates' errors.
        for name in ["twill.json", "satin5.json", "gingham.wif", "plain.json"] {
            let f = Fabric::from_path(
                &Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("../../tables")
                    .join(name),
            )
            .unwrap();
            let y = yarns(&f, FacetModel::Huo).unwrap();
            let rt = RayTracer::new(&f, FacetModel::Huo);
            for (k, (ti, pi, to, po)) in PAIRS.into_iter().enumerate() {
                let (wi, wo) = (
                    UnitVec3::from_degrees(ti, pi),
                    UnitVec3::from_degrees(to, po),
                );
                let (mean, cov, se) = period_mean(&y, wi, wo, 300);
                let e = rt.render(wi, wo, 1 << 18, 40 + k as u64);
                let k_f = 1.0 / (std::f64::consts::PI * wi.cos_theta());
                let want = e.reflection.total()[0] * k_f;
                let tol = 4.0 * (se * se + (e.std_err[0] * k_f).powi(2)).sqrt() + 1e-4 * want;
                assert!(
                    (mean[0] - want).abs() < tol,
                    "{name} {k}: {} vs {want} (tol {tol})",
                    mean[0]
                );
                let hits = e.yarn_hits as f64 / e.rays as f64;
                assert!((cov - hits).abs() < 0.01, "{name} {k}: {cov} vs {hits}");
            }
        }
    }

    #[test]
    fn a_footprint_of_the_whole_period_integrates_to_the_period_mean() {
        // look_within over one period, 8 x 8 jittered points, against the dense period mean:
        // within the sampling error of 64 points (the estimate's spread over many centres).
        let f = Fabric::from_path(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/twill.json"),
        )
        .unwrap();
        let y = yarns(&f, FacetModel::Huo).unwrap();
        let (wi, wo) = (
            UnitVec3::from_degrees(40.0, 30.0),
            UnitVec3::from_degrees(35.0, 200.0),
        );
        let (mean, cov, _) = period_mean(&y, wi, wo, 300);
        let mut rng = Rng::new(5);
        let (mut fc, mut c) = (0.0, 0.0);
        let n = 400;
        for _ in 0..n {
            let l = y.look_within(rng.next_f64(), rng.next_f64(), 1.0, 8, wi, wo);
            assert!((0.0..=1.0).contains(&l.coverage) && (l.coverage * 64.0).fract() == 0.0);
            fc += l.f[0] * l.coverage;
            c += l.coverage;
        }
        assert!(
            ((fc / c) - mean[0]).abs() < 0.01 * mean[0],
            "{} vs {}",
            fc / c,
            mean[0]
        );
        assert!(
            (c / n as f64 - cov).abs() < 0.01,
            "{} vs {cov}",
            c / n as f64
        );
        // One point, or none wide, is the look itself.
        for (w, k) in [(0.3, 1), (0.0, 8)] {
            assert_eq!(
                y.look_within(0.2, 0.7, w, k, wi, wo),
                y.look(0.2, 0.7, wi, wo)
            );
        }
    }

    #[test]
    fn a_period_of_too_many_segments_has_no_point_level() {
        // A 512 x 512 plain weave: 2^18 floats, more than MAX_YARNS.
        let n = 512;
        let rows: Vec<String> = (0..n)
            .map(|j| {
                let r: Vec<&str> = (0..n)
                    .map(|i| if (i + j) % 2 == 0 { "1" } else { "0" })
                    .collect();
                format!("[{}]", r.join(","))
            })
            .collect();
        let json = format!(
            r#"{{"pattern": [{}], "warp": {{"radius": 1.5, "spacing": 3.1}}, "weft": {{"radius": 1.5, "spacing": 3.1}}}}"#,
            rows.join(",")
        );
        let f = Fabric::from_json_str(&json, "big").unwrap();
        assert!(period(&f, FacetModel::Huo).is_none());
        assert!(yarns(&f, FacetModel::Huo).is_none());
        // A 32 x 32 one is traced, and has more segments than a table carries.
        let small = Fabric::from_path(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/plain.json"),
        )
        .unwrap();
        assert_eq!(period(&small, FacetModel::Huo).unwrap().yarns().len(), 4);
    }

    #[test]
    fn the_facet_terms_are_the_models() {
        let mut rng = Rng::new(3);
        for model in [FacetModel::Huo, FacetModel::Lewis] {
            for (_, fabric) in shipped() {
                let m = fabric.thread_material(Group::Warp, 0);
                let f = Finish {
                    albedo: m.albedo,
                    specular: m.specular,
                    exponent: m.exponent,
                };
                for _ in 0..200 {
                    let [n, l, e] = [0; 3].map(|_| {
                        UnitVec3::from_degrees(180.0 * rng.next_f64(), 360.0 * rng.next_f64()).get()
                    });
                    let want = model.intensity(&m, n, l, e);
                    let got = facet(model).intensity(&f, n, l, e);
                    for k in 0..3 {
                        let w = want.diffuse * m.albedo[k] + want.specular;
                        assert!((got[k] - w).abs() <= 1e-12 * w.max(1.0), "{got:?} {w}");
                    }
                }
            }
        }
    }
}
