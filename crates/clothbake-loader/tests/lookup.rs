//! The lookup's interpolation rules, checked against closed forms: nodes reproduced, linear
//! functions reproduced exactly, the pole's ring mean, the horizon, periodic azimuths,
//! reciprocity, the batched and angle entry points, and f16 storage.

use clothbake_loader::{
    write_exr, Brdf, Grid, Memory, Metadata, Options, Precision, Table, TableError,
};

const GRID: Grid = Grid::new(4, 6, 5, 8);

fn table_of(grid: Grid, f: impl Fn(u32, u32, u32, u32, usize) -> f32) -> Table {
    let mut values = vec![0f32; grid.len() * 3];
    for ti in 0..grid.n_theta_i {
        for pi in 0..grid.n_phi_i {
            for to in 0..grid.n_theta_o {
                for po in 0..grid.n_phi_o {
                    for k in 0..3 {
                        values[3 * grid.index(ti, pi, to, po) + k] = f(ti, pi, to, po, k);
                    }
                }
            }
        }
    }
    Table::new(Metadata::new("test", grid, "{}", "{}", "none"), values).unwrap()
}

/// Distinct values in every cell and channel.
fn wiggly(ti: u32, pi: u32, to: u32, po: u32, k: usize) -> f32 {
    let x = (ti * 7 + pi * 3 + to * 11 + po * 5 + k as u32 * 13) as f32;
    0.1 + (x * 0.731).sin().abs()
}

fn opts() -> Options {
    Options {
        sampling: false,
        ..Options::default()
    }
}

fn dir(theta_deg: f64, phi_deg: f64) -> [f32; 3] {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    [
        (t.sin() * p.cos()) as f32,
        (t.sin() * p.sin()) as f32,
        t.cos() as f32,
    ]
}

fn close(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol * b[k].abs().max(1e-3))
}

mod common;
use common::Rng;

#[test]
fn cell_centres_give_the_stored_values() {
    let t = table_of(GRID, wiggly);
    let b = Brdf::from_table(t.clone(), opts()).unwrap();
    for ti in 0..GRID.n_theta_i {
        for pi in 0..GRID.n_phi_i {
            for to in 0..GRID.n_theta_o {
                for po in 0..GRID.n_phi_o {
                    let want = t.rgb(ti, pi, to, po);
                    let (a, p) = (GRID.theta_i_deg(ti), GRID.phi_i_deg(pi));
                    let (c, q) = (GRID.theta_o_deg(to), GRID.phi_o_deg(po));
                    let got = b.eval_deg(a as f32, p as f32, c as f32, q as f32);
                    assert!(close(got, want, 1e-5), "{got:?} {want:?}");
                    let got = b.eval(dir(a, p), dir(c, q));
                    assert!(close(got, want, 1e-4), "vector {got:?} {want:?}");
                }
            }
        }
    }
}

#[test]
fn multilinear_functions_of_the_angles_are_reproduced_between_centres() {
    // f = (1 + theta_i) (2 + theta_o) (degrees / 10): bilinear, constant in the azimuths.
    let g = GRID;
    let f = |a: f64, c: f64| ((1.0 + a / 10.0) * (2.0 + c / 10.0)) as f32;
    let t = table_of(g, |ti, _, to, _, _| f(g.theta_i_deg(ti), g.theta_o_deg(to)));
    let b = Brdf::from_table(t, opts()).unwrap();
    let mut rng = Rng(1);
    for _ in 0..500 {
        // Between the first and the last centres of each polar axis.
        let a = g.theta_i_deg(0) + rng.next() * (g.theta_i_deg(3) - g.theta_i_deg(0));
        let c = g.theta_o_deg(0) + rng.next() * (g.theta_o_deg(4) - g.theta_o_deg(0));
        let (p, q) = (rng.next() * 360.0, rng.next() * 360.0);
        let want = f(a, c);
        let got = b.eval_deg(a as f32, p as f32, c as f32, q as f32);
        assert!(close(got, [want; 3], 1e-5), "{a} {c}: {got:?} vs {want}");
    }
}

