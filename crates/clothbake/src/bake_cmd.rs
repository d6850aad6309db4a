//! Baking a table: `clothbake --weave FILE [options]` and `clothbake bake --weave FILE [options]`.
//!
//! Order of work: check the options (one-line errors, exit 2), load the fabric, check the
//! output (an existing file without --force, a missing or unwritable folder: refused before any
//! time is spent), bake on a pool of `--threads` workers with a progress bar on a terminal,
//! then write the table atomically through the loader. Ctrl-C raises the cancel flag: the bake
//! stops and nothing is written (exit 130; a second Ctrl-C exits at once; `signals`).

use crate::cli::{BakeOpts, Faces, FormatArg, Method as MethodArg, ShardArg};
use crate::error::{table_error, CliError};
use crate::resolve::{
    self, output_format, preflight, progress_bar, thousands, thread_count, thread_pool,
};
use crate::signals;
use clothbake_bake::checkpoint::DEFAULT_INTERVAL;
use clothbake_bake::job::{self, Hooks, Job, JobError, Target};
use clothbake_bake::output::Format;
use clothbake_bake::settings::{Naming, Settings};
use clothbake_bake::shard::{describe_rows, shard_from_env, ShardId};
use clothbake_bake::BakeOptions;
use clothbake_core::Variant;
use clothbake_loader::Precision;
use clothbake_truth::Caps;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A bake request, checked and resolved.
#[derive(Debug)]
pub struct Plan {
    /// The fabric file.
    pub weave: PathBuf,
    /// Where the table goes.
    pub output: PathBuf,
    /// Its format.
    pub format: FormatArg,
    /// EXR sample precision.
    pub precision: Precision,
    /// Worker threads.
    pub threads: usize,
    /// The bake options (the fabric-independent part of the table).
    pub options: BakeOptions,
    /// The shard to bake (the output is then a shard file), and where `auto` found it.
    pub shard: Option<(ShardId, Option<String>)>,
    /// Time between checkpoints.
    pub checkpoint_every: Duration,
}

/// Checks the option combinations and resolves the defaults; reads no file.
pub fn plan(weave: &Path, o: &BakeOpts) -> Result<Plan, CliError> {
    plan_with_env(weave, o, &|k| std::env::var(k).ok())
}

/// [`plan`] with the environment (for `--shard auto`) given by `env`.
pub fn plan_with_env(
    weave: &Path,
    o: &BakeOpts,
    env: &dyn Fn(&str) -> Option<String>,
) -> Result<Plan, CliError> {
    let settings = Settings {
        grid: o.res,
        facet: o.facet.into(),
        raytrace: o.method == MethodArg::Raytrace,
        variant: o.variant.map(Variant::from),
        samples: o.samples,
        seed: o.seed,
        caps: o.caps.map(Caps::from),
        bounces: o.bounces.settings(),
        spatial: o.spatial,
        paths: o.paths,
        faces: match o.faces {
            Faces::One => clothbake_loader::Faces::One,
            Faces::Two => clothbake_loader::Faces::Two,
        },
    };
    let options = settings.options(Naming::Cli).map_err(CliError::line)?;
    let shard = match (o.shard, o.shards) {
        (None, None) => None,
        (None, Some(_)) | (Some(ShardArg::Fixed(_)), Some(_)) => {
            return Err(CliError::new(
                "--shards goes with --shard auto (Kubernetes Indexed Jobs)",
                "give --shard K/N alone, or --shard auto --shards N",
            ))
        }
        (Some(ShardArg::Fixed(id)), None) => Some((id, None)),
        (Some(ShardArg::Auto), n) => {
            let (id, how) = shard_from_env(env, n).map_err(CliError::line)?;
            Some((id, Some(how)))
        }
    };
    if shard.is_some() && (o.table.format.is_some() || o.table.precision.is_some()) {
        return Err(CliError::new(
            "--format and --precision do not apply to a shard: shards have their own file format",
            "give them to `clothbake merge`, which writes the table",
        ));
    }
    let (format, precision) =
        output_format(o.table.format, o.output.as_deref(), o.table.precision)?;
    let output = match &o.output {
        Some(p) => p.clone(),
        None => {
            let stem = weave.file_stem().ok_or_else(|| {
                CliError::new(
                    format!("{} does not name a file", weave.display()),
                    "give the fabric file with --weave FILE",
                )
            })?;
            let mut name = stem.to_os_string();
            match shard {
                Some((id, _)) => name.push(format!("-{}-of-{}.shard", id.index, id.count)),
                None => {
                    name.push(".");
                    name.push(format.ext());
                }
            }
            PathBuf::from(name)
        }
    };
    if output.file_name().is_none() {
        return Err(CliError::new(
            format!("the output {} does not name a file", output.display()),
            "give a file name with -o PATH, e.g. -o twill.exr",
        ));
    }
    let threads = thread_count(o.run.threads);
    Ok(Plan {
        weave: weave.to_path_buf(),
        output,
        format,
        precision,
        threads,
        options,
        shard,
        checkpoint_every: o
            .checkpoint_every
            .map_or(DEFAULT_INTERVAL, Duration::from_secs_f64),
    })
}

/// The bake's progress line: cells evaluated, with their rate.
const BAKE_BAR: &str = "{elapsed_precise} [{wide_bar}] {percent:>3}% {human_pos}/{human_len} \
                        cells evaluated, {rate}, ETA {eta}";

