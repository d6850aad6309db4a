//! Baking a table: `clothbake --weave FILE [options]` and `clothbake bake --weave FILE [options]`.
//!
//! Order of work: check the options (one-line errors, exit 2), load the fabric, check the
//! output (an existing file without --force, a missing or unwritable folder: refused before any
//! time is spent), bake on a pool of `--threads` workers with a progress bar on a terminal,
//! then write the table atomically through the loader. Ctrl-C raises the cancel flag: the bake
//! stops and nothing is written (exit 130; a second Ctrl-C exits at once).

use crate::cli::{BakeOpts, FormatArg, Method as MethodArg, PrecisionArg};
use crate::cli::{DEFAULT_SAMPLES, DEFAULT_SEED};
use crate::error::CliError;
use crate::eval_cmd::load_fabric;
use clothbake::bake::{self, BakeError, BakeOptions, Method, DEFAULT_GRID};
use clothbake::output::{write_table, Format};
use clothbake_core::{Caps, Variant};
use clothbake_loader::{Precision, TableError};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// Raised by Ctrl-C.
static CANCEL: AtomicBool = AtomicBool::new(false);

/// The exit status of an interrupted bake (128 + SIGINT, as shells report it).
pub const INTERRUPTED: u8 = 130;

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
}

fn ext_format(p: &Path) -> Option<FormatArg> {
    match p.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "exr" => Some(FormatArg::Exr),
        "bin" => Some(FormatArg::Bin),
        _ => None,
    }
}

/// Checks the option combinations and resolves the defaults; reads no file.
pub fn plan(weave: &Path, o: &BakeOpts) -> Result<Plan, CliError> {
    let raytrace = o.method == MethodArg::Raytrace;
    if !raytrace && (o.samples.is_some() || o.seed.is_some() || o.caps.is_some()) {
        return Err(CliError::new(
            "--samples, --seed and --caps apply only to the ray tracer",
            "add --method raytrace or drop them",
        ));
    }
    if raytrace && o.variant.is_some() {
        return Err(CliError::new(
            "--variant applies only to the analytic model",
            "drop --variant or use --method analytic",
        ));
    }
    let secondary = o.bounces.options()?;
    if o.bounces.bounces == 2 && raytrace {
        return Err(CliError::new(
            "--bounces 2 needs the analytic model: the ray tracer bakes the direct reflection only",
            "use --method analytic with --bounces 2 (--secondary raytrace selects the thesis's \
             two-level sampling of the secondary reflection)",
        ));
    }
    let format = match (o.format, &o.output) {
        (Some(f), Some(out)) => match ext_format(out) {
            Some(e) if e != f => {
                return Err(CliError::new(
                    format!(
                        "--format {} but the output {} ends in .{}",
                        f.ext(),
                        out.display(),
                        e.ext()
                    ),
                    format!("name the output *.{} or drop --format", f.ext()),
                ))
            }
            _ => f,
        },
        (Some(f), None) => f,
        (None, Some(out)) => ext_format(out).unwrap_or(FormatArg::Exr),
        (None, None) => FormatArg::Exr,
    };
    let precision = match (o.precision, format) {
        (Some(_), FormatArg::Bin) => {
            return Err(CliError::new(
                "--precision applies only to EXR tables: binary tables always hold f32",
                "drop --precision or write an EXR table (--format exr)",
            ))
        }
        (Some(PrecisionArg::F32), _) => Precision::F32,
        _ => Precision::F16,
    };
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
            name.push(".");
            name.push(format.ext());
            PathBuf::from(name)
        }
    };
    if output.file_name().is_none() {
        return Err(CliError::new(
            format!("the output {} does not name a file", output.display()),
            "give a file name with -o PATH, e.g. -o twill.exr",
        ));
    }
    let threads = o.threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let method = if raytrace {
        Method::Raytrace {
            samples: o.samples.unwrap_or(DEFAULT_SAMPLES),
            seed: o.seed.unwrap_or(DEFAULT_SEED),
            caps: o.caps.map_or(Caps::Excluded, Caps::from),
        }
    } else {
        Method::Analytic {
            variant: o.variant.map_or(Variant::Refined, Variant::from),
        }
    };
    let options = BakeOptions {
        grid: o.res.unwrap_or(DEFAULT_GRID),
        facet: o.facet.into(),
        method,
        bounces: o.bounces.bounces,
        secondary,
    };
    bake::check_options(&options).map_err(|e| CliError::line(e.to_string()))?;
    Ok(Plan {
        weave: weave.to_path_buf(),
        output,
        format,
        precision,
        threads,
        options,
    })
}

