//! Project chores: `cargo xtask <task>`.
//!
//! * `test [ARGS]`: the whole suite on a fresh machine: a local `.venv` with numpy, pytest,
//!   OpenEXR and mitsuba, then fmt, clippy and `cargo test --workspace [ARGS]` (see `test.rs`).
//! * `install-capi PREFIX`: the C API's header, libraries and pkg-config file under PREFIX (see
//!   `install_capi.rs`).
//! * `ch5`: the comparisons of thesis sec. 5.4 (sphere, disk, convergence) into
//!   `docs/results/interreflection.md`.
//! * `transport`: full light transport (every bounce, path-traced on the micro-geometry): the
//!   perpendicular share of I_2 and the orders past the second per shipped fabric, the furnace
//!   test and the orders at n = 1, into `docs/science/transport.md` (between its `transport` markers).
//! * `figures`: the thesis's rendered scenes (Figs 4.5, 5.10, 5.11, 5.17), the weave up
//!   close (`up-close`), the yarns against the truth and ThunderLoom (`yarns`) and `clothbake
//!   plot`'s three kinds (`plots`) into `docs/figures/`.
//! * `gallery [--quick] [--envmap FILE.exr]`: pictures of every shipped fabric rendered by
//!   Mitsuba 3 (draped over a ball under a sky, path traced) into `docs/gallery/` (see
//!   `gallery.rs`).
//! * `fitted`: the residuals of the fitted standard materials of every shipped fabric, into
//!   `docs/guide/export.md` (see `fitted.rs`).
//! * `lod`: the level-of-detail pictures (point, cells, period) against the ground-truth
//!   pictures at six distances, into `docs/results/validation.md` (see `lod.rs`).
//! * `error-sources`: the model's error split into masking, shadowing and shading, into
//!   docs/results/validation.md.
//! * `transmission`: the two-faced cloth's model against its ray tracer (both faces,
//!   transmission, openness) into docs/results/validation.md (see `transmission.rs`).
//! * `validate-spatial`: the model per crossing cell against the truth sorted into the same
//!   cells, written to `docs/results/validation-spatial.md`.
//! * `validate`: holds the analytic model against the ray-traced ground truth for every shipped
//!   fabric and writes the error tables to `docs/results/validation.md`.
//! * `golden`: bakes every shipped fabric (`tables/*.json`) at the golden grid into
//!   `tables/golden/<name>.bin` (see `clothbake_bake::golden` and `docs/guide/baking.md`).
//! * `bench-bake [--bounces-2]`: times the default-grid bake of the twill with 1 and 2 threads
//!   (and, with `--bounces-2`, once with the secondary reflection).
//! * `loader-accuracy`: the loader's interpolation error on the twill for several grids, into
//!   the table of `docs/reference/loader.md` (between its `loader-accuracy` markers).
//! * `ir-accuracy`: the secondary reflection's analytic orders and two-level sampling settings
//!   against a converged rule, into the table of `docs/science/interreflection.md`; with `--scan`, a grid
//!   of sampling settings and analytic orders on the benchmark's surfaces, the parallel
//!   cylinders and the twill (printed only).

use clothbake_bake::golden::{bake_golden, golden_path, shipped_fabrics};
use clothbake_bake::{bake, BakeOptions};
mod ch5;
mod error_sources;
mod figures;
mod fitted;
mod gallery;
mod install_capi;
mod ir_accuracy;
mod lod;
mod spatial;
mod test;
mod transmission;
mod transport;

use clothbake_core::directions::direction_set;
use clothbake_core::{Fabric, FacetModel, Variant};
use clothbake_loader::write_binary;
use clothbake_tests::validate::{compare_with, Report};
use clothbake_truth::Caps;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

const TABLES: [&str; 6] = ["plain", "basket", "twill", "twill31", "satin5", "parallel"];

/// Replaces the section of the document `path` between `<!-- name:begin -->` and
/// `<!-- name:end -->` by `section` (which holds both markers), or appends it.
pub fn replace_section(path: &Path, name: &str, section: &str) {
    let doc = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let (begin, end) = (
        format!("<!-- {name}:begin -->"),
        format!("<!-- {name}:end -->"),
    );
    let new = match (doc.find(&begin), doc.find(&end)) {
        (Some(a), Some(b)) => format!("{}{}{}", &doc[..a], section, &doc[b + end.len()..]),
        _ => format!("{}\n\n{section}\n", doc.trim_end()),
    };
    std::fs::write(path, new).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
}

fn root() -> PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    p.canonicalize().unwrap_or(p)
}

