//! The analytic direct model held against the ray-traced ground truth of the same
//! micro-geometry, for every shipped fabric (issue: within 10% mean relative error on total I
//! for directions up to 70 degrees from the normal). The full table is `docs/results/validation.md`
//! (`cargo xtask validate`).

use clothbake_core::directions::direction_set;
use clothbake_core::{Fabric, FacetModel, Variant};
use clothbake_tests::validate::compare_with;
use clothbake_truth::Caps;
use std::path::Path;

const TABLES: [&str; 6] = ["plain", "basket", "twill", "twill31", "satin5", "parallel"];
const PAIRS: usize = 48;
const SAMPLES: usize = 40_000;

fn fabric(name: &str) -> Fabric {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../tables/{name}.json"));
    Fabric::from_path(&p).unwrap()
}

fn check(variant: Variant, facet: FacetModel, mean_bound: f64, max_bound: f64) {
    let pairs = direction_set(PAIRS, 70.0);
    for name in TABLES {
        let r = compare_with(
            &fabric(name),
            facet,
            variant,
            Caps::Excluded,
            &pairs,
            SAMPLES,
            7,
        );
        let (mean, max) = (r.mean_rel_err(), r.max_rel_err());
        eprintln!(
            "{name:9} {variant:?} {facet:?}: mean {mean:.4} max {max:.4} noise {:.4}",
            r.mean_noise()
        );
        assert!(
            mean < 0.10,
            "{name}: mean relative error {mean} breaks the 10% contract"
        );
        assert!(
            mean < mean_bound,
            "{name}: mean relative error {mean} regressed past {mean_bound}"
        );
        assert!(
            max < max_bound,
            "{name}: worst direction {max} regressed past {max_bound}"
        );
        assert!(r.mean_noise() < 0.005, "{name}: ground truth too noisy");
    }
}

#[test]
fn refined_model_matches_ground_truth() {
    // Measured (docs/results/validation.md): mean <= 2%, worst 9.3% (plain weave); the bounds leave
    // a margin over the measured values and catch regressions well inside the 10% contract.
    check(Variant::Refined, FacetModel::Huo, 0.04, 0.12);
}

#[test]
fn thesis_variant_matches_ground_truth() {
    check(Variant::Thesis, FacetModel::Huo, 0.04, 0.12);
}

#[test]
fn lewis_facets_match_ground_truth() {
    check(Variant::Refined, FacetModel::Lewis, 0.04, 0.14);
}

#[test]
fn parallel_cylinders_are_exact() {
    // No crossing threads: the 2-D cross-section treatment is exact, only noise remains.
    let pairs = direction_set(PAIRS, 80.0);
    for facet in [FacetModel::Huo, FacetModel::Lewis] {
        let r = compare_with(
            &fabric("parallel"),
            facet,
            Variant::Refined,
            Caps::Excluded,
            &pairs,
            SAMPLES,
            3,
        );
        for c in &r.rows {
            let tol = 4.0 * c.std_err + 1e-3 * c.traced;
            assert!(
                (c.analytic - c.traced).abs() < tol,
                "{facet:?} {:?}: {} vs {} ± {}",
                c.pair,
                c.analytic,
                c.traced,
                c.std_err
            );
        }
    }
}

#[test]
fn presets_of_real_cloth_keep_the_10_percent_contract() {
    // The presets (docs/reference/fabric-format.md) are not the thesis's nearly touching, equal yarns:
    // the contract (mean relative error under 10% up to 70 degrees) is what they are
    // held to, for both facet models; the measured means are printed.
    let pairs = direction_set(PAIRS, 70.0);
    for file in [
        "denim.wif",
        "cotton-poplin.json",
        "silk-charmeuse.json",
        "polyester-taffeta.json",
        "wool-twill.json",
    ] {
        let p = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tables")
            .join(file);
        let f = Fabric::from_path(&p).unwrap();
        for facet in [FacetModel::Huo, FacetModel::Lewis] {
            let r = compare_with(
                &f,
                facet,
                Variant::Refined,
                Caps::Excluded,
                &pairs,
                4 * SAMPLES, // the charmeuse's narrow Lewis lobe (n 40) is noisy to trace
                5,
            );
            let (mean, max) = (r.mean_rel_err(), r.max_rel_err());
            eprintln!("{file:22} {facet:?}: mean {mean:.4} max {max:.4}");
            assert!(mean < 0.10, "{file} {facet:?}: mean relative error {mean}");
            assert!(
                r.mean_noise() < 0.005,
                "{file}: ground truth too noisy: {}",
                r.mean_noise()
            );
        }
    }
}

/// The `sliced3d` variant (docs/science/model.md), against the ground truth on every shipped fabric,
/// preset and draft: issue 37's bounds, 0.5% mean and 2% worst relative error on the total
/// intensity up to 70 degrees (measured over 96 pairs: 0.08-0.22% mean, 1.26% worst; the truth's
/// own noise at 100 000 rays is about 0.05%).
#[test]
fn sliced3d_is_within_half_a_percent_of_the_ground_truth() {
    let pairs = direction_set(24, 70.0);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables");
    let files = clothbake_bake::golden::fabric_files(&dir).unwrap();
    assert!(files.len() >= 13, "{} fabric files", files.len());
    for path in files {
        let f = Fabric::from_path(&path).unwrap();
        let r = compare_with(
            &f,
            FacetModel::Huo,
            Variant::Sliced3d,
            Caps::Excluded,
            &pairs,
            100_000,
            5,
        );
        let (mean, max) = (r.mean_rel_err(), r.max_rel_err());
        let name = path.file_name().unwrap().to_string_lossy();
        eprintln!(
            "{name:24} sliced3d: mean {mean:.4} max {max:.4} noise {:.4}",
            r.mean_noise()
        );
        assert!(mean < 0.005, "{name}: mean relative error {mean} over 0.5%");
        assert!(max < 0.02, "{name}: worst direction {max} over 2%");
        assert!(r.mean_noise() < 0.002, "{name}: ground truth too noisy");
    }
}
