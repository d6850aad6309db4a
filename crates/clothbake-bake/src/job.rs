//! The bake job: what `clothbake bake` and Python's `bake()` both run.
//!
//! A [`Job`] bakes a fabric with [`BakeOptions`] into a table in memory, a table file or a
//! shard file ([`Target`]). With a file it checks the output before any time is spent
//! ([`crate::output::preflight`]), keeps a checkpoint of the finished rows next to it
//! ([`checkpoint_path`]), resumes from one (only when asked: an unasked-for checkpoint is an
//! error, so that no bake silently mixes runs), writes the output atomically and removes the
//! checkpoint. Raising the cancel flag stops the sweep; the rows done are saved and
//! [`JobError::Interrupted`] says how many. Progress, notes and warnings go to [`Hooks`]; the
//! library prints nothing. Runs on the current rayon pool: the result does not depend on its
//! size, on the shard split or on resuming.

use crate::assembly::Assembly;
use crate::checkpoint::{checkpoint_path, Checkpointer, DEFAULT_INTERVAL};
use crate::lock::{LockError, OutputLock};
use crate::memory::{self, Kept};
use crate::merge::orbits_of;
use crate::output::{preflight, write_table, Format};
use crate::settings::Naming;
use crate::shard::{read_part, shard_rows, Kind, ShardId};
use crate::sweep::{check_options, BakeError, BakeOptions, Baker, Row};
use clothbake_core::Fabric;
use clothbake_loader::{Faces, Metadata, Table, TableError};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

/// Where a job's result goes.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    /// Returned in memory only (no file, no checkpoint, no shard, no resume).
    Memory,
    /// A table file in `format`.
    Table {
        /// The file.
        path: PathBuf,
        /// Its format.
        format: Format,
    },
    /// A shard file (the rows of one shard, for `clothbake merge`).
    Shard {
        /// The file.
        path: PathBuf,
        /// Which shard.
        id: ShardId,
    },
}

/// A bake request.
#[derive(Clone, Debug)]
pub struct Job<'a> {
    /// The fabric.
    pub fabric: &'a Fabric,
    /// The options (everything that determines the table besides the fabric).
    pub options: BakeOptions,
    /// Where the result goes.
    pub target: Target,
    /// Continue from the checkpoint next to the output, if there is one.
    pub resume: bool,
    /// Replace an existing output file.
    pub overwrite: bool,
    /// Time between checkpoints.
    pub checkpoint_every: Duration,
    /// How messages spell options (`--resume` or `resume=True`).
    pub naming: Naming,
    /// The files the fabric was read from (the fabric file, a draft): the output may not be
    /// one of them, and errors about the fabric's values name the first.
    pub inputs: Vec<PathBuf>,
}

impl<'a> Job<'a> {
    /// A job baking `fabric` with `options` into memory; set the other fields to write a file.
    pub fn new(fabric: &'a Fabric, options: BakeOptions) -> Job<'a> {
        Job {
            fabric,
            options,
            target: Target::Memory,
            resume: false,
            overwrite: false,
            checkpoint_every: DEFAULT_INTERVAL,
            naming: Naming::Cli,
            inputs: Vec::new(),
        }
    }
}

/// The caller's side of a running job: progress, notes, warnings, and the cancel flag.
pub struct Hooks<'a> {
    /// `(done, total)` cells evaluated, rows of a resumed checkpoint included; called from
    /// worker threads, with `done` never decreasing.
    pub progress: &'a (dyn Fn(u64, u64) + Sync),
    /// A sentence about what the job does (resuming, or nothing to resume from).
    pub note: &'a (dyn Fn(&str) + Sync),
    /// A problem the job goes on despite (a checkpoint that cannot be written or removed).
    pub warn: &'a (dyn Fn(&str) + Sync),
    /// Raised to stop the job (Ctrl-C).
    pub cancel: &'a AtomicBool,
}

/// A finished job.
#[derive(Debug)]
pub struct Done {
    /// The table (`None` for a shard).
    pub table: Option<Table>,
    /// Its metadata (of the whole table, for a shard too).
    pub metadata: Metadata,
    /// The rows baked (all of them, or the shard's).
    pub rows: Range<usize>,
    /// Cells evaluated in those rows, resumed ones included (the rest are symmetry copies).
    pub evaluated: usize,
    /// Cells of the output: the grid's, or the shard rows'.
    pub cells: usize,
    /// The symmetry used, `None` without one.
    pub symmetry: Option<String>,
}

