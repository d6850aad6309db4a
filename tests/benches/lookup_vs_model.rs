//! The loader's table lookup beside direct evaluation of the analytic model, in one run: the
//! twill baked on the default grid (f16, as the default EXR holds it), the same direction
//! pairs for both (issue 5: the lookup must be at least 50 times faster; issue 22: the model
//! within 0.5 us, lookups near one memory miss).
//!
//! Every function reads distinct random pairs (`random`: a pool of 2^20 pairs, uniform in
//! solid angle, 48 MiB of f64 pairs and 24 MiB of f32 ones, far larger than the caches, walked
//! in order so that the pool's own reads are prefetched; a lookup's table nodes mostly come from
//! memory and the model's branches cannot be learnt), beside the coherent case (`coherent`: 64
//! pairs cycled, whose table nodes stay in the caches, as for neighbouring rays of a renderer).

use clothbake_bake::DEFAULT_GRID;
use clothbake_core::{AnalyticModel, Fabric, FacetModel};
use clothbake_loader::Precision;
use clothbake_tests::accuracy::{baked_brdf, random_pairs, to_f32};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use std::path::Path;

/// Pairs of the random pool (a power of two: the index wraps with a mask, not a division that
/// would add its latency to every lookup).
const POOL: usize = 1 << 20;
/// Pairs of the coherent set.
const COHERENT: usize = 64;
/// Pairs per batch call.
const BATCH: usize = 4096;

fn side_by_side(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/twill.json");
    let fabric = Fabric::from_path(&path).expect("tables/twill.json");
    let brdf = baked_brdf(&fabric, DEFAULT_GRID, Precision::F16);
    let model = AnalyticModel::new(&fabric, FacetModel::Huo);
    let pairs = random_pairs(POOL, 99);
    let (wi, wo): (Vec<[f32; 3]>, Vec<[f32; 3]>) =
        pairs.iter().map(|&(a, b)| (to_f32(a), to_f32(b))).unzip();
    let mut g = c.benchmark_group("twill_default_grid");
    for (name, mask) in [("random", POOL - 1), ("coherent", COHERENT - 1)] {
        g.bench_function(format!("analytic_model/{name}"), |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 1) & mask;
                let (a, o) = pairs[k];
                black_box(model.intensity(black_box(a), black_box(o)).brdf(a))
            })
        });
        g.bench_function(format!("table_lookup/{name}"), |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 1) & mask;
                black_box(brdf.eval(black_box(wi[k]), black_box(wo[k])))
            })
        });
    }
    let mut out = vec![[0f32; 3]; BATCH];
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function("table_lookup_batch/random", |b| {
        let mut start = 0;
        b.iter(|| {
            start = (start + BATCH) & (POOL - 1);
            let r = start..start + BATCH;
            brdf.eval_batch(black_box(&wi[r.clone()]), black_box(&wo[r]), &mut out)
        })
    });
    g.throughput(Throughput::Elements(COHERENT as u64));
    g.bench_function("table_lookup_batch/coherent", |b| {
        let out = &mut out[..COHERENT];
        b.iter(|| brdf.eval_batch(black_box(&wi[..COHERENT]), black_box(&wo[..COHERENT]), out))
    });
    g.finish();
}

criterion_group!(benches, side_by_side);
criterion_main!(benches);
