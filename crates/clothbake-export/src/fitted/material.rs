//! A fitted material over one weave period: one [`Params`] per crossing cell (or one for the
//! whole cloth), the textures that carry them, and the residual against the cloth's averaged
//! reflectance.

use super::fit::{fit, residual, Directions, Residual, Samples};
use super::microfacet::Albedos;
use super::{Convention, Family, Params};
use clothbake_core::{Bsdf, Footprint};
use rayon::prelude::*;
use std::collections::HashMap;

/// The most crossing cells a material is fitted per cell (a 32 x 32 period): each distinct
/// cell costs a fit (about a second), and the cells' samples are held at once
/// ([`Fitted::peak_bytes`]). A weave with more cells gets one material for the whole cloth.
pub const MAX_CELLS: usize = 1024;

/// The reflectance a material is fitted to.
pub struct Source<'a> {
    /// The averaged reflectance (the period's mean).
    pub average: &'a dyn Bsdf,
    /// The crossing cells, when the source resolves them.
    pub cells: Option<Cells<'a>>,
}

/// A reflectance resolved per crossing cell: `bsdf.f_at` at a point of width 0 answers the
/// cell containing it (no point level attached).
pub struct Cells<'a> {
    /// The reflectance.
    pub bsdf: &'a dyn Bsdf,
    /// Cell edges along u (+X, the weft) in fractions of the period, increasing, last = first + 1.
    pub u_edges: Vec<f64>,
    /// Likewise along v (+Y, the warp).
    pub v_edges: Vec<f64>,
}

/// A fitted material over one period.
#[derive(Clone, Debug)]
pub struct Fitted {
    /// The family it was fitted for.
    pub family: Family,
    /// Cell edges along u, as in [`Cells`] (`[0, 1]` for a uniform material).
    pub u_edges: Vec<f64>,
    /// Cell edges along v.
    pub v_edges: Vec<f64>,
    /// The parameters of each cell, row-major (v row, then u column).
    pub cells: Vec<Params>,
    /// The residual of the material's period mean against the averaged reflectance.
    pub residual: Residual,
}

impl Fitted {
    /// Fits `family`'s material to `src`: each distinct cell on its own (cells whose sampled
    /// reflectances are identical share one fit), or the average when `src` has no cells.
    /// A cell is fitted to its f_r times its coverage over the period's coverage, so that the
    /// texture's mean is the averaged f_r.
    pub fn new(family: Family, src: &Source<'_>, tables: &Albedos) -> Fitted {
        let conv = family.convention();
        let too_many = src
            .cells
            .as_ref()
            .is_some_and(|c| (c.u_edges.len() - 1) * (c.v_edges.len() - 1) > MAX_CELLS);
        let cells_src = if too_many { None } else { src.cells.as_ref() };
        let (u_edges, v_edges, cells) = match cells_src {
            None => {
                let r = Samples::of(src.average, Directions::fitting());
                (vec![0.0, 1.0], vec![0.0, 1.0], vec![fit(conv, tables, &r)])
            }
            Some(c) => {
                let (nu, nv) = (c.u_edges.len() - 1, c.v_edges.len() - 1);
                let centres: Vec<(f64, f64)> = (0..nu * nv)
                    .map(|k| {
                        let (i, j) = (k % nu, k / nu);
                        (
                            0.5 * (c.u_edges[i] + c.u_edges[i + 1]),
                            0.5 * (c.v_edges[j] + c.v_edges[j + 1]),
                        )
                    })
                    .collect();
                // Each cell's f_r times its coverage, over the period's coverage
                // sum_k a_k c_k: the texels' area-weighted mean is then the averaged f_r,
                // which is that coverage-weighted mean (docs/science/spatial.md). A material has no
                // gaps: a cell whose yarn covers half its area shows half its f_r.
                let locals: Vec<(Samples, Vec<f64>)> = centres
                    .par_iter()
                    .map(|&(u, v)| {
                        let at = Footprint { u, v, width: 0.0 };
                        Samples::local_at(c.bsdf, at, Directions::fitting())
                    })
                    .collect();
                let n_o = locals[0].1.len();
                let mut period = vec![0.0; n_o];
                for (k, (_, cover)) in locals.iter().enumerate() {
                    let (i, j) = (k % nu, k / nu);
                    let a = (c.u_edges[i + 1] - c.u_edges[i]) * (c.v_edges[j + 1] - c.v_edges[j]);
                    for (p, x) in period.iter_mut().zip(cover) {
                        *p += a * x;
                    }
                }
                let samples: Vec<Samples> = locals
                    .into_iter()
                    .map(|(mut s, _)| {
                        s.divide_by_view(&period);
                        s
                    })
                    .collect();
                // Distinct reflectances, in first-seen order.
                let mut key_of: HashMap<Vec<u64>, usize> = HashMap::new();
                let mut distinct = Vec::new();
                let mut which = Vec::with_capacity(samples.len());
                for (k, s) in samples.iter().enumerate() {
                    let key: Vec<u64> = s.f.iter().flat_map(|c| c.map(f64::to_bits)).collect();
                    let n = key_of.len();
                    let d = *key_of.entry(key).or_insert_with(|| {
                        distinct.push(k);
                        n
                    });
                    which.push(d);
                }
                let fits: Vec<Params> = distinct
                    .par_iter()
                    .map(|&k| fit(conv, tables, &samples[k]))
                    .collect();
                let cells = which.iter().map(|&d| fits[d]).collect();
                (c.u_edges.clone(), c.v_edges.clone(), cells)
            }
        };
        let mut m = Fitted {
            family,
            u_edges,
            v_edges,
            cells,
            residual: Residual {
                l2: 0.0,
                albedo_mean: 0.0,
                albedo_max: 0.0,
            },
        };
        m.residual = m.residual_against(src.average, conv, tables);
        m
    }