/// A job stopped by its cancel flag.
#[derive(Debug)]
pub struct Interrupted {
    /// `"table"` or `"shard"`: what was not written.
    pub what: &'static str,
    /// Rows saved in the checkpoint (0: none, or nothing was saved).
    pub saved: usize,
    /// Rows of the job.
    pub rows: usize,
    /// The checkpoint file (`None` for a bake in memory).
    pub checkpoint: Option<PathBuf>,
    /// Why the checkpoint could not be saved, if it could not.
    pub save_error: Option<TableError>,
    /// How the message spells resuming.
    pub naming: Naming,
}

/// Why a job produced nothing. Every message names the problem and the fix.
#[derive(Debug)]
pub enum JobError {
    /// The options or the request cannot be baked: one line, problem and fix.
    Invalid(String),
    /// A file could not be read or written (the output, a checkpoint).
    File(TableError),
    /// The checkpoint to resume from cannot be read; the fix: delete it to start again.
    Checkpoint {
        /// The checkpoint file.
        path: PathBuf,
        /// Why it cannot be read.
        error: TableError,
    },
    /// Cancelled; the rows done so far are saved where a checkpoint is kept.
    Interrupted(Box<Interrupted>),
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (&self.save_error, &self.checkpoint) {
            (Some(e), _) => write!(
                f,
                "interrupted; nothing was written (the checkpoint could not be saved: {e})"
            ),
            (None, Some(ck)) if self.saved > 0 => write!(
                f,
                "interrupted; no {} was written, {} of {} rows are saved in {}; {} with {} to \
                 continue",
                self.what,
                self.saved,
                self.rows,
                ck.display(),
                self.naming.again(),
                self.naming.switch("resume"),
            ),
            _ => f.write_str("interrupted; nothing was written"),
        }
    }
}

impl std::fmt::Display for JobError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            JobError::Invalid(m) => f.write_str(m),
            JobError::File(e) => write!(f, "{e}"),
            JobError::Checkpoint { path, error } => write!(
                f,
                "{error}; or delete {} to start the bake again",
                path.display()
            ),
            JobError::Interrupted(i) => write!(f, "{i}"),
        }
    }
}

impl std::error::Error for JobError {}

impl From<TableError> for JobError {
    fn from(e: TableError) -> Self {
        JobError::File(e)
    }
}

fn invalid(problem: impl std::fmt::Display, fix: impl std::fmt::Display) -> JobError {
    JobError::Invalid(format!("{problem}; {fix}"))
}

/// The rows of an earlier run of this bake from its checkpoint at `path`, after checking that
/// it belongs to this bake (tool, fabric, options, metadata, shard) and holds only its rows.
pub fn load_checkpoint(
    path: &Path,
    baker: &Baker,
    shard: Option<ShardId>,
    rows: &Range<usize>,
) -> Result<BTreeMap<usize, Row>, JobError> {
    let part = read_part(path, orbits_of).map_err(|error| JobError::Checkpoint {
        path: path.to_path_buf(),
        error,
    })?;
    let restart = format!("delete {} to start again", path.display());
    if part.kind != Kind::Checkpoint {
        return Err(invalid(
            format!("{}: not a checkpoint", path.display()),
            restart,
        ));
    }
    let (m, want) = (&part.meta, baker.metadata());
    let differs = if m.tool != want.tool {
        Some(format!("was written by {}, this is {}", m.tool, want.tool))
    } else if m.fabric_json != want.fabric_json {
        Some("is of another fabric (or other material overrides)".to_string())
    } else if m.options_json != want.options_json {
        Some(format!(
            "is of a bake with other options ({} instead of {})",
            m.options_json, want.options_json
        ))
    } else if m != want {
        Some("has other metadata".to_string())
    } else if part.shard != shard {
        let name =
            |s: Option<ShardId>| s.map_or("the whole table".into(), |s| format!("shard {s}"));
        Some(format!(
            "is of {}, this bake is of {}",
            name(part.shard),
            name(shard)
        ))
    } else {
        None
    };
    if let Some(d) = differs {
        return Err(invalid(
            format!("{}: the checkpoint {d}", path.display()),
            format!("resume with the command that wrote it, or {restart}"),
        ));
    }
    if let Some(r) = part.rows.keys().find(|r| !rows.contains(r)) {
        return Err(invalid(
            format!(
                "{}: the checkpoint holds row {r}, outside this bake's rows",
                path.display()
            ),
            restart,
        ));
    }
    Ok(part.rows)
}

