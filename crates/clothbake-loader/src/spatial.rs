//! Spatially varying tables: the layout of the weave period's crossing cells, the class of
//! reflection each cell shows and its thread's colour ([`Spatial`], stored in the
//! [`crate::Metadata`]), and where the classes' values lie in a table (the render-time lookup
//! at a point of the period is `crate::spatial_lookup`).
//!
//! A spatial table holds, beside the averaged RGB table, two values per grid cell and class:
//! f_r of the class's diffuse term at unit albedo (D) and of its specular term (S), after the
//! averaged values, class by class, cell by cell, D then S (`docs/reference/table-format.md`). A cell of
//! the period whose class is `k` and whose thread has diffuse albedo rho_d reflects
//! `rho_d D_k + S_k` (with the second bounce six values: its neighbours of albedos rho_+ and
//! rho_- add `rho_+ (N+ + rho_d B+) + rho_- (N- + rho_d B-)`); its coverage c(x; wo) is the
//! class's visible share of the period ([`Spatial::visible`], tabulated over the outgoing
//! directions) over the cell's share of the period's area. The coverage-weighted mean of the
//! cells' f_r is the averaged table (docs/science/spatial.md).

use serde::{Deserialize, Serialize};

use crate::error::TableError;
use crate::grid::Grid;

/// Most crossing cells a spatial table's period may have (2^16): the layout is stored as JSON
/// in the header.
pub const MAX_SPATIAL_CELLS: usize = 1 << 16;

/// Most classes a spatial table may have (2^12).
pub const MAX_CLASSES: u32 = 1 << 12;

/// The layout of a spatially varying table: the period's crossing cells and what each shows.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Spatial {
    /// Number of classes K: the table holds 2 K values per grid cell beside the average.
    pub classes: u32,
    /// Cell edges along u (the weft direction, +X) in fractions of the period: one more than
    /// the warp threads, increasing, the last exactly 1 more than the first.
    pub u_edges: Vec<f64>,
    /// Cell edges along v (the warp direction, +Y), likewise, one more than the weft threads.
    pub v_edges: Vec<f64>,
    /// The class of each cell, row-major (weft row, then warp column).
    pub cell_class: Vec<u32>,
    /// The diffuse albedo (RGB) of the thread on top in each cell, row-major.
    pub cell_albedo: Vec<[f32; 3]>,
    /// Each class's visible projected area over the period's projected area, at the grid's
    /// outgoing cell centres: `visible[(k * n_theta_o + to) * n_phi_o + po]`.
    pub visible: Vec<f32>,
    /// Whether the classes hold the second bounce: six values per class and grid cell
    /// ([`Spatial::lanes`]) instead of two.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub secondary: bool,
    /// With `secondary`: the diffuse albedos (RGB) of the parallel neighbours on the +c and
    /// the -c side of each cell's thread, row-major (0 where there is none); empty otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cell_neighbours: Vec<[[f32; 3]; 2]>,
}

/// The values a class holds per grid cell: D, S and, with the second bounce, the +c
/// neighbour's and both threads' terms, then the -c side's.
const LANE_NAMES: [&str; 6] = [
    "diffuse",
    "specular",
    "plus_neighbour",
    "plus_both",
    "minus_neighbour",
    "minus_both",
];

/// The names of a table's channels in an OpenEXR file: `R`, `G`, `B` and, for a spatial table
/// of `classes` classes of `lanes` values ([`Spatial::lanes`]), `class<k>.diffuse`,
/// `class<k>.specular` and with the second bounce `class<k>.plus_neighbour`,
/// `class<k>.plus_both`, `class<k>.minus_neighbour`, `class<k>.minus_both` for each class `k`.
pub fn channel_names(classes: u32, lanes: usize) -> Vec<String> {
    let mut names: Vec<String> = ["R", "G", "B"].map(String::from).to_vec();
    for k in 0..classes {
        for lane in &LANE_NAMES[..lanes] {
            names.push(format!("class{k}.{lane}"));
        }
    }
    names
}