#[test]
fn azimuth_is_periodic_and_wraps_between_the_last_and_first_cells() {
    let b = Brdf::from_table(table_of(GRID, wiggly), opts()).unwrap();
    let t = table_of(GRID, wiggly);
    let (a, c) = (GRID.theta_i_deg(1) as f32, GRID.theta_o_deg(2) as f32);
    // phi_i = 0 lies halfway between the centres of cells n - 1 and 0.
    let q = GRID.phi_o_deg(3) as f32;
    let got = b.eval_deg(a, 0.0, c, q);
    let (x, y) = (t.rgb(1, 5, 2, 3), t.rgb(1, 0, 2, 3));
    let want = [
        0.5 * (x[0] + y[0]),
        0.5 * (x[1] + y[1]),
        0.5 * (x[2] + y[2]),
    ];
    assert!(close(got, want, 1e-5), "{got:?} {want:?}");
    // 360 and -360 degrees are the same azimuth; values are continuous across 0.
    for p in [3.0f32, 17.0, 200.0] {
        let base = b.eval_deg(a, p, c, q);
        assert!(close(b.eval_deg(a, p + 360.0, c, q), base, 1e-4));
        assert!(close(b.eval_deg(a, p - 720.0, c, q), base, 1e-4));
    }
    assert!(close(
        b.eval_deg(a, 359.999, c, q),
        b.eval_deg(a, 0.001, c, q),
        1e-3
    ));
}

#[test]
fn at_the_pole_the_lookup_is_the_ring_mean_and_does_not_depend_on_the_azimuth() {
    let t = table_of(GRID, wiggly);
    let b = Brdf::from_table(t.clone(), opts()).unwrap();
    let (c, q) = (GRID.theta_o_deg(2), GRID.phi_o_deg(5));
    let mut mean = [0f32; 3];
    for pi in 0..GRID.n_phi_i {
        let v = t.rgb(0, pi, 2, 5);
        for k in 0..3 {
            mean[k] += v[k] / GRID.n_phi_i as f32;
        }
    }
    for p in [0.0, 41.0, 123.0, 301.0] {
        let got = b.eval_deg(0.0, p, c as f32, q as f32);
        assert!(close(got, mean, 1e-5), "phi {p}: {got:?} vs {mean:?}");
        assert!(close(b.eval([0.0, 0.0, 1.0], dir(c, q)), mean, 1e-5));
    }
    // Halfway between the pole and the first centre: the average of the pole and the ring.
    let half = GRID.theta_i_deg(0) as f32 / 2.0;
    let p = GRID.phi_i_deg(4) as f32;
    let ring = t.rgb(0, 4, 2, 5);
    let got = b.eval_deg(half, p, c as f32, q as f32);
    let want = [0, 1, 2].map(|k| 0.5 * (mean[k] + ring[k]));
    assert!(close(got, want, 1e-5), "{got:?} {want:?}");
    // Both directions at the pole: the mean over both azimuths of the first rings.
    let mut both = [0f32; 3];
    let n = (GRID.n_phi_i * GRID.n_phi_o) as f32;
    for pi in 0..GRID.n_phi_i {
        for po in 0..GRID.n_phi_o {
            let v = t.rgb(0, pi, 0, po);
            for k in 0..3 {
                both[k] += v[k] / n;
            }
        }
    }
    assert!(close(b.eval([0.0, 0.0, 1.0], [0.0, 0.0, 1.0]), both, 1e-5));
}

#[test]
fn beyond_the_last_centre_the_last_ring_is_held_and_below_the_horizon_is_zero() {
    let t = table_of(GRID, wiggly);
    let b = Brdf::from_table(t.clone(), opts()).unwrap();
    let (p, c, q) = (GRID.phi_i_deg(2), GRID.theta_o_deg(1), GRID.phi_o_deg(6));
    let want = t.rgb(3, 2, 1, 6);
    for a in [GRID.theta_i_deg(3) + 0.1, 85.0, 89.9] {
        let got = b.eval_deg(a as f32, p as f32, c as f32, q as f32);
        assert!(close(got, want, 1e-5), "theta {a}: {got:?} vs {want:?}");
    }
    let up = dir(c, q);
    for below in [[1.0, 0.0, 0.0], [0.6, 0.0, -0.8], [0.0, 1.0, 1e-10]] {
        assert_eq!(b.eval(below, up), [0.0; 3]);
        assert_eq!(b.eval(up, below), [0.0; 3]);
    }
    for bad in [f32::NAN, 90.0, 120.0, -1.0] {
        assert_eq!(b.eval_deg(bad, 0.0, 10.0, 0.0), [0.0; 3]);
        assert_eq!(b.eval_deg(10.0, 0.0, bad, 0.0), [0.0; 3]);
    }
    let nan = [f32::NAN, 0.0, 0.5];
    let v = b.eval(nan, up);
    assert!(v.iter().all(|x| x.is_finite()), "{v:?}");
    assert!(b
        .eval_deg(10.0, f32::NAN, 10.0, f32::INFINITY)
        .iter()
        .all(|x| x.is_finite()));
}