    /// An upper bound on the memory a fit of `cells` crossing cells holds at its peak: each
    /// cell's samples (24 bytes a pair of the fitting directions), the albedo tables and the
    /// residual's samples.
    pub fn peak_bytes(cells: usize) -> u64 {
        let pairs = (Directions::fitting().dirs().len() as u64).pow(2);
        let report = (Directions::reporting().dirs().len() as u64).pow(2);
        let per_cell = 24 * pairs + 64;
        (cells.min(MAX_CELLS) as u64 + 2) * per_cell + 8 * 24 * report + (1 << 20)
    }

    /// Whether `cells` crossing cells are fitted one by one ([`MAX_CELLS`]).
    pub fn fits_per_cell(cells: usize) -> bool {
        cells <= MAX_CELLS
    }

    /// The residual of this material's period mean, evaluated under `conv`, against `average`.
    pub fn residual_against(&self, average: &dyn Bsdf, conv: Convention, t: &Albedos) -> Residual {
        let reference = Samples::of(average, Directions::reporting());
        residual(
            &self.mean_samples(conv, t, Directions::reporting()),
            &reference,
        )
    }

    /// The period mean of the material's f_r (each cell weighted by its area) on every pair
    /// of `dirs`.
    pub fn mean_samples(&self, conv: Convention, t: &Albedos, dirs: Directions) -> Samples {
        let mut weight: Vec<(Params, f64)> = Vec::new();
        for (k, p) in self.cells.iter().enumerate() {
            let a = self.area(k);
            match weight.iter_mut().find(|(q, _)| q == p) {
                Some(e) => e.1 += a,
                None => weight.push((*p, a)),
            }
        }
        let sets: Vec<(Samples, f64)> = weight
            .par_iter()
            .map(|(p, a)| (Samples::of_params(conv, p, t, dirs.clone()), *a))
            .collect();
        let mut f = vec![[0.0; 3]; sets[0].0.f.len()];
        for (s, a) in &sets {
            for (x, y) in f.iter_mut().zip(&s.f) {
                for c in 0..3 {
                    x[c] += a * y[c];
                }
            }
        }
        Samples { dirs, f }
    }

    /// Columns and rows of cells.
    pub fn dims(&self) -> (usize, usize) {
        (self.u_edges.len() - 1, self.v_edges.len() - 1)
    }

    /// Cell `k`'s share of the period's area.
    pub fn area(&self, k: usize) -> f64 {
        let (nu, _) = self.dims();
        let (i, j) = (k % nu, k / nu);
        (self.u_edges[i + 1] - self.u_edges[i]) * (self.v_edges[j + 1] - self.v_edges[j])
    }

    /// Whether one set of parameters covers the whole period.
    pub fn is_uniform(&self) -> bool {
        self.cells.iter().all(|p| *p == self.cells[0])
    }

    /// The cell at the point (u, v) of the period (any finite values, wrapped).
    pub fn cell_at(&self, u: f64, v: f64) -> usize {
        let locate = |e: &[f64], x: f64| {
            let x = e[0] + (x - e[0]).rem_euclid(1.0);
            e.partition_point(|&b| b <= x).clamp(1, e.len() - 1) - 1
        };
        let (nu, _) = self.dims();
        locate(&self.v_edges, v) * nu + locate(&self.u_edges, u)
    }

    /// The texture size that resolves the cells: `k` texels across each cell's mean width,
    /// at most 1024 across, at least 1 texel a cell.
    pub fn texture_size(&self) -> (usize, usize) {
        let (nu, nv) = self.dims();
        if self.is_uniform() {
            return (1, 1);
        }
        let k = (256 / nu.max(nv)).clamp(1, 16);
        ((nu * k).min(1024.max(nu)), (nv * k).min(1024.max(nv)))
    }

    /// For each texel of a `w` x `h` texture over the period (row 0 at v = 0), the cell
    /// whose parameters it holds: the cell under the texel's centre.
    pub fn texel_cells(&self, w: usize, h: usize) -> Vec<usize> {
        let mut out = Vec::with_capacity(w * h);
        for r in 0..h {
            for c in 0..w {
                out.push(self.cell_at((c as f64 + 0.5) / w as f64, (r as f64 + 0.5) / h as f64));
            }
        }
        out
    }

    /// The same material with every cell's parameters replaced by `f` of them (for what a
    /// file holds after quantisation).
    pub fn map(&self, f: impl Fn(&Params) -> Params) -> Fitted {
        Fitted {
            cells: self.cells.iter().map(f).collect(),
            ..self.clone()
        }
    }

    /// The area-weighted mean of the parameters (what a file without textures holds for a
    /// textured material; the tangent is the one covering the most area).
    pub fn mean_params(&self) -> Params {
        let mut m = Params {
            base: [0.0; 3],
            roughness: 0.0,
            anisotropy: 0.0,
            tangent_deg: 0.0,
            sheen: 0.0,
            sheen_roughness: 0.0,
            diffuse_roughness: 0.0,
        };
        let mut along = 0.0;
        for (k, p) in self.cells.iter().enumerate() {
            let a = self.area(k);
            for c in 0..3 {
                m.base[c] += a * p.base[c];
            }
            m.roughness += a * p.roughness;
            m.anisotropy += a * p.anisotropy;
            m.sheen += a * p.sheen;
            m.sheen_roughness += a * p.sheen_roughness;
            m.diffuse_roughness += a * p.diffuse_roughness;
            along += a * if p.tangent_deg.abs() < 45.0 {
                1.0
            } else {
                -1.0
            };
        }
        m.tangent_deg = if along >= 0.0 { 0.0 } else { 90.0 };
        m
    }
}
