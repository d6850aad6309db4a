//! pbrt-v4's `measured` material and the spectral RGL file. pbrt-v4 cannot be built here (see
//! docs/guide/export.md), so this is NOT a real-client proof: tests/python/rgl_check.py reads the
//! file with its own numpy parser and checks every condition pbrt-v4's reader
//! (`MeasuredBxDFData::Create`, src/pbrt/bxdfs.cpp) places on it, as found in pbrt-v4's public
//! source: field names, types, ranks, matching extents, a full 2 pi azimuth range, increasing
//! nodes, wavelengths covering the 360-830 nm pbrt samples. With Mitsuba installed it also
//! projects every spectrum back to sRGB with Mitsuba's own CIE tables and compares with the RGB
//! file of the same export.
//!
//! Ignored, with the reason, when python3 cannot import numpy (the projection: mitsuba); under
//! `CI` they run and fail without them (.ci/run and `cargo xtask test` install them).

use clothbake_core::Fabric;
use clothbake_export::rgl;
use clothbake_tests::fixtures::{huo_bsdf, python, rgl_grid, succeeded, tables, temp_dir};
use clothbake_tests::probe::{MITSUBA, NUMPY};

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/python/rgl_check.py");

fn check(args: &[&str]) -> serde_json::Value {
    let text = succeeded(&format!("rgl_check.py {args:?}"), &python(SCRIPT, args));
    serde_json::from_str(text.trim()).unwrap()
}

/// The denim draft exported as a spectral and an RGB RGL file into a fresh folder `name`.
fn export(name: &str) -> (std::path::PathBuf, std::path::PathBuf, std::path::PathBuf) {
    let fabric = Fabric::from_path(&tables().join("denim.wif")).unwrap();
    let brdf = huo_bsdf(&fabric);
    let grid = rgl_grid(6, 8, 12);
    let dir = temp_dir(name);
    let (spec, rgb) = (dir.join("denim_spec.bsdf"), dir.join("denim_rgb.bsdf"));
    for (p, c) in [(&spec, rgl::Colour::Spectral), (&rgb, rgl::Colour::Rgb)] {
        let fields = rgl::rgl_fields(&brdf, &grid, "clothbake test: denim", c);
        clothbake_export::write_file(p, &rgl::tensor_file(&fields), true).unwrap();
    }
    (dir, spec, rgb)
}

#[test]
#[cfg_attr(
    missing_numpy,
    ignore = "needs python3 with numpy: python3 -m pip install numpy, or run `cargo xtask test`"
)]
fn the_spectral_file_meets_pbrt_v4s_reader() {
    NUMPY.require();
    let (dir, spec, rgb) = export("pbrt-reader");
    let s = check(&["pbrt", spec.to_str().unwrap()]);
    eprintln!("pbrt-v4 reader conditions: {s}");
    assert_eq!(s["ok"], true);
    assert_eq!(s["shape"], serde_json::json!([9, 6, 25, 12, 12]));
    // The RGB file is not a pbrt-v4 file (no spectra): the check must say so.
    let out = python(SCRIPT, &["pbrt", rgb.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("missing field spectra"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[cfg_attr(
    missing_mitsuba,
    ignore = "needs the mitsuba and numpy Python packages: python3 -m pip install mitsuba numpy, or run `cargo xtask test`"
)]
fn the_spectral_file_projects_back_to_the_rgb_file_with_mitsubas_cie_tables() {
    MITSUBA.require();
    let (dir, spec, rgb) = export("pbrt-projection");
    let p = check(&["project", spec.to_str().unwrap(), rgb.to_str().unwrap()]);
    eprintln!("spectra projected back with Mitsuba's CIE tables: {p}");
    assert!(p["max_error_rel_to_max"].as_f64().unwrap() < 1e-4, "{p}");
    std::fs::remove_dir_all(&dir).unwrap();
}
