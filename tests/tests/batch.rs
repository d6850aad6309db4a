//! The direct model's batches (four pairs in the lanes of an AVX2 register:
//! `AnalyticModel::intensity_batch`, `AnalyticModel::class_terms_batch`, `Bsdf::f_batch`)
//! against single evaluations (`intensity`, `class_terms`, `f`): the same bits, on every
//! shipped fabric, both end-length variants, pairs uniform in solid angle, on the symmetry
//! planes (the projections' zero branches), grazing, below the horizon, and a group of pairs
//! padded to four.

use clothbake_core::{
    AnalyticBsdf, AnalyticModel, Bsdf, ClassTerms, Component, Fabric, FacetModel, Reflection,
    SecondaryOptions, UnitVec3, Variant,
};
use clothbake_tests::accuracy::random_pairs;
use clothbake_tests::fixtures::shipped_files;
use clothbake_tests::probe;

/// Random pairs with the model's edge pairs (the pole, the symmetry planes, near grazing), one
/// more grazing pair, two below the horizon, and a count that is not a multiple of four.
fn pairs(seed: u64) -> Vec<(UnitVec3, UnitVec3)> {
    let mut p = random_pairs(2001, seed);
    p.extend(clothbake_core::directions::edge_pairs());
    let d = UnitVec3::from_degrees;
    p.push((d(89.9999, 10.0), d(30.0, 190.0)));
    let below = d(95.0, 10.0);
    p.insert(5, (below, p[0].1));
    p.insert(10, (p[0].0, below));
    p
}

fn bits(r: &Reflection) -> ([u64; 3], [u64; 3], bool) {
    (
        r.i_d.map(f64::to_bits),
        r.i_s.map(f64::to_bits),
        r.secondary.is_some(),
    )
}

fn shipped() -> Vec<(String, Fabric)> {
    let mut files = shipped_files("json");
    files.extend(shipped_files("wif"));
    files
        .into_iter()
        .map(|p| {
            let f = Fabric::from_path(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p.display().to_string(), f)
        })
        .collect()
}

#[test]
#[cfg_attr(
    missing_avx2,
    ignore = "needs an x86-64 processor with AVX2, FMA and F16C: nothing to install, run on such a processor"
)]
fn the_batch_gives_the_bits_of_single_evaluations() {
    probe::AVX2.require();
    let fabrics = shipped();
    assert!(fabrics.len() >= 12, "{}", fabrics.len());
    let mut compared = 0;
    for (k, (name, fabric)) in fabrics.iter().enumerate() {
        for variant in [Variant::Refined, Variant::Thesis] {
            let m = AnalyticModel::with_variant(fabric, FacetModel::Huo, variant)
                .expect("the variant takes the period");
            let p = pairs(k as u64);
            let mut out = vec![Reflection::default(); p.len()];
            m.intensity_batch(&p, &mut out);
            for (&(wi, wo), got) in p.iter().zip(&out) {
                let want = m.intensity(wi, wo);
                assert_eq!(
                    bits(got),
                    bits(&want),
                    "{name} {variant:?} {wi:?} {wo:?}: {got:?} vs {want:?}"
                );
                compared += 1;
            }
        }
    }
    assert!(compared > 40_000, "{compared}");
}

/// Lewis facets and exponents the closed form does not take go pair by pair: the same values.
#[test]
fn other_facets_are_evaluated_pair_by_pair() {
    let twill = std::fs::read_to_string(clothbake_tests::fixtures::tables().join("twill.json"))
        .expect("tables/twill.json");
    let fractional = twill.replace("\"exponent\": 10", "\"exponent\": 10.5");
    assert_ne!(fractional, twill);
    let p = pairs(3)[..41].to_vec();
    for (text, facet) in [(&twill, FacetModel::Lewis), (&fractional, FacetModel::Huo)] {
        let m = AnalyticModel::new(&Fabric::from_json_str(text, "twill.json").unwrap(), facet);
        let mut out = vec![Reflection::default(); p.len()];
        m.intensity_batch(&p, &mut out);
        for (&(wi, wo), got) in p.iter().zip(&out) {
            assert_eq!(bits(got), bits(&m.intensity(wi, wo)), "{facet:?}");
        }
    }
}

