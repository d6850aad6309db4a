//! Two-faced tables (docs/reference/table-format.md, "Two-faced tables"): the sphere grid, the four
//! blocks the lookup cuts it into, the openness, sampling over the sphere, both file formats
//! and the checks.

use clothbake_loader::{
    read_table, write_binary, write_exr, Brdf, Faces, Grid, Lookup, Metadata, Options, Precision,
    Table, TableError, TwoFacedBrdf,
};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

mod common;
use common::Rng;

/// Per side: 6 polar cells, 12 azimuths of the light; 5 and 10 of the eye.
const SIDE: Grid = Grid::new(6, 12, 5, 10);

fn dir(theta: f64, phi: f64) -> [f64; 3] {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

fn f32s(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

/// A smooth f over the sphere that tells the four blocks apart: a level per block (front
/// reflection 0.1, transmission from the front 0.2, back reflection 0.3, from the back 0.4),
/// a glossy lobe toward the mirror direction (reflection) or straight through (transmission),
/// and a different scale per channel.
fn f(wi: [f64; 3], wo: [f64; 3], k: usize) -> f64 {
    let level = match (wi[2] > 0.0, wo[2] > 0.0) {
        (true, true) => 0.1,
        (true, false) => 0.2,
        (false, false) => 0.3,
        (false, true) => 0.4,
    };
    // Reflection peaks at wi = (-wo.x, -wo.y, wo.z), transmission at wi = -wo.
    let peak = if (wi[2] > 0.0) == (wo[2] > 0.0) {
        [-wo[0], -wo[1], wo[2]]
    } else {
        [-wo[0], -wo[1], -wo[2]]
    };
    let c = (wi[0] * peak[0] + wi[1] * peak[1] + wi[2] * peak[2]).max(0.0);
    (level + 0.6 * c.powi(4)) * (1.0 + 0.25 * k as f64)
}

/// The openness the test tables hold at an incident direction: largest at normal incidence,
/// falling with it, a little azimuth dependence; the back a different level.
fn open_at(wi: [f64; 3]) -> f64 {
    let c = wi[2].abs();
    let level = if wi[2] > 0.0 { 0.2 } else { 0.15 };
    level * c * c * (1.0 + 0.1 * wi[0])
}

/// The values of `g`'s cells, in cell order: `value(wi, wo, channel)` at each cell's centre
/// directions.
fn tabulate(g: Grid, value: impl Fn([f64; 3], [f64; 3], usize) -> f64) -> Vec<f32> {
    let mut values = Vec::with_capacity(3 * g.len());
    for ti in 0..g.n_theta_i {
        for pi in 0..g.n_phi_i {
            let wi = dir(g.theta_i_deg(ti).to_radians(), g.phi_i_deg(pi).to_radians());
            for to in 0..g.n_theta_o {
                for po in 0..g.n_phi_o {
                    let wo = dir(g.theta_o_deg(to).to_radians(), g.phi_o_deg(po).to_radians());
                    values.extend((0..3).map(|k| value(wi, wo, k) as f32));
                }
            }
        }
    }
    values
}

fn table() -> Table {
    let g = SIDE.two_faced();
    let values = tabulate(g, f);
    let mut meta = Metadata::new("test", g, "{}", "{}", "none");
    meta.openness = Some(
        (0..g.n_theta_i)
            .flat_map(|ti| (0..g.n_phi_i).map(move |pi| (ti, pi)))
            .map(|(ti, pi)| {
                open_at(dir(
                    g.theta_i_deg(ti).to_radians(),
                    g.phi_i_deg(pi).to_radians(),
                )) as f32
            })
            .collect(),
    );
    Table::new(meta, values).unwrap()
}

fn lookup() -> TwoFacedBrdf {
    TwoFacedBrdf::from_table(table(), Options::default()).unwrap()
}

#[test]
fn the_grid_covers_the_sphere_with_the_sides_cells() {
    let g = SIDE.two_faced();
    assert_eq!((g.n_theta_i, g.n_theta_o, g.faces), (12, 10, Faces::Two));
    assert_eq!(g.side(), SIDE);
    assert_eq!(g.len(), 4 * SIDE.len());
    // Polar centres over 0..180: the lower half mirrors the upper one.
    for k in 0..g.n_theta_i {
        let mirrored = 180.0 - g.theta_i_deg(g.n_theta_i - 1 - k);
        assert!((g.theta_i_deg(k) - mirrored).abs() < 1e-12);
    }
    assert_eq!(g.theta_i_deg(5), SIDE.theta_i_deg(5));
    assert!(g.theta_i_deg(6) > 90.0);
    // An odd polar count leaves a cell on the horizon: refused.
    let odd = Grid { n_theta_o: 7, ..g };
    let e = odd.validate().unwrap_err().to_string();
    assert!(e.contains("even number of cells"), "{e}");
}

#[test]
fn at_cell_centres_every_block_returns_its_values() {
    let t = table();
    let b = lookup();
    let g = t.meta.grid;
    // Every incident and outgoing ring of both sides, some azimuths.
    for ti in 0..g.n_theta_i {
        for to in 0..g.n_theta_o {
            for (pi, po) in [(0, 0), (3, 7), (11, 9)] {
                let wi = dir(g.theta_i_deg(ti).to_radians(), g.phi_i_deg(pi).to_radians());
                let wo = dir(g.theta_o_deg(to).to_radians(), g.phi_o_deg(po).to_radians());
                let got = b.eval(f32s(wi), f32s(wo));
                let want = t.rgb(ti, pi, to, po);
                for k in 0..3 {
                    assert!(
                        (got[k] - want[k]).abs() <= 2e-5 * want[k],
                        "cell ({ti}, {pi}, {to}, {po}) channel {k}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    }
}

/// Block `b`'s one-faced table built on its own: f at the side grid's cell centres, each
/// direction mirrored below the cloth where the block's side is the back.
fn block_table(b: usize) -> Table {
    let (up_i, up_o) = [(true, true), (true, false), (false, false), (false, true)][b];
    let g = SIDE;
    // A new array, not a `mut` parameter changed in place (issue 36's note: a debug build
    // miscomputed the in-place form).
    let side = |w: [f64; 3], up: bool| [w[0], w[1], if up { w[2] } else { -w[2] }];
    let values = tabulate(g, |wi, wo, k| f(side(wi, up_i), side(wo, up_o), k));
    Table::new(Metadata::new("test", g, "{}", "{}", "none"), values).unwrap()
}

#[test]
fn between_centres_each_block_is_a_one_faced_lookup_of_its_side() {
    let b = lookup();
    let blocks: Vec<Brdf> = (0..4)
        .map(|k| Brdf::from_table(block_table(k), Options::default()).unwrap())
        .collect();
    let mut rng = Rng(12345);
    let mut u = || rng.next();
    let mut errs = Vec::new();
    for _ in 0..4000 {
        let (ti, to) = (FRAC_PI_2 * 0.999 * u(), FRAC_PI_2 * 0.999 * u());
        let (up_i, up_o) = (u() < 0.5, u() < 0.5);
        let (pi, po) = (TAU * u(), TAU * u());
        let (wi, wo) = (dir(ti, pi), dir(to, po));
        let flip = |w: [f64; 3], up: bool| [w[0], w[1], if up { w[2] } else { -w[2] }];
        let k = match (up_i, up_o) {
            (true, true) => 0,
            (true, false) => 1,
            (false, false) => 2,
            (false, true) => 3,
        };
        let got = b.eval(f32s(flip(wi, up_i)), f32s(flip(wo, up_o)));
        let want = blocks[k].eval(f32s(wi), f32s(wo));
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= 1e-5 * want[c],
                "block {k} at {wi:?} {wo:?}: {got:?} vs {want:?}"
            );
        }
        if ti > 0.2 && ti < 1.3 && to > 0.2 && to < 1.3 {
            let exact = f(flip(wi, up_i), flip(wo, up_o), 1);
            let e = (f64::from(got[1]) - exact).abs() / exact;
            errs.push(e);
        }
    }
    // And against the function itself (pairs away from the normal and the plane): the
    // interpolation error of a glossy lobe on 15-degree polar and 30-36-degree azimuth cells,
    // 4.4% in the mean and 36% at worst here; a block looked up on the wrong side (levels 0.1
    // to 0.4) would be off by 100-300% on average.
    let mean = errs.iter().sum::<f64>() / errs.len() as f64;
    let worst = errs.iter().fold(0.0f64, |a, &e| a.max(e));
    assert!(mean < 0.08 && worst < 0.5, "mean {mean}, worst {worst}");
}

#[test]
fn the_plane_and_nan_give_zero() {
    let b = lookup();
    let up = f32s(dir(0.3, 0.2));
    assert_eq!(b.eval([1.0, 0.0, 0.0], up), [0.0; 3]);
    assert_eq!(b.eval(up, [0.0, 1.0, 0.0]), [0.0; 3]);
    assert_eq!(b.eval([f32::NAN, 0.0, 1.0], up), [0.0; 3]);
    assert_eq!(b.openness([1.0, 0.0, 0.0]), 0.0);
    assert_eq!(b.sample([1.0, 0.0, 0.0], 0.3, 0.4).pdf, 0.0);
}

#[test]
fn the_openness_interpolates_the_incident_cells_of_its_side() {
    let t = table();
    let b = lookup();
    let g = t.meta.grid;
    let o = t.meta.openness.as_ref().unwrap();
    for ti in 0..g.n_theta_i {
        for pi in [0, 5] {
            let wi = dir(g.theta_i_deg(ti).to_radians(), g.phi_i_deg(pi).to_radians());
            let got = b.openness(f32s(wi));
            let want = o[(ti * g.n_phi_i + pi) as usize];
            assert!(
                (got - want).abs() < 1e-6,
                "cell ({ti}, {pi}): {got} vs {want}"
            );
        }
    }
    // At the normals: the first rings, held (0.2 and 0.15 at their centres' cos^2).
    let front = f64::from(b.openness([0.0, 0.0, 1.0]));
    let back = f64::from(b.openness([0.0, 0.0, -1.0]));
    assert!(
        (front - 0.2).abs() < 0.02 && (back - 0.15).abs() < 0.015,
        "{front} {back}"
    );
}

/// A midpoint rule over the sphere: `n x n` cells in (theta, phi) on each side, `f` given each
/// cell's centre direction and solid angle.
fn over_sphere(n: usize, mut f: impl FnMut([f64; 3], f64)) {
    let (dt, dp) = (FRAC_PI_2 / n as f64, TAU / n as f64);
    for side in [1.0, -1.0] {
        for i in 0..n {
            let theta = (i as f64 + 0.5) * dt;
            for j in 0..n {
                let mut w = dir(theta, (j as f64 + 0.5) * dp);
                w[2] *= side;
                f(w, theta.sin() * dt * dp);
            }
        }
    }
}

/// The density over the sphere by [`over_sphere`].
fn integral_of_pdf(b: &TwoFacedBrdf, wo: [f32; 3]) -> f64 {
    let mut sum = 0.0;
    over_sphere(200, |w, d| sum += f64::from(b.pdf(f32s(w), wo)) * d);
    sum
}

#[test]
fn the_density_integrates_to_one_over_the_sphere() {
    let b = lookup();
    for wo in [dir(0.4, 1.0), dir(PI - 0.9, 4.0), dir(1.4, 2.5)] {
        let total = integral_of_pdf(&b, f32s(wo));
        assert!((total - 1.0).abs() < 0.01, "{wo:?}: {total}");
    }
}

#[test]
fn samples_carry_their_density_and_estimate_the_albedo() {
    let b = lookup();
    for wo in [dir(0.5, 0.7), dir(PI - 0.6, 3.0)] {
        let wo32 = f32s(wo);
        let n = 40_000;
        let mut rng = Rng(99);
        let mut u = || rng.next() as f32;
        let (mut est, mut sides) = (0.0, [0usize; 2]);
        for _ in 0..n {
            let smp = b.sample(wo32, u(), u());
            assert!(smp.pdf > 0.0);
            let pdf = b.pdf(smp.wi, wo32);
            assert!((pdf - smp.pdf).abs() <= 1e-4 * pdf, "{} vs {pdf}", smp.pdf);
            est += f64::from(smp.weight[1]) / n as f64;
            sides[usize::from(smp.wi[2] > 0.0)] += 1;
        }
        // The albedo over the sphere by quadrature of the lookup itself.
        let mut albedo = 0.0;
        over_sphere(150, |w, d| {
            albedo += f64::from(b.eval(f32s(w), wo32)[1]) * w[2].abs() * d;
        });
        assert!(
            (est - albedo).abs() < 0.02 * albedo,
            "{wo:?}: estimate {est} vs {albedo}"
        );
        assert!(sides[0] > n / 10 && sides[1] > n / 10, "{sides:?}");
    }
}

#[test]
fn both_formats_round_trip_and_the_lookups_tell_the_kinds_apart() {
    let tmp = tempfile::tempdir().unwrap();
    let t = table();
    let bin = tmp.path().join("two.bin");
    let exr = tmp.path().join("two.exr");
    write_binary(&bin, &t, false).unwrap();
    write_exr(&exr, &t, Precision::F32, false).unwrap();
    for p in [&bin, &exr] {
        let back = read_table(p).unwrap();
        assert_eq!(back, t, "{}", p.display());
        // A one-faced lookup refuses it, naming the kind and the door.
        let e = Brdf::open(p, Options::default()).unwrap_err().to_string();
        assert!(e.contains("two-faced") && e.contains("TwoFacedBrdf"), "{e}");
        // Lookup opens either kind.
        let any = Lookup::open(p, Options::default()).unwrap().into_bsdf();
        let (wi, wo) = (dir_unit(0.3, 0.1, false), dir_unit(0.5, 2.0, true));
        let want = lookup().eval(f32s(wi.into_arr()), f32s(wo.into_arr()));
        let got = any.f(wi, wo);
        assert_eq!(got, want.map(f64::from), "{}", p.display());
        assert!(any.openness(dir_unit(0.1, 0.0, true)) > 0.1);
    }
    // Half floats keep the blocks (rounded once).
    let half = tmp.path().join("half.exr");
    write_exr(&half, &t, Precision::F16, false).unwrap();
    let h = TwoFacedBrdf::open(&half, Options::default()).unwrap();
    let (wi, wo) = (f32s(dir(2.5, 0.3)), f32s(dir(0.7, 1.1)));
    let (a, b) = (h.eval(wi, wo), lookup().eval(wi, wo));
    assert!((a[0] - b[0]).abs() < 1e-3 * b[0], "{a:?} {b:?}");
    // A one-faced table is refused by the two-faced lookup.
    let one = tmp.path().join("one.bin");
    let g = Grid::new(2, 4, 2, 4);
    write_binary(
        &one,
        &Table::new(
            Metadata::new("t", g, "{}", "{}", "none"),
            vec![0.1; 3 * g.len()],
        )
        .unwrap(),
        false,
    )
    .unwrap();
    let e = TwoFacedBrdf::open(&one, Options::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("one-faced"), "{e}");
    assert!(matches!(
        Lookup::open(&one, Options::default()),
        Ok(Lookup::One(_))
    ));
}

fn dir_unit(theta: f64, phi: f64, up: bool) -> clothbake_loader::UnitVec3 {
    let mut d = dir(theta, phi);
    if !up {
        d[2] = -d[2];
    }
    clothbake_loader::UnitVec3::new(clothbake_bsdf::Vec3::new(d[0], d[1], d[2])).unwrap()
}

trait Arr {
    fn into_arr(self) -> [f64; 3];
}

impl Arr for clothbake_loader::UnitVec3 {
    fn into_arr(self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }
}

#[test]
fn a_bad_openness_is_refused() {
    let t = table();
    let g = t.meta.grid;
    let with = |o: Option<Vec<f32>>| {
        let mut m = t.meta.clone();
        m.openness = o;
        Table::new(m, t.values.clone())
    };
    let msg = |r: Result<Table, TableError>| r.unwrap_err().to_string();
    let n = (g.n_theta_i * g.n_phi_i) as usize;
    assert!(msg(with(None)).contains("needs the openness"));
    assert!(msg(with(Some(vec![0.1; n - 1]))).contains("incident cells"));
    let mut bad = vec![0.1; n];
    bad[7] = 1.5;
    assert!(msg(with(Some(bad))).contains("in [0, 1]"));
    bad = vec![0.1; n];
    bad[3] = f32::NAN;
    assert!(msg(with(Some(bad))).contains("incident cell 3"));
    // A two-faced table is at version 2, so that a reader of version 1 alone refuses it.
    assert_eq!(t.meta.format_version, clothbake_loader::TWO_FACED_VERSION);
    let mut v1 = t.meta.clone();
    v1.format_version = clothbake_loader::FORMAT_VERSION;
    assert!(msg(Table::new(v1, t.values.clone())).contains("a two-faced table is version 2"));
    // A one-faced table has none.
    let one = Grid::new(2, 2, 2, 2);
    let mut m = Metadata::new("t", one, "{}", "{}", "none");
    m.openness = Some(vec![0.0; 4]);
    assert!(msg(Table::new(m, vec![0.1; 3 * one.len()])).contains("one-faced"));
}

#[test]
fn the_reciprocal_option_pairs_the_two_transmissions() {
    let plain = lookup();
    let b = TwoFacedBrdf::from_table(
        table(),
        Options {
            reciprocal: true,
            ..Options::default()
        },
    )
    .unwrap();
    let (a, c) = (f32s(dir(0.4, 0.3)), f32s(dir(PI - 0.7, 2.0)));
    // Light from the front to the eye at the back, and back: equal, the mean of both blocks.
    assert_eq!(b.eval(a, c), b.eval(c, a));
    let (x, y) = (plain.eval(a, c), plain.eval(c, a));
    assert!(x != y, "the test table is not reciprocal");
    let want = [0, 1, 2].map(|k| 0.5 * (x[k] + y[k]));
    assert_eq!(b.eval(a, c), want);
}
