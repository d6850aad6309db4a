//! Criterion benchmarks of the direct model: the analytic path per (wi, wo) pair, on distinct
//! random pairs (a pool of 2^16, uniform in solid angle: the branches cannot be learnt) beside 64
//! pairs cycled (`coherent`, as neighbouring rays of a renderer). The ray tracer's cost at 1%
//! error is reported beside it by the `raytrace_1pct` group; the secondary reflection per pair
//! (random pairs), and against the two-level sampling (the fixed direction set whose errors
//! `cargo xtask ir-accuracy` tabulates), by `secondary` and `secondary_vs_sampling`. The point
//! level's look at a random point of the period for each random pair: `point_look`.

use clothbake_core::directions::secondary_direction_set;
use clothbake_core::interreflection::{Orders, Ranges, Sampling, ORDERS_FAST};
use clothbake_core::rng::Rng;
use clothbake_core::{
    AnalyticModel, Fabric, FacetModel, Kernel, SecondaryMethod, SecondaryOptions, UnitVec3, Variant,
};
use clothbake_truth::RayTracer;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;

fn twill() -> Fabric {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/twill.json");
    Fabric::from_path(&p).expect("tables/twill.json")
}

/// `n` (a power of two) random direction pairs, uniform in solid angle over the upper
/// hemisphere, strictly above the horizon (deterministic).
fn directions(n: usize) -> Vec<(UnitVec3, UnitVec3)> {
    assert!(n.is_power_of_two());
    let mut rng = Rng::new(22);
    let mut dir = move || {
        let mu = 1e-6 + (1.0 - 1e-6) * rng.next_f64();
        UnitVec3::from_spherical(mu.acos(), std::f64::consts::TAU * rng.next_f64())
    };
    (0..n).map(|_| (dir(), dir())).collect()
}

fn analytic(c: &mut Criterion) {
    let fabric = twill();
    let dirs = directions(1 << 16);
    for facet in [FacetModel::Huo, FacetModel::Lewis] {
        let m = AnalyticModel::new(&fabric, facet);
        for (name, mask) in [("random", dirs.len() - 1), ("coherent", 63)] {
            c.bench_function(
                &format!("analytic_direct/twill/{}/{name}", facet.name()),
                |b| {
                    let mut k = 0;
                    b.iter(|| {
                        k = (k + 1) & mask;
                        let (wi, wo) = dirs[k];
                        black_box(m.intensity(black_box(wi), black_box(wo)))
                    })
                },
            );
        }
    }
    // The batch: 64 consecutive pairs of the pool an iteration (time per iteration / 64 is the
    // time per pair), the walk wrapping round the pool.
    let m = AnalyticModel::new(&fabric, FacetModel::Huo);
    let mut out = vec![clothbake_core::Reflection::default(); 64];
    for (name, mask) in [("random", dirs.len() - 1), ("coherent", 63)] {
        c.bench_function(&format!("analytic_direct/twill/huo_batch_64/{name}"), |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 64) & mask;
                let end = (k + 64).min(dirs.len());
                let pairs = &dirs[k.min(end - 64)..end];
                m.intensity_batch(black_box(pairs), &mut out);
                black_box(&out);
            })
        });
    }
    // The variants side by side, one pair at a time (docs/science/model.md, "The sliced variant" and
    // "The sliced3d variant").
    for variant in [Variant::Refined, Variant::Sliced, Variant::Sliced3d] {
        let m = AnalyticModel::with_variant(&fabric, FacetModel::Huo, variant)
            .expect("the variant takes the period");
        c.bench_function(
            &format!("analytic_variant/twill/{}/random", variant.name()),
            |b| {
                let mut k = 0;
                b.iter(|| {
                    k = (k + 1) & (dirs.len() - 1);
                    let (wi, wo) = dirs[k];
                    black_box(m.intensity(black_box(wi), black_box(wo)))
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
    // One iteration traces all 8 pairs (their costs differ by up to 10x: cycling one pair per
    // iteration made the sample's mix of pairs, and so the median, depend on the iteration count).
    g.bench_function("twill/huo/8_pairs", |b| {
        let mut seed = 0;
        b.iter(|| {
            seed += 1;
            for &(wi, wo) in &dirs {
                black_box(rt.render_to_error(wi, wo, 0.01, 1 << 22, seed));
            }
        })
    });
    g.finish();
}

/// Secondary reflection on the parallel-cylinder surface (thesis ch. 5) and on the twill.
fn secondary(c: &mut Criterion) {
    let dirs = directions(1 << 12);
    let pf = Fabric::from_path(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/parallel.json"),
    )
    .unwrap();
    for (name, fabric) in [("parallel", pf), ("twill", twill())] {
        let m = AnalyticModel::new(&fabric, FacetModel::Huo);
        let opts = SecondaryOptions::default();
        c.bench_function(&format!("secondary_analytic/{name}/random"), |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 1) & (dirs.len() - 1);
                let (wi, wo) = dirs[k];
                black_box(m.intensity_with(black_box(wi), black_box(wo), Some(&opts)))
            })
        });
    }
}

