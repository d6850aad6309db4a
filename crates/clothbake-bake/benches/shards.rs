//! Criterion benchmarks of sharding: a single bake against the same table baked as 4 shards
//! (one after the other, in-process) and merged, and the merge alone. One thread, the twill on
//! a 16 x 32 x 16 x 32 grid, direct reflection.

use clothbake_bake::merge::merge;
use clothbake_bake::shard::{shard_rows, Kind, Part, ShardId};
use clothbake_bake::{bake, BakeOptions, Baker, Row};
use clothbake_core::Fabric;
use clothbake_loader::Grid;
use criterion::{criterion_group, criterion_main, Criterion};
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

fn setup() -> (Fabric, BakeOptions) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/twill.json");
    let o = BakeOptions {
        grid: Grid::new(16, 32, 16, 32),
        ..BakeOptions::default()
    };
    (Fabric::from_path(&p).expect("tables/twill.json"), o)
}

fn shards(f: &Fabric, o: &BakeOptions, n: u32) -> Vec<(PathBuf, Part)> {
    let none = AtomicBool::new(false);
    (0..n)
        .map(|index| {
            let id = ShardId { index, count: n };
            let baker = Baker::new(f, o).expect("valid options");
            let rows: Vec<usize> = shard_rows(baker.orbits(), id).collect();
            let done = Mutex::new(BTreeMap::<usize, Row>::new());
            baker
                .sweep(&rows, &|_| {}, &none, &|r, v| {
                    done.lock().expect("no panic").insert(r, v);
                })
                .expect("not cancelled");
            let part = Part {
                kind: Kind::Shard,
                shard: Some(id),
                meta: baker.metadata().clone(),
                rows: done.into_inner().expect("no panic"),
            };
            (PathBuf::from(format!("{index}.shard")), part)
        })
        .collect()
}

fn sharding(c: &mut Criterion) {
    let (f, o) = setup();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool");
    let none = AtomicBool::new(false);
    let mut g = c.benchmark_group("twill_16x32x16x32_1thread");
    g.sample_size(10);
    g.bench_function("single_bake", |b| {
        b.iter(|| pool.install(|| black_box(bake(&f, &o, &|_| {}, &none).expect("bakes"))))
    });
    g.bench_function("4_shards_and_merge", |b| {
        b.iter(|| pool.install(|| black_box(merge(&shards(&f, &o, 4)).expect("merges"))))
    });
    let parts = shards(&f, &o, 4);
    g.bench_function("merge_only", |b| {
        b.iter(|| black_box(merge(&parts).expect("merges")))
    });
    g.finish();
}

criterion_group!(benches, sharding);
criterion_main!(benches);