/// A job's error as the CLI's one line (exit 130 for an interrupted bake).
fn job_error(e: JobError) -> CliError {
    match e {
        JobError::Invalid(m) => CliError::line(m),
        JobError::File(e) => table_error(&e),
        JobError::Checkpoint { path, error } => CliError::new(
            table_error(&error).to_string(),
            format!("or delete {} to start the bake again", path.display()),
        ),
        JobError::Interrupted(i) => {
            let msg = match &i.save_error {
                Some(e) => format!(
                    "interrupted; nothing was written (the checkpoint could not be saved: {})",
                    table_error(e)
                ),
                None => i.to_string(),
            };
            CliError::line(msg).with_code(signals::INTERRUPTED)
        }
    }
}

/// Runs a bake and returns the summary line for stdout (empty with --quiet).
pub fn run(weave: &Path, o: &BakeOpts) -> Result<String, CliError> {
    let plan = plan(weave, o)?;
    let fabric = resolve::fabric(&plan.weave, &o.draft, &o.material)?;
    if let Some(v) = o.variant {
        resolve::variant(&plan.weave, &fabric, v)?;
    }
    let what = if plan.shard.is_some() {
        "shard"
    } else {
        "table"
    };
    preflight(&[(&plan.output, what)], o.run.force, &[&plan.weave])?;
    if let Some((_, Some(how))) = &plan.shard {
        if !o.run.quiet {
            eprintln!("clothbake: {how}");
        }
    }
    let target = match plan.shard {
        Some((id, _)) => Target::Shard {
            path: plan.output.clone(),
            id,
        },
        None => Target::Table {
            path: plan.output.clone(),
            format: match plan.format {
                FormatArg::Exr => Format::Exr(plan.precision),
                FormatArg::Bin => Format::Binary,
            },
        },
    };
    let job = Job {
        fabric: &fabric,
        options: plan.options,
        target,
        resume: o.resume,
        overwrite: o.run.force,
        checkpoint_every: plan.checkpoint_every,
        naming: Naming::Cli,
        inputs: vec![plan.weave.clone()],
    };
    signals::install(signals::OnSignal::Cancel);
    let start = Instant::now();
    let pool = thread_pool(plan.threads)?;
    let bar = progress_bar(0, BAKE_BAR, o.run.quiet);
    let progress = |done: u64, total: u64| {
        if let Some(b) = &bar {
            b.set_length(total);
            b.set_position(done);
        }
    };
    let note = |m: &str| {
        if !o.run.quiet {
            eprintln!("clothbake: {m}");
        }
    };
    let warn = |m: &str| eprintln!("clothbake: warning: {m}");
    let hooks = Hooks {
        progress: &progress,
        note: &note,
        warn: &warn,
        cancel: &signals::CANCEL,
    };
    let result = pool.install(|| job::run(&job, &hooks));
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let done = result.map_err(job_error)?;
    let secs = start.elapsed().as_secs_f64();
    if o.run.quiet {
        return Ok(String::new());
    }
    let g = plan.options.grid;
    let what = match plan.shard {
        Some((id, _)) => format!("shard {id}, {}", describe_rows(&g, &done.rows)),
        None => format!(
            "grid {}x{}x{}x{} (theta_i x phi_i x theta_o x phi_o)",
            g.n_theta_i, g.n_phi_i, g.n_theta_o, g.n_phi_o
        ),
    };
    let symmetry = match &done.symmetry {
        None => "no symmetry".to_string(),
        Some(s) => format!("symmetry {s}"),
    };
    let total = done.cells as u64;
    let mut summary = format!(
        "wrote {}: {what}, {} of {} cells evaluated ({symmetry}), {secs:.2} s, {} cells/s, {} \
         thread{}\n",
        plan.output.display(),
        thousands(done.evaluated as u64),
        thousands(total),
        thousands((total as f64 / secs.max(1e-9)).round() as u64),
        plan.threads,
        if plan.threads == 1 { "" } else { "s" },
    );
    if plan.shard.is_none() {
        let two = plan.options.grid.faces == clothbake_loader::Faces::Two;
        summary.push_str(&next_steps(&plan.weave, &plan.output, two));
    }
    Ok(summary)
}

/// The line after a baked table's summary: what to try with it next, spelled as this program
/// can be run ([`invocation`]).
pub fn next_steps(weave: &Path, table: &Path, two_faced: bool) -> String {
    if two_faced {
        return format!(
            "next: `{c} info {t}` (what it holds: reflection, transmission and openness from \
             each side), `{c} render --table {t} --faces two --scene swatch --eye 0,-55,-45 \
             --light 0,0.5,0.87 -o {png}` (backlit), `{c} eval --weave {w} --faces two --wi 30,0 \
             --wo 150,180` (one pair of directions through the cloth)\n",
            c = invocation(),
            t = table.display(),
            png = table.with_extension("png").display(),
            w = weave.display(),
        );
    }
    format!(
        "next: `{c} info {t}` (what it holds), `{c} render --table {t} -o {png}` (a picture), \
         `{c} eval --weave {w} --wi 30,0 --wo 45,180` (one pair of directions)\n",
        c = invocation(),
        t = table.display(),
        png = table.with_extension("png").display(),
        w = weave.display(),
    )
}

/// How a hint runs this program: `clothbake` when a `clothbake` is on PATH; else, when cargo
/// runs it (`cargo run`, which sets `CARGO`), `cargo run --release -p clothbake --`; else the
/// path of this executable.
pub fn invocation() -> String {
    let on_path = std::env::var_os("PATH").is_some_and(|p| {
        std::env::split_paths(&p)
            .any(|d| std::fs::metadata(d.join("clothbake")).is_ok_and(|m| m.is_file()))
    });
    if on_path {
        "clothbake".into()
    } else if std::env::var_os("CARGO").is_some() {
        "cargo run --release -p clothbake --".into()
    } else {
        std::env::current_exe().map_or_else(|_| "clothbake".into(), |e| e.display().to_string())
    }
}
