//! The bake library: copied (symmetric) cells equal directly evaluated ones, and the table does
//! not depend on the number of threads.

use clothbake_bake::{bake, direction, BakeBounces, BakeOptions, DEFAULT_GRID};
use clothbake_core::symmetry::symmetries;
use clothbake_core::{AnalyticModel, Fabric, FacetModel, SecondaryOptions, Variant};
use clothbake_loader::{Grid, Table};
use std::sync::atomic::AtomicBool;

mod common;
use common::{fabric, options, small};

fn bake_on(threads: usize, f: &Fabric, o: &BakeOptions) -> (Table, usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let b = pool
        .install(|| bake(f, o, &|_| {}, &AtomicBool::new(false)))
        .unwrap();
    (b.table, b.evaluated)
}

/// Every cell of the table, copied or evaluated, is the f32 rounding of the model evaluated
/// directly at the cell's centre; and the model itself is symmetric to 1e-12 (relative) under
/// the fabric's symmetries, cell by cell.
fn check_copies(name: &str, bounces: u32) {
    let f = fabric(name);
    let o = BakeOptions {
        grid: small(),
        bounces: BakeBounces::of(bounces, Default::default()),
        ..BakeOptions::default()
    };
    let (t, evaluated) = bake_on(2, &f, &o);
    let syms = symmetries(&f);
    assert!(!syms.is_empty(), "{name} should have a symmetry");
    assert!(evaluated < small().len(), "{name}: no cell was copied");
    let m = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Refined)
        .expect("the variant takes the period");
    let sec = (bounces == 2).then(SecondaryOptions::default);
    let g = small();
    let eval = |ti, pi, to, po| {
        let wi = direction(ti, g.n_theta_i, pi, g.n_phi_i);
        let wo = direction(to, g.n_theta_o, po, g.n_phi_o);
        m.intensity_with(wi, wo, sec.as_ref()).brdf(wi)
    };
    for ti in 0..g.n_theta_i {
        for pi in 0..g.n_phi_i {
            for to in 0..g.n_theta_o {
                for po in 0..g.n_phi_o {
                    let direct = eval(ti, pi, to, po);
                    let stored = t.rgb(ti, pi, to, po);
                    for k in 0..3 {
                        // f32 rounding (2^-24) plus the model's own rounding (1e-12).
                        let tol = (2f64.powi(-24) + 1e-12) * direct[k].abs() + 1e-30;
                        assert!(
                            (f64::from(stored[k]) - direct[k]).abs() <= tol,
                            "{name} bounces {bounces} cell ({ti},{pi},{to},{po})[{k}]: \
                             stored {} direct {}",
                            stored[k],
                            direct[k]
                        );
                    }
                    for s in &syms {
                        let (Some(qi), Some(qo)) = (
                            s.phi_index(pi as usize, g.n_phi_i as usize),
                            s.phi_index(po as usize, g.n_phi_o as usize),
                        ) else {
                            continue;
                        };
                        let image = eval(ti, qi as u32, to, qo as u32);
                        for k in 0..3 {
                            let d = (image[k] - direct[k]).abs();
                            assert!(
                                d <= 1e-12 * direct[k].abs() + 1e-300,
                                "{name} bounces {bounces} {s:?} cell ({ti},{pi},{to},{po}): \
                                 {} vs {}",
                                direct[k],
                                image[k]
                            );
                        }
                        // The copy is bit-identical to its source.
                        assert_eq!(stored, t.rgb(ti, qi as u32, to, qo as u32), "{name} {s:?}");
                    }
                }
            }
        }
    }
}

#[test]
fn copied_cells_equal_direct_evaluations() {
    for name in ["plain", "basket", "twill", "twill31", "satin5", "parallel"] {
        check_copies(name, 1);
    }
}

#[test]
fn copied_cells_equal_direct_evaluations_with_two_bounces() {
    for name in ["twill", "plain"] {
        check_copies(name, 2);
    }
}

#[test]
fn thread_count_does_not_change_the_table() {
    let f = fabric("satin5");
    for bounces in [1, 2] {
        let o = BakeOptions {
            grid: small(),
            bounces: BakeBounces::of(bounces, Default::default()),
            ..BakeOptions::default()
        };
        let (a, _) = bake_on(1, &f, &o);
        let (b, _) = bake_on(2, &f, &o);
        let (c, _) = bake_on(3, &f, &o);
        let bits = |t: &Table| t.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b));
        assert_eq!(bits(&a), bits(&c));
        assert_eq!(a.meta, b.meta);
    }
}

#[test]
fn symmetry_is_used_and_reported() {
    let f = fabric("plain");
    let (t, evaluated) = bake_on(2, &f, &options(small()));
    // The plain weave has all three symmetries: a quarter of the (phi_i, phi_o) pairs.
    assert_eq!(t.meta.symmetry, "mirror x, mirror y, rotate 180");
    assert_eq!(evaluated, small().len() / 4);
    // An odd number of azimuth cells leaves only mirror y.
    let odd = Grid {
        n_phi_i: 7,
        n_phi_o: 5,
        ..small()
    };
    let (t, evaluated) = bake_on(1, &f, &options(odd));
    assert_eq!(t.meta.symmetry, "mirror y");
    assert!(evaluated > odd.len() / 2 && evaluated < odd.len());
    // Metadata: everything a reader needs.
    assert_eq!(t.meta.centring, "cell");
    assert_eq!(t.meta.units, "1/sr");
    let opts: serde_json::Value = serde_json::from_str(&t.meta.options_json).unwrap();
    assert_eq!(opts["bounces"], 1);
    assert_eq!(opts["grid"]["n_phi_i"], 7);
    let fab: serde_json::Value = serde_json::from_str(&t.meta.fabric_json).unwrap();
    assert_eq!(fab["name"], "plain");
    assert_eq!(DEFAULT_GRID.len(), 4_194_304);
}

#[test]
fn progress_reaches_the_total() {
    use std::sync::atomic::{AtomicU64, Ordering};
    let f = fabric("twill");
    let max = AtomicU64::new(0);
    let calls = AtomicU64::new(0);
    let o = BakeOptions {
        grid: small(),
        ..BakeOptions::default()
    };
    bake(
        &f,
        &o,
        &|n| {
            max.fetch_max(n, Ordering::Relaxed);
            calls.fetch_add(1, Ordering::Relaxed);
        },
        &AtomicBool::new(false),
    )
    .unwrap();
    // Progress counts evaluated cells: half of them for the twill's rotation symmetry.
    assert_eq!(
        max.load(Ordering::Relaxed),
        clothbake_bake::evaluations(&f, &small()) as u64
    );
    assert_eq!(clothbake_bake::evaluations(&f, &small()), small().len() / 2);
    assert_eq!(
        calls.load(Ordering::Relaxed),
        u64::from(small().n_theta_i * small().n_phi_i)
    );
}
