//! Probes the optional dependencies of these tests (Python packages, Mitsuba's llvm variant, Radiance through pyradiance, SLURM,
//! AVX2 for the direct model's batch, the real renderers of the fitted materials: Blender's bpy,
//! MaterialX with usd-core, node with Chromium and tests/renderers/node_modules) and sets
//! `missing_<name>` for each one absent, so that the tests needing it show as ignored, with the
//! reason, instead of passing without running (and fail under `CI`); see the shared probes in
//! crates/clothbake-loader/build/probe.rs.

include!("../crates/clothbake-loader/build/probe.rs");
include!("llvm_probe.rs");

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-changed=../crates/clothbake-loader/build/probe.rs");
    println!("cargo::rerun-if-changed=llvm_probe.rs");
    // The web probe looks into renderers/node_modules (which `npm ci` replaces) and at $CHROMIUM.
    println!("cargo::rerun-if-changed=renderers");
    println!("cargo::rerun-if-env-changed=CHROMIUM");
    println!("cargo::rerun-if-env-changed=DRJIT_LIBLLVM_PATH");
    emit(&[
        PYTHON,
        NUMPY,
        MITSUBA,
        MITSUBA_LLVM,
        OPENEXR,
        MATERIALX,
        BLENDER,
        WEB,
        SLURM,
        PKG_CONFIG,
        AVX2,
        PYRADIANCE,
    ]);
}
