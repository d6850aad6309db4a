//! The grid's directions as the bake walks them: the incident cell of a row ([`row_cell`]) and
//! the direction at a cell's centre ([`direction`] on a hemisphere, [`incident`] and
//! [`outgoing`] on a grid's own axes, which cover the sphere for a two-faced table; by the
//! loader's [`Axis`] rule). A leaf: the sweep, the spatial layout and the transport's coarse
//! grid all use it.

use clothbake_core::UnitVec3;
use clothbake_loader::{Axis, Grid};

/// The rows of a grid are numbered `ti * n_phi_i + pi`, the order of the table's cells.
pub fn row_cell(g: &Grid, row: usize) -> (u32, u32) {
    let npi = g.n_phi_i as usize;
    ((row / npi) as u32, (row % npi) as u32)
}

/// The grid's direction for polar index `k` of `n` and azimuth index `m` of `nm`: the centre
/// of the cell.
pub fn direction(k: u32, n: u32, m: u32, nm: u32) -> UnitVec3 {
    let theta = Axis::polar(n).centre_deg(k);
    let phi = Axis::azimuth(nm).centre_deg(m);
    UnitVec3::from_degrees(theta, phi)
}

/// The incident direction at the centre of cell (`ti`, `pi`) of `g`'s axes (below the cloth
/// from a two-faced grid's lower half on).
pub fn incident(g: &Grid, ti: u32, pi: u32) -> UnitVec3 {
    UnitVec3::from_degrees(g.theta_i().centre_deg(ti), g.phi_i().centre_deg(pi))
}

/// The outgoing direction at the centre of cell (`to`, `po`) of `g`'s axes.
pub fn outgoing(g: &Grid, to: u32, po: u32) -> UnitVec3 {
    UnitVec3::from_degrees(g.theta_o().centre_deg(to), g.phi_o().centre_deg(po))
}
