//! The loader's table lookup beside direct evaluation of the analytic model, in one run: the
//! twill baked on the default grid (f16, as the default EXR holds it), the same direction
//! pairs for both (issue 5: the lookup must be at least 50 times faster).

use clothbake_bake::DEFAULT_GRID;
use clothbake_core::{AnalyticModel, Fabric, FacetModel};
use clothbake_loader::Precision;
use clothbake_tests::accuracy::{baked_brdf, random_pairs, to_f32};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use std::path::Path;

/// Direction pairs cycled through (a constant: the index wraps with a mask, not a division
/// that would add its latency to every lookup).
const N: usize = 64;

fn side_by_side(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/twill.json");
    let fabric = Fabric::from_path(&path).expect("tables/twill.json");
    let brdf = baked_brdf(&fabric, DEFAULT_GRID, Precision::F16);
    let model = AnalyticModel::new(&fabric, FacetModel::Huo);
    let pairs = random_pairs(N, 99);
    let (wi, wo): (Vec<[f32; 3]>, Vec<[f32; 3]>) =
        pairs.iter().map(|&(a, b)| (to_f32(a), to_f32(b))).unzip();
    let mut g = c.benchmark_group("twill_default_grid");
    g.bench_function("analytic_model/per_pair", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) % N;
            let (a, o) = pairs[k];
            black_box(model.intensity(black_box(a), black_box(o)).brdf(a))
        })
    });
    g.bench_function("table_lookup/per_pair", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) % N;
            black_box(brdf.eval(black_box(wi[k]), black_box(wo[k])))
        })
    });
    let mut out = vec![[0f32; 3]; N];
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("table_lookup_batch/64_pairs", |b| {
        b.iter(|| brdf.eval_batch(black_box(&wi), black_box(&wo), &mut out))
    });
    g.finish();
}

criterion_group!(benches, side_by_side);
criterion_main!(benches);
