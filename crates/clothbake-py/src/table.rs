//! `clothbake.Table`: a baked BRDF table with the loader's interpolated lookup
//! (`clothbake_loader::Brdf`) and importance sampling.

use crate::vectors::{
    check_footprint, check_unit, period_rows, rows, same_len, to_array, to_array1, unit_rows,
    unit_rows_f32, widths,
};
use clothbake_loader::{
    write_binary, write_exr, Brdf, Memory, Options, Precision, StoredTable, TableError,
};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyFileExistsError, PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::path::PathBuf;

/// The Python exception of a table error: FileNotFoundError, FileExistsError, OSError for
/// other I/O failures, ValueError for a file that is not a valid table. The message is the
/// loader's (it names the file, the cause and the fix).
pub fn table_err(e: TableError) -> PyErr {
    let msg = e.to_string();
    match &e {
        TableError::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(msg)
        }
        TableError::Io { .. } | TableError::NoSuchFolder { .. } => PyOSError::new_err(msg),
        TableError::AlreadyExists { path } => PyFileExistsError::new_err(format!(
            "{}: the file already exists; pass overwrite=True to replace it",
            path.display()
        )),
        _ => PyValueError::new_err(msg),
    }
}

/// A baked table of f_r (1/sr, RGB) on a cell-centred (theta_i, phi_i, theta_o, phi_o) grid.
#[pyclass(name = "Table", module = "clothbake", frozen)]
pub struct PyTable {
    /// A spatial table's values as stored (an averaged table's are read back from the
    /// lookup's nodes when asked for: `Brdf::to_stored`).
    stored: Option<StoredTable>,
    brdf: Brdf,
    reciprocal: bool,
}

/// The options a Python table is opened with: as stored, sampling ready.
fn table_options(reciprocal: bool, point_level: bool) -> Options {
    Options {
        memory: Memory::AsStored,
        reciprocal,
        sampling: true,
        point_level,
    }
}

impl PyTable {
    /// A table in memory, ready for lookups and sampling; `point_level` as
    /// [`Options::point_level`].
    pub fn from_stored(
        stored: StoredTable,
        reciprocal: bool,
        point_level: bool,
    ) -> Result<PyTable, TableError> {
        let options = table_options(reciprocal, point_level);
        let spatial = stored.meta.spatial.is_some();
        let (brdf, stored) = if spatial {
            (Brdf::from_stored(stored.clone(), options)?, Some(stored))
        } else {
            (Brdf::from_stored(stored, options)?, None)
        };
        Ok(PyTable {
            stored,
            brdf,
            reciprocal,
        })
    }

    /// Opens a table file as [`Brdf::open`] does (an averaged half-float OpenEXR table straight
    /// into the lookup's nodes); a spatial table is read as stored, which it keeps.
    fn open_file(
        path: &std::path::Path,
        reciprocal: bool,
        point_level: bool,
    ) -> Result<PyTable, TableError> {
        let options = table_options(reciprocal, point_level);
        let brdf = Brdf::open(path, options)?;
        if brdf.spatial().is_none() {
            return Ok(PyTable {
                stored: None,
                brdf,
                reciprocal,
            });
        }
        let stored = clothbake_loader::read_table_stored(path)?;
        PyTable::from_stored(stored, reciprocal, point_level)
    }

    /// The table's values as stored.
    fn stored(&self) -> StoredTable {
        match &self.stored {
            Some(s) => s.clone(),
            None => self
                .brdf
                .to_stored()
                .expect("an averaged table's values are its nodes'"),
        }
    }
}

/// Three floats as Python sees them: a direction or an RGB value.
type Triple = (f32, f32, f32);

/// Rows as f32 vectors (the loader's precision).
/// The fewest rows `sample` and `pdf` hand one of rayon's threads (a renderer's wavefronts of
/// tens of thousands of rows use every core; a few rows stay on the caller's thread).
const PAR_CHUNK: usize = 4096;

fn narrow(r: &[[f64; 3]]) -> Vec<[f32; 3]> {
    r.iter().map(|w| w.map(|x| x as f32)).collect()
}

