//! Tables whose values are not physical (not finite, negative, or so large that albedos and
//! sampling weights overflow) are refused on loading, in every format, with the value, the
//! cell and the rule; the largest value allowed still samples with finite weights, and their
//! mean is the closed-form albedo of a constant BRDF, pi f_r.

use std::path::{Path, PathBuf};

use clothbake_loader::{
    read_table, write_container, write_exr, Brdf, ContainerKind, Grid, Memory, Metadata, Options,
    Precision, Table, MAX_VALUE,
};

const GRID: Grid = Grid::new(4, 8, 4, 8);

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("loader-values-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn meta() -> Metadata {
    Metadata::new("clothbake test", GRID, "{}", "{}", "none")
}

/// A CRC-valid binary table holding `values`, written around the writer's own checks.
fn raw_table(path: &Path, values: &[f32]) {
    let header = serde_json::to_value(meta()).unwrap();
    write_container(path, ContainerKind::Table, &header, values, true).unwrap();
}

fn message<T: std::fmt::Debug>(r: Result<T, clothbake_loader::TableError>) -> String {
    r.unwrap_err().to_string()
}

#[test]
fn unphysical_values_are_refused_on_loading() {
    let d = dir("refused");
    let n = 3 * GRID.len();
    let cases: [(f32, &str); 5] = [
        (3e38, "is 3e38; the largest value a table may hold is 1e30"),
        (f32::INFINITY, "is inf; every value must be finite"),
        (f32::NAN, "is NaN; every value must be finite"),
        (-1.0, "is -1e0; a BRDF is never negative"),
        (1.0000001e30, "the largest value a table may hold"),
    ];
    for (k, (v, words)) in cases.into_iter().enumerate() {
        let p = d.join(format!("t{k}.bin"));
        let mut values = vec![0.25f32; n];
        values[3 * 5 + 1] = v;
        raw_table(&p, &values);
        let e = message(read_table(&p));
        assert!(e.contains(&p.display().to_string()), "{e}");
        assert!(e.contains("value 16 of cell 5 (channel G)"), "{e}");
        assert!(e.contains(words), "{v}: {e}");
        assert!(e.contains("bake it again"), "{e}");
        // What renderers call (clothbake_open in C) refuses it too.
        assert!(Brdf::open(&p, Options::default()).is_err());
    }
    // The writers refuse them as well: no such table is ever written.
    let bad = Table {
        meta: meta(),
        values: vec![3e38; n],
    };
    let e = message(write_exr(&d.join("w.exr"), &bad, Precision::F32, true));
    assert!(e.contains("cannot write the table"), "{e}");
    assert!(Table::new(meta(), vec![-0.5; n]).is_err());
    // -0.0 is zero, not negative.
    assert!(Table::new(meta(), vec![-0.0; n]).is_ok());
}

#[test]
fn the_largest_value_samples_with_finite_weights_whose_mean_is_the_albedo() {
    let d = dir("largest");
    let p = d.join("max.bin");
    raw_table(&p, &vec![MAX_VALUE; 3 * GRID.len()]);
    let b = Brdf::open(
        &p,
        Options {
            memory: Memory::F32,
            ..Options::default()
        },
    )
    .unwrap();
    // Straight down and grazing outgoing directions.
    for wo in [[0.0f32, 0.0, 1.0], [0.6, 0.0, 0.8], [0.0, 0.995, 0.0998]] {
        let (n, mut sum) = (256u32, 0.0f64);
        for i in 0..n {
            for j in 0..n {
                let u1 = (i as f32 + 0.5) / n as f32;
                let u2 = (j as f32 + 0.5) / n as f32;
                let s = b.sample(wo, u1, u2);
                assert!(s.pdf > 0.0 && s.pdf.is_finite(), "{wo:?}: pdf {}", s.pdf);
                for w in s.weight {
                    assert!(w.is_finite() && w >= 0.0, "{wo:?}: weight {w}");
                }
                sum += f64::from(s.weight[0]);
            }
        }
        // A constant BRDF f has the directional albedo integral f cos = pi f.
        let mean = sum / f64::from(n * n);
        let albedo = std::f64::consts::PI * f64::from(MAX_VALUE);
        assert!(
            (mean / albedo - 1.0).abs() < 0.01,
            "{wo:?}: mean weight {mean:e}, albedo {albedo:e}"
        );
    }
}

#[test]
fn an_exr_file_larger_than_its_header_allows_is_refused_before_reading() {
    let d = dir("exr-size");
    let p = d.join("t.exr");
    let t = Table::new(meta(), vec![0.5; 3 * GRID.len()]).unwrap();
    write_exr(&p, &t, Precision::F32, true).unwrap();
    assert_eq!(read_table(&p).unwrap(), t);
    // 64 GiB of (sparse) trailing bytes: refused after reading the first 64 MiB.
    let f = std::fs::OpenOptions::new().write(true).open(&p).unwrap();
    if f.set_len(64 << 30).is_err() {
        eprintln!("no sparse files here: skipped");
        return;
    }
    let e = message(read_table(&p));
    assert!(
        e.contains("the file is 68719476736 bytes, but its header describes at most"),
        "{e}"
    );
}
