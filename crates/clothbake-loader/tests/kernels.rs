//! Both lookup kernels (portable and AVX2 + FMA + F16C) against a straightforward f64
//! quadrilinear interpolation written here from the documented rules (std `atan2`, the unpadded
//! table, pole nodes as ring means), and against each other; the batched path against single
//! lookups per kernel; odd inputs never panic.
//!
//! The AVX2 cases are tests of their own, ignored (with the reason) on a processor without
//! AVX2, FMA and F16C (the build script probes it); under `CI` they run and fail there.

use clothbake_loader::{Brdf, Grid, Memory, Metadata, Options, SimdPath, Table};
use std::f64::consts::{FRAC_PI_2, TAU};

mod common;
use common::Rng;

/// The probes of the build script (build/probe.rs), to fail with its message when the AVX2
/// cases run without AVX2 (under `CI`).
mod probe {
    include!("../build/probe.rs");
}

const GRID: Grid = Grid::new(5, 7, 4, 9);

fn table() -> Table {
    let values = (0..GRID.len() * 3)
        .map(|i| 0.2 + ((i as f32) * 0.613).sin().abs())
        .collect();
    Table::new(Metadata::new("kernels", GRID, "{}", "{}", "none"), values).unwrap()
}

/// `kernel` on f32 and f16 values; panics when this processor cannot run it.
fn brdfs(kernel: SimdPath, reciprocal: bool) -> Vec<(Memory, Brdf)> {
    let mut out = Vec::new();
    for memory in [Memory::F32, Memory::AsStored] {
        let opts = Options {
            memory,
            reciprocal,
            sampling: false,
            point_level: false,
        };
        let stored =
            clothbake_loader::StoredTable::from_table(table(), clothbake_loader::Precision::F16)
                .unwrap();
        let b = Brdf::from_stored(stored, opts).unwrap();
        let b = b.with_simd_path(kernel).unwrap_or_else(|| {
            panic!("the {kernel:?} kernel cannot run on this processor (AVX2, FMA and F16C needed)")
        });
        out.push((memory, b));
    }
    out
}

/// Polar axis of `n` cells at `theta`: (cell or None for the pole node, weight) pairs.
fn polar(theta: f64, n: u32) -> [(Option<u32>, f64); 2] {
    let c = theta / (FRAC_PI_2 / f64::from(n));
    if c < 0.5 {
        let t = c / 0.5;
        [(None, 1.0 - t), (Some(0), t)]
    } else if c >= f64::from(n) - 0.5 {
        [(Some(n - 1), 1.0), (Some(n - 1), 0.0)]
    } else {
        let x = c - 0.5;
        let lo = x.floor();
        [
            (Some(lo as u32), 1.0 - (x - lo)),
            (Some(lo as u32 + 1), x - lo),
        ]
    }
}

/// Azimuth axis of `n` cells at `phi`: periodic (cell, weight) pairs.
fn azimuth(phi: f64, n: u32) -> [(u32, f64); 2] {
    let x = phi.rem_euclid(TAU) / (TAU / f64::from(n)) - 0.5;
    let lo = x.floor();
    let cell = |k: f64| k.rem_euclid(f64::from(n)) as u32;
    [(cell(lo), 1.0 - (x - lo)), (cell(lo + 1.0), x - lo)]
}

/// The value of a node: a cell, or a pole node (mean over the azimuths of the first ring).
fn node(t: &Table, ti: Option<u32>, pi: u32, to: Option<u32>, po: u32) -> [f64; 3] {
    let is: Vec<(u32, u32)> = match ti {
        Some(k) => vec![(k, pi)],
        None => (0..GRID.n_phi_i).map(|p| (0, p)).collect(),
    };
    let os: Vec<(u32, u32)> = match to {
        Some(k) => vec![(k, po)],
        None => (0..GRID.n_phi_o).map(|p| (0, p)).collect(),
    };
    let mut sum = [0f64; 3];
    for &(a, b) in &is {
        for &(c, d) in &os {
            let v = t.rgb(a, b, c, d);
            for k in 0..3 {
                sum[k] += f64::from(v[k]);
            }
        }
    }
    sum.map(|s| s / (is.len() * os.len()) as f64)
}

