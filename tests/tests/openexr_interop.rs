//! Cross-check with the reference OpenEXR library: tables written by the `exr` crate are read
//! by the PyPI `OpenEXR` package (tests/python/read_exr.py) and must give the same dimensions,
//! metadata and every value.
//!
//! Ignored, with the reason, when `python3` cannot import OpenEXR and numpy (the build script
//! probes them); under `CI` it runs and fails without them (.ci/run and `cargo xtask test`
//! install them). It lives here, not in the loader, so that building the loader never runs a
//! probe of Python.

use std::path::Path;

use clothbake_loader::{write_exr, Grid, Metadata, Precision, Table};
use clothbake_tests::fixtures::{python, succeeded, temp_dir};
use clothbake_tests::probe::OPENEXR;
use serde_json::Value;

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/python/read_exr.py");

fn sample_table() -> Table {
    let grid = Grid::new(2, 3, 4, 5);
    let meta = Metadata::new(
        "clothbake 0.1.0",
        grid,
        "{\"name\": \"Köper – twill 🧵\", \"spacing\": [1.5, 2.0]}",
        "{\"samples\": 64, \"precision\": \"f16\"}",
        "mirror x, mirror y",
    );
    let values = (0..grid.len() * 3)
        .map(|i| {
            let x = i as f32;
            (x * 0.731).cos().abs() * 10f32.powi((i % 9) as i32 - 5) + x * 0.01
        })
        .collect();
    Table::new(meta, values).unwrap()
}

fn run_script(path: &Path) -> Value {
    let stdout = succeeded(SCRIPT, &python(SCRIPT, &[path]));
    serde_json::from_str(&stdout).expect("the script prints JSON")
}

fn check(precision: Precision) {
    let dir = temp_dir(&format!("openexr-{precision:?}"));
    let path = dir.join("interop.exr");
    let table = sample_table();
    write_exr(&path, &table, precision, false).unwrap();
    let got = run_script(&path);
    std::fs::remove_dir_all(&dir).unwrap();
    let grid = table.meta.grid;

    let (width, height) = (15u64, 8u64);
    assert_eq!(got["width"], width, "{got}");
    assert_eq!(got["height"], height);
    let kind = match precision {
        Precision::F16 => "half",
        Precision::F32 => "float",
    };
    for c in ["R", "G", "B"] {
        assert_eq!(got["channels"][c], kind, "channel {c}");
    }
    assert_eq!(got["channels"].as_object().unwrap().len(), 3);

    let attrs = &got["attributes"];
    assert_eq!(attrs["clothbake.format_version"], "1");
    assert_eq!(
        attrs["clothbake.grid"],
        "theta_i 2 phi_i 3 theta_o 4 phi_o 5, cell-centred, degrees"
    );
    assert_eq!(attrs["clothbake.units"], "1/sr");
    assert_eq!(attrs["clothbake.tool"], "clothbake 0.1.0");
    // The self-explaining attributes, as another library reads them.
    let layout = attrs["clothbake.layout"].as_str().unwrap();
    assert!(
        layout.contains("x = pi * 5 + po, y = ti * 4 + to (15 x 8 pixels)"),
        "{layout}"
    );
    let dirs = attrs["clothbake.directions"].as_str().unwrap();
    assert!(
        dirs.contains("theta_i = (ti + 0.5) * 90 / 2, phi_i = (pi + 0.5) * 360 / 3"),
        "{dirs}"
    );
    assert!(attrs["clothbake.values"]
        .as_str()
        .unwrap()
        .starts_with("R, G, B: f_r in 1/sr"));
    assert_eq!(got["crc32"]["ok"], true, "{}", got["crc32"]);
    let meta: Metadata = serde_json::from_value(got["metadata"].clone()).unwrap();
    assert_eq!(meta, table.meta);
    let meta: Metadata =
        serde_json::from_str(attrs["clothbake.metadata"].as_str().unwrap()).unwrap();
    assert_eq!(meta, table.meta);

    for (k, c) in ["R", "G", "B"].into_iter().enumerate() {
        let plane = got["values"][c].as_array().unwrap();
        assert_eq!(plane.len() as u64, width * height);
        for ti in 0..grid.n_theta_i {
            for pi in 0..grid.n_phi_i {
                for to in 0..grid.n_theta_o {
                    for po in 0..grid.n_phi_o {
                        let (x, y) = (pi * grid.n_phi_o + po, ti * grid.n_theta_o + to);
                        let v = table.values[3 * grid.index(ti, pi, to, po) + k];
                        let expected = match precision {
                            Precision::F16 => half::f16::from_f32(v).to_f32(),
                            Precision::F32 => v,
                        };
                        let seen = plane[(y as u64 * width + x as u64) as usize]
                            .as_f64()
                            .unwrap();
                        assert_eq!(
                            seen,
                            f64::from(expected),
                            "{c} at pixel ({x}, {y}) = cell ({ti}, {pi}, {to}, {po})"
                        );
                    }
                }
            }
        }
    }
}

#[test]
#[cfg_attr(
    missing_openexr,
    ignore = "needs the OpenEXR and numpy Python packages: python3 -m pip install OpenEXR numpy, or run `cargo xtask test`"
)]
fn openexr_reads_what_we_write() {
    OPENEXR.require();
    check(Precision::F32);
    check(Precision::F16);
}