/// Runs `job` on the current rayon pool.
pub fn run(job: &Job<'_>, hooks: &Hooks<'_>) -> Result<Done, JobError> {
    let (output, shard) = match &job.target {
        Target::Memory => {
            if job.resume {
                return Err(invalid(
                    "resuming needs an output file (its checkpoint lies next to it)",
                    "give the output file, or do not resume",
                ));
            }
            (None, None)
        }
        Target::Table { path, .. } => (Some(path.as_path()), None),
        Target::Shard { path, id } => (Some(path.as_path()), Some(*id)),
    };
    if let Some(out) = output {
        let what = if shard.is_some() { "shard" } else { "table" };
        let inputs: Vec<&Path> = job.inputs.iter().map(PathBuf::as_path).collect();
        preflight(&[(out, what)], job.overwrite, &inputs)?;
    }
    check_options(&job.options).map_err(bake_error)?;
    let available = memory::available_bytes();
    check_memory(job, None, available)?;
    // Held until this function returns: one bake at a time writes this output and its
    // checkpoint.
    let _lock = match output.map(OutputLock::take) {
        None => None,
        Some(Ok(lock)) => Some(lock),
        Some(Err(e @ LockError::Unavailable { .. })) => {
            (hooks.warn)(&format!(
                "{e}; the bake goes on unlocked (do not start another bake to this output)"
            ));
            None
        }
        Some(Err(e)) => return Err(JobError::Invalid(e.to_string())),
    };
    let baker = Baker::new(job.fabric, &job.options).map_err(bake_error)?;
    if output.is_some() {
        check_header(job, baker.metadata())?;
    }
    let orbits = baker.orbits();
    let rows = match shard {
        Some(id) => shard_rows(orbits, id),
        None => 0..orbits.rows(),
    };
    if shard.is_some() {
        check_memory(job, Some(rows.len()), available)?;
    }
    let ck_path = output.map(checkpoint_path);
    let exists = ck_path
        .as_deref()
        .is_some_and(|p| std::fs::symlink_metadata(p).is_ok());
    let resumed = match (&ck_path, exists, job.resume) {
        (Some(ck), true, true) => {
            let r = load_checkpoint(ck, &baker, shard, &rows)?;
            (hooks.note)(&format!(
                "resuming from {}: {} of {} rows done",
                ck.display(),
                r.len(),
                rows.len()
            ));
            r
        }
        (Some(ck), true, false) => {
            return Err(invalid(
                format!(
                    "{} exists: the checkpoint of an interrupted bake of {}",
                    ck.display(),
                    output.expect("a checkpoint has an output").display()
                ),
                format!(
                    "continue it: {} with {}; or delete {} to start again",
                    job.naming.again(),
                    job.naming.switch("resume"),
                    ck.display()
                ),
            ))
        }
        (Some(ck), false, true) => {
            (hooks.note)(&format!(
                "no checkpoint {} to resume from: starting at the beginning",
                ck.display()
            ));
            BTreeMap::new()
        }
        _ => BTreeMap::new(),
    };

    let todo: Vec<usize> = rows.clone().filter(|r| !resumed.contains_key(r)).collect();
    let to_evaluate: usize = todo.iter().map(|&r| orbits.row_evaluations(r)).sum();
    let done_before: usize = resumed.keys().map(|&r| orbits.row_evaluations(r)).sum();
    let total = (to_evaluate + done_before) as u64;
    let shown = AtomicU64::new(0);
    (hooks.progress)(done_before as u64, total);
    let progress = |n: u64| {
        // Rows finish out of order: report the largest count seen.
        let m = shown.fetch_max(n, Ordering::Relaxed).max(n);
        (hooks.progress)(done_before as u64 + m, total);
    };
    // The one buffer of the output's values: the resumed rows first (each dropped once
    // copied), then the sweep's.
    let assembly = Assembly::new(orbits, rows.clone());
    for (r, vals) in resumed {
        assembly.put(r, &vals);
    }
    let ck = match &ck_path {
        Some(p) => Checkpointer::new(
            p.clone(),
            job.checkpoint_every,
            shard,
            baker.metadata().clone(),
            assembly,
        ),
        None => Checkpointer::in_memory(baker.metadata().clone(), assembly),
    };
    let warned = AtomicBool::new(false);
    let sink = |row: usize, vals: Row| {
        if let Err(e) = ck.record(row, vals) {
            if !warned.swap(true, Ordering::Relaxed) {
                (hooks.warn)(&format!(
                    "the checkpoint could not be written ({e}); the bake goes on"
                ));
            }
        }
    };
    let result = baker.sweep(&todo, &progress, hooks.cancel, &sink);
    match result {
        Ok(()) if !hooks.cancel.load(Ordering::SeqCst) => {}
        Ok(()) | Err(BakeError::Cancelled) => {
            let (saved, save_error) = match ck.save() {
                Ok(n) => (n, None),
                Err(e) => (0, Some(e)),
            };
            return Err(JobError::Interrupted(Box::new(Interrupted {
                what: if shard.is_some() { "shard" } else { "table" },
                saved,
                rows: rows.len(),
                checkpoint: ck_path,
                save_error,
                naming: job.naming,
            })));
        }
        Err(e) => return Err(bake_error(e)),
    }
    let done = ck.into_assembly();
    let evaluated: usize = done
        .done_rows()
        .iter()
        .map(|&r| orbits.row_evaluations(r))
        .sum::<usize>()
        / orbits.stride();
    let g = job.options.grid;
    let table = match &job.target {
        Target::Shard { path, id } => {
            done.write_part(
                path,
                Kind::Shard,
                Some(*id),
                baker.metadata(),
                job.overwrite,
            )?;
            None
        }
        target => {
            // The buffer becomes the table's values: the writers stream from them.
            check_values(&done, &baker, job)?;
            let table = Table::new(baker.metadata().clone(), done.into_values())
                .map_err(|e| JobError::Invalid(e.to_string()))?;
            if let Target::Table { path, format } = target {
                write_table(path, &table, *format, job.overwrite)?;
            }
            Some(table)
        }
    };
    // The output is in place: the checkpoint has served.
    if let Some(ck) = &ck_path {
        match std::fs::remove_file(ck) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => (hooks.warn)(&format!(
                "cannot remove the checkpoint {}: {e}",
                ck.display()
            )),
            _ => {}
        }
    }
    let cells = match shard {
        Some(_) => rows.len() * (g.n_theta_o * g.n_phi_o) as usize,
        None => g.len(),
    };
    Ok(Done {
        table,
        metadata: baker.metadata().clone(),
        rows,
        evaluated,
        cells,
        symmetry: (!baker.symmetries().is_empty()).then(|| baker.metadata().symmetry.clone()),
    })
}