/// The documented lookup in f64, at angles in radians.
fn reference(t: &Table, ti: f64, pi: f64, to: f64, po: f64) -> [f64; 3] {
    let mut out = [0f64; 3];
    for (a, wa) in polar(ti, GRID.n_theta_i) {
        for (b, wb) in azimuth(pi, GRID.n_phi_i) {
            for (c, wc) in polar(to, GRID.n_theta_o) {
                for (d, wd) in azimuth(po, GRID.n_phi_o) {
                    let v = node(t, a, b, c, d);
                    for k in 0..3 {
                        out[k] += wa * wb * wc * wd * v[k];
                    }
                }
            }
        }
    }
    out
}

fn angles(w: [f32; 3]) -> (f64, f64) {
    let (x, y, z) = (f64::from(w[0]), f64::from(w[1]), f64::from(w[2]));
    (x.hypot(y).atan2(z), y.atan2(x))
}

/// Random directions above the horizon, a fifth of them near the pole or the horizon.
fn direction(rng: &mut Rng) -> [f32; 3] {
    let theta = match (rng.next() * 5.0) as u32 {
        0 => rng.next() * 0.05,
        1 => FRAC_PI_2 - 1e-4 - rng.next() * 0.05,
        _ => rng.next() * (FRAC_PI_2 - 1e-4),
    };
    let phi = rng.next() * TAU;
    [
        (theta.sin() * phi.cos()) as f32,
        (theta.sin() * phi.sin()) as f32,
        theta.cos() as f32,
    ]
}

fn matches_an_f64_quadrilinear_reference(kernel: SimdPath) {
    let t = table();
    // The table's values rounded to half (the f16 memory reads those).
    let half = Table::new(
        t.meta.clone(),
        t.values
            .iter()
            .map(|&v| half::f16::from_f32(v).to_f32())
            .collect(),
    )
    .unwrap();
    let mut rng = Rng(17);
    let pairs: Vec<_> = (0..4000)
        .map(|_| (direction(&mut rng), direction(&mut rng)))
        .collect();
    for (memory, b) in brdfs(kernel, false) {
        let mut worst = 0f64;
        for &(wi, wo) in &pairs {
            let ((ti, pi), (to, po)) = (angles(wi), angles(wo));
            // The table is half-rounded for both memories here (StoredTable F16); f32 memory
            // widens those halves exactly, f16 memory rounds the pole means to half too.
            let want = reference(&half, ti, pi, to, po);
            let got = b.eval(wi, wo);
            for k in 0..3 {
                worst = worst.max((f64::from(got[k]) - want[k]).abs() / want[k]);
            }
        }
        // atan2 within 2e-6 rad (a 2e-5 shift in cells on these grids) and f32 sums; f16
        // memory also rounds the pole nodes to half (relative 5e-4).
        let tol = if memory == Memory::F32 { 1e-4 } else { 1e-3 };
        assert!(
            worst < tol,
            "{kernel:?} {memory:?}: worst relative error {worst}"
        );
        eprintln!("{kernel:?} {memory:?}: worst relative error {worst:.2e}");
    }
}

/// Each batch equals its single lookups, and the kernel agrees with the portable one.
fn batches_equal_single_lookups_and_agree_with_portable(kernel: SimdPath) {
    let mut rng = Rng(5);
    let n = 1001; // not a multiple of the batch group
    let wi: Vec<[f32; 3]> = (0..n).map(|_| direction(&mut rng)).collect();
    let mut wo: Vec<[f32; 3]> = (0..n).map(|_| direction(&mut rng)).collect();
    wo[10] = [0.3, 0.2, -0.5]; // below the horizon, inside a batch group
    wo[11] = [f32::NAN, 0.0, 1.0];
    let portable = brdfs(SimdPath::Portable, false);
    for ((memory, b), (_, p)) in brdfs(kernel, false).iter().zip(&portable) {
        let mut out = vec![[9f32; 3]; n];
        b.eval_batch(&wi, &wo, &mut out).unwrap();
        for k in 0..n {
            assert_eq!(
                out[k],
                b.eval(wi[k], wo[k]),
                "{kernel:?} {memory:?} pair {k}"
            );
        }
        assert_eq!(out[10], [0.0; 3]);
        assert_eq!(out[11], [0.0; 3]);
        let mut worst = 0f32;
        for k in 0..n {
            let (x, y) = (b.eval(wi[k], wo[k]), p.eval(wi[k], wo[k]));
            for c in 0..3 {
                worst = worst.max((x[c] - y[c]).abs() / y[c].abs().max(1e-3));
            }
        }
        assert!(worst <= 1e-5, "{kernel:?} {memory:?} vs portable: {worst}");
    }
}