/// The analytic secondary reflection against the two-level sampling, side by side over the
/// direction set of `cargo xtask ir-accuracy` (whose table gives each setting's error), with
/// the thesis's sec. 5.4 facets (rho_d 0.4, rho_s 0.7, n 10) on the parallel-cylinder surface,
/// and on the twill: default and fast orders, the floor of the analytic rule (one node asked
/// for everywhere: what the per-pair and per-point work costs whatever the orders) and the
/// cheapest orders of `cargo xtask ir-accuracy --scan` at the default's accuracy on the twill
/// (8, 4, 3); the sampling with exact solid angles (the thesis's) and with eq. 5.16, all over
/// |y| <= 3, at the cheapest settings at or under 2% mean error of the scan (and, on the
/// parallel surface, at steps 0.2 and 0.15 with 32 first-level samples).
fn secondary_vs_sampling(c: &mut Criterion) {
    let json = r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 2,
        "material": {"albedo": 0.4, "specular": 0.7, "exponent": 10}},
        "weft": {"radius": 1, "spacing": 2}}"#;
    let parallel = Fabric::from_json_str(json, "parallel").unwrap();
    let analytic = |orders| SecondaryMethod::Analytic {
        ranges: Ranges::Full,
        orders,
    };
    let sampling = |first_level, step, exact_solid_angle| {
        SecondaryMethod::Sampling(Sampling {
            first_level,
            d_alpha: step,
            d_l: step,
            l0: 3.0,
            exact_solid_angle,
        })
    };
    let floor = Orders {
        theta: 1,
        tol: 0.0,
        beta: 1,
        axial: 1,
    };
    let orders = |theta, beta, axial| Orders {
        theta,
        tol: 0.0,
        beta,
        axial,
    };
    let analytic_rows = [
        ("analytic_default", analytic(Orders::default()), 100),
        ("analytic_fast", analytic(ORDERS_FAST), 100),
        ("analytic_floor", analytic(floor), 100),
        // The cheapest orders of the scan at or under the default's errors on the twill.
        ("analytic_8_4_3", analytic(orders(8, 4, 3)), 100),
    ];
    let surfaces = [
        (
            "secondary_vs_sampling",
            parallel,
            vec![
                ("sampling_0.2", sampling(32, 0.2, true), 10),
                ("sampling_0.15", sampling(32, 0.15, true), 10),
                ("sampling_24_0.17", sampling(24, 0.17, true), 10),
                ("sampling_eq516_28_0.15", sampling(28, 0.15, false), 10),
            ],
        ),
        (
            "secondary_vs_sampling_twill",
            twill(),
            vec![
                ("sampling_12_0.2", sampling(12, 0.2, true), 10),
                ("sampling_eq516_16_0.2", sampling(16, 0.2, false), 10),
            ],
        ),
    ];
    let dirs = secondary_direction_set();
    for (group, fabric, rows) in surfaces {
        let m = AnalyticModel::new(&fabric, FacetModel::Huo);
        let mut g = c.benchmark_group(group);
        for (name, method, samples) in analytic_rows.iter().cloned().chain(rows) {
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
                    black_box(m.intensity_with(black_box(wi), black_box(wo), Some(&opts)))
                })
            });
        }
        g.finish();
    }
}

/// The point level (clothbake-point): one eye ray and one shadow ray through the twill's
/// yarns, at a random point of the period for each random pair of the pool.
fn point(c: &mut Criterion) {
    let fabric = twill();
    let dirs = directions(1 << 16);
    let mut rng = Rng::new(35);
    let points: Vec<(f64, f64)> = (0..dirs.len())
        .map(|_| (rng.next_f64(), rng.next_f64()))
        .collect();
    let yarns = clothbake_core::point::yarns(&fabric, FacetModel::Huo).expect("a small period");
    for (name, mask) in [("random", dirs.len() - 1), ("coherent", 63)] {
        c.bench_function(&format!("point_look/twill/huo/{name}"), |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 1) & mask;
                let (wi, wo) = dirs[k];
                let (u, v) = points[k];
                black_box(yarns.look(black_box(u), black_box(v), wi, wo))
            })
        });
    }
}

criterion_group!(
    benches,
    analytic,
    point,
    raytrace_1pct,
    secondary,
    secondary_vs_sampling
);
criterion_main!(benches);