/// Room kept in a checkpoint's or shard's header for what it holds besides the metadata (the
/// row ranges done, the shard): 1 MiB.
pub const HEADER_ROOM: u64 = 1 << 20;

/// Refuses, before any work, a bake whose metadata (the fabric's description as JSON,
/// escaped again inside the header's JSON) would not fit the header of its checkpoints, shard
/// or binary table ([`clothbake_loader::container::MAX_HEADER_LEN`], less [`HEADER_ROOM`]): a
/// fabric file within the input limit whose names or notes grow when escaped.
pub fn check_header(job: &Job<'_>, meta: &Metadata) -> Result<(), JobError> {
    let len = serde_json::to_vec(meta).map_or(u64::MAX, |v| v.len() as u64);
    let most = clothbake_loader::container::MAX_HEADER_LEN - HEADER_ROOM;
    if len <= most {
        return Ok(());
    }
    let source = job
        .inputs
        .first()
        .map_or("the fabric".to_string(), |p| p.display().to_string());
    Err(invalid(
        format!(
            "{source}: the fabric's description takes {len} bytes in a table's header (its \
             JSON escaped once more), more than the {most} bytes (16 MiB less 1 MiB for the \
             rows) a header of its checkpoints, shards and binary tables holds"
        ),
        "shorten its name and notes (characters such as quotes, backslashes and control \
         characters take two to six bytes each once escaped); nothing was baked",
    ))
}

