//! Criterion benchmarks of the render-time lookup on a default-size (32 x 64 x 32 x 64) table
//! of synthetic values: one lookup (f16 and f32 storage, vector and degree entry points), the
//! batched lookup per item, reciprocal lookups, `sample` and `pdf`; the default kernel (AVX2
//! where the processor has it) and the portable one (`*_portable`). Direction pairs cycle
//! through a fixed set of 64 random pairs (`warm`: the nodes of each stay in the caches, as
//! for coherent rays) or of 1 << 20 (`random`: most of the 8 cache lines a lookup touches
//! come from memory).
//! The side-by-side comparison with the analytic model is `cargo bench -p clothbake-tests`.

use clothbake_loader::{
    Brdf, Grid, Memory, Metadata, Options, Precision, SimdPath, StoredTable, Table,
};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;

/// Pairs of the cache-warm set.
const WARM: usize = 64;

const GRID: Grid = Grid {
    n_theta_i: 32,
    n_phi_i: 64,
    n_theta_o: 32,
    n_phi_o: 64,
};

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
    let mut g = c.benchmark_group("lookup");
    println!("default kernel: {:?}", half.simd_path());
    for (name, b) in [
        ("f16", &half),
        ("f32", &wide),
        ("f16_reciprocal", &recip),
        ("f16_portable", &half_p),
        ("f32_portable", &wide_p),
    ] {
        g.bench_function(format!("eval/{name}/warm"), |bench| {
            let mut k = 0;
            bench.iter(|| {
                k = (k + 1) % WARM;
                black_box(b.eval(black_box(wi[k]), black_box(wo[k])))
            })
        });
    }
    // The same pairs as angles in degrees.
    let angles = |w: [f32; 3]| {
        let (t, p) = (w[2].acos().to_degrees(), w[1].atan2(w[0]).to_degrees());
        [t, p.rem_euclid(360.0)]
    };
    let deg: Vec<([f32; 2], [f32; 2])> = wi
        .iter()
        .zip(&wo)
        .map(|(&a, &b)| (angles(a), angles(b)))
        .collect();
    g.bench_function("eval_deg/f16/warm", |bench| {
        let mut k = 0;
        bench.iter(|| {
            k = (k + 1) % WARM;
            let (a, b) = (deg[k].0, deg[k].1);
            black_box(half.eval_deg(
                black_box(a[0]),
                black_box(a[1]),
                black_box(b[0]),
                black_box(b[1]),
            ))
        })
    });
    let (cold_i, cold_o) = pairs(1 << 20);
    g.bench_function("eval/f16/random", |bench| {
        let mut k = 0;
        bench.iter(|| {
            k = (k + 1) & ((1 << 20) - 1);
            black_box(half.eval(black_box(cold_i[k]), black_box(cold_o[k])))
        })
    });
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
    g.bench_function("eval_batch/f16/random", |bench| {
        let mut start = 0;
        bench.iter(|| {
            start = (start + n) & ((1 << 20) - 1);
            let r = start..start + n;
            half.eval_batch(
                black_box(&cold_i[r.clone()]),
                black_box(&cold_o[r]),
                &mut out,
            )
        })
    });
    g.finish();

    let mut g = c.benchmark_group("sampling");
    g.bench_function("sample/f16/warm", |bench| {
        let mut k = 0;
        bench.iter(|| {
            k = (k + 1) % WARM;
            black_box(half.sample(
                black_box(wo[k]),
                black_box(wi[k][0].abs()),
                black_box(wi[k][2]),
            ))
        })
    });
    g.bench_function("pdf/f16/warm", |bench| {
        let mut k = 0;
        bench.iter(|| {
            k = (k + 1) % WARM;
            black_box(half.pdf(black_box(wo[k]), black_box(wi[k])))
        })
    });
    g.finish();
}

criterion_group!(benches, lookup);
criterion_main!(benches);
