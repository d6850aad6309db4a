//! Criterion benchmarks of the direct model: the analytic path per (wi, wo) pair.
//! The ray tracer's cost at 1% error is reported beside it by the `raytrace_1pct` group; the
//! secondary reflection per pair, and against the two-level sampling, by `secondary` and
//! `secondary_vs_sampling`.

use clothbake_core::interreflection::{Orders, Ranges, Sampling, ORDERS_FAST};
use clothbake_core::validate::secondary_direction_set;
use clothbake_core::{
    AnalyticModel, Fabric, FacetModel, Kernel, RayTracer, SecondaryMethod, SecondaryOptions,
    UnitVec3,
};
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

/// The analytic secondary reflection against the two-level sampling, side by side on the
/// parallel-cylinder surface with the thesis's sec. 5.4 facets (rho_d 0.4, rho_s 0.7, n 10),
/// over the direction set of `cargo xtask ir-accuracy` (whose table gives each setting's
/// error): default and fast orders; sampling with 0.2 and 0.15 steps over |y| <= 3.
fn secondary_vs_sampling(c: &mut Criterion) {
    let json = r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 2,
        "material": {"albedo": 0.4, "specular": 0.7, "exponent": 10}},
        "weft": {"radius": 1, "spacing": 2}}"#;
    let m = AnalyticModel::new(
        &Fabric::from_json_str(json, "parallel").unwrap(),
        FacetModel::Huo,
    );
    let dirs = secondary_direction_set();
    let analytic = |orders| SecondaryMethod::Analytic {
        ranges: Ranges::Full,
        orders,
    };
    let sampling = |step| {
        SecondaryMethod::Sampling(Sampling {
            first_level: 32,
            d_alpha: step,
            d_l: step,
            l0: 3.0,
            exact_solid_angle: true,
        })
    };
    let mut g = c.benchmark_group("secondary_vs_sampling");
    for (name, method, samples) in [
        ("analytic_default", analytic(Orders::default()), 100),
        ("analytic_fast", analytic(ORDERS_FAST), 100),
        ("sampling_0.2", sampling(0.2), 10),
        ("sampling_0.15", sampling(0.15), 10),
    ] {
        g.sample_size(samples);
        let opts = SecondaryOptions {
            method,
            kernel: Kernel::Radiometric,
        };
        g.bench_function(name, |b| {
            let mut k = 0;
            b.iter(|| {
                let (wi, wo) = dirs[k % dirs.len()];
                k += 1;
                black_box(m.eval_with(black_box(wi), black_box(wo), Some(&opts)))
            })
        });
    }
    g.finish();
}

criterion_group!(
    benches,
    analytic,
    raytrace_1pct,
    secondary,
    secondary_vs_sampling
);
criterion_main!(benches);
