//! Quick look: analytic vs ray-traced on a few directions of one table.
//! `cargo run --release -p clothbake-tests --example compare -- tables/twill.json 20 20000`
use clothbake_core::{directions, Fabric, FacetModel};
use clothbake_tests::validate;
use std::path::Path;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let f = Fabric::from_path(Path::new(&a[1])).unwrap();
    let n: usize = a.get(2).map_or(20, |s| s.parse().unwrap());
    let s: usize = a.get(3).map_or(20000, |s| s.parse().unwrap());
    let pairs = if a.get(4).is_some_and(|m| m == "axes") {
        let mut v = Vec::new();
        for t in [20.0, 40.0, 60.0, 70.0] {
            for p in [0.0, 45.0, 90.0] {
                let d = clothbake_core::UnitVec3::from_degrees(t, p);
                v.push((clothbake_core::UnitVec3::Z, d));
                v.push((d, clothbake_core::UnitVec3::Z));
            }
        }
        v
    } else if a.get(4).is_some_and(|m| m == "ring") {
        let l = clothbake_core::UnitVec3::from_degrees(60.0, 0.0);
        [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0]
            .iter()
            .map(|&p| (l, clothbake_core::UnitVec3::from_degrees(60.0, p)))
            .collect()
    } else {
        directions::direction_set(n, 70.0)
    };
    let nb = if std::env::var("ROW").is_ok() {
        clothbake_core::Variant::Thesis
    } else {
        clothbake_core::Variant::Refined
    };
    let r = validate::compare_with(
        &f,
        FacetModel::Huo,
        nb,
        if std::env::var("CAPS").is_ok() {
            clothbake_truth::Caps::Shaded
        } else {
            clothbake_truth::Caps::Excluded
        },
        &pairs,
        s,
        1,
    );
    for c in &r.rows {
        let (ti, pi) = c.pair.0.to_spherical();
        let (to, po) = c.pair.1.to_spherical();
        println!(
            "wi ({:5.1},{:6.1}) wo ({:5.1},{:6.1})  analytic {:.4}  traced {:.4} ± {:.4}  rel {:+.3}",
            ti.to_degrees(), pi.to_degrees(), to.to_degrees(), po.to_degrees(),
            c.analytic, c.traced, c.std_err, (c.analytic - c.traced) / c.traced
        );
    }
    println!(
        "mean rel err {:.4}  max {:.4}  bias {:+.4}  noise {:.4}",
        r.mean_rel_err(),
        r.max_rel_err(),
        r.mean_bias(),
        r.mean_noise()
    );
}
