//! Importance sampling of the incident direction from tabulated CDFs of `f_r cos theta_i`.
//!
//! For each outgoing cell `(to, po)` the incident hemisphere is split into the table's incident
//! cells `(ti, pi)`: `theta` from `ti * 90 / n_theta_i` to `(ti + 1) * 90 / n_theta_i` degrees,
//! `phi` from `pi * 360 / n_phi_i` to `(pi + 1) * 360 / n_phi_i` (the axes' edges,
//! [`crate::Axis::edge_rad`]; `wo`'s and `wi`'s cells by [`crate::Axis::cell_of`]). The density
//! is **piecewise constant per unit solid angle** on those cells. A cell's probability is
//!
//! ```text
//! P(cell) = (1 - e) m(cell) / sum m  +  e Omega(cell) / (2 pi),       e = DEFENSIVE = 0.01
//! m(cell) = mean_RGB f_r(cell centre, outgoing centre) * integral over the cell of cos theta d omega
//! ```
//!
//! where `Omega(cell) = dphi (cos theta_lo - cos theta_hi)` is its solid angle and
//! the integral of `cos theta` is `dphi (sin^2 theta_hi - sin^2 theta_lo) / 2`. The uniform
//! part `e` keeps the density positive wherever the interpolated BRDF may be (cells whose
//! centre value is 0 but whose neighbours are not), so the estimator stays unbiased; an
//! outgoing cell whose values are all 0 is sampled uniformly. The pdf of `wi` is
//! `P(cell) / Omega(cell)`; `wo` selects the outgoing cell that contains it.
//!
//! Sampling: `u1` picks the polar row from the marginal CDF, `u2` the azimuth cell from that
//! row's conditional CDF; the remainders of both, rescaled to [0, 1), place the direction
//! uniformly in solid angle inside the cell (`cos theta` and `phi` uniform).

use crate::axis::Axis;
use crate::grid::Grid;

/// Weight of the uniform part of the sampling density (see the module documentation).
pub const DEFENSIVE: f64 = 0.01;

/// The CDFs of every outgoing cell, built on the first `sample` or `pdf` of a table.
#[derive(Clone, Debug)]
pub(crate) struct Sampler {
    grid: Grid,
    /// Per outgoing cell, `n_theta_i` cumulative row probabilities (the last is 1).
    marginal: Vec<f32>,
    /// Per outgoing cell and row, `n_phi_i` cumulative cell probabilities (the last is 1).
    conditional: Vec<f32>,
    /// `cos(k * 90 / n_theta_i degrees)`, `k = 0..=n_theta_i`.
    cos_edges: Vec<f32>,
    /// `1 / Omega` of an incident cell in each polar row.
    inv_solid_angle: Vec<f32>,
}

/// Cumulative sums of `p` divided by their total, the last exactly 1; uniform when the total
/// is 0.
fn cdf(p: &[f64], out: &mut Vec<f32>) {
    let total: f64 = p.iter().sum();
    let mut acc = 0.0;
    let n = p.len();
    for (k, &x) in p.iter().enumerate() {
        acc += x;
        let c = if k + 1 == n {
            1.0
        } else if total > 0.0 {
            acc / total
        } else {
            (k + 1) as f64 / n as f64
        };
        out.push(c as f32);
    }
}

/// The index `k` with `c[k - 1] <= u < c[k]` (`c[-1] = 0`) and the remainder of `u` in that
/// interval, rescaled to [0, 1).
#[inline]
fn pick(c: &[f32], u: f32) -> (usize, f32) {
    let k = c.partition_point(|&x| x <= u).min(c.len() - 1);
    let lo = if k == 0 { 0.0 } else { c[k - 1] };
    let width = c[k] - lo;
    let r = if width > 0.0 { (u - lo) / width } else { 0.5 };
    (k, r.clamp(0.0, 1.0 - f32::EPSILON))
}

/// Probability of interval `k` of a cumulative array.
#[inline]
fn mass(c: &[f32], k: usize) -> f32 {
    c[k] - if k == 0 { 0.0 } else { c[k - 1] }
}

