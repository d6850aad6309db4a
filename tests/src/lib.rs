//! Cross-crate helpers shared by the integration tests (`tests/tests/`), the benchmarks
//! (`tests/benches/`) and `cargo xtask loader-accuracy`.

pub mod accuracy;
pub mod fixtures;
