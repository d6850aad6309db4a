//! Criterion benchmark of a bake with each analytic variant: the twill on a 16 x 32 x 16 x 32
//! grid, direct reflection, one thread. `sliced3d` keeps the open arcs of the grid's directions
//! (docs/guide/baking.md), so that its bake costs a few times `refined`'s rather than its pairs'
//! hundred times.

use clothbake_bake::{bake, BakeOptions, Method};
use clothbake_core::{Fabric, Variant};
use clothbake_loader::Grid;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn variants(c: &mut Criterion) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/twill.json");
    let f = Fabric::from_path(&p).expect("tables/twill.json");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool");
    let none = AtomicBool::new(false);
    let mut g = c.benchmark_group("bake_twill_16x32x16x32_1thread");
    g.sample_size(10);
    for variant in [Variant::Refined, Variant::Sliced, Variant::Sliced3d] {
        let o = BakeOptions {
            grid: Grid::new(16, 32, 16, 32),
            method: Method::Analytic { variant },
            ..BakeOptions::default()
        };
        g.bench_function(variant.name(), |b| {
            b.iter(|| pool.install(|| black_box(bake(&f, &o, &|_| {}, &none).expect("bakes"))))
        });
    }
    g.finish();
}

criterion_group!(benches, variants);
criterion_main!(benches);