/// Refuses a job whose estimated peak memory ([`memory::peak_bytes`]) exceeds `available`
/// (bytes; `None`: unknown, no check). A shard's rows are known once its orbits are
/// (`shard_rows`); before, an even split of the rows is counted, and the rows' costs that
/// the split reads (8 bytes a row).
pub fn check_memory(
    job: &Job<'_>,
    shard_rows: Option<usize>,
    available: Option<u64>,
) -> Result<(), JobError> {
    let g = job.options.grid;
    let per_row = u64::from(g.n_theta_o) * u64::from(g.n_phi_o);
    let rows = u64::from(g.n_theta_i) * u64::from(g.n_phi_i);
    let (baked, kept, shard, extra) = match &job.target {
        Target::Shard { id, .. } => {
            let even = rows.div_ceil(u64::from(id.count.max(1)));
            let r = shard_rows.map_or(even, |r| r as u64);
            (r, Kept::Shard, Some(*id), 8 * rows)
        }
        Target::Table { format, .. } => (rows, Kept::Table(Some(*format)), None, 0),
        Target::Memory => (rows, Kept::Table(None), None, 0),
    };
    let cells = baked * per_row;
    // A spatial bake holds 3 + 2 K values a cell (3 + 6 K with the second bounce) where an
    // averaged one holds 3.
    let values = if job.options.spatial {
        let variant = match job.options.method {
            crate::sweep::Method::Analytic { variant } => variant,
            crate::sweep::Method::Raytrace { .. } => Default::default(),
        };
        let two = job.options.bounces.count() == 2;
        let k = clothbake_core::AnalyticModel::with_variant(job.fabric, job.options.facet, variant)
            .map_err(|e| invalid(e, e.fix()))?
            .classes_with(two) as u64;
        3 + clothbake_loader::spatial::lanes(two) as u64 * k
    } else {
        3
    };
    // A sliced3d model's open arcs kept for the grid's directions (`with_grid_arcs`): at most
    // their budget.
    let arcs = match (job.options.method, g.faces, job.options.bounces.count()) {
        (
            crate::sweep::Method::Analytic {
                variant: clothbake_core::Variant::Sliced3d,
            },
            Faces::One,
            1 | 2,
        ) => crate::sweep::OPEN_ARCS_BUDGET as u64,
        _ => 0,
    };
    let need = memory::peak_bytes(&g, baked, values, kept, job.resume)
        .saturating_add(extra)
        .saturating_add(arcs);
    match available {
        Some(have) if need > have => Err(invalid(
            format!(
                "grid {},{},{},{} ({} cells{}) needs about {} of memory to bake, but {} is \
                 available",
                g.n_theta_i,
                g.n_phi_i,
                g.n_theta_o,
                g.n_phi_o,
                g.len(),
                shard.map_or(String::new(), |id| format!(", {cells} in shard {id}")),
                memory::describe(need),
                memory::describe(have)
            ),
            "give a smaller --res (halving every axis needs 1/16 of the memory), or bake \
             it in parts with --shard K/N (merging still holds the whole table)",
        )),
        _ => Ok(()),
    }
}

/// Refuses rows holding a value that is not finite or negative, naming the fabric file and
/// the cell's directions (a table file would be refused on reading anyway).
fn check_values(done: &Assembly, baker: &Baker, job: &Job<'_>) -> Result<(), JobError> {
    for row in done.rows() {
        let values = done.row(row).expect("every row is done");
        if let Some(k) = values
            .iter()
            .flatten()
            .position(|v| !v.is_finite() || *v < 0.0)
        {
            let v = values[k / 3][k % 3];
            let g = baker.orbits().grid();
            let (ti, pi, to, po) = baker
                .orbits()
                .evaluated_cell(row, k / 3)
                .expect("a value of the row");
            let (wi, wo) = (
                (g.theta_i_deg(ti), g.phi_i_deg(pi)),
                (g.theta_o_deg(to), g.phi_o_deg(po)),
            );
            let source = job
                .inputs
                .first()
                .map_or("the fabric".to_string(), |p| p.display().to_string());
            return Err(invalid(
                format!(
                    "{source}: the model gives f_r = {v} (channel {}) at theta_i {:.2}, phi_i \
                     {:.2}, theta_o {:.2}, phi_o {:.2} degrees, not a finite non-negative value",
                    ['R', 'G', 'B'][k % 3],
                    wi.0,
                    wi.1,
                    wo.0,
                    wo.1
                ),
                "check the fabric's sizes and materials (docs/reference/limits.md gives the ranges that \
                 compute); nothing was written",
            ));
        }
    }
    Ok(())
}

