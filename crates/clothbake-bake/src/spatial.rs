//! `bake --spatial`: what a spatially varying table adds to the averaged one (docs/science/spatial.md,
//! docs/reference/table-format.md): the period's layout ([`layout`]) and, per grid cell, each class's
//! diffuse and specular f_r and with the second bounce its neighbours' terms
//! ([`class_values`]), packed three to a [`crate::Row`] entry after the averaged RGB.

use clothbake_core::{AnalyticModel, ClassTerms};
use clothbake_loader::spatial::MAX_SPATIAL_CELLS;
use clothbake_loader::{Grid, Spatial};

use crate::directions::direction;

/// Entries of a row per grid cell in a spatial bake whose classes hold `class_values` values
/// per grid cell (2 K, or 6 K with the second bounce): the averaged RGB and those, three to an
/// entry.
pub fn stride(class_values: usize) -> usize {
    1 + class_values.div_ceil(3)
}

/// The layout of `model`'s period on grid `g`, with the second bounce's classes and neighbour
/// albedos when `secondary`, or why it cannot be baked.
pub fn layout(model: &AnalyticModel, g: &Grid, secondary: bool) -> Result<Spatial, String> {
    let cells = model.cells();
    let (nx, ny) = cells.dims();
    if nx * ny > MAX_SPATIAL_CELLS {
        return Err(format!(
            "the period has {nx} x {ny} crossing cells, more than a spatial table's limit of \
             {MAX_SPATIAL_CELLS}; bake it without --spatial (the averaged table)"
        ));
    }
    let (u_edges, v_edges) = cells.edge_fractions();
    let classes = model.classes_with(secondary);
    let cell_classes = model.cell_classes_with(secondary);
    let mut visible = vec![0.0f32; classes * g.n_theta_o as usize * g.n_phi_o as usize];
    let mut vis = vec![0.0; classes];
    for to in 0..g.n_theta_o {
        for po in 0..g.n_phi_o {
            let wo = direction(to, g.n_theta_o, po, g.n_phi_o);
            model.class_visible(wo, secondary, &mut vis);
            for (k, v) in vis.iter().enumerate() {
                let n = (k * g.n_theta_o as usize + to as usize) * g.n_phi_o as usize + po as usize;
                visible[n] = *v as f32;
            }
        }
    }
    Ok(Spatial {
        classes: classes as u32,
        u_edges,
        v_edges,
        cell_class: cell_classes.iter().map(|c| c.class).collect(),
        cell_albedo: cell_classes
            .iter()
            .map(|c| c.albedo.map(|a| a as f32))
            .collect(),
        visible,
        secondary,
        cell_neighbours: if secondary {
            cell_classes
                .iter()
                .map(|c| c.neighbours.map(|n| n.map(|a| a as f32)))
                .collect()
        } else {
            Vec::new()
        },
    })
}

/// The classes' values (from [`AnalyticModel::class_terms_with`]) appended to `out` three to
/// an entry: per class diffuse and specular and, with the second bounce (`secondary`), its +c
/// side's neighbour and both terms, then the -c side's; the last entry padded with 0.
pub fn class_values(terms: &[ClassTerms], secondary: bool, out: &mut Vec<[f32; 3]>) {
    let lanes = clothbake_loader::spatial::lanes(secondary);
    let mut flat = terms.iter().flat_map(|t| {
        [
            t.diffuse,
            t.specular,
            t.neighbour[0],
            t.both[0],
            t.neighbour[1],
            t.both[1],
        ]
        .into_iter()
        .take(lanes)
    });
    while let Some(a) = flat.next() {
        let b = flat.next().unwrap_or(0.0);
        let c = flat.next().unwrap_or(0.0);
        out.push([a as f32, b as f32, c as f32]);
    }
}
