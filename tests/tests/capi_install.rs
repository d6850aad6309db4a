//! `cargo xtask install-capi PREFIX` into a temporary folder, then examples/c/sample.c compiled
//! the way docs/reference/loader.md says, with `pkg-config --cflags --libs clothbake` (shared library)
//! and against the installed, stripped static library, and run on a baked table: both print
//! what the Rust loader computes.
//!
//! Runs xtask with a nested cargo (a release build: minutes the first time). Ignored, with the
//! reason, without pkg-config (the build script probes it); under `CI` it runs and fails
//! without it (.ci/run installs it).

use clothbake_bake::BakeOptions;
use clothbake_tests::fixtures::{
    check_sample_c_output, grid, root, succeeded as ok, temp_dir, twill_table,
};
use clothbake_tests::probe::PKG_CONFIG;
use std::path::Path;
use std::process::Command;

#[test]
#[cfg_attr(
    missing_pkgconfig,
    ignore = "needs pkg-config: apt-get install pkg-config (see the build warning)"
)]
fn installed_library_builds_the_example_with_pkg_config() {
    PKG_CONFIG.require();
    let dir = temp_dir("capi-install");
    let prefix = dir.join("prefix");
    // As `cargo xtask install-capi PREFIX` runs it (.cargo/config.toml's alias).
    let out = Command::new(env!("CARGO"))
        .current_dir(root())
        .args(["run", "--release", "--quiet", "--package", "xtask", "--"])
        .arg("install-capi")
        .arg(&prefix)
        .output()
        .expect("cargo runs");
    let log = ok("cargo xtask install-capi", &out);
    let prefix = prefix.canonicalize().unwrap();
    for f in [
        "include/clothbake.h",
        "lib/libclothbake_capi.a",
        "lib/libclothbake_capi.so",
        "lib/pkgconfig/clothbake.pc",
    ] {
        assert!(prefix.join(f).is_file(), "{f} not installed:\n{log}");
    }
    let header = std::fs::read(prefix.join("include/clothbake.h")).unwrap();
    assert_eq!(
        header,
        std::fs::read(root().join("crates/clothbake-capi/include/clothbake.h")).unwrap()
    );

    // A table to run the example on.
    let opts = BakeOptions {
        grid: grid(4, 8),
        ..BakeOptions::default()
    };
    let (table_path, b) = twill_table(&dir, &opts);

    let example = root().join("examples/c/sample.c");
    let cc = |args: &[String], exe: &Path| {
        let out = Command::new("cc")
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror"])
            .arg(&example)
            .args(args)
            .arg("-o")
            .arg(exe)
            .output()
            .expect("cc runs");
        ok("cc", &out);
    };

    // Shared: `cc sample.c $(pkg-config --cflags --libs clothbake)`.
    let flags = pkg_args(&prefix);
    assert!(flags.0.iter().any(|f| f == "-lclothbake_capi"), "{flags:?}");
    let shared = dir.join("sample-shared");
    cc(&flags.0, &shared);
    let run = Command::new(&shared)
        .env("LD_LIBRARY_PATH", prefix.join("lib"))
        .arg(&table_path)
        .output()
        .unwrap();
    check_sample_c_output(&ok("the shared-library example", &run), &b);
    // It is the shared library: without the folder on the search path it does not start.
    let run = Command::new(&shared)
        .env_remove("LD_LIBRARY_PATH")
        .arg(&table_path)
        .output()
        .unwrap();
    assert!(!run.status.success(), "linked statically after all");

    // Static: the installed (stripped) archive and the system libraries it needs.
    let stat = dir.join("sample-static");
    let mut args = flags.1.clone();
    args.push(prefix.join("lib/libclothbake_capi.a").display().to_string());
    args.extend(["-lpthread", "-ldl", "-lm"].map(String::from));
    cc(&args, &stat);
    let run = Command::new(&stat).arg(&table_path).output().unwrap();
    check_sample_c_output(&ok("the static-library example", &run), &b);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The words of `pkg-config --cflags --libs clothbake` and of `--cflags` alone, as a shell's
/// `$(...)` splits them.
fn pkg_args(prefix: &Path) -> (Vec<String>, Vec<String>) {
    let run = |args: &[&str]| -> Vec<String> {
        let out = Command::new("pkg-config")
            .env("PKG_CONFIG_PATH", prefix.join("lib/pkgconfig"))
            .args(args)
            .arg("clothbake")
            .output()
            .expect("pkg-config runs");
        ok("pkg-config", &out)
            .split_whitespace()
            .map(str::to_string)
            .collect()
    };
    (run(&["--cflags", "--libs"]), run(&["--cflags"]))
}
