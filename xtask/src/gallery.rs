//! `cargo xtask gallery [--quick] [--envmap FILE.exr] [--only NAME,...]`: regenerates
//! `docs/gallery/` (the PNGs and their README) with Mitsuba 3, through
//! `python/gallery/gallery.py`, then (full gallery) `python/gallery/mainstream.py`, the
//! fitted materials in three.js and Cycles beside the plugin. Builds the `clothbake` binary and the Python extension in
//! release mode, stages the `clothbake` package under `target/gallery/python`, installs
//! numpy, pytest, OpenEXR and mitsuba into `.venv` when they are missing (as `cargo xtask
//! test`), sets DRJIT_LIBLLVM_PATH to a libLLVM >= 17 when it is unset (Mitsuba's llvm variant
//! needs one; `apt-get install libllvm19`), and runs the script under `nice`. Baked tables are
//! cached under `target/gallery/tables`. `--quick` renders small and noisy pictures into
//! `target/gallery/quick` instead (what the test `gallery_quick` runs).

use crate::test::{cargo, path_with, venv};
use clothbake_tests::fixtures::stage_python_package;
use clothbake_tests::probe::{libllvm, LLVM_MIN};
use std::path::Path;
use std::process::Command;

fn fail(msg: &str) -> ! {
    eprintln!("cargo xtask gallery: {msg}");
    std::process::exit(1);
}

/// The task: see the module documentation. `args` go to gallery.py.
pub fn run(root: &Path, args: &[String]) {
    let venv = venv(root);
    let path = path_with(&venv.join("bin"));
    println!("==> cargo build --release -p clothbake -p clothbake-py");
    // With the environment's python first, as `cargo xtask test` builds (PyO3's build
    // configuration follows the python on PATH: the same one, no rebuild between the two).
    let status = Command::new(cargo())
        .current_dir(root)
        .env("PATH", &path)
        .env("VIRTUAL_ENV", &venv)
        .args([
            "build",
            "--release",
            "-p",
            "clothbake",
            "-p",
            "clothbake-py",
        ])
        .status()
        .unwrap_or_else(|e| fail(&format!("cannot run cargo: {e}")));
    if !status.success() {
        fail("the release build failed");
    }
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(Into::into)
        .unwrap_or_else(|| root.join("target"));
    let release = target.join("release");
    let staged = target.join("gallery/python");
    let _ = std::fs::remove_dir_all(&staged);
    stage_python_package(&release.join("lib_native.so"), &staged)
        .unwrap_or_else(|e| fail(&format!("cannot stage the Python package: {e}")));
    let llvm = libllvm().unwrap_or_else(|| {
        fail(&format!(
            "Mitsuba's llvm variant needs a libLLVM of version {LLVM_MIN} or later: apt-get \
             install libllvm19, or set DRJIT_LIBLLVM_PATH to one"
        ))
    });
    // One of python/gallery's scripts, under nice, with the staged package and Mitsuba's LLVM.
    let script = |name: &str| {
        let mut cmd = Command::new("nice");
        cmd.current_dir(root)
            .env("PATH", &path)
            .env("VIRTUAL_ENV", &venv)
            .env("PYTHONPATH", &staged)
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .env("DRJIT_LIBLLVM_PATH", &llvm)
            .args(["-n", "10"])
            .arg(venv.join("bin/python3"))
            .arg(Path::new("python/gallery").join(name))
            .arg("--clothbake")
            .arg(release.join("clothbake"))
            .arg("--cache")
            .arg(target.join("gallery"));
        cmd
    };
    let mut cmd = script("gallery.py");
    if args.iter().any(|a| a == "--quick") {
        cmd.arg("--out").arg(target.join("gallery/quick"));
    }
    println!("==> python/gallery/gallery.py {}", args.join(" "));
    let status = cmd
        .args(args)
        .status()
        .unwrap_or_else(|e| fail(&format!("cannot run python: {e}")));
    if !status.success() {
        std::process::exit(status.code().unwrap_or(1));
    }
    // The fitted materials in three.js and Cycles beside the plugin (full gallery only, or
    // when --only names it).
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1));
    let wanted = only.is_none_or(|o| {
        o.split(',')
            .any(|n| "gingham-three-renderers".starts_with(n))
    });
    if args.iter().any(|a| a == "--quick") || !wanted {
        return;
    }
    crate::test::node_modules(root);
    println!("==> python/gallery/mainstream.py");
    let status = script("mainstream.py")
        .status()
        .unwrap_or_else(|e| fail(&format!("cannot run python: {e}")));
    if !status.success() {
        std::process::exit(status.code().unwrap_or(1));
    }
}
