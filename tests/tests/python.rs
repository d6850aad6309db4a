//! The Python package (crates/clothbake-py) and its Mitsuba 3 plugin, end to end: builds the
//! extension module with a nested cargo (`fixtures::release_build`), stages it beside the
//! package's Python files and runs the package's pytest files (crates/clothbake-py/tests) with
//! `python3`: the package's own tests, and the Mitsuba plugin's in the scalar and the llvm
//! variant (with DRJIT_LIBLLVM_PATH set to the libLLVM >= 17 that `probe::libllvm` finds).
//!
//! Each is ignored, with the reason, when its Python packages are missing (the build script
//! probes them); under `CI` they run and fail without them (.ci/run and `cargo xtask test`
//! install numpy, pytest and mitsuba). A pytest skip inside counts as a failure: nothing that
//! can be installed is skipped silently.

use clothbake_tests::fixtures::{release_build, stage_python_package, temp_dir};
use clothbake_tests::probe::{libllvm, MITSUBA, MITSUBA_LLVM, PYTHON};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A folder holding the `clothbake` package as a wheel would install it, with the extension
/// module `lib`.
fn stage(lib: &Path, name: &str) -> PathBuf {
    let dir = temp_dir(name);
    stage_python_package(lib, &dir).expect("the package stages");
    dir
}

/// Runs pytest on one file of crates/clothbake-py/tests against a freshly built and staged
/// package (and the `clothbake` binary, for the comparison with `clothbake render`); fails
/// when pytest fails or skips anything.
fn pytest(file: &str) {
    let release = release_build(&["clothbake-py", "clothbake"]);
    let lib = release.join("lib_native.so");
    assert!(lib.exists(), "{} was not built", lib.display());
    let dir = stage(&lib, &format!("py-{}", file.trim_end_matches(".py")));
    let mut cmd = Command::new("python3");
    if let Some(llvm) = libllvm() {
        // For Mitsuba's llvm variants (tests/llvm_probe.rs).
        cmd.env("DRJIT_LIBLLVM_PATH", llvm);
    }
    let out = cmd
        .current_dir(root())
        .env("PYTHONPATH", &dir)
        .env("CLOTHBAKE_BIN", release.join("clothbake"))
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .args(["-m", "pytest", "-q", "-rs", "-s", "-p", "no:cacheprovider"])
        .arg(Path::new("crates/clothbake-py/tests").join(file))
        .output()
        .expect("python3 runs");
    let _ = std::fs::remove_dir_all(&dir);
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{text}");
    assert!(out.status.success(), "the Python tests failed:\n{text}");
    // The summary line, e.g. "12 passed, 1 skipped in 3.2s".
    let summary = text
        .lines()
        .rev()
        .find(|l| l.contains(" passed"))
        .unwrap_or("");
    assert!(
        !summary.contains("skipped"),
        "pytest skipped tests ({summary}); see the SKIPPED lines above for what to install"
    );
}

#[test]
#[cfg_attr(
    any(missing_python, not(target_os = "linux")),
    ignore = "needs Linux and python3 with numpy and pytest: python3 -m pip install numpy pytest, or run `cargo xtask test`"
)]
fn python_package() {
    PYTHON.require();
    pytest("test_clothbake.py");
}

#[test]
#[cfg_attr(
    any(missing_python, missing_mitsuba, not(target_os = "linux")),
    ignore = "needs Linux and python3 with numpy, pytest and mitsuba: python3 -m pip install numpy pytest mitsuba, or run `cargo xtask test`"
)]
fn python_mitsuba_plugin() {
    PYTHON.require();
    MITSUBA.require();
    pytest("test_mitsuba.py");
}

#[test]
#[cfg_attr(
    any(missing_python, missing_mitsuba_llvm, not(target_os = "linux")),
    ignore = "needs Linux, python3 with numpy, pytest and mitsuba, and a libLLVM >= 17 for Mitsuba's llvm_ad_rgb variant: python3 -m pip install numpy pytest mitsuba; apt-get install libllvm19 (or set DRJIT_LIBLLVM_PATH; `cargo xtask test` installs the Python packages, not libLLVM)"
)]
fn python_mitsuba_plugin_llvm() {
    PYTHON.require();
    MITSUBA_LLVM.require();
    pytest("test_mitsuba_llvm.py");
}

/// `cargo xtask gallery --quick`'s pipeline (python/gallery/gallery.py): bakes and exports
/// every shipped fabric's tables, renders each picture small with few samples in
/// `llvm_ad_rgb`, and writes the PNGs and `gallery.json`; every shipped fabric (tables/*.json,
/// *.wif) has its far and close picture, and the comparisons are there, finite and not black.
#[test]
#[cfg_attr(
    any(missing_python, missing_mitsuba_llvm, not(target_os = "linux")),
    ignore = "needs Linux, python3 with numpy and mitsuba, and a libLLVM >= 17 for Mitsuba's llvm_ad_rgb variant: python3 -m pip install numpy pytest mitsuba; apt-get install libllvm19 (or set DRJIT_LIBLLVM_PATH; `cargo xtask test` installs the Python packages, not libLLVM)"
)]
fn gallery_quick() {
    PYTHON.require();
    MITSUBA_LLVM.require();
    let release = release_build(&["clothbake-py", "clothbake"]);
    let dir = stage(&release.join("lib_native.so"), "gallery");
    let out = dir.join("out");
    let mut cmd = Command::new("python3");
    if let Some(llvm) = libllvm() {
        cmd.env("DRJIT_LIBLLVM_PATH", llvm);
    }
    let run = cmd
        .current_dir(root())
        .env("PYTHONPATH", &dir)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .arg("python/gallery/gallery.py")
        .arg("--quick")
        .arg("--clothbake")
        .arg(release.join("clothbake"))
        .arg("--out")
        .arg(&out)
        .arg("--cache")
        .arg(dir.join("cache"))
        .output()
        .expect("python3 runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    eprintln!("{text}");
    assert!(run.status.success(), "the gallery failed:\n{text}");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("gallery.json")).unwrap()).unwrap();
    let pictures = manifest["pictures"].as_object().expect("pictures");
    let mut expected = vec![
        "denim-direct-vs-all-bounces".to_string(),
        "satin5-model-vs-table".to_string(),
        "twill-plugin-vs-measured".to_string(),
    ];
    for entry in std::fs::read_dir(root().join("tables")).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "json" || e == "wif") {
            let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
            expected.push(format!("{stem}-far"));
            expected.push(format!("{stem}-close"));
        }
    }
    for name in &expected {
        let pic = &pictures
            .get(name)
            .unwrap_or_else(|| panic!("no picture {name} in {pictures:?}"));
        assert!(
            out.join(format!("{name}.png")).is_file(),
            "{name}.png missing"
        );
        assert_eq!(pic["finite"], true, "{name}: NaN or infinite pixels");
        assert_eq!(
            (pic["width"].as_u64(), pic["height"].as_u64()),
            (Some(160), Some(120))
        );
        let mean: Vec<f64> = pic["mean"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert!(mean.iter().all(|&m| m > 0.01), "{name}: black ({mean:?})");
    }
    assert_eq!(pictures.len(), expected.len(), "unexpected pictures");
    let _ = std::fs::remove_dir_all(&dir);
}