/// Values per class and grid cell: 2 (D, S), or 6 with the second bounce (`secondary`).
pub fn lanes(secondary: bool) -> usize {
    if secondary {
        6
    } else {
        2
    }
}

/// Index in a table's values of channel `ch` (in [`channel_names`] order) of grid cell `cell`,
/// for a grid of `n` cells and classes of `lanes` values.
pub fn value_index(ch: usize, cell: usize, n: usize, lanes: usize) -> usize {
    if ch < 3 {
        3 * cell + ch
    } else {
        let (k, j) = ((ch - 3) / lanes, (ch - 3) % lanes);
        3 * n + lanes * (k * n + cell) + j
    }
}

/// The grid cell and the channel (in [`channel_names`] order) of value `k` of a table's
/// values: the inverse of [`value_index`].
pub fn value_cell_channel(k: usize, n: usize, lanes: usize) -> (usize, usize) {
    if k < 3 * n {
        (k / 3, k % 3)
    } else {
        let r = k - 3 * n;
        let (class, within) = (r / (lanes * n), r % (lanes * n));
        (within / lanes, 3 + class * lanes + within % lanes)
    }
}

impl Spatial {
    /// Number of warp columns and weft rows of cells.
    pub fn dims(&self) -> (usize, usize) {
        (
            self.u_edges.len().saturating_sub(1),
            self.v_edges.len().saturating_sub(1),
        )
    }

    /// Values per class and grid cell ([`lanes`]).
    pub fn lanes(&self) -> usize {
        lanes(self.secondary)
    }

    /// Number of values the classes add to a table on `grid` ([`Spatial::lanes`] K per grid
    /// cell), saturating.
    pub fn values_len(&self, grid: &Grid) -> usize {
        grid.len()
            .saturating_mul(self.lanes())
            .saturating_mul(self.classes as usize)
    }

    /// Checks the layout against the table's grid.
    pub fn validate(&self, grid: &Grid) -> Result<(), TableError> {
        let bad = |reason: String| Err(TableError::InvalidTable { reason });
        if self.classes == 0 || self.classes > MAX_CLASSES {
            return bad(format!(
                "a spatial table has 1 to {MAX_CLASSES} classes, not {}",
                self.classes
            ));
        }
        for (name, e) in [("u_edges", &self.u_edges), ("v_edges", &self.v_edges)] {
            let ok = e.len() >= 2
                && e.iter().all(|x| x.is_finite())
                && e.windows(2).all(|w| w[1] > w[0])
                && (e[e.len() - 1] - e[0] - 1.0).abs() < 1e-9;
            if !ok {
                return bad(format!(
                    "spatial {name} must be at least 2 increasing fractions spanning one period"
                ));
            }
        }
        let (nx, ny) = self.dims();
        let cells = nx.saturating_mul(ny);
        if cells > MAX_SPATIAL_CELLS {
            return bad(format!(
                "the period has {cells} cells, more than the limit of {MAX_SPATIAL_CELLS}"
            ));
        }
        if self.cell_class.len() != cells || self.cell_albedo.len() != cells {
            return bad(format!(
                "{nx} x {ny} cells need {cells} classes and albedos, but there are {} and {}",
                self.cell_class.len(),
                self.cell_albedo.len()
            ));
        }
        if let Some(c) = self.cell_class.iter().find(|&&c| c >= self.classes) {
            return bad(format!(
                "a cell has class {c}, but there are {} classes",
                self.classes
            ));
        }
        let albedo_ok = |a: &[f32; 3]| a.iter().all(|x| (0.0..=1.0).contains(x));
        if !self.cell_albedo.iter().all(albedo_ok) {
            return bad("every albedo of a spatial table lies in [0, 1]".to_string());
        }
        let neighbours = if self.secondary { cells } else { 0 };
        if self.cell_neighbours.len() != neighbours {
            return bad(format!(
                "a spatial table {} has {neighbours} neighbour albedo pairs, not {}",
                if self.secondary {
                    "with the second bounce"
                } else {
                    "of the direct reflection"
                },
                self.cell_neighbours.len()
            ));
        }
        if !self.cell_neighbours.iter().flatten().all(albedo_ok) {
            return bad("every neighbour albedo of a spatial table lies in [0, 1]".to_string());
        }
        let n_vis = (self.classes as usize)
            .saturating_mul(grid.n_theta_o as usize)
            .saturating_mul(grid.n_phi_o as usize);
        if self.visible.len() != n_vis {
            return bad(format!(
                "{} classes on grid {grid} need {n_vis} visible areas, but there are {}",
                self.classes,
                self.visible.len()
            ));
        }
        if !self.visible.iter().all(|v| v.is_finite() && *v >= 0.0) {
            return bad("every visible area of a spatial table is finite and >= 0".to_string());
        }
        Ok(())
    }

