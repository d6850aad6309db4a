//! The model's pieces held against the ground truth's independent ones: the facet terms, the
//! placement of the yarns and the second bounce. Each is a cross-check, not a definition: a
//! disagreement is a bug in one of the two. The truth (clothbake-truth) is only a
//! dev-dependency of the model, so these live here, outside both crates' code. The facet terms
//! are the point level's too (clothbake_point::facet holds the one formula).

use clothbake_bsdf::rng::Rng;
use clothbake_core::facet::{Facet, FacetModel};
use clothbake_core::{AnalyticModel, Fabric, Geometry, Kernel, SecondaryOptions, UnitVec3, Vec3};
use clothbake_truth::yarns::Yarns;
use clothbake_truth::{Description, Finish, PathOptions, RayTracer, Terms};
use std::path::Path;

fn finish(specular: f64, exponent: f64) -> Finish {
    Finish {
        albedo: [0.4; 3],
        specular,
        exponent,
        transmittance: [0.0; 3],
    }
}

fn dir(t: f64, p: f64) -> Vec3 {
    UnitVec3::from_degrees(t, p).get()
}

fn pf() -> Fabric {
    Fabric::from_json_str(
        r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 2,
            "material": {"albedo": 0.4, "specular": 0.7, "exponent": 4}},
            "weft": {"radius": 1, "spacing": 2}}"#,
        "pf",
    )
    .unwrap()
}

/// Cross-check, not the definition: the truth's terms against the model's `facet` module at
/// random vectors. A disagreement is a bug in one of the two.
#[test]
fn agree_with_the_models_facets() {
    let mut rng = Rng::new(11);
    let mut both = 0;
    for k in 0..4000 {
        let exponent = [10.0, 9.0, 7.5, 0.0, 1.0][k % 5];
        let f = finish(0.3 + 0.5 * rng.next_f64(), exponent);
        let m = clothbake_core::yarn::Material {
            albedo: f.albedo,
            specular: f.specular,
            exponent,
            translucency: 0.0,
        };
        let mut d = || dir(100.0 * rng.next_f64(), 360.0 * rng.next_f64());
        let (n, l, e) = (d(), d(), d());
        for (mine, model) in [
            (Terms::Huo, FacetModel::Huo),
            (Terms::Lewis, FacetModel::Lewis),
        ] {
            let a = mine.shade(&f, n, l, e);
            let b = model.intensity(&m, n, l, e);
            assert!(
                (a.diffuse - b.diffuse).abs() < 1e-14,
                "{mine:?} {a:?} vs {b:?}"
            );
            assert!(
                (a.specular - b.specular).abs() < 1e-12 * (1.0 + b.specular),
                "{mine:?} {n:?} {l:?} {e:?}: {a:?} vs {b:?}"
            );
            // The point level's terms are the same formula (clothbake_point::facet): the truth's
            // copy holds them too, per channel.
            let finish = clothbake_point::Finish {
                albedo: f.albedo,
                specular: f.specular,
                exponent,
            };
            let p = clothbake_core::facet::point_facet(model).intensity(&finish, n, l, e);
            for (k, got) in p.iter().enumerate() {
                let want = a.diffuse * f.albedo[k] + a.specular;
                assert!(
                    (got - want).abs() < 1e-12 * (1.0 + want),
                    "{mine:?} point level: {p:?} vs {a:?}"
                );
            }
            both += usize::from(a.specular > 0.0);
        }
    }
    assert!(both > 1000, "{both}");
}

/// Cross-check, not the definition: the truth's independent placement against the model's
/// `Geometry`, for every shipped fabric (JSON and WIF). A disagreement is a bug in one of
/// the two.
#[test]
fn agrees_with_the_models_geometry_on_every_shipped_fabric() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if !p.is_file() {
            continue;
        }
        let f = Fabric::from_path(&p).unwrap();
        let mine = Yarns::build(&Description::of(&f));
        let model = Geometry::new(&f);
        assert_eq!(mine.period, model.period, "{}", p.display());
        assert_eq!(
            mine.cylinders.len(),
            model.segments.len(),
            "{}",
            p.display()
        );
        for (c, s) in mine.cylinders.iter().zip(&model.segments) {
            let m = f.thread_material(s.group, s.thread);
            let same = c.group == s.group
                && c.thread == s.thread
                && c.axis == s.axis
                && c.radius == s.radius
                && c.height == s.height
                && match (c.extent, s.extent) {
                    (None, None) => true,
                    (Some(a), Some(b)) => (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12,
                    _ => false,
                }
                && c.finish.albedo == m.albedo
                && c.finish.specular == m.specular
                && c.finish.exponent == m.exponent;
            assert!(same, "{}: {c:?} vs {s:?}", p.display());
        }
        n += 1;
    }
    assert!(n >= 9, "only {n} shipped fabrics found");
}

#[test]
fn second_order_matches_the_analytic_secondary_for_both_kernels() {
    let f = pf();
    let rt = RayTracer::new(&f, FacetModel::Huo);
    let m = AnalyticModel::new(&f, FacetModel::Huo);
    for kernel in [Kernel::Radiometric, Kernel::Thesis] {
        for (wi, wo) in [
            (
                UnitVec3::from_degrees(40.0, 0.0),
                UnitVec3::from_degrees(35.0, 180.0),
            ),
            (
                UnitVec3::from_degrees(20.0, 60.0),
                UnitVec3::from_degrees(50.0, 10.0),
            ),
        ] {
            let opts = SecondaryOptions {
                kernel,
                ..Default::default()
            };
            let a = m
                .intensity_with(wi, wo, Some(&opts))
                .secondary
                .unwrap()
                .total()[0];
            let p = rt.render_paths(
                wi,
                wo,
                200_000,
                5,
                PathOptions {
                    max_bounces: 2,
                    kernel,
                    roulette_from: 9,
                    first_order: 1,
                },
            );
            let (b, e) = (p.orders[1][0], p.std_err[1][0]);
            eprintln!("{kernel:?}: analytic {a} vs path {b} ± {e}");
            assert!(
                (a - b).abs() < 4.0 * e + 0.01 * a,
                "{kernel:?}: analytic {a} vs path {b} ± {e}"
            );
        }
    }
}
