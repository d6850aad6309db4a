//! `clothbake.bake`: a table baked in memory by the baker library (`clothbake_bake::bake`).

use crate::fabric::{check_bounces, facet_model, PyFabric};
use crate::table::{table_err, PyTable};
use clothbake_bake::{bake as bake_grid, BakeError, BakeOptions};
use clothbake_loader::{Grid, StoredTable};
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;
use std::io::Write;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Bakes `fabric` into a Table in memory (f32 values), on all cores with the GIL released;
/// bit-identical whatever the thread count.
///
/// res: (n_theta_i, n_phi_i, n_theta_o, n_phi_o) cells, default (32, 64, 32, 64).
/// bounces: 1, or 2 to add the secondary reflection (thesis ch. 5; minutes at full res).
/// facet: "huo" (default) or "lewis". progress: print the percentage done to stderr.
#[pyfunction]
#[pyo3(signature = (fabric, res=(32, 64, 32, 64), bounces=1, facet="huo", progress=false))]
pub fn bake(
    py: Python<'_>,
    fabric: &PyFabric,
    res: (u32, u32, u32, u32),
    bounces: u32,
    facet: &str,
    progress: bool,
) -> PyResult<PyTable> {
    check_bounces(bounces)?;
    let grid = Grid {
        n_theta_i: res.0,
        n_phi_i: res.1,
        n_theta_o: res.2,
        n_phi_o: res.3,
    };
    grid.validate()
        .map_err(|e| PyValueError::new_err(format!("res: {e}")))?;
    let opts = BakeOptions {
        grid,
        facet: facet_model(facet)?,
        bounces,
        ..BakeOptions::default()
    };
    let total = clothbake_bake::evaluations(&fabric.fabric, &grid).max(1) as u64;
    let shown = AtomicU64::new(0);
    let report = |done: u64| {
        if !progress {
            return;
        }
        let pct = done * 100 / total;
        if shown.fetch_max(pct + 1, Ordering::Relaxed) < pct + 1 {
            let mut err = std::io::stderr().lock();
            let _ = write!(err, "\rbaking {}: {pct:3}%", fabric.fabric.name());
            if done >= total {
                let _ = writeln!(err);
            }
        }
    };
    let cancel = AtomicBool::new(false);
    let baked = py
        .detach(|| bake_grid(&fabric.fabric, &opts, &report, &cancel))
        .map_err(|e| match e {
            BakeError::Cancelled => PyKeyboardInterrupt::new_err("the bake was cancelled"),
            BakeError::Invalid(m) => PyValueError::new_err(m),
        })?;
    PyTable::from_stored(StoredTable::from(baked.table), false).map_err(table_err)
}