/// Refuses an output that would fail only after the bake: an existing file without --force, a
/// missing folder, a folder we may not write into.
fn preflight(out: &Path, force: bool) -> Result<(), CliError> {
    if !force && std::fs::symlink_metadata(out).is_ok() {
        return Err(TableError::AlreadyExists {
            path: out.to_path_buf(),
        }
        .into());
    }
    let dir = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(CliError::new(
                format!("{}: {} is not a folder", out.display(), dir.display()),
                "give an output path inside a folder with -o PATH",
            ))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(TableError::NoSuchFolder {
                dir: dir.to_path_buf(),
                path: out.to_path_buf(),
            }
            .into())
        }
        Err(e) => {
            return Err(TableError::Io {
                path: dir.to_path_buf(),
                action: "open the folder",
                source: e,
            }
            .into())
        }
    }
    // Probe: can we create a file there? (The table itself goes through a temporary file too.)
    let mut name = std::ffi::OsString::from(".");
    name.push(out.file_name().unwrap_or_default());
    name.push(format!(".probe-{}", std::process::id()));
    let probe = dir.join(name);
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(f) => {
            drop(f);
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(TableError::Io {
            path: out.to_path_buf(),
            action: "create the table",
            source: e,
        }
        .into()),
    }
}

fn install_ctrlc() {
    // A second Ctrl-C exits at once. If a handler cannot be installed, Ctrl-C keeps its
    // default action (the process ends; the atomic write still leaves no partial table).
    let _ = ctrlc::set_handler(|| {
        if CANCEL.swap(true, Ordering::SeqCst) {
            eprintln!("clothbake: interrupted twice; nothing was written");
            std::process::exit(i32::from(INTERRUPTED));
        }
    });
}

fn progress_bar(total: u64, quiet: bool) -> Option<ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(
        "{elapsed_precise} [{wide_bar}] {percent:>3}% {human_pos}/{human_len} cells evaluated, \
         {rate}, ETA {eta}",
    )
    .expect("valid template")
    .with_key(
        "rate",
        |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = write!(w, "{} cells/s", thousands(s.per_sec().round() as u64));
        },
    )
    .progress_chars("=> ");
    bar.set_style(style);
    Some(bar)
}

/// Groups digits by thousands: 4194304 -> 4,194,304.
pub fn thousands(n: u64) -> String {
    let digits = n.to_string().into_bytes();
    let groups: Vec<&str> = digits
        .rchunks(3)
        .rev()
        .map(|g| std::str::from_utf8(g).expect("ASCII digits"))
        .collect();
    groups.join(",")
}

/// Runs a bake and returns the summary line for stdout (empty with --quiet).
pub fn run(weave: &Path, o: &BakeOpts) -> Result<String, CliError> {
    let plan = plan(weave, o)?;
    let fabric = load_fabric(&plan.weave, &o.draft, &o.material)?;
    preflight(&plan.output, o.force)?;
    install_ctrlc();

    let start = Instant::now();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(plan.threads)
        .build()
        .map_err(|e| {
            CliError::new(
                format!("cannot start {} worker threads: {e}", plan.threads),
                "give fewer with --threads N",
            )
        })?;
    let g = plan.options.grid;
    let total = g.len() as u64;
    let bar = progress_bar(bake::evaluations(&fabric, &g) as u64, o.quiet);
    let shown = AtomicU64::new(0);
    let progress = |n: u64| {
        if let Some(b) = &bar {
            // Rows finish out of order: show the largest count seen.
            let m = shown.fetch_max(n, Ordering::Relaxed).max(n);
            b.set_position(m);
        }
    };
    let result = pool.install(|| bake::bake(&fabric, &plan.options, &progress, &CANCEL));
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let baked = match result {
        Ok(b) => b,
        Err(BakeError::Cancelled) => {
            return Err(CliError::line("interrupted; nothing was written").with_code(INTERRUPTED))
        }
        Err(BakeError::Invalid(m)) => return Err(CliError::line(m)),
    };
    if CANCEL.load(Ordering::SeqCst) {
        return Err(CliError::line("interrupted; nothing was written").with_code(INTERRUPTED));
    }
    let format = match plan.format {
        FormatArg::Exr => Format::Exr(plan.precision),
        FormatArg::Bin => Format::Binary,
    };
    write_table(&plan.output, &baked.table, format, o.force)?;
    let secs = start.elapsed().as_secs_f64();
    if o.quiet {
        return Ok(String::new());
    }
    let symmetry = if baked.symmetries.is_empty() {
        "no symmetry".to_string()
    } else {
        format!("symmetry {}", baked.table.meta.symmetry)
    };
    Ok(format!(
        "wrote {}: grid {}x{}x{}x{} (theta_i x phi_i x theta_o x phi_o), {} of {} cells evaluated \
         ({symmetry}), {secs:.2} s, {} cells/s, {} thread{}\n",
        plan.output.display(),
        g.n_theta_i,
        g.n_phi_i,
        g.n_theta_o,
        g.n_phi_o,
        thousands(baked.evaluated as u64),
        thousands(total),
        thousands((total as f64 / secs.max(1e-9)).round() as u64),
        plan.threads,
        if plan.threads == 1 { "" } else { "s" },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digit_groups() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(4194304), "4,194,304");
    }
}