#[pymethods]
impl PyTable {
    /// Opens a table file (OpenEXR or binary, docs/reference/table-format.md). `reciprocal=True`
    /// symmetrises every lookup, 0.5 (f(wi, wo) + f(wo, wi)). `point_level=False` makes a
    /// spatial table that carries its yarns answer every footprint under a period with its
    /// crossing cells (docs/science/spatial.md). Raises FileNotFoundError for a missing file and
    /// ValueError for a file that is not a valid table.
    #[staticmethod]
    #[pyo3(signature = (path, reciprocal=false, point_level=true))]
    fn open(
        py: Python<'_>,
        path: PathBuf,
        reciprocal: bool,
        point_level: bool,
    ) -> PyResult<PyTable> {
        py.detach(|| {
            PyTable::open_file(&path, reciprocal, point_level).map_err(|e| match e {
                TableError::InvalidTable { reason } => TableError::Corrupted {
                    path: path.clone(),
                    reason,
                },
                other => other,
            })
        })
        .map_err(|e| match e {
            e if e.is_two_faced_table() => PyValueError::new_err(format!(
                "{}: a two-faced table (reflection and transmission over the sphere); open \
                     it with clothbake.TwoFaced.open (in Mitsuba: faces=\"two\")",
                path.display()
            )),
            other => table_err(other),
        })
    }

