//! The Python package (crates/clothbake-py) and its Mitsuba 3 plugin, end to end: builds the
//! extension module with a nested cargo (`fixtures::release_build`), stages it beside the
//! package's Python files and runs the package's pytest files (crates/clothbake-py/tests) with
//! `python3`: the package's own tests, and the Mitsuba plugin's.
//!
//! Each is ignored, with the reason, when its Python packages are missing (the build script
//! probes them); under `CI` they run and fail without them (.ci/run and `cargo xtask test`
//! install numpy, pytest and mitsuba). A pytest skip inside counts as a failure: nothing that
//! can be installed is skipped silently.

use clothbake_tests::fixtures::{release_build, temp_dir};
use clothbake_tests::probe::{MITSUBA, PYTHON};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A folder holding the `clothbake` package as a wheel would install it, with the extension
/// module `lib`.
fn stage(lib: &Path, name: &str) -> PathBuf {
    let dir = temp_dir(name);
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

/// Runs pytest on one file of crates/clothbake-py/tests against a freshly built and staged
/// package (and the `clothbake` binary, for the comparison with `clothbake render`); fails
/// when pytest fails or skips anything.
fn pytest(file: &str) {
    let release = release_build(&["clothbake-py", "clothbake"]);
    let lib = release.join("lib_native.so");
    assert!(lib.exists(), "{} was not built", lib.display());
    let dir = stage(&lib, &format!("py-{}", file.trim_end_matches(".py")));
    let out = Command::new("python3")
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
