//! Properties of the analytic direct model that need no reference values: symmetries of
//! symmetric weaves, zero below the horizon, finite and non-negative everywhere.

use clothbake_core::{AnalyticModel, Fabric, FacetModel, UnitVec3};
use proptest::prelude::*;
use std::path::Path;

fn table(name: &str) -> Fabric {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tables")
        .join(name);
    Fabric::from_path(&p).unwrap()
}

fn dir() -> impl Strategy<Value = UnitVec3> {
    (0.0f64..89.0, 0.0f64..360.0).prop_map(|(t, p)| UnitVec3::from_degrees(t, p))
}

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    a.iter()
        .zip(&b)
        .all(|(x, y)| (x - y).abs() <= 1e-9 * (1.0 + x.abs().max(y.abs())))
}

type Map = fn(UnitVec3) -> UnitVec3;

fn rot180(v: UnitVec3) -> UnitVec3 {
    v.rotate_z90().rotate_z90()
}

/// (table, symmetry maps of its micro-geometry)
fn symmetric_tables() -> Vec<(&'static str, Vec<(&'static str, Map)>)> {
    let mx: Map = UnitVec3::mirror_x;
    let my: Map = UnitVec3::mirror_y;
    let r90: Map = UnitVec3::rotate_z90;
    vec![
        (
            "plain.json",
            vec![("mirror x", mx), ("mirror y", my), ("rotate 90", r90)],
        ),
        (
            "basket.json",
            vec![("mirror x", mx), ("mirror y", my), ("rotate 90", r90)],
        ),
        ("twill.json", vec![("rotate 180", rot180)]),
        ("twill31.json", vec![("rotate 180", rot180)]),
        ("satin5.json", vec![("rotate 180", rot180)]),
        ("parallel.json", vec![("mirror x", mx), ("mirror y", my)]),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn symmetric_weaves_give_symmetric_brdfs(wi in dir(), wo in dir()) {
        for (name, maps) in symmetric_tables() {
            for facet in [FacetModel::Huo, FacetModel::Lewis] {
                let m = AnalyticModel::new(&table(name), facet);
                let a = m.intensity(wi, wo).total();
                for (what, f) in &maps {
                    let b = m.intensity(f(wi), f(wo)).total();
                    prop_assert!(close(a, b), "{name} {what} {facet:?}: {a:?} vs {b:?}");
                }
            }
        }
    }

    #[test]
    fn zero_below_the_horizon(t in 90.0f64..180.0, p in 0.0f64..360.0, other in dir()) {
        let below = UnitVec3::from_degrees(t, p);
        let m = AnalyticModel::new(&table("twill.json"), FacetModel::Huo);
        prop_assert_eq!(m.intensity(below, other).total(), [0.0; 3]);
        prop_assert_eq!(m.intensity(other, below).total(), [0.0; 3]);
    }

    #[test]
    fn random_fabrics_are_finite_and_non_negative(
        rows in 1usize..5, cols in 1usize..5, bits in any::<u32>(),
        r in prop::collection::vec(0.3f64..2.0, 8), gaps in prop::collection::vec(0.0f64..1.5, 8),
        hf in prop::collection::vec(-0.8f64..0.8, 8), n in 0.0f64..60.0, lewis in any::<bool>(),
        wi in dir(), wo in dir(),
    ) {
        let pattern: Vec<Vec<u8>> = (0..rows)
            .map(|j| (0..cols).map(|i| ((bits >> ((j * cols + i) % 32)) & 1) as u8).collect())
            .collect();
        let group = |count: usize, off: usize| {
            let rad: Vec<f64> = (0..count).map(|k| r[(k + off) % 8]).collect();
            let h: Vec<f64> = (0..count).map(|k| hf[(k + off) % 8] * rad[k]).collect();
            let s: Vec<f64> = (0..count)
                .map(|k| rad[k] + rad[(k + 1) % count] + gaps[(k + off) % 8])
                .collect();
            serde_json::json!({"radius": rad, "height": h, "spacing": s,
                "material": {"albedo": [0.5, 0.3, 0.2], "specular": 0.4, "exponent": n}})
        };
        let json = serde_json::json!({"pattern": pattern, "warp": group(cols, 0), "weft": group(rows, 3)});
        let f = Fabric::from_json_str(&json.to_string(), "random").unwrap();
        let facet = if lewis { FacetModel::Lewis } else { FacetModel::Huo };
        let m = AnalyticModel::new(&f, facet);
        let r = m.intensity(wi, wo);
        for v in r.i_d.iter().chain(&r.i_s) {
            prop_assert!(v.is_finite() && *v >= 0.0, "{json} -> {r:?}");
        }
        for v in r.brdf(wi) {
            prop_assert!(v.is_finite() && v >= 0.0);
        }
    }
}