    /// The grid: a dict of n_theta_i, n_phi_i, n_theta_o, n_phi_o (cells per axis; polar
    /// axes cover 0-90 degrees from +Z, azimuths 0-360 degrees from +X toward +Y).
    #[getter]
    fn grid<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let g = self.brdf.grid();
        let d = PyDict::new(py);
        d.set_item("n_theta_i", g.n_theta_i)?;
        d.set_item("n_phi_i", g.n_phi_i)?;
        d.set_item("n_theta_o", g.n_theta_o)?;
        d.set_item("n_phi_o", g.n_phi_o)?;
        Ok(d)
    }

    /// The metadata as a dict (format_version, tool, grid, centring, quantity, units,
    /// fabric_json, options_json, symmetry), with `fabric` and `options` parsed from the two
    /// JSON texts.
    #[getter]
    fn metadata<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let json = py.import("json")?;
        let meta = self.brdf.meta();
        let d = json.call_method1("loads", (meta.to_ascii_json(),))?;
        d.set_item("fabric", json.call_method1("loads", (&meta.fabric_json,))?)?;
        d.set_item(
            "options",
            json.call_method1("loads", (&meta.options_json,))?,
        )?;
        Ok(d)
    }

    /// "f16" or "f32": how the values are held (as stored in the file).
    #[getter]
    fn precision(&self) -> &'static str {
        match self.brdf.precision() {
            Precision::F16 => "f16",
            Precision::F32 => "f32",
        }
    }

    /// The values as a float32 array of shape (n_theta_i, n_phi_i, n_theta_o, n_phi_o, 3):
    /// f_r in 1/sr at the cell centres, RGB last (a copy).
    fn to_numpy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let g = self.brdf.grid();
        let stored = self.stored();
        let s = &stored.samples;
        let v: Vec<f32> = (0..s.len()).map(|i| s.get(i)).collect();
        let shape = [
            g.n_theta_i as usize,
            g.n_phi_i as usize,
            g.n_theta_o as usize,
            g.n_phi_o as usize,
            3,
        ];
        Ok(PyArray1::from_vec(py, v).reshape(shape)?.into_any())
    }

    /// Interpolated f_r(wi, wo) in 1/sr, RGB, float32 (N, 3), for unit vectors (N, 3) or
    /// (3,) in the table's frame (+X weft, +Y warp, +Z normal; `wi` toward the light, `wo`
    /// toward the eye); 0 at or below the horizon. One thread, GIL released.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        // Read once into single precision; the result is written in place into the flat
        // buffer the numpy array takes over (no copies besides the inputs' narrowing).
        let (wi32, single_i) = unit_rows_f32("wi", wi)?;
        let (wo32, single_o) = unit_rows_f32("wo", wo)?;
        same_len(("wi", wi32.len()), ("wo", wo32.len()))?;
        let mut flat = vec![0f32; 3 * wi32.len()];
        let (out, _) = flat.as_chunks_mut::<3>();
        py.detach(|| self.brdf.eval_batch(&wi32, &wo32, out))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let n = wi32.len();
        let a = PyArray1::from_vec(py, flat);
        if single_i && single_o {
            Ok(a.into_any())
        } else {
            Ok(a.reshape([n, 3])?.into_any())
        }
    }

    /// f_r at points of the weave period through a footprint (docs/science/spatial.md): `uv` (N, 2)
    /// or (2,) in period fractions (u along the weft, v along the warp, wrapped), `width` the
    /// side of the square each lookup covers, in periods (0: the point at uv; 1 or more: the
    /// averaged table), answered at its level of detail: a table baked with `spatial=True`
    /// (one bounce) traces its yarns under a crossing cell and shows its cells from two cells
    /// wide; an averaged table answers `eval`. `width` is one number or one a row (N,).
    /// Returns (f_r (N, 3), coverage (N,)), float32.
    #[pyo3(signature = (wi, wo, uv, width=None))]
    fn eval_at<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
        uv: &Bound<'py, PyAny>,
        width: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let a = unit_rows("wi", wi)?;
        let b = unit_rows("wo", wo)?;
        same_len(("wi", a.rows.len()), ("wo", b.rows.len()))?;
        let p = period_rows(uv, a.rows.len())?;
        let w = match width {
            Some(w) => widths(w, a.rows.len())?,
            None => vec![0.0; a.rows.len()],
        };
        let (wi32, wo32) = (narrow(&a.rows), narrow(&b.rows));
        let (f, c): (Vec<[f32; 3]>, Vec<f32>) = py.detach(|| {
            wi32.iter()
                .zip(&wo32)
                .zip(p.rows.iter().zip(&w))
                .map(|((&i, &o), (&[u, v], &width))| self.brdf.local_at(i, o, u, v, width))
                .unzip()
        });
        let single = a.single && b.single && p.single;
        Ok((to_array(py, &f, single)?, to_array1(py, c, single)?))
    }

    /// Importance-samples incident directions for unit vectors `wo` (N, 3) with uniform
    /// numbers `u` (N, 2) in [0, 1): density proportional to f_r cos(theta_i) per table cell.
    /// Returns (wi (N, 3), weight (N, 3) = f_r cos(theta_i) / pdf, pdf (N,) per steradian),
    /// float32; pdf 0 (and weight 0) where `wo` is below the horizon. GIL released; rows
    /// in chunks of 4096 on rayon's threads (each row's answer is the same).
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (wo32, single_o) = unit_rows_f32("wo", wo)?;
        let u = rows::<2>("u", u)?;
        same_len(("wo", wo32.len()), ("u", u.rows.len()))?;
        if let Some(i) = u
            .rows
            .iter()
            .position(|r| !r.iter().all(|x| (0.0..=1.0).contains(x)))
        {
            return Err(PyValueError::new_err(format!(
                "u[{i}] = ({}, {}) is not in [0, 1); pass uniform random numbers",
                u.rows[i][0], u.rows[i][1]
            )));
        }
        let s: Vec<_> = py.detach(|| {
            wo32.par_iter()
                .zip(u.rows.par_iter())
                .with_min_len(PAR_CHUNK)
                .map(|(&w, r)| self.brdf.sample(w, r[0] as f32, r[1] as f32))
                .collect()
        });
        let single = single_o && u.single;
        let wi: Vec<[f32; 3]> = s.iter().map(|x| x.wi).collect();
        let weight: Vec<[f32; 3]> = s.iter().map(|x| x.weight).collect();
        let pdf: Vec<f32> = s.iter().map(|x| x.pdf).collect();
        Ok((
            to_array(py, &wi, single)?,
            to_array(py, &weight, single)?,
            to_array1(py, pdf, single)?,
        ))
    }

    /// The density (per steradian, float32 (N,)) with which `sample` draws `wi` for `wo`,
    /// both unit vectors (N, 3). GIL released; rows in chunks on rayon's threads, as `sample`.
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (wo32, single_o) = unit_rows_f32("wo", wo)?;
        let (wi32, single_i) = unit_rows_f32("wi", wi)?;
        same_len(("wo", wo32.len()), ("wi", wi32.len()))?;
        let p: Vec<f32> = py.detach(|| {
            wo32.par_iter()
                .zip(wi32.par_iter())
                .with_min_len(PAR_CHUNK)
                .map(|(&o, &i)| self.brdf.pdf(i, o))
                .collect()
        });
        to_array1(py, p, single_i && single_o)
    }

    /// Whether `eval_at` answers footprints under two crossing cells at the point level (the
    /// table carries its yarns and was opened with `point_level=True`).
    #[getter]
    fn has_point_level(&self) -> bool {
        self.brdf.has_point_level()
    }

    /// The same table without its point level: its crossing cells answer every footprint
    /// under a period (what a spatial table held before it carried its yarns).
    fn without_point_level(&self, py: Python<'_>) -> PyResult<PyTable> {
        py.detach(|| PyTable::from_stored(self.stored(), self.reciprocal, false))
            .map_err(table_err)
    }

    /// f_r(wi, wo) in 1/sr for one pair of unit vectors given as 3 floats each: the scalar
    /// path renderers call per sample.
    fn eval1(&self, wi: [f64; 3], wo: [f64; 3]) -> PyResult<Triple> {
        check_unit("wi", 0, wi)?;
        check_unit("wo", 0, wo)?;
        let f = self.brdf.eval(wi.map(|x| x as f32), wo.map(|x| x as f32));
        Ok((f[0], f[1], f[2]))
    }

    /// f_r at point (u, v) of the weave period through a footprint of side `width` periods,
    /// for one pair of unit vectors (see `eval_at`): the scalar path of the Mitsuba plugin.
    fn eval1_at(&self, wi: [f64; 3], wo: [f64; 3], u: f64, v: f64, width: f64) -> PyResult<Triple> {
        Ok(self.eval1_local(wi, wo, u, v, width)?.0)
    }

    /// As `eval1_at`, with the footprint's coverage from the same lookup: ((r, g, b),
    /// coverage).
    fn eval1_local(
        &self,
        wi: [f64; 3],
        wo: [f64; 3],
        u: f64,
        v: f64,
        width: f64,
    ) -> PyResult<(Triple, f32)> {
        check_unit("wi", 0, wi)?;
        check_unit("wo", 0, wo)?;
        check_footprint(u, v, width)?;
        let (f, c) = self
            .brdf
            .local_at(wi.map(|x| x as f32), wo.map(|x| x as f32), u, v, width);
        Ok(((f[0], f[1], f[2]), c))
    }

    /// One importance sample for `wo` (3 floats, unit) and `u1, u2` in [0, 1):
    /// (wi, weight, pdf) as tuples and a float (see `sample`).
    fn sample1(&self, wo: [f64; 3], u1: f64, u2: f64) -> PyResult<(Triple, Triple, f32)> {
        check_unit("wo", 0, wo)?;
        let s = self.brdf.sample(wo.map(|x| x as f32), u1 as f32, u2 as f32);
        Ok((
            (s.wi[0], s.wi[1], s.wi[2]),
            (s.weight[0], s.weight[1], s.weight[2]),
            s.pdf,
        ))
    }

    /// The density of `sample1` drawing `wi` for `wo` (3 floats each, unit), per steradian.
    fn pdf1(&self, wo: [f64; 3], wi: [f64; 3]) -> PyResult<f32> {
        check_unit("wo", 0, wo)?;
        check_unit("wi", 0, wi)?;
        Ok(self.brdf.pdf(wi.map(|x| x as f32), wo.map(|x| x as f32)))
    }

    /// Writes the table atomically: OpenEXR (`.exr`, precision "f16" or "f32") or the binary
    /// format (any other extension, f32). An existing file is kept, with FileExistsError,
    /// unless `overwrite=True`.
    #[pyo3(signature = (path, precision="f16", overwrite=false))]
    fn save(
        &self,
        py: Python<'_>,
        path: PathBuf,
        precision: &str,
        overwrite: bool,
    ) -> PyResult<()> {
        let precision = match precision {
            "f16" => Precision::F16,
            "f32" => Precision::F32,
            other => {
                return Err(PyValueError::new_err(format!(
                    "precision: {other:?}; use \"f16\" or \"f32\""
                )))
            }
        };
        let table = self.stored().into_table();
        let exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        py.detach(|| {
            if exr {
                write_exr(&path, &table, precision, overwrite)
            } else {
                write_binary(&path, &table, overwrite)
            }
        })
        .map_err(table_err)
    }

    /// Seconds of the loader's Rust batch loop (`Brdf::eval_batch`) over `n` direction pairs
    /// made in Rust (no numpy, no checks): the median of `repeats` runs. For bench.py.
    #[pyo3(signature = (n, repeats=5))]
    fn _rust_batch_seconds(&self, py: Python<'_>, n: usize, repeats: usize) -> f64 {
        py.detach(|| {
            let (wi, wo) = crate::bench_directions(n);
            let mut out = vec![[0f32; 3]; n];
            let mut t: Vec<f64> = (0..repeats.max(1))
                .map(|_| {
                    let start = std::time::Instant::now();
                    self.brdf
                        .eval_batch(&wi, &wo, &mut out)
                        .expect("equal lengths");
                    std::hint::black_box(&out);
                    start.elapsed().as_secs_f64()
                })
                .collect();
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "clothbake.Table({}, {})",
            self.brdf.grid(),
            self.precision()
        )
    }
}
