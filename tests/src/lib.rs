//! Cross-crate helpers shared by the integration tests (`tests/tests/`), the benchmarks
//! (`tests/benches/`) and the xtasks that compare the model with the ground truth.

pub mod accuracy;
pub mod fixtures;
pub mod renderers;
pub mod validate;

/// The optional dependencies of some tests (Python packages, SLURM, AVX2): the same probes the
/// build script turns into `missing_<name>` cfgs; tests call [`probe::Dependency::require`] to
/// fail with a clear message when they run without theirs (under `CI`, or with `--ignored`).
pub mod probe {
    include!("../../crates/clothbake-loader/build/probe.rs");
    include!("../llvm_probe.rs");
}
