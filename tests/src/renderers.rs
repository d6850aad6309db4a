//! The real renderers the fitted materials are tested in, run through the scripts of
//! tests/renderers, whose header comments document their conventions: three.js in headless
//! Chromium (`three_swatch.mjs`, with `node` from PATH and tests/renderers/node_modules), the
//! Khronos glTF validator (`validate_gltf.mjs`) and Blender's Cycles (`cycles_swatch.py`, with
//! the `python3` on PATH, which `cargo xtask test` makes the local .venv's).
//!
//! In short: the swatch is the unit square [0,1]^2 of the XY plane at z = 0, normal +Z, u along
//! +X, v along +Y in Blender (glTF's UV is (x, 1 - y)), the tangent +X; one parallel light of
//! irradiance 1 toward `light`; an orthographic image of exactly the square [0.25, 0.75]^2 seen
//! from (theta, phi); no tone mapping. Each result is the image's mean linear RGB: the mean over
//! the square of f_r(light, view) cos(theta_light).
//!
//! Each helper first requires its probe ([`crate::probe::WEB`], [`crate::probe::BLENDER`]), so
//! a test run without the renderer fails saying what to install.

use crate::probe;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One view of the swatch: the unit direction toward the light, and the view direction's
/// polar angle and azimuth in degrees.
#[derive(Clone, Copy, Debug)]
pub struct SwatchView {
    /// Toward the light (normalised by the renderers), above the swatch.
    pub light: [f64; 3],
    /// The view's polar angle, degrees, below 80; `width` cos(theta) whole gives square
    /// pixels (otherwise the harnesses keep the coverage exact with slightly oblong pixels).
    pub theta_deg: f64,
    /// The view's azimuth, degrees, a multiple of 90.
    pub phi_deg: f64,
}

impl SwatchView {
    /// The unit vector toward the eye.
    pub fn view(&self) -> [f64; 3] {
        let (t, p) = (self.theta_deg.to_radians(), self.phi_deg.to_radians());
        [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]
    }
}

/// tests/renderers.
pub fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("renderers")
}

/// The CONFIGS.json of `views` at `width` pixels.
pub fn configs_json(views: &[SwatchView], width: usize) -> String {
    let c: Vec<serde_json::Value> = views
        .iter()
        .map(|v| {
            serde_json::json!({"light": v.light, "view_theta_deg": v.theta_deg,
                               "view_phi_deg": v.phi_deg})
        })
        .collect();
    serde_json::json!({"width": width, "configs": c}).to_string()
}

/// Runs `cmd`; panics with its output when it fails; returns its stdout.
fn run(what: &str, cmd: &mut Command) -> String {
    let o = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what} cannot be started: {e}"));
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "{what} failed ({}): {}{out}",
        o.status,
        String::from_utf8_lossy(&o.stderr)
    );
    out
}

/// Runs `cmd` with a configs file and an output file in `work`, and returns (renderer, the
/// mean RGB of each view).
fn run_swatch(
    what: &str,
    mut cmd: Command,
    work: &Path,
    views: &[SwatchView],
    width: usize,
) -> (String, Vec<[f64; 3]>) {
    std::fs::create_dir_all(work).expect("the work folder");
    let configs = work.join("configs.json");
    let out = work.join("out.json");
    let _ = std::fs::remove_file(&out);
    std::fs::write(&configs, configs_json(views, width)).expect("write configs");
    run(what, cmd.arg(&configs).arg(&out));
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&out).expect("its output")).expect("JSON");
    let rgb = v["results"]
        .as_array()
        .expect("results")
        .iter()
        .map(|r| {
            let c = &r["rgb"];
            [0, 1, 2].map(|k| c[k].as_f64().expect("a number"))
        })
        .collect::<Vec<_>>();
    assert_eq!(rgb.len(), views.len(), "{what}: one result per view");
    (v["renderer"].as_str().unwrap_or("?").to_string(), rgb)
}

/// The swatch of `glb` rendered by three.js in Chromium, one mean RGB per view, and the
/// renderer's name ("three.js 0.187.0"). `work` receives the configs and the output.
pub fn three_js(
    glb: &Path,
    views: &[SwatchView],
    width: usize,
    work: &Path,
) -> (String, Vec<[f64; 3]>) {
    probe::WEB.require();
    let mut cmd = Command::new("node");
    cmd.arg(dir().join("three_swatch.mjs")).arg(glb);
    run_swatch("three_swatch.mjs", cmd, work, views, width)
}

/// The material of the Blender module `module` (its `build_material`) rendered on the swatch
/// by Cycles with `samples` per pixel, and the renderer's name ("Blender 5.0.1 Cycles").
pub fn cycles(
    module: &Path,
    views: &[SwatchView],
    width: usize,
    samples: u32,
    work: &Path,
) -> (String, Vec<[f64; 3]>) {
    probe::BLENDER.require();
    let mut cmd = Command::new("python3");
    cmd.arg(dir().join("cycles_swatch.py"))
        .arg(module)
        .args(["--samples", &samples.to_string()]);
    run_swatch("cycles_swatch.py", cmd, work, views, width)
}

/// The Khronos validator's report on `glb` (numErrors, numWarnings, numInfos, numHints,
/// messages); panics with it when it finds an error.
pub fn validate_gltf(glb: &Path) -> serde_json::Value {
    probe::WEB.require();
    let report = run(
        "the glTF validator",
        Command::new("node")
            .arg(dir().join("validate_gltf.mjs"))
            .arg(glb),
    );
    serde_json::from_str(&report).expect("the validator's JSON")
}

/// Runs a harness's own self-test (`--selftest`: its conventions checked on materials it
/// builds itself); panics with its output when a check fails; returns the output (one line
/// per check, the measurements, the time).
pub fn three_js_selftest() -> String {
    probe::WEB.require();
    run(
        "three_swatch.mjs --selftest",
        Command::new("node")
            .arg(dir().join("three_swatch.mjs"))
            .arg("--selftest"),
    )
}

/// `cycles_swatch.py --selftest`, as [`three_js_selftest`].
pub fn cycles_selftest() -> String {
    probe::BLENDER.require();
    run(
        "cycles_swatch.py --selftest",
        Command::new("python3")
            .arg(dir().join("cycles_swatch.py"))
            .arg("--selftest"),
    )
}
