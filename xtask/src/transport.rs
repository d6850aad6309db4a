//! `cargo xtask transport`: the numbers of docs/science/transport.md (between its `transport` markers):
//! per shipped fabric the perpendicular share of I_2 and the energy of the orders past the
//! second, the furnace test, and the convergence of the orders on the parallel surface.

use clothbake_bake::golden::fabric_files;
use clothbake_bake::transport::{Transport, ALL_BOUNCES};
use clothbake_core::directions::direction_set;
use clothbake_core::{AnalyticModel, Fabric, FacetModel, PlainNaming};
use clothbake_core::{Kernel, UnitVec3};
use clothbake_truth::{PathOptions, RayTracer};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::Path;

/// Direction pairs of the per-fabric table and their polar bound.
const PAIRS: usize = 16;
const BOUND: f64 = 60.0;
/// Paths per pair.
const PATHS: usize = 40_000;

fn mean_channel(v: [f64; 3]) -> f64 {
    (v[0] + v[1] + v[2]) / 3.0
}

/// The parallel surface of tables/parallel.json with a material.
fn parallel(root: &Path, albedo: f64, specular: f64, exponent: f64) -> Fabric {
    Fabric::from_path(&root.join("tables/parallel.json"))
        .unwrap()
        .with_groups(
            |_, g| {
                g.material.albedo = [albedo; 3];
                g.material.specular = specular;
                g.material.exponent = exponent;
            },
            &PlainNaming("parallel"),
        )
        .unwrap()
}

/// Per shipped fabric: perpendicular share of I_2 and the orders past the second.
fn fabrics(out: &mut String, root: &Path) {
    let pairs = direction_set(PAIRS, BOUND);
    writeln!(
        out,
        "### Every shipped fabric\n\n{PAIRS} direction pairs up to {BOUND} degrees \
         (`directions::direction_set({PAIRS}, {BOUND})`), {PATHS} paths each, Huo facets with each \
         fabric's own material, radiometric kernel, all bounces (roulette from order 4). I_1 is \
         the analytic direct term; I_2 and I_3+ (orders 3 and up) are path-traced; values are \
         channel means. `perp. share` is the perpendicular part of I_2 summed over the pairs over \
         I_2 summed (worst pair in brackets, pairs with I_2 > 1% of I_1); `I_2 / I_1` and \
         `I_3+ / I_1` are means over the pairs (largest pair in brackets); `se` the standard \
         error of the mean I_3+ / I_1. `perp. / par.` is the thesis's measure, the \
         perpendicular part over the parallel part (sums over the pairs); the last column \
         says which of the two quarters it stays under.\n\n\
         | fabric | I_2 / I_1 | perp. share of I_2 | perp. / par. | I_3+ / I_1 | se | under a quarter? |\n\
         |---|---|---|---|---|---|---|"
    )
    .unwrap();
    for path in fabric_files(&root.join("tables")).unwrap() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let f = Fabric::from_path(&path).unwrap();
        let model = AnalyticModel::new(&f, FacetModel::Huo);
        let t = Transport::new(RayTracer::new(&f, FacetModel::Huo), ALL_BOUNCES, PATHS, 5);
        let rows: Vec<(f64, f64, f64, f64, f64)> = pairs
            .par_iter()
            .map(|&(wi, wo)| {
                let i1 = mean_channel(model.intensity(wi, wo).direct());
                let p = t.multiple(wi, wo);
                let i2 = mean_channel(p.orders[1]);
                let perp = mean_channel(p.i2_split[1]);
                let rest = mean_channel(p.multiple) - i2;
                let rest_err = mean_channel(p.multiple_err).hypot(mean_channel(p.std_err[1]));
                (i1, i2, perp, rest, rest_err)
            })
            .collect();
        let n = rows.len() as f64;
        let i2_sum: f64 = rows.iter().map(|r| r.1).sum();
        let perp_sum: f64 = rows.iter().map(|r| r.2).sum();
        let worst_share = rows
            .iter()
            .filter(|r| r.1 > 0.01 * r.0)
            .map(|r| r.2 / r.1)
            .fold(0.0, f64::max);
        let r2: Vec<f64> = rows.iter().map(|r| r.1 / r.0).collect();
        let r3: Vec<f64> = rows.iter().map(|r| r.3 / r.0).collect();
        let se3 = rows.iter().map(|r| (r.4 / r.0).powi(2)).sum::<f64>().sqrt() / n;
        let share = perp_sum / i2_sum;
        let mx = |v: &[f64]| v.iter().cloned().fold(0.0, f64::max);
        let ratio = perp_sum / (i2_sum - perp_sum);
        writeln!(
            out,
            "| {name} | {:.4} ({:.4}) | {:.1}% ({:.1}%) | {:.2} | {:.4} ({:.4}) | {:.4} | {} |",
            r2.iter().sum::<f64>() / n,
            mx(&r2),
            100.0 * share,
            100.0 * worst_share,
            ratio,
            r3.iter().sum::<f64>() / n,
            mx(&r3),
            se3,
            match (share < 0.25, ratio < 0.25) {
                _ if perp_sum == 0.0 => "both (none)",
                (true, true) => "both, on average",
                (true, false) => "share only, on average",
                _ => "neither",
            }
        )
        .unwrap();
        eprintln!("transport {name}: share {share:.3}");
    }
}

