//! The real renderers the fitted materials are tested in, run through the scripts of
//! tests/renderers (their conventions are documented there): three.js in headless Chromium
//! (`three_swatch.mjs`), the Khronos glTF validator (`validate_gltf.mjs`) and Blender's Cycles
//! (`cycles_swatch.py`, with the `python3` on PATH, which `cargo xtask test` makes the local
//! .venv's).

use std::path::{Path, PathBuf};
use std::process::Command;

/// One view of the swatch: the unit direction toward the light, and the view direction's
/// polar angle and azimuth in degrees (the azimuth a multiple of 90).
#[derive(Clone, Copy, Debug)]
pub struct SwatchView {
    /// Toward the light.
    pub light: [f64; 3],
    /// The view's polar angle, degrees; `width` cos(theta) must be whole.
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

fn configs_json(views: &[SwatchView], width: usize) -> String {
    let c: Vec<serde_json::Value> = views
        .iter()
        .map(|v| {
            serde_json::json!({"light": v.light, "view_theta_deg": v.theta_deg,
                               "view_phi_deg": v.phi_deg})
        })
        .collect();
    serde_json::json!({"width": width, "configs": c}).to_string()
}

/// Runs `cmd` with a configs file and an output file in `work`, and returns (renderer, the
/// mean RGB of each view).
fn run_swatch(
    mut cmd: Command,
    work: &Path,
    views: &[SwatchView],
    width: usize,
) -> (String, Vec<[f64; 3]>) {
    let configs = work.join("configs.json");
    let out = work.join("out.json");
    std::fs::write(&configs, configs_json(views, width)).expect("write configs");
    let o = cmd
        .arg(&configs)
        .arg(&out)
        .output()
        .expect("the renderer starts");
    assert!(
        o.status.success(),
        "the renderer failed: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
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
    assert_eq!(rgb.len(), views.len());
    (v["renderer"].as_str().unwrap_or("?").to_string(), rgb)
}

/// The swatch of `glb` rendered by three.js in Chromium, one mean RGB per view (and the
/// renderer's name).
pub fn three_js(
    glb: &Path,
    views: &[SwatchView],
    width: usize,
    work: &Path,
) -> (String, Vec<[f64; 3]>) {
    let mut cmd = Command::new("node");
    cmd.arg(dir().join("three_swatch.mjs")).arg(glb);
    run_swatch(cmd, work, views, width)
}

/// The material of the Blender module `module` rendered on the swatch by Cycles.
pub fn cycles(
    module: &Path,
    views: &[SwatchView],
    width: usize,
    samples: u32,
    work: &Path,
) -> (String, Vec<[f64; 3]>) {
    let mut cmd = Command::new("python3");
    cmd.arg(dir().join("cycles_swatch.py"))
        .arg(module)
        .args(["--samples", &samples.to_string()]);
    run_swatch(cmd, work, views, width)
}

/// The Khronos validator's report on `glb`; panics with it when it finds an error.
pub fn validate_gltf(glb: &Path) -> serde_json::Value {
    let o = Command::new("node")
        .arg(dir().join("validate_gltf.mjs"))
        .arg(glb)
        .output()
        .expect("node runs");
    let report = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "glTF validator: {report}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_str(&report).expect("the validator's JSON")
}
