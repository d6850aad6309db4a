//! `clothbake merge -o TABLE SHARD...`: the shards of a bake into its table.
//!
//! Reads every shard (refusing damaged or foreign files), checks them with
//! [`clothbake_bake::merge::merge`] (same fabric, options, grid and tool version; every shard once),
//! then writes the table atomically through the loader. Any failure: one line naming the shard
//! and the cause, exit 2, nothing written.

use crate::cli::{FormatArg, MergeArgs};
use crate::error::CliError;
use crate::resolve::{output_format, preflight};
use clothbake_bake::memory;
use clothbake_bake::merge::{merge, orbits_of};
use clothbake_bake::output::{write_table, Format};
use clothbake_bake::shard::read_part;

/// Runs the merge and returns the summary line for stdout (empty with --quiet).
pub fn run(a: &MergeArgs) -> Result<String, CliError> {
    let (format, precision) = output_format(a.table.format, Some(&a.output), a.table.precision)?;
    if a.output.file_name().is_none() {
        return Err(CliError::new(
            format!("the output {} does not name a file", a.output.display()),
            "give a file name with -o TABLE, e.g. -o twill.exr",
        ));
    }
    let inputs: Vec<&std::path::Path> = a.shards.iter().map(|p| p.as_path()).collect();
    preflight(&[(&a.output, "table")], a.out.force, &inputs)?;
    let format = match format {
        FormatArg::Exr => Format::Exr(precision),
        FormatArg::Bin => Format::Binary,
    };
    check_memory(&a.shards, format)?;
    let mut parts = Vec::with_capacity(a.shards.len());
    for p in &a.shards {
        let part = read_part(p, orbits_of)?;
        parts.push((p.clone(), part));
    }
    let table = merge(&parts).map_err(|e| CliError::line(e.to_string()))?;
    write_table(&a.output, &table, format, a.out.force)?;
    if a.out.quiet {
        return Ok(String::new());
    }
    let g = table.meta.grid;
    Ok(format!(
        "wrote {}: {} shards merged, grid {}x{}x{}x{} (theta_i x phi_i x theta_o x phi_o)\n",
        a.output.display(),
        parts.len(),
        g.n_theta_i,
        g.n_phi_i,
        g.n_theta_o,
        g.n_phi_o
    ))
}

/// Refuses a merge whose shards and table would not fit in the memory available
/// ([`memory::merge_bytes`]), before any shard is read.
fn check_memory(shards: &[std::path::PathBuf], format: Format) -> Result<(), CliError> {
    let bytes: u64 = shards
        .iter()
        .filter_map(|p| std::fs::metadata(p).ok())
        .map(|m| m.len())
        .sum();
    let need = memory::merge_bytes(bytes, format);
    match memory::available_bytes() {
        Some(have) if need > have => Err(CliError::new(
            format!(
                "merging these {} shards ({} of files) needs up to {} of memory, but {} is \
                 available",
                shards.len(),
                memory::describe(bytes),
                memory::describe(need),
                memory::describe(have)
            ),
            "merge on a machine with more memory, or bake a smaller --res",
        )),
        _ => Ok(()),
    }
}
