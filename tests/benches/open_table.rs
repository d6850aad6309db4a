//! Opening a table (issue 38): `Brdf::open` of the default table (the twill baked on the
//! default grid, written as the default half-float OpenEXR, as `clothbake --weave
//! tables/twill.json` writes it) and of the same table as an f32 binary file; the first
//! `sample` after an open (the sampling CDFs are built then); and, for the time's proportion to
//! the size, synthetic half-float tables of growing grids (`open_scaling/<cells>`).
//!
//! `cargo bench -p clothbake-tests --bench open_table` (docs/reference/benchmarks.md, "Opening a table").

use std::hint::black_box;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use clothbake_bake::{bake, BakeOptions, DEFAULT_GRID};
use clothbake_core::Fabric;
use clothbake_loader::{write_binary, write_exr, Brdf, Grid, Metadata, Options, Precision, Table};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

fn folder() -> PathBuf {
    let d = std::env::temp_dir().join(format!("clothbake-open-bench-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("a temporary folder");
    d
}

fn open(c: &mut Criterion) {
    let d = folder();
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tables/twill.json");
    let fabric = Fabric::from_path(&path).expect("tables/twill.json");
    let opts = BakeOptions {
        grid: DEFAULT_GRID,
        ..BakeOptions::default()
    };
    let table = bake(&fabric, &opts, &|_| {}, &AtomicBool::new(false))
        .expect("bake")
        .table;
    let (exr, bin) = (d.join("twill.exr"), d.join("twill.bin"));
    write_exr(&exr, &table, Precision::F16, true).expect("write");
    write_binary(&bin, &table, true).expect("write");
    let mut g = c.benchmark_group("open");
    g.sample_size(20);
    g.bench_function("twill_default/exr_f16", |b| {
        b.iter(|| black_box(Brdf::open(black_box(&exr), Options::default()).unwrap()))
    });
    g.bench_function("twill_default/bin_f32", |b| {
        b.iter(|| black_box(Brdf::open(black_box(&bin), Options::default()).unwrap()))
    });
    g.bench_function("twill_default/exr_f16_first_sample", |b| {
        b.iter(|| {
            let t = Brdf::open(black_box(&exr), Options::default()).unwrap();
            black_box(t.sample([0.3, 0.1, 0.948_683_3], 0.25, 0.75))
        })
    });
    g.finish();

    // Synthetic tables of growing grids: time per cell.
    let mut g = c.benchmark_group("open_scaling");
    g.sample_size(10);
    for n in [8u32, 16, 32, 48] {
        let grid = Grid::new(n, 2 * n, n, 2 * n);
        let values = (0..3 * grid.len())
            .map(|i| 0.1 + ((i as f32) * 0.37).sin().abs())
            .collect();
        let t = Table::new(Metadata::new("bench", grid, "{}", "{}", "none"), values).unwrap();
        let p = d.join(format!("s{n}.exr"));
        write_exr(&p, &t, Precision::F16, true).expect("write");
        drop(t);
        g.throughput(Throughput::Elements(grid.len() as u64));
        g.bench_function(format!("exr_f16/{}", grid.len()), |b| {
            b.iter(|| black_box(Brdf::open(black_box(&p), Options::default()).unwrap()))
        });
        let _ = std::fs::remove_file(&p);
    }
    g.finish();
    let _ = std::fs::remove_dir_all(&d);
}

criterion_group!(benches, open);
criterion_main!(benches);