fn main() {
    let task = std::env::args().nth(1).unwrap_or_default();
    match task.as_str() {
        "test" => test::run_all(&root(), &std::env::args().skip(2).collect::<Vec<_>>()),
        "install-capi" => install_capi::run(&root(), &std::env::args().skip(2).collect::<Vec<_>>()),
        "validate" => validate(),
        "validate-spatial" => spatial::run(&root()),
        "error-sources" => error_sources::run(&root()),
        "transmission" => transmission::run(&root()),
        "lod" => lod::run(&root()),
        "fitted" => fitted::run(&root()),
        "ch5" => ch5::run(&root()),
        "transport" => transport::run(&root(), std::env::args().nth(2).as_deref()),
        "figures" => figures::run(&root(), &std::env::args().skip(2).collect::<Vec<_>>()),
        "gallery" => gallery::run(&root(), &std::env::args().skip(2).collect::<Vec<_>>()),
        "golden" => golden(),
        "bench-bake" => bench_bake(std::env::args().skip(2).any(|a| a == "--bounces-2")),
        "loader-accuracy" => loader_accuracy(),
        "ir-accuracy" if std::env::args().skip(2).any(|a| a == "--scan") => {
            ir_accuracy::scan(&root())
        }
        "ir-accuracy" => ir_accuracy::run(&root()),
        _ => {
            eprintln!(
                "usage: cargo xtask test [CARGO TEST ARGS] | install-capi PREFIX | validate | validate-spatial | error-sources | lod | fitted | golden | ch5 | figures [fig4-5|disks|fig5-17|up-close|plots|yarns [--thunderloom DIR]] | gallery [--quick] [--envmap FILE.exr] [--only NAME,...] | bench-bake [--bounces-2] | loader-accuracy | ir-accuracy [--scan]"
            );
            std::process::exit(2);
        }
    }
}

fn pct(x: f64) -> String {
    format!("{:.2}%", 100.0 * x)
}

fn row(out: &mut String, name: &str, what: &str, r: &Report) {
    writeln!(
        out,
        "| {name} | {what} | {} | {} | {:+.2}% | {} |",
        pct(r.mean_rel_err()),
        pct(r.max_rel_err()),
        100.0 * r.mean_bias(),
        pct(r.mean_noise())
    )
    .unwrap();
}