/// Reciprocal lookups are symmetric and agree with the portable kernel's.
fn reciprocal_lookups_agree_with_portable(kernel: SimdPath) {
    let all = brdfs(kernel, true);
    let portable = brdfs(SimdPath::Portable, true);
    let mut rng = Rng(8);
    for _ in 0..500 {
        let (wi, wo) = (direction(&mut rng), direction(&mut rng));
        for ((memory, b), (_, p)) in all.iter().zip(&portable) {
            let want = p.eval(wi, wo);
            let got = b.eval(wi, wo);
            assert_eq!(got, b.eval(wo, wi), "{kernel:?} {memory:?}");
            for c in 0..3 {
                assert!(
                    (got[c] - want[c]).abs() <= 1e-5 * want[c].abs(),
                    "{kernel:?} {memory:?}"
                );
            }
        }
    }
}

fn odd_inputs_give_finite_values_and_nan_gives_zero(kernel: SimdPath) {
    let big = 1e30f32;
    let odd = [
        [0.0, 0.0, 1.0],
        [0.0, 0.0, big],
        [big, -big, 1.0],
        [-1.0, -0.0, 1e-3],
        [-1.0, 0.0, 1e-3],
        [1e-30, 1e-30, 1.0],
        [f32::INFINITY, 0.0, 1.0],
        [0.0, f32::NEG_INFINITY, 1.0],
        [0.0, 0.0, f32::INFINITY],
        [f32::MIN_POSITIVE, 0.0, f32::MIN_POSITIVE],
    ];
    for (memory, b) in brdfs(kernel, false) {
        for &a in &odd {
            for &c in &odd {
                let f = b.eval(a, c);
                assert!(
                    f.iter().all(|x| x.is_finite() && *x >= 0.0),
                    "{kernel:?} {memory:?} {a:?} {c:?} {f:?}"
                );
            }
            for nan in [
                [f32::NAN, 0.0, 1.0],
                [0.0, f32::NAN, 1.0],
                [0.0, 0.0, f32::NAN],
            ] {
                assert_eq!(b.eval(a, nan), [0.0; 3], "{kernel:?}");
                assert_eq!(b.eval(nan, a), [0.0; 3], "{kernel:?}");
            }
        }
        for (t, p) in [
            (0.0, 0.0),
            (89.99999, 359.99997),
            (45.0, -1e30),
            (45.0, 1e30),
            (45.0, f32::NAN),
            (45.0, 720.5),
        ] {
            let f = b.eval_deg(t, p, t, p);
            assert!(f.iter().all(|x| x.is_finite()), "{kernel:?} {t} {p} {f:?}");
        }
        assert_eq!(b.eval_deg(90.0, 0.0, 10.0, 0.0), [0.0; 3]);
        assert_eq!(b.eval_deg(f32::NAN, 0.0, 10.0, 0.0), [0.0; 3]);
    }
}

/// Each check as two tests: on the portable kernel, and on the AVX2 kernel, which is reported
/// as ignored, with the reason, on a processor without it (and fails under `CI`). A macro: a
/// function cannot declare tests.
macro_rules! on_both_kernels {
    ($($check:ident: $portable:ident, $avx2:ident;)*) => {$(
        #[test]
        fn $portable() {
            $check(SimdPath::Portable);
        }

        #[test]
        #[cfg_attr(
            missing_avx2,
            ignore = "needs an x86-64 processor with AVX2, FMA and F16C: nothing to install, run on such a processor"
        )]
        fn $avx2() {
            probe::AVX2.require();
            $check(SimdPath::Avx2);
        }
    )*};
}

on_both_kernels! {
    matches_an_f64_quadrilinear_reference:
        portable_kernel_matches_an_f64_quadrilinear_reference,
        avx2_kernel_matches_an_f64_quadrilinear_reference;
    batches_equal_single_lookups_and_agree_with_portable:
        portable_batches_equal_single_lookups,
        avx2_batches_equal_single_lookups_and_agree_with_the_portable_kernel;
    reciprocal_lookups_agree_with_portable:
        portable_reciprocal_lookups_are_symmetric,
        avx2_reciprocal_lookups_are_symmetric_and_agree_with_the_portable_kernel;
    odd_inputs_give_finite_values_and_nan_gives_zero:
        portable_odd_inputs_give_finite_values_and_nan_gives_zero,
        avx2_odd_inputs_give_finite_values_and_nan_gives_zero;
}
