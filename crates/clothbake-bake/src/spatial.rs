//! `bake --spatial`: what a spatially varying table adds to the averaged one (docs/spatial.md,
//! docs/table-format.md): the period's layout ([`layout`]) and, per grid cell, each class's
//! diffuse and specular f_r ([`class_values`]), packed three to a [`crate::Row`] entry after
//! the averaged RGB.

use clothbake_core::{AnalyticModel, ClassTerms, UnitVec3};
use clothbake_loader::spatial::MAX_SPATIAL_CELLS;
use clothbake_loader::{Grid, Spatial};

use crate::sweep::direction;

/// Entries of a row per grid cell in a spatial bake of `classes` classes: the averaged RGB and
/// the classes' 2 K values, three to an entry.
pub fn stride(classes: usize) -> usize {
    1 + (2 * classes).div_ceil(3)
}

/// The layout of `model`'s period on grid `g`, or why it cannot be baked.
pub fn layout(model: &AnalyticModel, g: &Grid) -> Result<Spatial, String> {
    let cells = model.cells();
    let (nx, ny) = cells.dims();
    if nx * ny > MAX_SPATIAL_CELLS {
        return Err(format!(
            "the period has {nx} x {ny} crossing cells, more than a spatial table's limit of \
             {MAX_SPATIAL_CELLS}; bake it without --spatial (the averaged table)"
        ));
    }
    let (u_edges, v_edges) = cells.edge_fractions();
    let classes = model.classes();
    let cell_classes = model.cell_classes();
    let mut visible = vec![0.0f32; classes * g.n_theta_o as usize * g.n_phi_o as usize];
    let mut terms = vec![ClassTerms::default(); classes];
    for to in 0..g.n_theta_o {
        for po in 0..g.n_phi_o {
            let wo = direction(to, g.n_theta_o, po, g.n_phi_o);
            model.class_terms(UnitVec3::Z, wo, &mut terms);
            for (k, t) in terms.iter().enumerate() {
                let n = (k * g.n_theta_o as usize + to as usize) * g.n_phi_o as usize + po as usize;
                visible[n] = t.visible as f32;
            }
        }
    }
    Ok(Spatial {
        classes: classes as u32,
        u_edges,
        v_edges,
        cell_class: cell_classes.iter().map(|c| c.0).collect(),
        cell_albedo: cell_classes.iter().map(|c| c.1.map(|a| a as f32)).collect(),
        visible,
    })
}

/// The classes' values (from [`AnalyticModel::class_terms`]) appended to `out` three to an
/// entry (diffuse and specular of class 0, diffuse of class 1, ...; the last entry padded with
/// 0).
pub fn class_values(terms: &[ClassTerms], out: &mut Vec<[f32; 3]>) {
    let mut flat = terms.iter().flat_map(|t| [t.diffuse, t.specular]);
    while let Some(a) = flat.next() {
        let b = flat.next().unwrap_or(0.0);
        let c = flat.next().unwrap_or(0.0);
        out.push([a as f32, b as f32, c as f32]);
    }
}