    /// The cell (warp column, weft row) holding point (u, v) of the period, wrapped.
    #[inline]
    pub(crate) fn cell_at(&self, u: f64, v: f64) -> (usize, usize) {
        (
            Spatial::locate(&self.u_edges, u),
            Spatial::locate(&self.v_edges, v),
        )
    }

    /// The cell column (or row) of `edges` holding fraction `t` of the period, wrapped.
    #[inline]
    pub(crate) fn locate(edges: &[f64], t: f64) -> usize {
        let e0 = edges[0];
        let t = if t.is_finite() { t } else { 0.0 };
        // Wrapped into [e0, e0 + 1) by floor (no library call on the lookup's path).
        let d = t - e0;
        let x = e0 + (d - d.floor());
        let n = edges.len() - 1;
        edges
            .partition_point(|&e| e <= x)
            .saturating_sub(1)
            .min(n - 1)
    }

    /// Cells overlapping `[t0, t1]` (fractions, `t1 - t0 < 1`) with the share of each cell's
    /// width the interval covers.
    #[inline]
    pub(crate) fn overlaps(edges: &[f64], t0: f64, t1: f64, out: &mut Vec<(usize, f64)>) {
        out.clear();
        let n = edges.len() - 1;
        let mut k = Spatial::locate(edges, t0);
        // The unwrapped start of cell k at or before t0.
        let mut start = edges[k] + (t0 - edges[k]).floor();
        while start < t1 && out.len() <= n {
            let w = edges[k + 1] - edges[k];
            let end = start + w;
            let covered = end.min(t1) - start.max(t0);
            if covered > 0.0 {
                out.push((k, covered / w));
            }
            start = end;
            k = (k + 1) % n;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_cell_channel_inverts_value_index() {
        // Every value of a table of 7 grid cells and 3 classes, with one bounce and two: each
        // index once, and back to its cell and channel.
        let n = 7;
        for lanes in [lanes(false), lanes(true)] {
            let channels = 3 + 3 * lanes;
            let mut seen = vec![false; n * channels];
            for ch in 0..channels {
                for cell in 0..n {
                    let k = value_index(ch, cell, n, lanes);
                    assert!(!seen[k], "{k} twice");
                    seen[k] = true;
                    assert_eq!(value_cell_channel(k, n, lanes), (cell, ch));
                }
            }
        }
    }

    #[test]
    fn overlaps_cover_the_interval_once() {
        // Edges -0.25, 0.25, 0.75 (two cells of half a period, the first across 0).
        let e = [-0.25, 0.25, 0.75];
        assert_eq!(Spatial::locate(&e, 0.0), 0);
        assert_eq!(Spatial::locate(&e, 0.5), 1);
        assert_eq!(Spatial::locate(&e, 0.8), 0);
        assert_eq!(Spatial::locate(&e, -3.6), 1);
        let mut out = Vec::new();
        Spatial::overlaps(&e, 0.0, 0.5, &mut out);
        // Half of cell 0 (0..0.25) and half of cell 1 (0.25..0.5).
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].0, 0);
        assert!((out[0].1 - 0.5).abs() < 1e-12 && (out[1].1 - 0.5).abs() < 1e-12);
        // Wrapping past the end.
        Spatial::overlaps(&e, 0.6, 1.1, &mut out);
        let total: f64 = out.iter().map(|(_, s)| s * 0.5).sum();
        assert!((total - 0.5).abs() < 1e-12, "{out:?}");
    }
}
