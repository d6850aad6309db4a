//! `cargo xtask test [ARGS]`: the whole suite on a fresh machine, nothing skipped that pip can
//! install. Creates the virtual environment `.venv` in the repository root (once, with
//! `python3 -m venv`), installs numpy, pytest, OpenEXR, mitsuba, bpy, materialx, usd-core and
//! pyradiance into it and the npm packages of tests/renderers with `npm ci` (the first time takes
//! minutes), then runs `cargo fmt --all -- --check`, `cargo clippy --workspace --all-targets --
//! -D warnings` and `cargo test --workspace [ARGS]` with the environment's `bin` first on PATH
//! and VIRTUAL_ENV set, so that the Python, Mitsuba and OpenEXR tests run, and with
//! DRJIT_LIBLLVM_PATH set (when unset) to a libLLVM >= 17 if one is found, for Mitsuba's llvm
//! variant. SLURM, LLVM, Chromium and Node.js are not pip packages: `.ci/run` installs them with
//! apt and then runs this with `CI=true`.

use clothbake_tests::probe::{libllvm, LLVM_MIN};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The Python packages the tests import: (the name pip installs, the name Python imports).
/// bpy is Blender as a module (its wheels exist for the Python version Blender ships with);
/// materialx and usd-core check the fitted OpenPBR material.
/// pyradiance (pinned) ships Radiance's binaries for the daylighting export's round trip.
const PACKAGES: [(&str, &str); 8] = [
    ("numpy", "numpy"),
    ("pytest", "pytest"),
    ("OpenEXR", "OpenEXR"),
    ("mitsuba", "mitsuba"),
    ("bpy", "bpy"),
    ("materialx", "MaterialX"),
    ("usd-core", "pxr"),
    ("pyradiance==1.3.1", "pyradiance"),
];

/// Runs `cmd`, printing it first; exits with its status when it fails.
fn run(what: &str, cmd: &mut Command) {
    println!("==> {what}");
    let status = cmd
        .status()
        .unwrap_or_else(|e| fail(&format!("{what}: cannot start: {e}")));
    if !status.success() {
        fail(&format!("{what} failed ({status})"));
    }
}

fn fail(msg: &str) -> ! {
    eprintln!("cargo xtask test: {msg}");
    std::process::exit(1);
}

/// The virtual environment, created when absent; returns its folder.
pub fn venv(root: &Path) -> PathBuf {
    let dir = root.join(".venv");
    let python = dir.join("bin/python3");
    if !python.exists() {
        run(
            "python3 -m venv .venv (a local Python environment for the tests, once)",
            Command::new("python3")
                .current_dir(root)
                .args(["-m", "venv", ".venv"]),
        );
        if !python.exists() {
            fail(
                "python3 -m venv did not create .venv/bin/python3; on Debian or Ubuntu install \
                 python3-venv (apt-get install python3-venv), then rerun",
            );
        }
    }
    let imports = format!("import {}", PACKAGES.map(|(_, import)| import).join(", "));
    let pip_names = PACKAGES.map(|(pip, _)| pip);
    let ready = Command::new(&python)
        .args(["-c", &imports])
        .output()
        .is_ok_and(|o| o.status.success());
    if ready {
        println!("==> .venv has {}", pip_names.join(", "));
    } else {
        run(
            &format!(
                "pip install {} into .venv (quietly; the first time installs about 1 GB, \
                 up to a few minutes)",
                pip_names.join(" ")
            ),
            Command::new(&python)
                .args([
                    "-m",
                    "pip",
                    "install",
                    "--quiet",
                    "--disable-pip-version-check",
                ])
                .args(pip_names),
        );
    }
    dir
}

/// The npm packages of tests/renderers (three.js, playwright-core, the glTF validator),
/// installed with `npm ci` from its lock file when `node_modules` is missing or older than the
/// lock file. Without npm, says so: the tests needing them are ignored (and fail under CI).
pub fn node_modules(root: &Path) {
    let dir = root.join("tests/renderers");
    let lock = dir.join("package-lock.json");
    let marker = dir.join("node_modules/.package-lock.json");
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let fresh = matches!((modified(&marker), modified(&lock)), (Some(m), Some(l)) if m >= l);
    if fresh {
        println!("==> tests/renderers/node_modules is installed");
        return;
    }
    if Command::new("npm").arg("--version").output().is_err() {
        println!(
            "==> npm not found (apt-get install nodejs npm chromium): the three.js tests \
             will be ignored (and fail under CI)"
        );
        return;
    }
    run(
        "npm ci in tests/renderers (three.js, playwright-core, gltf-validator; once)",
        Command::new("npm").current_dir(&dir).args([
            "ci",
            "--no-audit",
            "--no-fund",
            "--loglevel=error",
        ]),
    );
}

/// PATH with `bin` first.
pub fn path_with(bin: &Path) -> OsString {
    let mut dirs = vec![bin.to_path_buf()];
    if let Some(p) = std::env::var_os("PATH") {
        dirs.extend(std::env::split_paths(&p));
    }
    std::env::join_paths(dirs).unwrap_or_else(|e| fail(&format!("cannot build PATH: {e}")))
}

/// The cargo running this task (`CARGO`), or `cargo`.
pub fn cargo() -> OsString {
    std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into())
}

/// The task: see the module documentation. `args` go to `cargo test` after `--workspace`.
pub fn run_all(root: &Path, args: &[String]) {
    let venv = venv(root);
    node_modules(root);
    let cargo = cargo();
    let path = path_with(&venv.join("bin"));
    // Mitsuba's llvm variant (its tests and the gallery's) needs a libLLVM >= 17.
    let llvm = libllvm();
    match &llvm {
        Some(p) => println!("==> DRJIT_LIBLLVM_PATH={}", p.display()),
        None => println!(
            "==> no libLLVM >= {LLVM_MIN} found (apt-get install libllvm19): the tests of \
             Mitsuba's llvm variant will be ignored (and fail under CI)"
        ),
    }
    let cargo_cmd = |a: &[&str]| {
        let mut c = Command::new(&cargo);
        c.current_dir(root)
            .env("PATH", &path)
            .env("VIRTUAL_ENV", &venv)
            .env_remove("PYTHONHOME")
            .args(a);
        if let Some(p) = &llvm {
            c.env("DRJIT_LIBLLVM_PATH", p);
        }
        c
    };
    run(
        "cargo fmt --all -- --check",
        &mut cargo_cmd(&["fmt", "--all", "--", "--check"]),
    );
    run(
        "cargo clippy --workspace --all-targets -- -D warnings",
        &mut cargo_cmd(&[
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ]),
    );
    let mut test = cargo_cmd(&["test", "--workspace"]);
    test.args(args);
    let label: Vec<&str> = ["cargo test --workspace"]
        .into_iter()
        .chain(args.iter().map(String::as_str))
        .collect();
    run(&label.join(" "), &mut test);
    println!("==> all passed");
}
