//! `clothbake.bake`: a bake through the baker library's job (`clothbake_bake::job`), the one
//! the `clothbake bake` command runs: in memory, or into a table or shard file with
//! checkpoints and resume.

use crate::args::{bad, bounces_arg, choice, count, facet_model, VARIANTS};
use crate::fabric::PyFabric;
use crate::table::{table_err, PyTable};
use clothbake_bake::job::{self, Hooks, Job, JobError, Target};
use clothbake_bake::output::Format;
use clothbake_bake::settings::{parse_orders, parse_sampling, Bounces, Naming, Settings};
use clothbake_bake::shard::parse_shard_id_as;
use clothbake_core::Kernel;
use clothbake_loader::{Grid, Precision, StoredTable};
use clothbake_truth::Caps;
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Duration;

/// The table format of `output` from `format=` and `precision=` (default: from the
/// extension, `.bin` binary, anything else EXR; EXR precision f16).
fn table_format(output: &Path, format: Option<&str>, precision: Option<&str>) -> PyResult<Format> {
    let ext = output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let binary = match (
        choice("format", format, &[("exr", false), ("bin", true)])?,
        ext.as_deref(),
    ) {
        (Some(b), Some(e @ ("exr" | "bin"))) if b != (e == "bin") => {
            return Err(bad(
                "format",
                format!(
                    "{:?} but the output {} ends in .{e}; name the output *.{} or drop format=",
                    format.unwrap_or_default(),
                    output.display(),
                    format.unwrap_or_default()
                ),
            ))
        }
        (Some(b), _) => b,
        (None, e) => e == Some("bin"),
    };
    let precision = choice(
        "precision",
        precision,
        &[("f16", Precision::F16), ("f32", Precision::F32)],
    )?;
    match (binary, precision) {
        (true, Some(_)) => Err(bad(
            "precision",
            "applies only to EXR tables (binary tables always hold f32); drop precision= or write an EXR table",
        )),
        (true, None) => Ok(Format::Binary),
        (false, p) => Ok(Format::Exr(p.unwrap_or(Precision::F16))),
    }
}

/// Bakes `fabric` into a table, on all cores with the GIL released; bit-identical whatever the
/// thread count, shard split or resume.
///
/// res: (n_theta_i, n_phi_i, n_theta_o, n_phi_o) cells, default (32, 64, 32, 64).
/// bounces: 1 (default), or 2 to add the secondary reflection (thesis ch. 5; minutes at full
/// res), or N from 3 to 64 or "all": every bounce, path-traced from the second on over the
/// analytic second bounce on a coarse grid (docs/science/transport.md; about 5 minutes at full res).
/// facet: "huo" (default) or "lewis". progress: True prints the percentage done to stderr (on
/// a terminal one line redrawn in place, else a line every 10%); a
/// callable is called as progress(done, total) (cells evaluated) and stops the bake by
/// returning False (the rows done are kept in the checkpoint; KeyboardInterrupt is raised).
/// output: write the table (or the shard) to this file, atomically (overwrite: replace an
/// existing file); the bake then keeps a checkpoint `<output>.checkpoint` every
/// checkpoint_every seconds (default 60). resume: continue from that checkpoint.
/// shard: "K/N", bake only shard K (0-based) of N into `output` (for `clothbake merge`).
/// format: "exr" or "bin" (default from the extension); precision: "f16" (default) or "f32".
/// method: "analytic" (default; variant "refined", "thesis", "sliced" or "sliced3d") or "raytrace" (samples, seed,
/// caps "excluded" or "shaded"). With bounces=2: secondary "analytic" (orders: "default",
/// "fast" or "T,B,A") or "raytrace" (sampling: "N,STEP,L0,exact|area"); kernel
/// "radiometric" (default) or "thesis". spatial: True tabulates the weave up close beside the
/// average (docs/science/spatial.md; analytic model, bounces=1 or 2); look it up with Table.eval_at(wi, wo, uv,
/// width). faces: "one" (default) or "two", the two-faced cloth over the sphere
/// (docs/science/transmission.md; res's polar counts per side; paths: eye rays per node of its
/// path-traced rest, default 8192), returned as a TwoFaced.
/// Returns the Table (a TwoFaced for faces="two"; None for a shard).
#[pyfunction]
#[pyo3(signature = (fabric, res=(32, 64, 32, 64), bounces=None, facet="huo", progress=None, *,
    output=None, overwrite=false, resume=false, shard=None, format=None, precision=None,
    method="analytic", variant=None, samples=None, seed=None, caps=None, secondary=None,
    kernel=None, orders=None, sampling=None, checkpoint_every=None, spatial=false, faces="one",
    paths=None))]
