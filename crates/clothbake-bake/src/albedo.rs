//! Directional albedo of a baked table: how much of the light arriving from one incident cell
//! the fabric reflects, `integral over the hemisphere of f_r cos(theta_o) d omega_o`; for a
//! two-faced table also how much it transmits (the same over the other side, with
//! |cos(theta_o)|).
//!
//! The integral is the sum over the outgoing cells of the cell's value times the exact integral
//! of `cos(theta_o)` over the cell's solid angle,
//! `delta_phi * (sin^2 theta_hi - sin^2 theta_lo) / 2` (midpoint rule in f_r, exact in the
//! weight). The weights of a whole hemisphere add up to pi exactly, so a constant
//! `f_r = rho / pi` has albedo rho at any resolution.

use clothbake_loader::{Grid, Table};

/// `integral of |cos(theta)| d omega` over outgoing polar cell `to` and one azimuth cell (the
/// cells' edges: [`clothbake_loader::Axis::edge_rad`]; a cell never straddles the horizon).
pub fn cell_weight(g: &Grid, to: u32) -> f64 {
    let (lo, hi) = (g.theta_o().edge_rad(to), g.theta_o().edge_rad(to + 1));
    let dphi = g.phi_o().width_rad();
    dphi * (hi.sin().powi(2) - lo.sin().powi(2)).abs() / 2.0
}

/// Directional albedo, per RGB channel, for the incident cell (ti, pi): the light leaving on
/// the light's side (for a one-faced table, all of it).
pub fn directional_albedo(t: &Table, ti: u32, pi: u32) -> [f64; 3] {
    reflected_and_transmitted(t, ti, pi).0
}

/// The light from incident cell (ti, pi) that leaves on its side (reflected) and on the other
/// (transmitted, 0 for a one-faced table), per RGB channel; the straight-through openness
/// apart.
pub fn reflected_and_transmitted(t: &Table, ti: u32, pi: u32) -> ([f64; 3], [f64; 3]) {
    let g = t.meta.grid;
    let above = |k: u32, n: u32| g.faces == clothbake_loader::Faces::One || k < n / 2;
    let (mut r, mut tr) = ([0.0; 3], [0.0; 3]);
    for to in 0..g.n_theta_o {
        let w = cell_weight(&g, to);
        let out = if above(ti, g.n_theta_i) == above(to, g.n_theta_o) {
            &mut r
        } else {
            &mut tr
        };
        for po in 0..g.n_phi_o {
            let v = t.rgb(ti, pi, to, po);
            for k in 0..3 {
                out[k] += w * f64::from(v[k]);
            }
        }
    }
    (r, tr)
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

    #[test]
    fn a_two_faced_lambertian_sheet_splits_into_its_two_albedos() {
        // f = r / pi on the light's side and t / pi on the other, from either side.
        let g = Grid::new(3, 4, 5, 6).two_faced();
        let (r, t) = (0.3f32, 0.45f32);
        let mut values = Vec::new();
        for ti in 0..g.n_theta_i {
            for _ in 0..g.n_phi_i {
                for to in 0..g.n_theta_o {
                    let same = (ti < g.n_theta_i / 2) == (to < g.n_theta_o / 2);
                    let v = if same { r } else { t } / std::f32::consts::PI;
                    values.extend((0..g.n_phi_o * 3).map(|_| v));
                }
            }
        }
        let mut meta = Metadata::new("t", g, "{}", "{}", "none");
        meta.openness = Some(vec![0.0; (g.n_theta_i * g.n_phi_i) as usize]);
        let table = Table::new(meta, values).unwrap();
        for ti in [0, 2, 3, 5] {
            let (a, b) = reflected_and_transmitted(&table, ti, 1);
            assert!((a[1] - f64::from(r)).abs() < 1e-6, "{ti}: {a:?}");
            assert!((b[1] - f64::from(t)).abs() < 1e-6, "{ti}: {b:?}");
        }
    }
}
