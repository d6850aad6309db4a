//! The real-renderer harnesses of tests/renderers checked on their own, before any exported
//! material goes through them (tests/tests/export_fitted.rs): each harness's `--selftest`
//! renders materials it builds itself and checks the conventions the exporters rely on (a
//! Lambert material gives c / pi cos(theta_light); textures land where UV says; the framing
//! covers exactly [0.25, 0.75]^2; an anisotropic highlight follows the tangent +X by the
//! renderer's own GGX ratio), and the glTF validator reports a broken file.

use clothbake_tests::renderers;
use std::path::PathBuf;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clothbake-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
#[cfg_attr(
    missing_web,
    ignore = "needs node, Chromium and tests/renderers/node_modules (apt-get install chromium; npm ci in tests/renderers; or cargo xtask test)"
)]
fn three_js_harness_selftest() {
    let out = renderers::three_js_selftest();
    eprintln!("{out}");
    assert!(
        out.lines().filter(|l| l.starts_with("ok")).count() >= 12,
        "{out}"
    );
    assert!(!out.contains("FAIL"), "{out}");
}

#[test]
#[cfg_attr(
    any(missing_python, missing_blender),
    ignore = "needs python3 with bpy and numpy (pip install bpy numpy, or cargo xtask test)"
)]
fn cycles_harness_selftest() {
    let out = renderers::cycles_selftest();
    eprintln!("{out}");
    assert!(
        out.lines().filter(|l| l.starts_with("ok")).count() >= 14,
        "{out}"
    );
    assert!(!out.contains("FAIL"), "{out}");
}

#[test]
#[cfg_attr(
    missing_web,
    ignore = "needs node, Chromium and tests/renderers/node_modules (apt-get install chromium; npm ci in tests/renderers; or cargo xtask test)"
)]
fn gltf_validator_reports_a_broken_file() {
    // A GLB header that declares a length shorter than itself: one error, and the helper
    // panics with the report.
    let dir = temp_dir("validator");
    let glb = dir.join("broken.glb");
    let mut bytes = b"glTF".to_vec();
    bytes.extend(2u32.to_le_bytes());
    bytes.extend(12u32.to_le_bytes());
    bytes.extend([0u8; 8]);
    std::fs::write(&glb, &bytes).unwrap();
    let panic = std::panic::catch_unwind(|| renderers::validate_gltf(&glb))
        .expect_err("the validator finds an error");
    let msg = panic.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(msg.contains("numErrors"), "{msg}");
    assert!(msg.contains("GLB_"), "{msg}");
}
