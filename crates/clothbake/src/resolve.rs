//! The one layer between the parsed command line ([`crate::cli`]) and the commands' work, after
//! ripgrep's `hiargs`: each command takes from here what it needs and no command imports
//! another (tests/tests/module_graph.rs holds it).
//!
//! * the fabric: `--weave` read (a file, a WIF draft with its size flags, or a shipped name) with
//!   the material options applied ([`fabric`], [`fabric_of`]);
//! * the model: the analytic variant checked against the period ([`variant`]); the facet and
//!   variant defaults are the model's own (`FacetModel::default()`, `Variant::default()`);
//! * the outputs: checked as one set before any work ([`preflight`]), a table's format and
//!   precision ([`output_format`]);
//! * the run: worker threads ([`thread_count`], [`thread_pool`]) and the progress bar
//!   ([`progress_bar`], [`thousands`]).

use crate::cli::{DraftArgs, FormatArg, MaterialArgs, PrecisionArg};
use crate::error::{table_error, CliError};
use clothbake_core::{Fabric, FabricError, PlainNaming, Variant};
use clothbake_loader::Precision;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::Path;

/// The analytic variant `v` for the fabric of `weave`, refused where it does not take the
/// period (`Variant::check`: sliced3d's size limit).
pub fn variant(weave: &Path, fabric: &Fabric, v: impl Into<Variant>) -> Result<Variant, CliError> {
    let v = v.into();
    v.check(fabric)
        .map_err(|e| CliError::new(format!("{}: {e}", weave.display()), e.fix()))?;
    Ok(v)
}

/// Reads the fabric of `--weave` (JSON or WIF draft, with the draft's size flags; or a shipped
/// fabric's name, [`crate::fabrics`]) and applies the material overrides.
pub fn fabric(weave: &Path, draft: &DraftArgs, m: &MaterialArgs) -> Result<Fabric, CliError> {
    if draft.any() && !crate::fabrics::is_draft(weave) {
        return Err(CliError::new(
            format!(
                "--radius and --spacing apply only to a WIF draft (*.wif), and {} is a fabric file, which gives its sizes itself",
                weave.display()
            ),
            "drop them, or edit radius and spacing in the fabric file",
        ));
    }
    let fabric = crate::fabrics::read(weave, &draft.options())?;
    Ok(apply_material(fabric, m)?)
}

/// The fabric of `--weave` with the material options, for the commands that take no draft size
/// flags (render, plot, export).
pub fn fabric_of(weave: &Path, m: &MaterialArgs) -> Result<Fabric, CliError> {
    let fabric = crate::fabrics::read(weave, &Default::default())?;
    Ok(apply_material(fabric, m)?)
}

/// Replaces the facet-material fields given on the command line, in both yarn groups; fields not
/// given keep each group's value from the file. `--albedo` also replaces per-thread albedos.
/// (The values were range-checked by the parsers.)
pub fn apply_material(fabric: Fabric, m: &MaterialArgs) -> Result<Fabric, FabricError> {
    if m.albedo.is_none()
        && m.specular.is_none()
        && m.exponent.is_none()
        && m.translucency.is_none()
    {
        return Ok(fabric);
    }
    fabric.with_groups(
        |_, g| {
            if let Some(a) = m.albedo {
                g.material.albedo = a;
                g.threads.iter_mut().for_each(|y| y.albedo = None);
            }
            if let Some(s) = m.specular {
                g.material.specular = s;
            }
            if let Some(n) = m.exponent {
                g.material.exponent = n;
            }
            if let Some(t) = m.translucency {
                g.material.translucency = t;
            }
        },
        &PlainNaming("the material options"),
    )
}

fn ext_format(p: &Path) -> Option<FormatArg> {
    match p.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "exr" => Some(FormatArg::Exr),
        "bin" => Some(FormatArg::Bin),
        _ => None,
    }
}

/// The table format and EXR precision from `--format`, the output's extension and
/// `--precision` (shared by `bake` and `merge`).
pub fn output_format(
    format: Option<FormatArg>,
    output: Option<&Path>,
    precision: Option<PrecisionArg>,
) -> Result<(FormatArg, Precision), CliError> {
    let format = match (format, output) {
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
    let precision = match (precision, format) {
        (Some(_), FormatArg::Bin) => {
            return Err(CliError::new(
                "--precision applies only to EXR tables: binary tables always hold f32",
                "drop --precision or write an EXR table (--format exr)",
            ))
        }
        (Some(PrecisionArg::F32), _) => Precision::F32,
        _ => Precision::F16,
    };
    Ok((format, precision))
}

/// Refuses outputs that would fail or do harm only after the work (bake, merge, render, plot,
/// export): an input given as an output, two outputs to one file, a folder or special file,
/// an existing file without --force, a missing folder, a folder we may not write into (the
/// library's check, [`clothbake_bake::output::preflight`], as one line); each output's `what`
/// names it (`table`, `PNG image`).
pub fn preflight(outputs: &[(&Path, &str)], force: bool, inputs: &[&Path]) -> Result<(), CliError> {
    clothbake_bake::output::preflight(outputs, force, inputs).map_err(|e| table_error(&e))
}

/// A progress bar of `total` steps drawn with `template` on stderr, or none with --quiet or
/// when stderr is not a terminal (shared by bake and render). `{rate}` in the template shows
/// the steps per second with thousands grouped.
pub fn progress_bar(total: u64, template: &str, quiet: bool) -> Option<ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(template)
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

/// The worker thread count: `--threads N` if given, else every core.
pub fn thread_count(arg: Option<usize>) -> usize {
    arg.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// A rayon pool of `threads` workers, or the one-line error that says to give fewer (shared by
/// bake, export and render).
pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool, CliError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| {
            CliError::new(
                format!("cannot start {threads} worker threads: {e}"),
                "give fewer with --threads N",
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn material_overrides_keep_unset_fields() {
        let f = Fabric::from_json_str(
            r#"{"pattern": [[1,0],[0,1]],
                "warp": {"radius": 1.5, "spacing": 3.1, "material": {"specular": 0.1}},
                "weft": {"radius": 1.5, "spacing": 3.1, "material": {"specular": 0.2}}}"#,
            "t",
        )
        .unwrap();
        let m = MaterialArgs {
            albedo: Some([0.1, 0.2, 0.3]),
            specular: None,
            exponent: Some(4.0),
            translucency: Some(0.5),
        };
        let f = apply_material(f, &m).unwrap();
        assert_eq!(f.warp().material.albedo, [0.1, 0.2, 0.3]);
        assert_eq!(f.weft().material.exponent, 4.0);
        assert_eq!(f.weft().material.translucency, 0.5);
        assert_eq!(f.warp().material.specular, 0.1);
        assert_eq!(f.weft().material.specular, 0.2);
    }

    #[test]
    fn digit_groups() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(4194304), "4,194,304");
    }
}