/// Directional albedo by the path tracer, all orders: `k` stratified cosine-distributed eye
/// directions, `paths` each.
fn albedo(f: &Fabric, facet: FacetModel, theta_i: f64, k: usize, paths: usize) -> (f64, f64) {
    let t = Transport::new(RayTracer::new(f, facet), ALL_BOUNCES, paths, 9);
    let wi = UnitVec3::from_degrees(theta_i, 30.0);
    let side = (k as f64).sqrt() as usize;
    let vals: Vec<f64> = (0..side * side)
        .into_par_iter()
        .map(|j| {
            let (u, v) = (
                ((j % side) as f64 + 0.5) / side as f64,
                ((j / side) as f64 + 0.5) / side as f64,
            );
            // Cosine-distributed: sin^2 theta = u.
            let theta = u.sqrt().asin().to_degrees().min(89.0);
            let wo = UnitVec3::from_degrees(theta, 360.0 * v);
            let p = t.all_orders(wi, wo);
            let i: f64 = (0..p.orders.len()).map(|o| mean_channel(p.orders[o])).sum();
            i / wi.z
        })
        .collect();
    let n = vals.len() as f64;
    let m = vals.iter().sum::<f64>() / n;
    let var = vals.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

fn furnace(out: &mut String, root: &Path) {
    writeln!(
        out,
        "\n### Furnace test (parallel surface, touching cylinders: no light reaches the floor)\n\n\
         Directional albedo a(theta_i) = integral of f_r cos theta_o over the eye's hemisphere \
         with every order, path-traced (64 stratified cosine-distributed eye directions, \
         20000 paths each; the standard error is the spread over the eye directions, the \
         quadrature error included). With albedo-1 Lambertian facets nothing is absorbed: the \
         white-furnace value is 1.\n\n\
         | facets | rho_d | rho_s | n | a(0) | a(30) | a(60) | a(80) |\n|---|---|---|---|---|---|---|---|"
    )
    .unwrap();
    for (facet, rd, rs, n) in [
        (FacetModel::Lewis, 1.0, 0.0, 1.0),
        (FacetModel::Lewis, 0.5, 0.49, 10.0),
        (FacetModel::Lewis, 0.0, 0.98, 30.0),
        (FacetModel::Huo, 0.4, 0.3, 10.0),
        (FacetModel::Huo, 0.4, 0.7, 1.0),
        (FacetModel::Huo, 0.4, 0.7, 10.0),
    ] {
        let f = parallel(root, rd, rs, n);
        let cells: Vec<String> = [0.0, 30.0, 60.0, 80.0]
            .iter()
            .map(|&t| {
                let (a, e) = albedo(&f, facet, t, 64, 20_000);
                format!("{a:.4} +- {e:.4}")
            })
            .collect();
        let name = match facet {
            FacetModel::Lewis => "Lewis",
            FacetModel::Huo => "Huo",
        };
        writeln!(
            out,
            "| {name} | {rd} | {rs} | {n} | {} |",
            cells.join(" | ")
        )
        .unwrap();
        eprintln!("furnace {name} {rd} {rs} {n}: {}", cells.join(", "));
    }
}

/// One facet's directional reflectance in the path tracer's sense, the mean of 2 I_F over the
/// hemisphere of incoming directions for an outgoing `e` (the factor a path's throughput is
/// multiplied by at a bounce, on average), by quadrature.
fn facet_gain(rd: f64, rs: f64, n: f64, theta_e: f64) -> f64 {
    let e = [theta_e.to_radians().sin(), 0.0, theta_e.to_radians().cos()];
    let (nt, np) = (400, 800);
    let mut sum = 0.0;
    for i in 0..nt {
        let th = (i as f64 + 0.5) / nt as f64 * PI / 2.0;
        for j in 0..np {
            let ph = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
            let w = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
            let h = [w[0] + e[0], w[1] + e[1], w[2] + e[2]];
            let hl = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            let i_f = rd * w[2] + rs * (h[2] / hl).powf(n);
            sum += i_f * th.sin();
        }
    }
    // (1 / pi) * integral of I_F dw.
    sum * (PI / 2.0 / nt as f64) * (2.0 * PI / np as f64) / PI
}

fn convergence(out: &mut String, root: &Path) {
    let pairs = direction_set(8, 60.0);
    let paths = 400_000;
    writeln!(
        out,
        "\n### The orders on the parallel surface at n = 1 (rho_d 0.4, rho_s 0.7)\n\n\
         The 8 pairs of the convergence table in docs/results/interreflection.md, {paths} paths \
         each instead of 40 000 (10 times smaller errors); I_k / I_1 averaged over the pairs \
         with its standard error; without roulette (as that table) and with roulette from \
         order 4 (as `--bounces all`).\n\n\
         | roulette | I_2/I_1 | I_3/I_1 | I_4/I_1 | I_5/I_1 | I_6/I_1 | I_7/I_1 | I_8/I_1 |\n\
         |---|---|---|---|---|---|---|---|"
    )
    .unwrap();
    let f = parallel(root, 0.4, 0.7, 1.0);
    let rt = RayTracer::new(&f, FacetModel::Huo);
    for roulette in [99, 4] {
        let per: Vec<(Vec<f64>, Vec<f64>)> = pairs
            .par_iter()
            .enumerate()
            .map(|(k, &(wi, wo))| {
                let p = rt.render_paths(
                    wi,
                    wo,
                    paths,
                    100 + k as u64,
                    PathOptions {
                        max_bounces: 8,
                        kernel: Kernel::Radiometric,
                        roulette_from: roulette,
                        first_order: 1,
                    },
                );
                let i1 = p.orders[0][0];
                (
                    (1..8).map(|o| p.orders[o][0] / i1).collect(),
                    (1..8).map(|o| p.std_err[o][0] / i1).collect(),
                )
            })
            .collect();
        let n = per.len() as f64;
        let cells: Vec<String> = (0..7)
            .map(|o| {
                let m = per.iter().map(|p| p.0[o]).sum::<f64>() / n;
                let e = per.iter().map(|p| p.1[o].powi(2)).sum::<f64>().sqrt() / n;
                format!("{m:.4} +- {e:.4}")
            })
            .collect();
        let name = if roulette > 8 { "none" } else { "from 4" };
        writeln!(out, "| {name} | {} |", cells.join(" | ")).unwrap();
        eprintln!("convergence roulette {name}: {}", cells.join(", "));
    }
    writeln!(
        out,
        "\nThe same surface at four direction pairs, 400 000 paths each, no roulette: I_k / I_1 \
         with its standard error. In the cross-section plane of the grooves (azimuths 0 and \
         180: across the cylinders) a path bounces from one wall of a groove to the other, so \
         the order fixes the wall its last vertex lies on: with the light and the eye on \
         opposite sides the lit wall faces the seen one's neighbour and the even orders carry \
         the light, with both on one side the odd orders do. Along the grooves (azimuths 90 \
         and 270) there is no alternation, and from the fifth order on the orders grow: the \
         facets' gain exceeds 1 (below).\n\n\
         | wi | wo | I_2/I_1 | I_3/I_1 | I_4/I_1 | I_5/I_1 | I_6/I_1 | I_7/I_1 | I_8/I_1 |\n\
         |---|---|---|---|---|---|---|---|---|"
    )
    .unwrap();
    for (wi, wo) in [
        ((40.0, 0.0), (40.0, 180.0)),
        ((40.0, 0.0), (30.0, 0.0)),
        ((40.0, 90.0), (40.0, 270.0)),
        ((40.0, 0.0), (40.0, 90.0)),
    ] {
        let p = rt.render_paths(
            UnitVec3::from_degrees(wi.0, wi.1),
            UnitVec3::from_degrees(wo.0, wo.1),
            paths,
            7,
            PathOptions {
                max_bounces: 8,
                kernel: Kernel::Radiometric,
                roulette_from: 99,
                first_order: 1,
            },
        );
        let i1 = p.orders[0][0];
        let cells: Vec<String> = (1..8)
            .map(|o| format!("{:.4} +- {:.4}", p.orders[o][0] / i1, p.std_err[o][0] / i1))
            .collect();
        writeln!(
            out,
            "| {},{} | {},{} | {} |",
            wi.0,
            wi.1,
            wo.0,
            wo.1,
            cells.join(" | ")
        )
        .unwrap();
    }
    writeln!(
        out,
        "\nThe facet's gain, the mean factor a path's throughput is multiplied by at a bounce \
         ((1/pi) times the integral of I_F over the incoming hemisphere, for an eye at \
         theta_e from the facet's normal; 1 for an albedo-1 Lambertian facet):\n\n\
         | facets | theta_e 0 | 30 | 60 | 80 |\n|---|---|---|---|---|"
    )
    .unwrap();
    for (rd, rs, n) in [(0.4, 0.7, 1.0), (0.4, 0.7, 10.0), (0.4, 0.3, 10.0)] {
        let g: Vec<String> = [0.0, 30.0, 60.0, 80.0]
            .iter()
            .map(|&t| format!("{:.3}", facet_gain(rd, rs, n, t)))
            .collect();
        writeln!(out, "| Huo {rd}, {rs}, n {n} | {} |", g.join(" | ")).unwrap();
    }
}

/// The noise of a full-transport bake's multiple-bounce part on the default twill table: every
/// canonical cell's standard error (the nodes' combined by the interpolation weights) over the
/// analytic I_1 of the cell; and the time the nodes take.
fn bake_noise(out: &mut String, root: &Path) {
    use clothbake_bake::sweep::{direction, usable_symmetries, Orbits, DEFAULT_GRID};
    use clothbake_bake::transport::{Multiple, MAX_ROUNDS, PATHS, TARGET};
    let f = Fabric::from_path(&root.join("tables/twill.json")).unwrap();
    let g = DEFAULT_GRID;
    let orbits = Orbits::new(&g, &usable_symmetries(&f, &g));
    let model = AnalyticModel::new(&f, FacetModel::Huo);
    let m = Multiple::new(&f, FacetModel::Huo, &g, ALL_BOUNCES);
    let rows: Vec<usize> = (0..orbits.rows()).collect();
    let start = std::time::Instant::now();
    assert!(m.prepare(&g, &rows, &std::sync::atomic::AtomicBool::new(false)));
    let secs = start.elapsed().as_secs_f64();
    let mut rel: Vec<f64> = rows
        .par_iter()
        .flat_map_iter(|&r| {
            let orbits = &orbits;
            (0..orbits.row_evaluations(r)).filter_map(move |k| orbits.evaluated_cell(r, k))
        })
        .map(|(ti, pi, to, po)| {
            let wi = direction(ti, g.n_theta_i, pi, g.n_phi_i);
            let wo = direction(to, g.n_theta_o, po, g.n_phi_o);
            let f1 = mean_channel(model.intensity(wi, wo).brdf(wi));
            m.residual(wi, wo).1 / f1
        })
        .collect();
    rel.sort_by(f64::total_cmp);
    let n = rel.len();
    let q = |p: f64| rel[((p * (n - 1) as f64).round() as usize).min(n - 1)];
    let c = m.grid();
    writeln!(
        out,
        "\n### Noise of a full-transport bake (default twill table)\n\n\
         The {n} evaluated cells of the default 32 x 64 x 32 x 64 twill table with \
         `--bounces all`: the standard error of the multiple-bounce part (the coarse nodes' \
         errors combined by the interpolation weights) over the analytic I_1 of the cell. The \
         coarse grid is {c}; a node runs rounds of {PATHS} paths until its standard error is \
         at most {:.1}% of its I_1, or {MAX_ROUNDS} rounds.\n\n\
         | cells | median | 99th percentile | 99.99th percentile | largest |\n|---|---|---|---|---|\n\
         | {n} | {:.3}% | {:.3}% | {:.3}% | {:.3}% |\n\n\
         The nodes took {secs:.0} s on {} threads here (the whole bake adds the analytic direct \
         term and second bounce per cell).",
        100.0 * TARGET,
        100.0 * q(0.5),
        100.0 * q(0.99),
        100.0 * q(0.9999),
        100.0 * rel[n - 1],
        rayon::current_num_threads()
    )
    .unwrap();
    eprintln!(
        "bake noise: median {:.5} max {:.5}, {secs:.0} s",
        q(0.5),
        rel[n - 1]
    );
}

/// The shipped full-transport bake's multiple-bounce part against a brute-force path trace
/// (another seed, no roulette, every order gathered, at the exact directions): the table of
/// docs/results/validation.md between its `transport-validation` markers.
fn validation(root: &Path) -> String {
    use clothbake_bake::sweep::DEFAULT_GRID;
    use clothbake_bake::transport::{Multiple, PATHS};
    use clothbake_core::rng::Rng;
    let (n, bound, brute) = (50, 70.0, 200_000);
    let mut rng = Rng::stream(2026, 0);
    let cmax = 1.0 - f64::to_radians(bound).cos();
    let mut dir = move || {
        let z: f64 = 1.0 - cmax * rng.next_f64();
        UnitVec3::from_degrees(z.acos().to_degrees(), 360.0 * rng.next_f64())
    };
    let pairs: Vec<(UnitVec3, UnitVec3)> = (0..n).map(|_| (dir(), dir())).collect();
    let mut out = format!(
        "\n## Full transport: the multiple-bounce part of a `--bounces all` table\n\n\
         Generated by `cargo xtask transport` (docs/science/transport.md). The part a default-grid \
         `bake --bounces all` adds to the direct term (the analytic second bounce plus the \
         residual interpolated from the coarse grid's nodes, rounds of {PATHS} paths a node) against a \
         brute-force path trace of orders 2 and up at the exact directions ({brute} paths, \
         another seed, no Russian roulette, every order gathered), at {n} random direction \
         pairs uniform in solid angle up to {bound} degrees; Huo facets with the fabric's \
         material; channel means. The tolerance is 3 standard errors (both estimates) plus 1% \
         of the analytic I_1 (the test `crates/clothbake-bake/tests/transport.rs` checks the \
         same with rounds of 8192 paths a node and 40 000 brute-force paths).\n\n\
         | fabric | part / I_1 (mean) | mean abs. diff / I_1 | worst abs. diff / I_1 | worst diff / tolerance | within |\n\
         |---|---|---|---|---|---|\n"
    );
    for name in ["parallel", "twill"] {
        let f = Fabric::from_path(&root.join(format!("tables/{name}.json"))).unwrap();
        let m = Multiple::new(&f, FacetModel::Huo, &DEFAULT_GRID, ALL_BOUNCES);
        let model = AnalyticModel::new(&f, FacetModel::Huo);
        let rt = RayTracer::new(&f, FacetModel::Huo);
        let opts = PathOptions::brute_force();
        let rows: Vec<[f64; 5]> = pairs
            .par_iter()
            .enumerate()
            .map(|(k, &(wi, wo))| {
                let i1 = mean_channel(model.intensity(wi, wo).direct());
                let (t, te) = m.part(wi, wo);
                let to_i = PI * wi.z;
                let b = rt.render_paths(wi, wo, brute, 7_000_003 + k as u64, opts);
                [
                    i1,
                    mean_channel(t) * to_i,
                    te * to_i,
                    mean_channel(b.multiple),
                    mean_channel(b.multiple_err),
                ]
            })
            .collect();
        let nn = rows.len() as f64;
        let part = rows.iter().map(|r| r[3] / r[0]).sum::<f64>() / nn;
        let d: Vec<f64> = rows.iter().map(|r| (r[1] - r[3]).abs() / r[0]).collect();
        let tol: Vec<f64> = rows
            .iter()
            .map(|r| (r[1] - r[3]).abs() / (3.0 * r[2].hypot(r[4]) + 0.01 * r[0]))
            .collect();
        let within = tol.iter().filter(|&&x| x <= 1.0).count();
        writeln!(
            out,
            "| {name} | {:.2}% | {:.3}% | {:.3}% | {:.2} | {within} of {n} |",
            100.0 * part,
            100.0 * d.iter().sum::<f64>() / nn,
            100.0 * d.iter().cloned().fold(0.0, f64::max),
            tol.iter().cloned().fold(0.0, f64::max)
        )
        .unwrap();
        eprintln!("validation {name}: within {within}");
    }
    out
}

/// Regenerates the numbers of docs/science/transport.md between its markers; `only` names one part
/// (fabrics, furnace, convergence, bake) to print it without writing the file.
pub fn run(root: &Path, only: Option<&str>) {
    let mut out = String::new();
    match only {
        Some("fabrics") => fabrics(&mut out, root),
        Some("furnace") => furnace(&mut out, root),
        Some("convergence") => convergence(&mut out, root),
        Some("bake") => bake_noise(&mut out, root),
        Some("validation") => {
            let v = validation(root);
            write_between(
                &root.join("docs/results/validation.md"),
                "transport-validation",
                &v,
            );
            out = v;
        }
        Some(other) => {
            panic!("unknown part {other}; give fabrics, furnace, convergence, bake or validation")
        }
        None => {}
    }
    if only.is_some() {
        print!("{out}");
        return;
    }
    fabrics(&mut out, root);
    furnace(&mut out, root);
    convergence(&mut out, root);
    bake_noise(&mut out, root);
    print!("{out}");
    write_between(&root.join("docs/science/transport.md"), "transport", &out);
    let v = validation(root);
    print!("{v}");
    write_between(
        &root.join("docs/results/validation.md"),
        "transport-validation",
        &v,
    );
}

/// Replaces what lies between `<!-- {marker}:begin -->` and `<!-- {marker}:end -->` in `doc`.
pub fn write_between(doc: &Path, marker: &str, body: &str) {
    let text = std::fs::read_to_string(doc).unwrap();
    let (begin, end) = (
        format!("<!-- {marker}:begin -->\n"),
        format!("<!-- {marker}:end -->"),
    );
    let (a, b) = (text.find(&begin).unwrap(), text.find(&end).unwrap());
    let new = format!("{}{begin}{body}{}", &text[..a], &text[b..]);
    std::fs::write(doc, new).unwrap();
}
