//! `Fabric.two_faced()`: the two-faced cloth (docs/science/transmission.md) from Python: f over the
//! whole sphere (reflection off either face, transmission) and the openness, one pair at a time
//! or in batches.

use crate::args::{facet_model, variant_of};
use crate::table::table_err;
use crate::vectors::{check_unit, same_len, to_array, to_array1, unit_rows};
use clothbake_bake::two_faced::TwoFaced;
use clothbake_core::{Bsdf, Fabric, UnitVec3, Vec3};
use clothbake_loader::{Options, TableError, TwoFacedBrdf};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// The two-faced cloth of a fabric: no floor, light through the gaps and through translucent
/// yarns, the back the inverted weave (docs/science/transmission.md). `eval` gives f (1/sr, RGB) for
/// directions anywhere on the sphere (reflection where `wi` and `wo` are on one side,
/// transmission across), `openness` the share of the light from a direction that passes
/// straight through the gaps (a delta toward -wi, not in `eval`).
///
/// `TwoFaced.open(path)` opens a two-faced table (baked with `--faces two`) with the same
/// methods, looked up through the loader (docs/reference/table-format.md, "Two-faced tables").
#[pyclass(name = "TwoFaced", module = "clothbake", frozen)]
pub struct PyTwoFaced {
    /// The model (`Fabric.two_faced`) or a table's lookup (`TwoFaced.open`).
    cloth: Box<dyn Bsdf + Send + Sync>,
    name: String,
}

/// The `name` of a table's fabric JSON, if it has one.
fn fabric_name(json: &str) -> Option<String> {
    serde_json::from_str::<serde_json::Value>(json)
        .ok()
        .and_then(|v| v["name"].as_str().map(str::to_string))
}

fn unit(w: [f64; 3]) -> UnitVec3 {
    UnitVec3::new(Vec3::new(w[0], w[1], w[2])).unwrap_or(UnitVec3::Z)
}