#[allow(clippy::too_many_arguments)]
pub fn bake(
    py: Python<'_>,
    fabric: &PyFabric,
    res: (u32, u32, u32, u32),
    bounces: Option<Bound<'_, PyAny>>,
    facet: &str,
    progress: Option<Bound<'_, PyAny>>,
    output: Option<PathBuf>,
    overwrite: bool,
    resume: bool,
    shard: Option<&str>,
    format: Option<&str>,
    precision: Option<&str>,
    method: &str,
    variant: Option<&str>,
    samples: Option<i64>,
    seed: Option<u64>,
    caps: Option<&str>,
    secondary: Option<&str>,
    kernel: Option<&str>,
    orders: Option<&str>,
    sampling: Option<&str>,
    checkpoint_every: Option<f64>,
    spatial: bool,
    faces: &str,
    paths: Option<i64>,
) -> PyResult<Option<Py<PyAny>>> {
    let (samples, paths) = (count("samples", samples)?, count("paths", paths)?);
    let bounces = bounces_arg(bounces.as_ref())?;
    let grid = Grid::new(res.0, res.1, res.2, res.3);
    grid.validate().map_err(|e| bad("res", e))?;
    let raytrace = choice(
        "method",
        Some(method),
        &[("analytic", false), ("raytrace", true)],
    )?
    .unwrap_or(false);
    if samples == Some(0) {
        return Err(bad("samples", "0 rays; give at least 1"));
    }
    let faces = choice(
        "faces",
        Some(faces),
        &[
            ("one", clothbake_loader::Faces::One),
            ("two", clothbake_loader::Faces::Two),
        ],
    )?
    .unwrap_or_default();
    let settings = Settings {
        faces,
        paths,
        grid: Some(grid),
        facet: facet_model(facet)?,
        raytrace,
        variant: choice("variant", variant, VARIANTS)?,
        samples,
        seed,
        caps: choice(
            "caps",
            caps,
            &[("excluded", Caps::Excluded), ("shaded", Caps::Shaded)],
        )?,
        bounces: Bounces {
            bounces,
            sampled: choice(
                "secondary",
                secondary,
                &[("analytic", false), ("raytrace", true)],
            )?,
            kernel: choice(
                "kernel",
                kernel,
                &[
                    ("radiometric", Kernel::Radiometric),
                    ("thesis", Kernel::Thesis),
                ],
            )?,
            orders: orders
                .map(parse_orders)
                .transpose()
                .map_err(|e| bad("orders", e))?,
            sampling: sampling
                .map(parse_sampling)
                .transpose()
                .map_err(|e| bad("sampling", e))?,
        },
        spatial,
    };
    if let Some(v) = settings.variant {
        v.check(&fabric.fabric)
            .map_err(|e| bad("variant", e.line()))?;
    }
    let options = settings
        .options(Naming::Python)
        .map_err(PyValueError::new_err)?;
    let shard = shard
        .map(|s| parse_shard_id_as(s, Naming::Python))
        .transpose()
        .map_err(|e| bad("shard", e))?;
    let checkpoint_every = match checkpoint_every {
        None => clothbake_bake::checkpoint::DEFAULT_INTERVAL,
        Some(s) if s.is_finite() && s > 0.0 => Duration::from_secs_f64(s),
        Some(s) => {
            return Err(bad(
                "checkpoint_every",
                format!("{s} seconds; give a positive number"),
            ))
        }
    };
    let target = match (output, shard) {
        (None, Some(_)) => {
            return Err(bad(
                "shard",
                "a shard is written to a file for `clothbake merge`; give output= as well",
            ))
        }
        (None, None) => {
            for (name, given) in [
                ("resume", resume),
                ("format", format.is_some()),
                ("precision", precision.is_some()),
                (
                    "checkpoint_every",
                    checkpoint_every != clothbake_bake::checkpoint::DEFAULT_INTERVAL,
                ),
            ] {
                if given {
                    return Err(bad(
                        name,
                        "applies to a bake into a file; give output= as well, or drop it",
                    ));
                }
            }
            Target::Memory
        }
        (Some(path), Some(id)) => {
            if format.is_some() || precision.is_some() {
                return Err(bad(
                    if format.is_some() { "format" } else { "precision" },
                    "does not apply to a shard (shards have their own file format); give it to `clothbake merge`",
                ));
            }
            Target::Shard { path, id }
        }
        (Some(path), None) => {
            let format = table_format(&path, format, precision)?;
            Target::Table { path, format }
        }
    };
    let job = Job {
        fabric: &fabric.fabric,
        options,
        target,
        resume,
        overwrite,
        checkpoint_every,
        naming: Naming::Python,
        inputs: fabric.path.iter().cloned().collect(),
    };

    let (print, callback) = match &progress {
        None => (false, None),
        Some(p) if p.is_callable() => (false, Some(p.clone().unbind())),
        Some(p) => (p.is_truthy()?, None),
    };
    let cancel = AtomicBool::new(false);
    let callback_error: Mutex<Option<PyErr>> = Mutex::new(None);
    let shown = AtomicU64::new(0);
    let name = fabric.fabric.name().to_string();
    let tty = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let on_progress = |done: u64, total: u64| {
        if let Some(cb) = &callback {
            Python::attach(|py| match cb.call1(py, (done, total)) {
                Ok(r) => {
                    if r.bind(py).is(&*pyo3::types::PyBool::new(py, false)) {
                        cancel.store(true, Ordering::SeqCst);
                    }
                }
                Err(e) => {
                    cancel.store(true, Ordering::SeqCst);
                    callback_error
                        .lock()
                        .expect("no panic while held")
                        .get_or_insert(e);
                }
            });
        }
        if print {
            // On a terminal one line redrawn in place; into a log or a pipe a line every 10%
            // (no carriage returns).
            let pct = done * 100 / total.max(1);
            let step = if tty { pct } else { pct / 10 * 10 };
            if shown.fetch_max(step + 1, Ordering::Relaxed) < step + 1 {
                let mut err = std::io::stderr().lock();
                if tty {
                    let _ = write!(err, "\rbaking {name}: {pct:3}%");
                    if done >= total {
                        let _ = writeln!(err);
                    }
                } else {
                    let _ = writeln!(err, "baking {name}: {step:3}%");
                }
            }
        }
    };
    let note = |m: &str| {
        if print {
            eprintln!("clothbake: {m}");
        }
    };
    let warn = |m: &str| eprintln!("clothbake: warning: {m}");
    let hooks = Hooks {
        progress: &on_progress,
        note: &note,
        warn: &warn,
        cancel: &cancel,
    };
    let result = py.detach(|| job::run(&job, &hooks));
    if let Some(e) = callback_error.lock().expect("no panic while held").take() {
        return Err(e);
    }
    let done = result.map_err(|e| match e {
        JobError::Invalid(m) => PyValueError::new_err(m),
        JobError::File(e) => table_err(e),
        JobError::Checkpoint { path, error } => PyValueError::new_err(format!(
            "{error}; or delete {} to start the bake again",
            path.display()
        )),
        JobError::Interrupted(i) => PyKeyboardInterrupt::new_err(i.to_string()),
    })?;
    match done.table {
        None => Ok(None),
        Some(t) if t.meta.grid.faces == clothbake_loader::Faces::Two => {
            let cloth = crate::two_faced::PyTwoFaced::from_table(t).map_err(table_err)?;
            Ok(Some(Py::new(py, cloth)?.into_any()))
        }
        Some(t) => PyTable::from_stored(StoredTable::from(t), false, true)
            .map_err(table_err)
            .and_then(|t| Ok(Py::new(py, t)?.into_any()))
            .map(Some),
    }
}
