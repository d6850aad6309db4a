//! Criterion benchmarks of the render-time lookup on a default-size (32 x 64 x 32 x 64) table
//! of synthetic values: one lookup (f16 and f32 storage, vector and degree entry points), the
//! batched lookup per item, reciprocal lookups, `sample` and `pdf`; the default kernel (AVX2
//! where the processor has it) and the portable one (`*_portable`). Every function runs on
//! two sets of random pairs: 64 cycled (`warm`: the nodes of each stay in the caches, as for
//! coherent rays) and 1 << 20 walked in order (`random`: most of the 4 cache lines an f16
//! lookup touches, 8 for f32, come from memory).
//! The side-by-side comparison with the analytic model is `cargo bench -p clothbake-tests`.

use clothbake_loader::{
    Brdf, Grid, Memory, Metadata, Options, Precision, SimdPath, StoredTable, Table,
};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;

/// Pairs of the cache-warm set.
const WARM: usize = 64;
/// Pairs of the random pool (24 MiB of pairs; the table's values are 95 MB at f16, 190 MB at f32).
const RANDOM: usize = 1 << 20;

const GRID: Grid = Grid::new(32, 64, 32, 64);

fn brdf(memory: Memory, reciprocal: bool) -> Brdf {
    let values = (0..GRID.len() * 3)
        .map(|i| 0.1 + ((i as f32) * 0.37).sin().abs())
        .collect();
    let t = Table::new(Metadata::new("bench", GRID, "{}", "{}", "none"), values).unwrap();
    let stored = StoredTable::from_table(t, Precision::F16).unwrap();
    let opts = Options {
        memory,
        reciprocal,
        sampling: true,
        point_level: false,
    };
    Brdf::from_stored(stored, opts).unwrap()
}

/// Direction pairs uniform in solid angle (a fixed low-discrepancy-free hash sequence).
fn pairs(n: usize) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut s = 0x1234_5678u64;
    let mut u = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut dir = move || {
        let mu = 0.001 + 0.999 * u();
        let phi = std::f32::consts::TAU * u();
        let st = (1.0 - mu * mu).sqrt();
        [st * phi.cos(), st * phi.sin(), mu]
    };
    (0..n).map(|_| (dir(), dir())).unzip()
}

fn lookup(c: &mut Criterion) {
    let half = brdf(Memory::AsStored, false);
    let wide = brdf(Memory::F32, false);
    let recip = brdf(Memory::AsStored, true);
    let portable = |b: &Brdf| b.clone().with_simd_path(SimdPath::Portable).unwrap();
    let (half_p, wide_p) = (portable(&half), portable(&wide));
    let (wi, wo) = pairs(WARM);
    let (cold_i, cold_o) = pairs(RANDOM);
    let mut g = c.benchmark_group("lookup");
    println!("default kernel: {:?}", half.simd_path());
    for (name, b) in [
        ("f16", &half),
        ("f32", &wide),
        ("f16_reciprocal", &recip),
        ("f16_portable", &half_p),
        ("f32_portable", &wide_p),
    ] {
        for (set, mask, (vi, vo)) in [
            ("warm", WARM - 1, (&wi, &wo)),
            ("random", RANDOM - 1, (&cold_i, &cold_o)),
        ] {
            g.bench_function(format!("eval/{name}/{set}"), |bench| {
                let mut k = 0;
                bench.iter(|| {
                    k = (k + 1) & mask;
                    black_box(b.eval(black_box(vi[k]), black_box(vo[k])))
                })
            });
        }
    }
    // The same pairs as angles in degrees.
    let angles = |w: [f32; 3]| {
        let (t, p) = (w[2].acos().to_degrees(), w[1].atan2(w[0]).to_degrees());
        [t, p.rem_euclid(360.0)]
    };
    let degrees = |vi: &[[f32; 3]], vo: &[[f32; 3]]| -> Vec<([f32; 2], [f32; 2])> {
        vi.iter()
            .zip(vo)
            .map(|(&a, &b)| (angles(a), angles(b)))
            .collect()
    };
    for (set, deg) in [
        ("warm", degrees(&wi, &wo)),
        ("random", degrees(&cold_i, &cold_o)),
    ] {
        let mask = deg.len() - 1;
        g.bench_function(format!("eval_deg/f16/{set}"), |bench| {
            let mut k = 0;
            bench.iter(|| {
                k = (k + 1) & mask;
                let (a, b) = (deg[k].0, deg[k].1);
                black_box(half.eval_deg(
                    black_box(a[0]),
                    black_box(a[1]),
                    black_box(b[0]),
                    black_box(b[1]),
                ))
            })
        });
    }
    let mut out = vec![[0f32; 3]; WARM];
    g.throughput(Throughput::Elements(WARM as u64));
    g.bench_function("eval_batch/f16/warm", |bench| {
        bench.iter(|| half.eval_batch(black_box(&wi), black_box(&wo), &mut out))
    });
    g.bench_function("eval_batch/f32/warm", |bench| {
        bench.iter(|| wide.eval_batch(black_box(&wi), black_box(&wo), &mut out))
    });
    g.bench_function("eval_batch/f16_portable/warm", |bench| {
        bench.iter(|| half_p.eval_batch(black_box(&wi), black_box(&wo), &mut out))
    });
    let n = 4096;
    let mut out = vec![[0f32; 3]; n];
    g.throughput(Throughput::Elements(n as u64));
    for (name, b) in [("f16", &half), ("f32", &wide)] {
        g.bench_function(format!("eval_batch/{name}/random"), |bench| {
            let mut start = 0;
            bench.iter(|| {
                start = (start + n) & (RANDOM - 1);
                let r = start..start + n;
                b.eval_batch(
                    black_box(&cold_i[r.clone()]),
                    black_box(&cold_o[r]),
                    &mut out,
                )
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("sampling");
    for (set, mask, (vi, vo)) in [
        ("warm", WARM - 1, (&wi, &wo)),
        ("random", RANDOM - 1, (&cold_i, &cold_o)),
    ] {
        g.bench_function(format!("sample/f16/{set}"), |bench| {
            let mut k = 0;
            bench.iter(|| {
                k = (k + 1) & mask;
                black_box(half.sample(
                    black_box(vo[k]),
                    black_box(vi[k][0].abs()),
                    black_box(vi[k][2]),
                ))
            })
        });
        g.bench_function(format!("pdf/f16/{set}"), |bench| {
            let mut k = 0;
            bench.iter(|| {
                k = (k + 1) & mask;
                black_box(half.pdf(black_box(vi[k]), black_box(vo[k])))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, lookup);
criterion_main!(benches);
