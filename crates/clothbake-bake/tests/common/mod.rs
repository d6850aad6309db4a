//! Helpers shared by the bake library's tests (each test file uses some).
#![allow(dead_code)]

use clothbake_bake::BakeOptions;
use clothbake_core::Fabric;
use clothbake_loader::Grid;
use std::path::{Path, PathBuf};

/// The shipped fabric `tables/<name>.json`.
pub fn fabric(name: &str) -> Fabric {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tables")
        .join(format!("{name}.json"));
    Fabric::from_path(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// The grid of `[n_theta_i, n_phi_i, n_theta_o, n_phi_o]` cells.
pub fn grid([n_theta_i, n_phi_i, n_theta_o, n_phi_o]: [u32; 4]) -> Grid {
    Grid::new(n_theta_i, n_phi_i, n_theta_o, n_phi_o)
}

/// The small grid most tests bake on: 4 x 8 x 4 x 8.
pub fn small() -> Grid {
    grid([4, 8, 4, 8])
}

/// The default options on `grid`.
pub fn options(grid: Grid) -> BakeOptions {
    BakeOptions {
        grid,
        ..BakeOptions::default()
    }
}

/// A fresh, empty folder `name` under the test's scratch folder.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
