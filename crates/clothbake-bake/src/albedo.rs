//! Directional albedo of a baked table: how much of the light arriving from one incident cell
//! the fabric reflects, `integral over the hemisphere of f_r cos(theta_o) d omega_o`.
//!
//! The integral is the sum over the outgoing cells of the cell's value times the exact integral
//! of `cos(theta_o)` over the cell's solid angle,
//! `delta_phi * (sin^2 theta_hi - sin^2 theta_lo) / 2` (midpoint rule in f_r, exact in the
//! weight). The weights of a whole hemisphere add up to pi exactly, so a constant
//! `f_r = rho / pi` has albedo rho at any resolution.

use clothbake_loader::{Grid, Table};

/// `integral of cos(theta) d omega` over outgoing polar cell `to` and one azimuth cell (the
/// cells' edges: [`clothbake_loader::Axis::edge_rad`]).
pub fn cell_weight(g: &Grid, to: u32) -> f64 {
    let (lo, hi) = (g.theta_o().edge_rad(to), g.theta_o().edge_rad(to + 1));
    let dphi = g.phi_o().width_rad();
    dphi * (hi.sin().powi(2) - lo.sin().powi(2)) / 2.0
}

/// Directional albedo, per RGB channel, for the incident cell (ti, pi).
pub fn directional_albedo(t: &Table, ti: u32, pi: u32) -> [f64; 3] {
    let g = t.meta.grid;
    let mut out = [0.0; 3];
    for to in 0..g.n_theta_o {
        let w = cell_weight(&g, to);
        for po in 0..g.n_phi_o {
            let v = t.rgb(ti, pi, to, po);
            for k in 0..3 {
                out[k] += w * f64::from(v[k]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_loader::Metadata;

    #[test]
    fn lambertian_table_has_its_albedo() {
        let g = Grid::new(3, 4, 7, 5);
        let rho = [0.4f32, 0.2, 0.1];
        let values = (0..g.len())
            .flat_map(|_| rho.map(|r| r / std::f32::consts::PI))
            .collect();
        let t = Table::new(Metadata::new("t", g, "{}", "{}", "none"), values).unwrap();
        let a = directional_albedo(&t, 1, 2);
        for k in 0..3 {
            assert!((a[k] - f64::from(rho[k])).abs() < 1e-6, "{a:?}");
        }
    }
}