impl Sampler {
    /// CDFs of the table `value(ti, pi, to, po)` (RGB f_r at cell centres) on grid `g`.
    pub(crate) fn new(g: &Grid, value: impl Fn(u32, u32, u32, u32) -> [f32; 3]) -> Sampler {
        debug_assert_eq!(g.faces, crate::Faces::One, "a sampler's grid is one-faced");
        let (nti, npi, nto, npo) = (g.n_theta_i, g.n_phi_i, g.n_theta_o, g.n_phi_o);
        let d_phi = g.phi_i().width_rad();
        let edges: Vec<f64> = (0..=nti).map(|k| g.theta_i().edge_rad(k)).collect();
        // Solid angle and integral of cos theta of a cell in each row.
        let omega: Vec<f64> = (0..nti as usize)
            .map(|k| d_phi * (edges[k].cos() - edges[k + 1].cos()))
            .collect();
        let cos_int: Vec<f64> = (0..nti as usize)
            .map(|k| 0.5 * d_phi * (edges[k + 1].sin().powi(2) - edges[k].sin().powi(2)))
            .collect();
        let cells = (nti * npi) as usize;
        let mut marginal = Vec::with_capacity(nto as usize * npo as usize * nti as usize);
        let mut conditional = Vec::with_capacity(nto as usize * npo as usize * cells);
        let mut m = vec![0f64; cells];
        let mut rows = vec![0f64; nti as usize];
        for to in 0..nto {
            for po in 0..npo {
                for ti in 0..nti {
                    for pi in 0..npi {
                        let f = value(ti, pi, to, po);
                        let lum = (f64::from(f[0]) + f64::from(f[1]) + f64::from(f[2])) / 3.0;
                        m[(ti * npi + pi) as usize] = lum.max(0.0) * cos_int[ti as usize];
                    }
                }
                let total: f64 = m.iter().sum();
                let (e, scale) = if total > 0.0 {
                    (DEFENSIVE, (1.0 - DEFENSIVE) / total)
                } else {
                    (1.0, 0.0)
                };
                for ti in 0..nti as usize {
                    // The uniform density over the incident hemisphere's 2 pi sr (a polar axis
                    // over the hemisphere, `Span::Hemisphere`; a block of a sphere table keeps it).
                    let uniform = e * omega[ti] / std::f64::consts::TAU;
                    let row = &mut m[ti * npi as usize..(ti + 1) * npi as usize];
                    for x in row.iter_mut() {
                        *x = *x * scale + uniform;
                    }
                    rows[ti] = row.iter().sum();
                    cdf(row, &mut conditional);
                }
                cdf(&rows, &mut marginal);
            }
        }
        Sampler {
            grid: *g,
            marginal,
            conditional,
            cos_edges: edges.iter().map(|t| t.cos() as f32).collect(),
            inv_solid_angle: omega.iter().map(|o| (1.0 / o) as f32).collect(),
        }
    }

    /// Bytes held by the CDFs of a table on `g` (f32 marginals and conditionals).
    pub(crate) fn bytes_of(g: &Grid) -> usize {
        let outgoing = g.n_theta_o as usize * g.n_phi_o as usize;
        4 * outgoing * g.n_theta_i as usize * (1 + g.n_phi_i as usize)
    }

    /// Index of the outgoing cell that holds (theta_o, phi_o), radians. A sampler's grid is
    /// one-faced (a two-faced table samples block by block, each on a one-faced grid), so its
    /// polar axes are written as the hemisphere's constant ([`Axis::polar`]): the cell rule's
    /// span folds away on this path.
    #[inline]
    fn outgoing_cell(&self, theta: f32, phi: f32) -> usize {
        let g = &self.grid;
        let to = Axis::polar(g.n_theta_o).cell_of(theta);
        let po = g.phi_o().cell_of(phi);
        to * g.n_phi_o as usize + po
    }

    /// A sampled incident direction (theta, phi), radians, for the outgoing direction.
    pub(crate) fn sample(&self, theta_o: f32, phi_o: f32, u1: f32, u2: f32) -> (f32, f32) {
        let g = &self.grid;
        let (nti, npi) = (g.n_theta_i as usize, g.n_phi_i as usize);
        let oc = self.outgoing_cell(theta_o, phi_o);
        let (u1, u2) = (clamp_unit(u1), clamp_unit(u2));
        let (ti, r1) = pick(&self.marginal[oc * nti..(oc + 1) * nti], u1);
        let row = (oc * nti + ti) * npi;
        let (pi, r2) = pick(&self.conditional[row..row + npi], u2);
        let (c_lo, c_hi) = (self.cos_edges[ti], self.cos_edges[ti + 1]);
        let mu = c_lo + r1 * (c_hi - c_lo);
        let theta = mu.clamp(0.0, 1.0).acos();
        let phi = g.phi_i().angle_at(pi as f32 + r2);
        (theta, phi)
    }

    /// The density of [`Sampler::sample`] at incident (theta_i, phi_i) for the outgoing
    /// direction, per unit solid angle (radians in).
    pub(crate) fn pdf(&self, theta_o: f32, phi_o: f32, theta_i: f32, phi_i: f32) -> f32 {
        let g = &self.grid;
        let (nti, npi) = (g.n_theta_i as usize, g.n_phi_i as usize);
        let oc = self.outgoing_cell(theta_o, phi_o);
        let ti = Axis::polar(g.n_theta_i).cell_of(theta_i);
        let pi = g.phi_i().cell_of(phi_i);
        let row = (oc * nti + ti) * npi;
        let p = mass(&self.marginal[oc * nti..(oc + 1) * nti], ti)
            * mass(&self.conditional[row..row + npi], pi);
        p * self.inv_solid_angle[ti]
    }
}

/// `u` clamped into [0, 1) (NaN to 0).
#[inline]
fn clamp_unit(u: f32) -> f32 {
    if u >= 0.0 {
        u.min(1.0 - f32::EPSILON / 2.0)
    } else {
        0.0
    }
}