/// `AnalyticBsdf::f_batch` (what a one-bounce bake evaluates) against `Bsdf::f`: the same bits,
/// for the total and the direct component, and with the second bounce (pair by pair).
#[test]
#[cfg_attr(
    missing_avx2,
    ignore = "needs an x86-64 processor with AVX2, FMA and F16C: nothing to install, run on such a processor"
)]
fn the_bsdf_batch_gives_the_bits_of_f() {
    probe::AVX2.require();
    let twill = Fabric::from_path(&clothbake_tests::fixtures::tables().join("twill.json")).unwrap();
    let p = pairs(9);
    let model = || AnalyticModel::new(&twill, FacetModel::Huo);
    let cases = [
        (AnalyticBsdf::new(model(), None), p.len()),
        (
            AnalyticBsdf::new(model(), None)
                .with_component(Component::Direct)
                .unwrap(),
            p.len(),
        ),
        (
            AnalyticBsdf::new(model(), Some(SecondaryOptions::default())),
            61,
        ),
    ];
    for (bsdf, n) in cases {
        let p = &p[..n];
        let mut out = vec![[0.0; 3]; n];
        bsdf.f_batch(p, &mut out);
        for (&(wi, wo), got) in p.iter().zip(&out) {
            assert_eq!(got.map(f64::to_bits), bsdf.f(wi, wo).map(f64::to_bits));
        }
    }
}

/// `AnalyticModel::class_terms_batch` (what a one-bounce spatial bake evaluates) against
/// `class_terms`: the same bits on every shipped fabric.
#[test]
#[cfg_attr(
    missing_avx2,
    ignore = "needs an x86-64 processor with AVX2, FMA and F16C: nothing to install, run on such a processor"
)]
fn the_class_batch_gives_the_bits_of_class_terms() {
    probe::AVX2.require();
    let mut compared = 0;
    for (k, (name, fabric)) in shipped().iter().enumerate() {
        let m = AnalyticModel::new(fabric, FacetModel::Huo);
        let n = m.classes();
        let p = &pairs(100 + k as u64)[..403];
        let mut out = vec![ClassTerms::default(); n * p.len()];
        m.class_terms_batch(p, &mut out);
        let mut want = vec![ClassTerms::default(); n];
        for (&(wi, wo), got) in p.iter().zip(out.chunks(n)) {
            m.class_terms(wi, wo, &mut want);
            for (g, w) in got.iter().zip(&want) {
                let b = |t: &ClassTerms| {
                    [t.visible, t.diffuse, t.specular, t.neighbour[0], t.both[1]].map(f64::to_bits)
                };
                assert_eq!(b(g), b(w), "{name} {wi:?} {wo:?}: {g:?} vs {w:?}");
                compared += 1;
            }
        }
    }
    assert!(compared > 10_000, "{compared}");
}

/// A baked table's `Bsdf::f_batch` (through `Brdf::eval_batch`) against its `f`: the same bits,
/// averaged and spatial tables, f16 and f32.
#[test]
fn a_tables_batch_gives_the_bits_of_f() {
    use clothbake_bake::{bake, BakeOptions};
    use clothbake_loader::{Brdf, Options, Precision, StoredTable};
    use std::sync::atomic::AtomicBool;
    let twill = Fabric::from_path(&clothbake_tests::fixtures::tables().join("twill.json")).unwrap();
    let p = pairs(21);
    for spatial in [false, true] {
        for precision in [Precision::F16, Precision::F32] {
            let opts = BakeOptions {
                grid: clothbake_tests::fixtures::grid(8, 16),
                spatial,
                ..BakeOptions::default()
            };
            let baked = bake(&twill, &opts, &|_| {}, &AtomicBool::new(false)).expect("bake");
            let stored = StoredTable::from_table(baked.table, precision).expect("range");
            let brdf = Brdf::from_stored(stored, Options::default()).expect("valid table");
            let mut out = vec![[0.0; 3]; p.len()];
            brdf.f_batch(&p, &mut out);
            for (&(wi, wo), got) in p.iter().zip(&out) {
                let want = Bsdf::f(&brdf, wi, wo);
                assert_eq!(
                    got.map(f64::to_bits),
                    want.map(f64::to_bits),
                    "{spatial} {precision:?}"
                );
            }
        }
    }
}
