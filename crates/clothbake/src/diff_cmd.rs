//! `clothbake diff A B [--tol REL] [--abs ABS]`: how far apart two tables of the same grid are,
//! in their values and in everything else they carry that changes what they render (the
//! openness, a spatial table's cells and classes, the yarns: `compare::carried_differences`).
//!
//! Exit status: 0 when every value is within `|a - b| <= ABS + REL |a|` and the rest is the
//! same, 1 otherwise, 2 when the tables cannot be compared (unreadable file, different grids).

use crate::cli::DiffArgs;
use crate::error::CliError;
use clothbake_bake::compare::{carried_differences, compare, Tolerance, DEFAULT_ABS, DEFAULT_REL};
use clothbake_loader::read_table;
use std::fmt::Write as _;

/// The text to print and the exit status (0 or 1).
pub fn run(args: &DiffArgs) -> Result<(String, u8), CliError> {
    let a = read_table(&args.a)?;
    let b = read_table(&args.b)?;
    let tol = Tolerance {
        rel: args.tol.unwrap_or(DEFAULT_REL),
        abs: args.abs_tol.unwrap_or(DEFAULT_ABS),
    };
    let c = compare(&a, &b, tol).map_err(|e| {
        CliError::new(
            format!("{} and {}: {e}", args.a.display(), args.b.display()),
            "diff compares tables of the same grid: bake both with the same --res and --faces",
        )
    })?;
    let mut s = String::new();
    let g = a.meta.grid;
    let _ = writeln!(s, "A          {}", args.a.display());
    let _ = writeln!(s, "B          {}", args.b.display());
    let _ = writeln!(s, "grid       {g} ({} cells, {} values)", g.len(), c.values);
    let differ: Vec<&str> = [
        ("fabric", a.meta.fabric_json != b.meta.fabric_json),
        ("options", a.meta.options_json != b.meta.options_json),
        ("tool", a.meta.tool != b.meta.tool),
    ]
    .iter()
    .filter(|x| x.1)
    .map(|x| x.0)
    .collect();
    let _ = writeln!(
        s,
        "metadata   {}",
        if differ.is_empty() {
            "same fabric, options and tool".to_string()
        } else {
            format!(
                "{} {}",
                differ.join(", "),
                if differ.len() == 1 {
                    "differs"
                } else {
                    "differ"
                }
            )
        }
    );
    let carried = carried_differences(&a.meta, &b.meta);
    if a.meta.spatial.is_some() != b.meta.spatial.is_some() {
        let which = if a.meta.spatial.is_some() { "A" } else { "B" };
        let _ = writeln!(
            s,
            "carried    only {which} is spatial: the averaged values are compared"
        );
    } else if carried.is_empty() {
        let _ = writeln!(s, "carried    the same openness, cells, classes and yarns");
    } else {
        for (k, line) in carried.iter().enumerate() {
            let head = if k == 0 { "carried   " } else { "          " };
            let _ = writeln!(s, "{head} DIFFERENT {line}");
        }
    }
    let _ = writeln!(
        s,
        "abs diff   max {:.3e}  mean {:.3e}  (1/sr)",
        c.max_abs, c.mean_abs
    );
    let _ = writeln!(
        s,
        "rel diff   max {:.3e}  mean {:.3e}  (|a - b| / |a|, values with a != 0)",
        c.max_rel, c.mean_rel
    );
    let psnr = match c.psnr() {
        None => "undefined (A has no positive value)".to_string(),
        Some(p) if p.is_infinite() => "inf (identical)".to_string(),
        Some(p) => format!("{p:.2} dB"),
    };
    let _ = writeln!(s, "PSNR       {psnr}  (peak = max of A = {:.6e})", c.peak);
    let names = a.meta.channel_names();
    match &c.worst {
        None => {
            let _ = writeln!(s, "worst      none: every value is equal");
        }
        Some(w) => {
            let _ = writeln!(
                s,
                "worst      {}, {}: A {:.7e}, B {:.7e}, |a - b| {:.3e} = {} the tolerance",
                w.cell,
                names.get(w.channel).map_or("?", String::as_str),
                w.a,
                w.b,
                (f64::from(w.a) - f64::from(w.b)).abs(),
                if w.ratio.is_infinite() {
                    "infinitely many times".to_string()
                } else {
                    format!("{:.3} times", w.ratio)
                }
            );
        }
    }
    let _ = writeln!(
        s,
        "tolerance  |a - b| <= {:e} + {:e} |a|: {} of {} values beyond it",
        tol.abs, tol.rel, c.beyond, c.values
    );
    let code = if c.within() && carried.is_empty() {
        0
    } else {
        1
    };
    let _ = writeln!(
        s,
        "result     {}",
        match (c.within(), carried.is_empty()) {
            (true, true) => "within tolerance (exit 0)",
            (false, _) => "DIFFERENT: beyond tolerance (exit 1)",
            (true, false) =>
                "DIFFERENT: the values are within tolerance, what else the tables \
                              carry is not (exit 1)",
        }
    );
    Ok((s, code))
}