fn bake_error(e: BakeError) -> JobError {
    match e {
        BakeError::Invalid(m) => JobError::Invalid(m),
        BakeError::Cancelled => JobError::Invalid("the bake was cancelled".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_loader::Grid;

    /// The memory a job asks for: the `need` of [`check_memory`]'s refusal with 1 byte free.
    fn need(job: &Job<'_>) -> f64 {
        let e = check_memory(job, None, Some(1)).unwrap_err().to_string();
        let at = e.find("needs about ").expect("the refusal states the need") + 12;
        let words: Vec<&str> = e[at..].split_whitespace().take(2).collect();
        let x: f64 = words[0].parse().unwrap();
        x * match words[1] {
            "MB" => 1e6,
            "GB" => 1e9,
            u => panic!("unit {u}"),
        }
    }

    #[test]
    fn a_spatial_bake_needs_the_memory_of_its_classes() {
        // The basket weave has 8 classes: 3 + 16 values a cell against 3.
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables");
        let f = Fabric::from_path(&dir.join("basket.json")).unwrap();
        let grid = Grid::new(32, 64, 32, 64);
        let avg = BakeOptions {
            grid,
            ..BakeOptions::default()
        };
        let spatial = BakeOptions {
            spatial: true,
            ..avg
        };
        // What holds values grows 19 / 3 times; the fixed allowance (the program, 64 MiB)
        // does not.
        let (s, a) = (need(&Job::new(&f, spatial)), need(&Job::new(&f, avg)));
        let base = memory::BASE_BYTES as f64;
        let ratio = (s - base) / (a - base);
        assert!(
            (19.0 / 3.0 - 0.1..19.0 / 3.0 + 0.1).contains(&ratio),
            "ratio {ratio}: {s} against {a}"
        );
    }

    /// A spatial bake of few cells over a period of many classes needs little more than an
    /// averaged one: the fixed allowance is not multiplied by the class count (a one-cell
    /// spatial bake of a 64 x 64 random period was refused as needing 43.2 GB).
    #[test]
    fn a_spatial_bake_of_one_cell_needs_no_more_for_many_classes() {
        // A 24 x 24 period of pseudo-random interlacing: hundreds of classes.
        let mut state = 12345u64;
        let rows: Vec<Vec<u8>> = (0..24)
            .map(|_| {
                (0..24)
                    .map(|_| {
                        state = clothbake_core::rng::mix64(state);
                        (state >> 63) as u8
                    })
                    .collect()
            })
            .collect();
        let f = Fabric::from_json_str(
            &format!(
                r#"{{"pattern": {rows:?}, "warp": {{"radius": 1, "spacing": 2.5}},
                    "weft": {{"radius": 1, "spacing": 2.5}}}}"#
            ),
            "random.json",
        )
        .unwrap();
        let avg = BakeOptions {
            grid: Grid::new(1, 1, 1, 1),
            ..BakeOptions::default()
        };
        let spatial = BakeOptions {
            spatial: true,
            ..avg
        };
        let k = clothbake_core::AnalyticModel::new(&f, clothbake_core::FacetModel::Huo)
            .classes_with(false);
        assert!(k >= 100, "{k} classes");
        let more = need(&Job::new(&f, spatial)) - need(&Job::new(&f, avg));
        // One cell of 3 + 2 K f32 values: kilobytes, rounded to a megabyte.
        assert!(more < 2e6, "{more} more for {k} classes");
    }

    /// A sliced3d bake counts the open arcs it may keep (their budget) on top of what the
    /// same bake with refined needs; with three bounces it keeps none.
    #[test]
    fn a_sliced3d_bake_counts_its_kept_arcs() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables");
        let f = Fabric::from_path(&dir.join("twill.json")).unwrap();
        let refined = BakeOptions {
            grid: Grid::new(8, 16, 8, 16),
            ..BakeOptions::default()
        };
        let sliced3d = BakeOptions {
            method: crate::sweep::Method::Analytic {
                variant: clothbake_core::Variant::Sliced3d,
            },
            ..refined
        };
        let more = need(&Job::new(&f, sliced3d)) - need(&Job::new(&f, refined));
        let budget = crate::sweep::OPEN_ARCS_BUDGET as f64;
        // The need is rounded to a megabyte.
        assert!((more - budget).abs() < 2e6, "{more} more than refined");
        let three = |o: BakeOptions| BakeOptions {
            bounces: crate::sweep::BakeBounces::Paths(3),
            ..o
        };
        let more = need(&Job::new(&f, three(sliced3d))) - need(&Job::new(&f, three(refined)));
        assert!(more.abs() < 2e6, "{more} more with three bounces");
    }
}
