//! The default grid's lookup of the thesis's twill (exponent 10) reaches a mean relative error
//! under 3% against direct evaluation of the analytic model (issue 5; the full table with other
//! grids is `cargo xtask loader-accuracy`, docs/reference/loader.md).

use clothbake_bake::DEFAULT_GRID;
use clothbake_core::Fabric;
use clothbake_loader::Precision;
use clothbake_tests::accuracy::{baked_brdf, measure};
use std::path::Path;

#[test]
fn default_grid_twill_mean_relative_error_is_under_3_percent() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/twill.json");
    let fabric = Fabric::from_path(&path).unwrap();
    assert!(fabric.to_json().to_string().contains("\"exponent\":10"));
    let brdf = baked_brdf(&fabric, DEFAULT_GRID, Precision::F16);
    let a = measure(&fabric, &brdf, 4000, 2024);
    eprintln!("{a:?}");
    assert!(a.pairs > 3500, "{a:?}");
    assert!(
        a.mean < 0.03,
        "mean relative error {:.4} >= 3%: {a:?}",
        a.mean
    );
}