/// Path-traces every node of `cloth`'s grid on the worker threads, without the GIL, while this
/// thread looks for signals every tenth of a second: Ctrl-C stops the work and raises
/// KeyboardInterrupt.
fn prepare_interruptibly(py: Python<'_>, cloth: &TwoFaced) -> PyResult<()> {
    let cancel = AtomicBool::new(false);
    let mut signal = None;
    py.detach(|| {
        std::thread::scope(|s| {
            let worker = s.spawn(|| cloth.prepare_or_cancel(&cancel));
            while !worker.is_finished() {
                std::thread::sleep(Duration::from_millis(100));
                if let Err(e) = Python::attach(|py| py.check_signals()) {
                    cancel.store(true, Ordering::SeqCst);
                    signal = Some(e);
                    break;
                }
            }
            worker.join().expect("the path tracing does not panic")
        })
    });
    match signal {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

impl PyTwoFaced {
    /// A two-faced table in memory (a bake's), looked up through the loader.
    pub fn from_table(table: clothbake_loader::Table) -> Result<Self, TableError> {
        let name = fabric_name(&table.meta.fabric_json).unwrap_or_default();
        Ok(PyTwoFaced {
            cloth: Box::new(TwoFacedBrdf::from_table(table, Options::default())?),
            name,
        })
    }

    /// The cloth of `fabric` with `facet` and `variant`, its path-traced grid computed now
    /// (without the GIL).
    pub fn build(
        py: Python<'_>,
        fabric: &Fabric,
        facet: &str,
        variant: &str,
        nodes: (i64, i64),
        paths: i64,
    ) -> PyResult<Self> {
        if !(1..=64).contains(&nodes.0) || !(1..=128).contains(&nodes.1) {
            return Err(PyValueError::new_err(format!(
                "nodes: {nodes:?}; give (polar, azimuth) node counts from 1 to 64 and 1 to 128"
            )));
        }
        let nodes = (nodes.0 as u32, nodes.1 as u32);
        let max_paths = clothbake_bake::sweep::MAX_PATHS;
        if !(1..=max_paths as i64).contains(&paths) {
            return Err(PyValueError::new_err(format!(
                "paths: {paths}; give eye rays a node from 1 to {max_paths} (2^24, as the \
                 command line's --paths)"
            )));
        }
        let paths = paths as usize;
        let need = TwoFaced::grid_bytes(nodes);
        if let Some(have) = clothbake_bake::memory::available_bytes() {
            if need > have {
                return Err(PyValueError::new_err(format!(
                    "nodes: {nodes:?} holds {} of path-traced nodes, but {} is available; give \
                     fewer (the grid grows as the square of polar x azimuth nodes: the default \
                     (5, 8) holds {})",
                    clothbake_bake::memory::describe(need),
                    clothbake_bake::memory::describe(have),
                    clothbake_bake::memory::describe(TwoFaced::grid_bytes((5, 8)))
                )));
            }
        }
        let facet = facet_model(facet)?;
        let variant = variant_of(variant)?;
        variant
            .check(fabric)
            .map_err(|e| PyValueError::new_err(format!("variant: {}", e.line())))?;
        let cloth = TwoFaced::with_grid(fabric, facet, variant, nodes, paths)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        prepare_interruptibly(py, &cloth)?;
        Ok(PyTwoFaced {
            cloth: Box::new(cloth),
            name: fabric.name().to_string(),
        })
    }
}

#[pymethods]
impl PyTwoFaced {
    /// Opens a two-faced table file (either format; baked with `clothbake --faces two`): its
    /// four blocks interpolated, the openness between its incident cells. Raises
    /// FileNotFoundError for a missing file and ValueError for a file that is not a valid
    /// two-faced table (a one-faced one opens with `Table.open`).
    #[staticmethod]
    #[pyo3(signature = (path, reciprocal=false))]
    fn open(py: Python<'_>, path: PathBuf, reciprocal: bool) -> PyResult<PyTwoFaced> {
        let options = Options {
            reciprocal,
            ..Options::default()
        };
        let table = py
            .detach(|| TwoFacedBrdf::open(&path, options))
            .map_err(|e| match e {
                TableError::WrongKind { .. } => PyValueError::new_err(format!(
                    "{}: a one-faced table (reflection over the floor); open it with \
                     clothbake.Table.open, or bake it with --faces two",
                    path.display()
                )),
                other => table_err(other),
            })?;
        let name =
            fabric_name(&table.meta().fabric_json).unwrap_or_else(|| path.display().to_string());
        Ok(PyTwoFaced {
            cloth: Box::new(table),
            name,
        })
    }

    /// f(wi, wo) in 1/sr for `(N, 3)` unit vectors `wi` (toward the light) and `wo` (toward
    /// the eye) anywhere on the sphere: an `(N, 3)` array (or `(3,)` for one pair).
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let wi = unit_rows("wi", wi)?;
        let wo = unit_rows("wo", wo)?;
        same_len(("wi", wi.rows.len()), ("wo", wo.rows.len()))?;
        let f: Vec<[f64; 3]> = py.detach(|| {
            wi.rows
                .iter()
                .zip(&wo.rows)
                .map(|(&a, &b)| self.cloth.f(unit(a), unit(b)))
                .collect()
        });
        to_array(py, &f, wi.single && wo.single)
    }

    /// The openness along each of the `(N, 3)` unit vectors `w` (either side): an `(N,)`
    /// array (or a scalar array for one).
    fn openness<'py>(&self, py: Python<'py>, w: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let w = unit_rows("w", w)?;
        let o: Vec<f64> = w
            .rows
            .iter()
            .map(|&a| self.cloth.openness(unit(a)))
            .collect();
        to_array1(py, o, w.single)
    }

    /// f for one pair of unit vectors, as a tuple (the scalar Mitsuba plugin's call).
    fn eval1(&self, wi: [f64; 3], wo: [f64; 3]) -> PyResult<(f64, f64, f64)> {
        check_unit("wi", 0, wi)?;
        check_unit("wo", 0, wo)?;
        let f = self.cloth.f(unit(wi), unit(wo));
        Ok((f[0], f[1], f[2]))
    }

    /// The openness along one unit vector.
    fn openness1(&self, w: [f64; 3]) -> PyResult<f64> {
        check_unit("w", 0, w)?;
        Ok(self.cloth.openness(unit(w)))
    }

    fn __repr__(&self) -> String {
        format!("clothbake.TwoFaced({:?})", self.name)
    }
}
