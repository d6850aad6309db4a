//! Criterion benchmarks of the direct model: the analytic path per (wi, wo) pair.
//! The ray tracer's cost at 1% error is reported beside it by the `raytrace_1pct` group.

use clothbake_core::{AnalyticModel, Fabric, FacetModel, RayTracer, SecondaryOptions, UnitVec3};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;

fn twill() -> Fabric {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/twill.json");
    Fabric::from_path(&p).expect("tables/twill.json")
}

/// A fixed spread of direction pairs over the upper hemisphere (deterministic).
fn directions(n: usize) -> Vec<(UnitVec3, UnitVec3)> {
    (0..n)
        .map(|k| {
            let t = k as f64 + 0.5;
            let wi = UnitVec3::from_degrees((t * 37.0) % 85.0, (t * 61.0) % 360.0);
            let wo = UnitVec3::from_degrees((t * 53.0) % 85.0, (t * 97.0) % 360.0);
            (wi, wo)
        })
        .collect()
}

fn analytic(c: &mut Criterion) {
    let fabric = twill();
    let dirs = directions(256);
    for facet in [FacetModel::Huo, FacetModel::Lewis] {
        let m = AnalyticModel::new(&fabric, facet);
        c.bench_function(
            &format!("analytic_direct/twill/{}/per_pair", facet.name()),
            |b| {
                let mut k = 0;
                b.iter(|| {
                    let (wi, wo) = dirs[k % dirs.len()];
                    k += 1;
                    black_box(m.eval(black_box(wi), black_box(wo)))
                })
            },
        );
    }
    c.bench_function("analytic_preprocess/twill", |b| {
        b.iter(|| black_box(AnalyticModel::new(black_box(&fabric), FacetModel::Huo)))
    });
}

/// The ground truth's cost for a 1% standard error on the total intensity, same pairs.
fn raytrace_1pct(c: &mut Criterion) {
    let fabric = twill();
    let rt = RayTracer::new(&fabric, FacetModel::Huo);
    let dirs = directions(8);
    let mut g = c.benchmark_group("raytrace_1pct");
    g.sample_size(10);
    g.bench_function("twill/huo/per_pair", |b| {
        let mut k = 0;
        b.iter(|| {
            let (wi, wo) = dirs[k % dirs.len()];
            k += 1;
            black_box(rt.render_to_error(wi, wo, 0.01, 1 << 22, k as u64))
        })
    });
    g.finish();
}

/// Secondary reflection on the parallel-cylinder surface (thesis ch. 5) and on the twill.
fn secondary(c: &mut Criterion) {
    let dirs = directions(64);
    let pf = Fabric::from_path(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/parallel.json"),
    )
    .unwrap();
    for (name, fabric) in [("parallel", pf), ("twill", twill())] {
        let m = AnalyticModel::new(&fabric, FacetModel::Huo);
        let opts = SecondaryOptions::default();
        c.bench_function(&format!("secondary_analytic/{name}/per_pair"), |b| {
            let mut k = 0;
            b.iter(|| {
                let (wi, wo) = dirs[k % dirs.len()];
                k += 1;
                black_box(m.eval_with(black_box(wi), black_box(wo), Some(&opts)))
            })
        });
    }
}

criterion_group!(benches, analytic, raytrace_1pct, secondary);
criterion_main!(benches);