fn validate() {
    let (pairs_n, samples, seed) = (96, 100_000, 11);
    let mut out = String::new();
    writeln!(
        out,
        "# Validation: analytic model against the ray-traced ground truth\n\n\
         Generated by `cargo xtask validate` (do not edit by hand). For each shipped fabric, {pairs_n} \
         (wi, wo) pairs uniform in solid angle with both polar angles at most the stated bound \
         (`directions::direction_set`), {samples} primary rays each. Error measure: relative error of the \
         channel-mean total intensity I = I_d + I_s, |analytic - traced| / traced; bias is the mean signed \
         relative difference; noise is the ground truth's own mean relative standard error.\n\n\
         Facets: rho_d 0.4, rho_s 0.3, n 10 (sec. 4.3). `refined`, `thesis` and `sliced` are the analytic \
         variants (docs/science/model.md); `caps excluded` is the ground-truth convention the model is held to, `caps shaded` \
         shows what flat yarn ends would add if they were averaged as yarn surface. The same model resolved \
         per crossing cell of the period: docs/results/validation-spatial.md (`cargo xtask validate-spatial`).\n"
    )
    .unwrap();
    for (bound, title) in [
        (
            70.0,
            "directions up to 70 degrees (the contract: mean < 10%)",
        ),
        (85.0, "directions up to 85 degrees"),
    ] {
        let pairs = direction_set(pairs_n, bound);
        writeln!(out, "\n## {title}\n\n| fabric | configuration | mean rel. err | max rel. err | bias | noise |\n|---|---|---|---|---|---|").unwrap();
        for name in TABLES {
            let f = Fabric::from_path(&root().join(format!("tables/{name}.json"))).unwrap();
            let configs: &[(&str, FacetModel, Variant, Caps)] = if bound <= 70.0 {
                &[
                    (
                        "huo, refined, caps excluded",
                        FacetModel::Huo,
                        Variant::Refined,
                        Caps::Excluded,
                    ),
                    (
                        "huo, thesis, caps excluded",
                        FacetModel::Huo,
                        Variant::Thesis,
                        Caps::Excluded,
                    ),
                    (
                        "huo, sliced, caps excluded",
                        FacetModel::Huo,
                        Variant::Sliced,
                        Caps::Excluded,
                    ),
                    (
                        "huo, sliced3d, caps excluded",
                        FacetModel::Huo,
                        Variant::Sliced3d,
                        Caps::Excluded,
                    ),
                    (
                        "lewis, refined, caps excluded",
                        FacetModel::Lewis,
                        Variant::Refined,
                        Caps::Excluded,
                    ),
                    (
                        "huo, refined, caps shaded",
                        FacetModel::Huo,
                        Variant::Refined,
                        Caps::Shaded,
                    ),
                ]
            } else {
                &[
                    (
                        "huo, refined, caps excluded",
                        FacetModel::Huo,
                        Variant::Refined,
                        Caps::Excluded,
                    ),
                    (
                        "huo, sliced, caps excluded",
                        FacetModel::Huo,
                        Variant::Sliced,
                        Caps::Excluded,
                    ),
                    (
                        "huo, sliced3d, caps excluded",
                        FacetModel::Huo,
                        Variant::Sliced3d,
                        Caps::Excluded,
                    ),
                ]
            };
            for &(what, facet, variant, caps) in configs {
                let r = compare_with(&f, facet, variant, caps, &pairs, samples, seed);
                row(&mut out, name, what, &r);
                eprintln!("{name} {what}: mean {:.4}", r.mean_rel_err());
            }
        }
    }
    // Direction by direction for the thesis's twill.
    let f = Fabric::from_path(&root().join("tables/twill.json")).unwrap();
    let r = compare_with(
        &f,
        FacetModel::Huo,
        Variant::Refined,
        Caps::Excluded,
        &direction_set(16, 70.0),
        samples,
        seed,
    );
    writeln!(out, "\n## The twill direction by direction (huo, refined, caps excluded)\n\n| theta_i | phi_i | theta_o | phi_o | analytic I | traced I | std. err | rel. diff |\n|---|---|---|---|---|---|---|---|").unwrap();
    for c in &r.rows {
        let (ti, pi) = c.pair.0.to_spherical();
        let (to, po) = c.pair.1.to_spherical();
        writeln!(
            out,
            "| {:.1} | {:.1} | {:.1} | {:.1} | {:.4} | {:.4} | {:.4} | {:+.2}% |",
            ti.to_degrees(),
            pi.to_degrees(),
            to.to_degrees(),
            po.to_degrees(),
            c.analytic,
            c.traced,
            c.std_err,
            100.0 * (c.analytic - c.traced) / c.traced
        )
        .unwrap();
    }
    let path = root().join("docs/results/validation.md");
    // Keep the sections `cargo xtask transport`, `validate-spatial` and `lod` write between
    // markers.
    let old = std::fs::read_to_string(&path).unwrap_or_default();
    for marker in [
        "transport-validation",
        "spatial-validation",
        "lod-validation",
        "error-sources",
        "transmission-validation",
    ] {
        let (begin, end) = (
            format!("<!-- {marker}:begin -->"),
            format!("<!-- {marker}:end -->"),
        );
        let keep = old
            .find(&begin)
            .zip(old.find(&end))
            .map(|(a, b)| old[a..b + end.len()].to_string());
        out.push('\n');
        out.push_str(&keep.unwrap_or(format!("{begin}\n{end}")));
        out.push('\n');
    }
    std::fs::write(&path, out).unwrap();
    eprintln!("wrote {}", path.display());
}

/// Bakes the golden table of every shipped fabric.
fn golden() {
    let tables = root().join("tables");
    let dir = tables.join("golden");
    std::fs::create_dir_all(&dir).unwrap();
    let fabrics = shipped_fabrics(&tables).unwrap();
    // Remove golden tables whose fabric is gone.
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
        if p.extension().is_some_and(|x| x == "bin") && !fabrics.iter().any(|(n, _)| *n == stem) {
            std::fs::remove_file(&p).unwrap();
            eprintln!("removed {} (no tables/{stem}.json)", p.display());
        }
    }
    for (name, path) in fabrics {
        let f = Fabric::from_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let t = bake_golden(&f).unwrap_or_else(|e| panic!("{name}: {e}"));
        let out = golden_path(&tables, &name);
        write_binary(&out, &t, true).unwrap_or_else(|e| panic!("{e}"));
        eprintln!("wrote {} ({})", out.display(), t.meta.grid);
    }
}

/// Bakes `opts` for `f` on a pool of `threads`, returning (seconds, cells evaluated).
fn timed_bake(f: &Fabric, opts: &BakeOptions, threads: usize) -> (f64, usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let start = Instant::now();
    let b = pool
        .install(|| bake(f, opts, &|_| {}, &AtomicBool::new(false)))
        .unwrap();
    (start.elapsed().as_secs_f64(), b.evaluated)
}

