//! Spatial lookups (issue 19, docs/science/spatial.md) beside the averaged lookup, in one run: the
//! twill baked with `--spatial` on the default grid, held in f16 as a default EXR holds it;
//! 2^20 distinct random direction pairs and points of the period (not a small cycled set: each
//! lookup reads 4 cache lines of node tables of 95 MB each, and 2^20 lookups touch far more
//! lines than the 32 MB last-level cache holds, where 2^16 touched 16 MB and stayed in it).
//! Medians in docs/science/spatial.md.

use clothbake_bake::{bake, BakeOptions, DEFAULT_GRID};
use clothbake_core::Fabric;
use clothbake_loader::{Brdf, Options, Precision, StoredTable};
use clothbake_tests::accuracy::{random_pairs, to_f32};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// The pool of inputs, a power of two (the index wraps with a mask).
const N: usize = 1 << 20;

fn spatial_lookup(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/twill.json");
    let fabric = Fabric::from_path(&path).expect("tables/twill.json");
    let opts = BakeOptions {
        grid: DEFAULT_GRID,
        spatial: true,
        ..BakeOptions::default()
    };
    let table = bake(&fabric, &opts, &|_| {}, &AtomicBool::new(false))
        .expect("bake")
        .table;
    let stored = StoredTable::from_table(table, Precision::F16).expect("half-float range");
    // The crossing cells' lookup (the point level traces the yarns instead: its speed is the
    // `point_look` group of clothbake-core's bench).
    let options = Options {
        sampling: false,
        point_level: false,
        ..Options::default()
    };
    let brdf = Brdf::from_stored(stored, options).expect("valid table");
    eprintln!(
        "memory: {} MiB in all, {} MiB the classes; kernel {:?}",
        brdf.memory_bytes() >> 20,
        brdf.spatial().map_or(0, |s| s.memory_bytes()) >> 20,
        brdf.simd_path()
    );
    let (wi, wo): (Vec<[f32; 3]>, Vec<[f32; 3]>) = random_pairs(N, 7)
        .iter()
        .map(|&(a, b)| (to_f32(a), to_f32(b)))
        .unzip();
    let mut rng = clothbake_core::rng::Rng::new(11);
    let uv: Vec<(f64, f64)> = (0..N).map(|_| (rng.next_f64(), rng.next_f64())).collect();

    let mut g = c.benchmark_group("twill_spatial_default_grid_f16");
    g.bench_function("averaged/eval", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) & (N - 1);
            black_box(brdf.eval(black_box(wi[k]), black_box(wo[k])))
        })
    });
    for (name, width) in [("point", 0.0), ("footprint_0.25", 0.25)] {
        g.bench_function(format!("spatial/eval_at_{name}"), |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 1) & (N - 1);
                let (u, v) = uv[k];
                black_box(brdf.eval_at(black_box(wi[k]), black_box(wo[k]), u, v, width))
            })
        });
    }
    // Latency: each lookup's input depends on the previous result (as a path tracer's next
    // bounce depends on this one), so no two lookups' memory reads overlap.
    g.bench_function("averaged/eval_dependent", |b| {
        let mut k = 0;
        b.iter(|| {
            let f = brdf.eval(black_box(wi[k]), black_box(wo[k]));
            k = (k + 1 + usize::from(f[0] == f32::INFINITY)) & (N - 1);
            f
        })
    });
    g.bench_function("spatial/eval_at_point_dependent", |b| {
        let mut k = 0;
        b.iter(|| {
            let (u, v) = uv[k];
            let f = brdf.eval_at(black_box(wi[k]), black_box(wo[k]), u, v, 0.0);
            k = (k + 1 + usize::from(f[0] == f32::INFINITY)) & (N - 1);
            f
        })
    });
    // One cell: every lookup reads the same class pair's node table (the working set of an
    // averaged lookup), to tell the cost of spreading over the classes' tables.
    g.bench_function("spatial/eval_at_point_one_cell", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) & (N - 1);
            black_box(brdf.eval_at(black_box(wi[k]), black_box(wo[k]), 0.1, 0.1, 0.0))
        })
    });
    // A whole period: eval_at answers the averaged table (the wrapper's cost alone).
    g.bench_function("spatial/eval_at_whole_period", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) & (N - 1);
            let (u, v) = uv[k];
            black_box(brdf.eval_at(black_box(wi[k]), black_box(wo[k]), u, v, 1.0))
        })
    });
    g.bench_function("spatial/coverage_at_point", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) & (N - 1);
            let (u, v) = uv[k];
            black_box(brdf.coverage_at(black_box(wo[k]), u, v, 0.0))
        })
    });
    g.finish();
}

criterion_group!(benches, spatial_lookup);
criterion_main!(benches);
