//! Golden tables: every shipped fabric baked at a small grid and kept in `tables/golden/`, so
//! that any change of the model shows up as a table difference.
//!
//! `cargo xtask golden` writes them; the test `tests/tests/golden.rs` bakes each fabric afresh
//! with the same [`options`] and compares it with its golden table to [`TOLERANCE`].

use crate::compare::Tolerance;
use crate::sweep::{bake, BakeError, BakeOptions};
use clothbake_core::Fabric;
use clothbake_loader::{Grid, Table};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// The golden grid: 8 x 16 x 8 x 16 cells.
pub const GRID: Grid = Grid::new(8, 16, 8, 16);

/// A fresh bake must equal its golden table to a relative 1e-9: in effect bit for bit in f32
/// (an f32 carries 7 significant digits).
pub const TOLERANCE: Tolerance = Tolerance {
    rel: 1e-9,
    abs: 0.0,
};

/// The bake options of the golden tables: the defaults (analytic model, refined variant, Huo
/// facets, one bounce) on [`GRID`].
pub fn options() -> BakeOptions {
    BakeOptions {
        grid: GRID,
        ..BakeOptions::default()
    }
}

/// Bakes the golden table of `fabric` (on the current rayon pool).
pub fn bake_golden(fabric: &Fabric) -> Result<Table, BakeError> {
    bake(fabric, &options(), &|_| {}, &AtomicBool::new(false)).map(|b| b.table)
}

/// The shipped fabrics: every `*.json` in `tables_dir`, as (name, path), sorted by name.
pub fn shipped_fabrics(tables_dir: &Path) -> std::io::Result<Vec<(String, PathBuf)>> {
    let mut v = Vec::new();
    for p in fabric_files(tables_dir)? {
        if p.extension().is_some_and(|x| x == "json") {
            let name = p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            v.push((name, p));
        }
    }
    v.sort();
    Ok(v)
}

/// Every fabric file (`*.json` and `*.wif` drafts) directly in `tables_dir`, sorted by path.
pub fn fabric_files(tables_dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(tables_dir)? {
        let p = e?.path();
        if p.extension().is_some_and(|x| x == "json" || x == "wif") && p.is_file() {
            v.push(p);
        }
    }
    v.sort();
    Ok(v)
}

/// Where the golden table of fabric `name` lives: `<tables_dir>/golden/<name>.bin`.
pub fn golden_path(tables_dir: &Path, name: &str) -> PathBuf {
    tables_dir.join("golden").join(format!("{name}.bin"))
}
