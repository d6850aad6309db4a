//! Python bindings of clothbake: the `clothbake._native` extension module behind the
//! `clothbake` Python package (python/clothbake). A crate of its own so that PyO3 stays out of
//! `clothbake-loader`, which C and Rust renderers link.
//!
//! Frame everywhere: +X weft, +Y warp, +Z macro normal; `wi` toward the light, `wo` toward
//! the eye; f_r in 1/sr, RGB.

mod args;
mod bake;
mod fabric;
mod table;
mod two_faced;
mod vectors;

use pyo3::prelude::*;

/// `n` pairs of directions spread over the upper hemisphere (uniform in solid angle, from a
/// fixed integer hash): the Rust side of the Python benchmark.
pub(crate) fn bench_directions(n: usize) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 40) as f32 + 0.5) / (1u64 << 24) as f32
    };
    let mut dir = move || {
        let z = next();
        let phi = std::f32::consts::TAU * next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        [r * phi.cos(), r * phi.sin(), z]
    };
    (0..n).map(|_| (dir(), dir())).unzip()
}

/// The native module: `Fabric`, `Table`, `TwoFaced`, `bake`, `__version__` (the crate's version).
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<fabric::PyFabric>()?;
    m.add_class::<table::PyTable>()?;
    m.add_class::<two_faced::PyTwoFaced>()?;
    m.add_function(wrap_pyfunction!(bake::bake, m)?)?;
    m.add("UNIT_TOLERANCE", vectors::UNIT_TOLERANCE)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