/// Times the default-grid bake of the twill, direct reflection, with 1 and 2 threads (best of
/// 3 each), and optionally once with two bounces on all cores.
fn bench_bake(bounces_2: bool) {
    let f = Fabric::from_path(&root().join("tables/twill.json")).unwrap();
    let opts = BakeOptions::default();
    let cells = opts.grid.len() as f64;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "twill, grid {} ({} cells), analytic, refined, huo, bounces 1; {cores} cores",
        opts.grid, cells
    );
    println!("| threads | wall time (best of 3) | table entries/s | evaluations/s |");
    println!("|---|---|---|---|");
    let mut best = Vec::new();
    for threads in [1, 2] {
        let runs: Vec<(f64, usize)> = (0..3).map(|_| timed_bake(&f, &opts, threads)).collect();
        let (t, evaluated) = runs
            .iter()
            .copied()
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap();
        println!(
            "| {threads} | {t:.2} s | {:.0} | {:.0} |",
            cells / t,
            evaluated as f64 / t
        );
        best.push(t);
    }
    println!(
        "parallel efficiency t1 / (2 t2) = {:.2}",
        best[0] / (2.0 * best[1])
    );
    if bounces_2 {
        let opts = BakeOptions {
            bounces: clothbake_bake::BakeBounces::Two(Default::default()),
            ..BakeOptions::default()
        };
        let (t, evaluated) = timed_bake(&f, &opts, cores);
        println!(
            "bounces 2 (secondary analytic, radiometric kernel), {cores} threads: {t:.1} s, {:.0} \
             table entries/s, {:.0} evaluations/s",
            cells / t,
            evaluated as f64 / t
        );
    }
}

/// The loader's interpolation error against the analytic model (see
/// `clothbake_tests::accuracy`), written between the markers of `docs/reference/loader.md`.
fn loader_accuracy() {
    use clothbake_loader::{Grid, Precision};
    use clothbake_tests::accuracy::{baked_brdf, measure};
    let (pairs, seed) = (20_000, 7);
    let fabric = Fabric::from_path(&root().join("tables/twill.json")).expect("tables/twill.json");
    let grid = |t: u32, p: u32| Grid::new(t, p, t, p);
    let cases = [
        (grid(8, 16), Precision::F32),
        (grid(16, 32), Precision::F32),
        (grid(32, 64), Precision::F16),
        (grid(32, 64), Precision::F32),
        (grid(48, 96), Precision::F16),
    ];
    let mut out = String::new();
    writeln!(
        out,
        "Generated by `cargo xtask loader-accuracy` (do not edit by hand): the twill \
         (`tables/twill.json`, n = 10), direct reflection, {pairs} random direction pairs uniform in \
         solid angle (seed {seed}); error of a pair: the largest over R, G, B of \
         |f_table - f_model| / f_model, the same for f_r cos theta_i.\n\n\
         | grid | memory | mean | 99th percentile | max | pairs with a zero model value |\n\
         |---|---|---|---|---|---|"
    )
    .unwrap();
    for (g, precision) in cases {
        let t = Instant::now();
        let brdf = baked_brdf(&fabric, g, precision);
        let a = measure(&fabric, &brdf, pairs, seed);
        eprintln!(
            "{g} {precision:?}: {a:?} ({:.1} s)",
            t.elapsed().as_secs_f64()
        );
        writeln!(
            out,
            "| {}x{}x{}x{} | {} | {} | {} | {} | {} |",
            g.n_theta_i,
            g.n_phi_i,
            g.n_theta_o,
            g.n_phi_o,
            match precision {
                Precision::F16 => "f16",
                Precision::F32 => "f32",
            },
            pct(a.mean),
            pct(a.p99),
            pct(a.max),
            a.zero
        )
        .unwrap();
    }
    let path = root().join("docs/reference/loader.md");
    let doc = std::fs::read_to_string(&path).expect("docs/reference/loader.md");
    let (begin, end) = (
        "<!-- loader-accuracy:begin -->",
        "<!-- loader-accuracy:end -->",
    );
    let (Some(b), Some(e)) = (doc.find(begin), doc.find(end)) else {
        eprintln!("docs/reference/loader.md lacks the markers {begin} and {end}");
        std::process::exit(1);
    };
    let new = format!("{}{begin}\n{out}{}", &doc[..b], &doc[e..]);
    clothbake_loader::write_atomic_as(&path, "document", true, |w| {
        std::io::Write::write_all(w, new.as_bytes())
    })
    .expect("write docs/reference/loader.md");
    println!("wrote {}", path.display());
}
