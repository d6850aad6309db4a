//! Inputs and scratch folders shared by the integration tests.

use clothbake_bake::{bake, BakeOptions};
use clothbake_core::{AnalyticBsdf, AnalyticModel, Fabric, FacetModel};
use clothbake_export::rgl;
use clothbake_loader::{write_exr, Brdf, Grid, Options, Precision};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::AtomicBool;

/// The folder `clothbake-<name>-<process id>` in the system's temporary directory, created.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("clothbake-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The workspace root (the folder above this crate).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The shipped fabrics' folder, `tables/`.
pub fn tables() -> PathBuf {
    root().join("tables")
}

/// The files in `tables/` whose extension is `ext`, sorted by name.
pub fn shipped_files(ext: &str) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(tables())
        .expect("tables/ lists")
        .map(|e| e.expect("a tables/ entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == ext))
        .collect();
    found.sort();
    found
}

/// A direction grid of `n_theta` by `n_phi` cells for both the incident and the outgoing
/// direction.
pub fn grid(n_theta: u32, n_phi: u32) -> Grid {
    Grid::new(n_theta, n_phi, n_theta, n_phi)
}

/// The thesis's model of `fabric` (Huo facets, one bounce) as a BSDF, f_r in 1/sr.
pub fn huo_bsdf(fabric: &Fabric) -> AnalyticBsdf {
    AnalyticBsdf::new(AnalyticModel::new(fabric, FacetModel::Huo), None)
}

/// An RGL export grid of `n_theta` x `n_phi` nodes and `n_slice` slices.
pub fn rgl_grid(n_theta: usize, n_phi: usize, n_slice: usize) -> rgl::RglGrid {
    rgl::RglGrid {
        n_theta,
        n_phi,
        n_slice,
    }
}

/// The stdout of a finished process; panics naming `what`, its exit status, stdout and stderr
/// unless it succeeded.
pub fn succeeded(what: &str, out: &Output) -> String {
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs the Python script `script` (a path) with `args` under `python3`, finished.
pub fn python<S: AsRef<OsStr>>(script: &str, args: &[S]) -> Output {
    Command::new("python3")
        .arg(script)
        .args(args)
        .output()
        .expect("run python3")
}

/// The shipped twill (`tables/twill.json`) baked with `opts`, written to `dir/twill.exr` as an
/// f16 EXR, and the loader (default options) on it.
pub fn twill_table(dir: &Path, opts: &BakeOptions) -> (PathBuf, Brdf) {
    let fabric = Fabric::from_path(&tables().join("twill.json")).expect("the shipped twill reads");
    let table = bake(&fabric, opts, &|_| {}, &AtomicBool::new(false))
        .expect("the bake succeeds")
        .table;
    let path = dir.join("twill.exr");
    write_exr(&path, &table, Precision::F16, false).expect("the table is written");
    let b = Brdf::open(&path, Options::default()).expect("the table reads back");
    (path, b)
}

/// Builds `packages` in release mode with a nested cargo and returns the folder of their
/// artefacts (target/release). Release, not the running test's profile: the running `cargo
/// test` holds the lock of target/debug, so a nested build there would wait forever.
pub fn release_build(packages: &[&str]) -> PathBuf {
    let root = root();
    let mut cmd = Command::new(env!("CARGO"));
    cmd.current_dir(&root)
        .args(["build", "--quiet", "--release"]);
    for p in packages {
        cmd.args(["-p", p]);
    }
    let status = cmd.status().expect("cargo runs");
    assert!(
        status.success(),
        "cargo build --release {packages:?} failed"
    );
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"))
        .join("release")
}

/// Stages the `clothbake` Python package in `dir` as a wheel would install it: `dir/clothbake`
/// holds the package's Python files (crates/clothbake-py/python/clothbake) and the extension
/// module `lib` (`lib_native.so` of a release build) as `_native.abi3.so`. Put `dir` on
/// PYTHONPATH to import it.
pub fn stage_python_package(lib: &Path, dir: &Path) -> std::io::Result<()> {
    let pkg = dir.join("clothbake");
    std::fs::create_dir_all(&pkg)?;
    for entry in std::fs::read_dir(root().join("crates/clothbake-py/python/clothbake"))? {
        let p = entry?.path();
        if p.is_file() {
            std::fs::copy(&p, pkg.join(p.file_name().unwrap_or_default()))?;
        }
    }
    std::fs::copy(lib, pkg.join("_native.abi3.so"))?;
    Ok(())
}

/// The shipped twill (`tables/twill.json`) with the albedo (0.6, 0.3, 0.12) on both groups, so
/// that the three channels differ.
pub fn coloured_twill() -> Fabric {
    Fabric::from_path(&tables().join("twill.json"))
        .expect("the shipped twill reads")
        .with_groups(
            |_, g| g.material.albedo = [0.6, 0.3, 0.12],
            &clothbake_core::PlainNaming("twill"),
        )
        .expect("albedos in [0, 1]")
}

/// Bakes `fabric` with the default options (analytic model, default grid), writes the table to
/// `path` as an f16 EXR and opens it for lookups (no sampling tables).
pub fn bake_and_open(fabric: &Fabric, path: &Path) -> Brdf {
    let table = bake(
        fabric,
        &BakeOptions::default(),
        &|_| {},
        &AtomicBool::new(false),
    )
    .expect("the bake succeeds")
    .table;
    write_exr(path, &table, Precision::F16, true).expect("the table is written");
    let options = Options {
        sampling: false,
        ..Default::default()
    };
    Brdf::open(path, options).expect("the table reads back")
}

/// The directions and random numbers of examples/c/sample.c, as it spells them.
pub const SAMPLE_C_WI: [f32; 3] = [0.3, 0.1, 0.948_683_3];
/// See [`SAMPLE_C_WI`].
pub const SAMPLE_C_WO: [f32; 3] = [-0.4, 0.2, 0.894_427_2];
/// See [`SAMPLE_C_WI`].
pub const SAMPLE_C_U: (f32, f32) = (0.25, 0.75);

/// Checks what examples/c/sample.c printed against the Rust loader's `b` on the same table:
/// every number (printed with 9 significant digits, enough to give the f32 back) equal.
pub fn check_sample_c_output(stdout: &str, b: &Brdf) {
    let numbers = |line: &str| -> Vec<f32> {
        line.split_whitespace()
            .filter_map(|w| w.parse::<f32>().ok())
            .collect()
    };
    let mut lines = stdout.lines();
    let f = numbers(lines.next().expect("an f_r line"));
    assert_eq!(f, b.eval(SAMPLE_C_WI, SAMPLE_C_WO), "{stdout}");
    let s = numbers(lines.next().expect("a sample line"));
    let want = b.sample(SAMPLE_C_WO, SAMPLE_C_U.0, SAMPLE_C_U.1);
    let mut expected = want.wi.to_vec();
    expected.extend(want.weight);
    expected.push(want.pdf);
    assert_eq!(s, expected, "{stdout}");
    assert!(want.pdf > 0.0, "the example's sample is a real one");
}
