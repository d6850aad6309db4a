//! Export from a baked table (`clothbake export --table`): the RGL file made through the
//! loader's lookup against the RGL file made from the model, node by node. They differ by the
//! table's interpolation error only (docs/reference/loader.md: 1.5% mean at the default grid, larger
//! within a few degrees of the horizon), so the luminance-weighted relative RMSE over all nodes
//! must be small and most nodes close.

use clothbake_export::rgl;
use clothbake_tests::fixtures::{bake_and_open, coloured_twill, huo_bsdf, rgl_grid, temp_dir};

fn rgb_values(fields: &[rgl::Field]) -> Vec<f32> {
    let f = fields
        .iter()
        .find(|f| f.name == "rgb")
        .expect("an rgb field");
    f.data
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn the_export_of_a_baked_table_matches_the_export_of_the_model() {
    let fabric = coloured_twill();
    let dir = temp_dir("export-table");
    let lookup = bake_and_open(&fabric, &dir.join("twill.exr"));
    let from_table = lookup;
    let from_model = huo_bsdf(&fabric);
    // A coarser grid than the default keeps the test fast; the nodes are where they always are.
    let grid = rgl_grid(8, 12, 16);
    let t = rgb_values(&rgl::rgl_fields(&from_table, &grid, "t", rgl::Colour::Rgb));
    let m = rgb_values(&rgl::rgl_fields(&from_model, &grid, "m", rgl::Colour::Rgb));
    assert_eq!(t.len(), m.len());
    let (mut se, mut sm, mut close, mut lit) = (0.0, 0.0, 0, 0);
    for (&a, &b) in t.iter().zip(&m) {
        let (a, b) = (f64::from(a), f64::from(b));
        se += (a - b).powi(2);
        sm += b * b;
        if b > 0.0 {
            lit += 1;
            if (a - b).abs() <= 0.05 * b {
                close += 1;
            }
        }
        assert_eq!(
            a == 0.0,
            b == 0.0,
            "the same nodes are dark (light below the horizon)"
        );
    }
    let rel_rmse = (se / sm).sqrt();
    let frac = close as f64 / lit as f64;
    eprintln!(
        "table export vs model export: relative RMSE {:.2}%, {:.1}% of {lit} lit nodes within 5%",
        100.0 * rel_rmse,
        100.0 * frac
    );
    assert!(rel_rmse < 0.03, "relative RMSE {rel_rmse}");
    assert!(frac > 0.9, "only {frac} of the nodes within 5%");
    std::fs::remove_dir_all(&dir).unwrap();
}
