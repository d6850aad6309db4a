//! The Python package (crates/clothbake-py) and its Mitsuba 3 plugin, end to end: builds the
//! extension module with cargo (`--release`, into target/release: the running `cargo test`
//! holds the lock of target/debug, so a nested build there would wait forever), stages it beside the package's Python files and
//! runs the package's pytest suite (crates/clothbake-py/tests) with `python3`.
//!
//! Skipped, with a message saying why, when `python3` with numpy and pytest is not there; the
//! Mitsuba rendering tests inside skip themselves when `mitsuba` is not installed (`.ci/run`
//! installs all three from PyPI).

use clothbake_tests::fixtures::temp_dir;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn python_ready() -> Result<(), String> {
    let out = Command::new("python3")
        .args(["-c", "import numpy, pytest"])
        .output()
        .map_err(|e| format!("python3 cannot be run: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "python3 lacks numpy or pytest ({}); pip install numpy pytest mitsuba",
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

/// Builds the extension module and the `clothbake` binary (for the comparison with
/// `clothbake render`); returns the shared library, beside which the binary lies.
fn build_extension() -> PathBuf {
    let status = Command::new(env!("CARGO"))
        .current_dir(root())
        .args([
            "build",
            "--quiet",
            "-p",
            "clothbake-py",
            "-p",
            "clothbake",
            "--release",
        ])
        .status()
        .expect("cargo runs");
    assert!(status.success(), "cargo build -p clothbake-py failed");
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target"));
    let lib = target.join("release").join("lib_native.so");
    assert!(lib.exists(), "{} was not built", lib.display());
    lib
}

/// A folder holding the `clothbake` package as a wheel would install it.
fn stage(lib: &Path) -> PathBuf {
    let dir = temp_dir("py-test");
    let pkg = dir.join("clothbake");
    std::fs::create_dir_all(&pkg).unwrap();
    let src = root().join("crates/clothbake-py/python/clothbake");
    for entry in std::fs::read_dir(&src).unwrap() {
        let p = entry.unwrap().path();
        std::fs::copy(&p, pkg.join(p.file_name().unwrap())).unwrap();
    }
    std::fs::copy(lib, pkg.join("_native.abi3.so")).unwrap();
    dir
}

#[test]
fn python_package_and_mitsuba_plugin() {
    if cfg!(not(target_os = "linux")) {
        eprintln!("SKIPPED python_package_and_mitsuba_plugin: the staging assumes Linux");
        return;
    }
    if let Err(why) = python_ready() {
        eprintln!("SKIPPED python_package_and_mitsuba_plugin: {why}");
        return;
    }
    let lib = build_extension();
    let dir = stage(&lib);
    let out = Command::new("python3")
        .current_dir(root())
        .env("PYTHONPATH", &dir)
        .env("CLOTHBAKE_BIN", lib.with_file_name("clothbake"))
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .args(["-m", "pytest", "-q", "-rs", "-s", "-p", "no:cacheprovider"])
        .arg("crates/clothbake-py/tests")
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
}