#[test]
fn reciprocal_lookups_are_symmetric_averages() {
    let g = Grid::new(4, 6, 4, 6);
    let t = table_of(g, wiggly);
    let plain = Brdf::from_table(t.clone(), opts()).unwrap();
    let sym = Brdf::from_table(
        t,
        Options {
            reciprocal: true,
            ..opts()
        },
    )
    .unwrap();
    assert!(sym.is_reciprocal() && !plain.is_reciprocal());
    let mut rng = Rng(7);
    for _ in 0..200 {
        let wi = dir(rng.next() * 89.0, rng.next() * 360.0);
        let wo = dir(rng.next() * 89.0, rng.next() * 360.0);
        let (f, r) = (plain.eval(wi, wo), plain.eval(wo, wi));
        let want = [0, 1, 2].map(|k| 0.5 * (f[k] + r[k]));
        assert!(close(sym.eval(wi, wo), want, 1e-6));
        assert_eq!(sym.eval(wi, wo), sym.eval(wo, wi));
    }
}

#[test]
fn batched_lookups_equal_single_ones_and_check_lengths() {
    let b = Brdf::from_table(table_of(GRID, wiggly), opts()).unwrap();
    let mut rng = Rng(3);
    let wi: Vec<[f32; 3]> = (0..300)
        .map(|_| dir(rng.next() * 95.0, rng.next() * 360.0))
        .collect();
    let wo: Vec<[f32; 3]> = (0..300)
        .map(|_| dir(rng.next() * 95.0, rng.next() * 360.0))
        .collect();
    let mut out = vec![[0f32; 3]; 300];
    b.eval_batch(&wi, &wo, &mut out).unwrap();
    for k in 0..300 {
        assert_eq!(out[k], b.eval(wi[k], wo[k]));
    }
    let e = b.eval_batch(&wi, &wo[..2], &mut out).unwrap_err();
    assert!(e.to_string().contains("wo 2"), "{e}");
}

#[test]
fn half_tables_stay_half_and_look_up_the_same_values() {
    let dir_ = tempfile::tempdir().unwrap();
    let path = dir_.path().join("t.exr");
    let t = table_of(GRID, wiggly);
    write_exr(&path, &t, Precision::F16, false).unwrap();
    let half = Brdf::open(&path, opts()).unwrap();
    let wide = Brdf::open(
        &path,
        Options {
            memory: Memory::F32,
            ..opts()
        },
    )
    .unwrap();
    assert_eq!(half.precision(), Precision::F16);
    assert_eq!(wide.precision(), Precision::F32);
    assert_eq!(2 * half.memory_bytes(), wide.memory_bytes());
    // Away from the poles (whose nodes are means, rounded to half) the nodes are the same
    // half values, so the lookups are identical.
    let mut rng = Rng(11);
    for _ in 0..300 {
        let a = GRID.theta_i_deg(0) + rng.next() * 75.0;
        let c = GRID.theta_o_deg(0) + rng.next() * 75.0;
        let (p, q) = (rng.next() * 360.0, rng.next() * 360.0);
        assert_eq!(
            half.eval(dir(a, p), dir(c, q)),
            wide.eval(dir(a, p), dir(c, q))
        );
    }
    // The values are the table's, rounded to half.
    let want = t.rgb(2, 3, 1, 4);
    let got = half.eval_deg(
        GRID.theta_i_deg(2) as f32,
        GRID.phi_i_deg(3) as f32,
        GRID.theta_o_deg(1) as f32,
        GRID.phi_o_deg(4) as f32,
    );
    assert!(close(got, want, 1e-3), "{got:?} {want:?}");
}

#[test]
fn a_bad_file_is_a_clear_error() {
    let d = tempfile::tempdir().unwrap();
    let path = d.path().join("nothing.exr");
    let e = Brdf::open(&path, opts()).unwrap_err();
    assert!(matches!(e, TableError::Io { .. }), "{e}");
    assert!(e.to_string().contains("nothing.exr"), "{e}");
    std::fs::write(&path, b"hello").unwrap();
    let e = Brdf::open(&path, opts()).unwrap_err();
    assert!(e.to_string().contains("not a clothbake table"), "{e}");
}
