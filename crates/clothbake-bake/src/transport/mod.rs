//! The multiple-bounce part of a full-transport bake (`--bounces N > 2`, `--bounces all`;
//! docs/science/transport.md): orders 2 to N path-traced on the micro-geometry on a coarse direction
//! grid and interpolated onto the table, whose direct term the analytic model gives per cell.
//!
//! * The part varies slowly with direction, so it is estimated on a coarse cell-centred grid
//!   ([`coarse_grid`], at most [`COARSE`]) and interpolated quadrilinearly in (theta_i, phi_i,
//!   theta_o, phi_o) (azimuths periodic, polar angles clamped to the outer centres: each axis's
//!   [`clothbake_loader::Axis::coarse_taps_deg`]). What is
//!   interpolated is the residual relative to the analytic direct term I_1 (per channel), which
//!   a cell multiplies by its own I_1: its noise stays a fixed fraction of I_1 toward the
//!   horizon, where I_1 falls faster than between two nodes.
//! * Each node is a pure function of its indices: [`Transport::multiple`] seeded by the node's
//!   direction pair ([`pair_seed`]). Nodes related by a symmetry of
//!   the fabric take the value of their orbit's representative. The nodes a set of rows needs
//!   are computed in parallel before the rows ([`Multiple::prepare`]), each once; so the table
//!   is bit-identical for any thread count, shard split and resume.

mod orders;

pub use orders::{
    bounces_name, max_order, pair_seed, Transport, ALL_BOUNCES, DEFAULT_PATHS, DEFAULT_SEED,
    MAX_ORDER,
};

use crate::directions::{direction, row_cell};
use crate::orbit::{representative, usable_symmetries};
use clothbake_core::symmetry::Symmetry;
use clothbake_core::{
    AnalyticBsdf, AnalyticModel, Bsdf, Fabric, FacetModel, Kernel, Rgb, SecondaryOptions, UnitVec3,
    Variant, VariantError,
};
use clothbake_loader::Grid;
use clothbake_truth::RayTracer;
use rayon::prelude::*;
use serde_json::{json, Value};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// The largest coarse grid: 8 x 16 x 8 x 16 nodes (11 degrees in theta, 22.5 in phi).
pub const COARSE: Grid = Grid::new(8, 16, 8, 16);

/// Primary rays per coarse node and round.
pub const PATHS: usize = 65_536;

/// A node adds rounds of [`PATHS`] fresh paths until the standard error of its multiple-bounce
/// part is at most this fraction of the analytic I_1 there ...
pub const TARGET: f64 = 0.004;

/// ... or it has run this many rounds.
pub const MAX_ROUNDS: u64 = 8;

fn mean(v: [f64; 3]) -> f64 {
    (v[0] + v[1] + v[2]) / 3.0
}

/// Base seed of the node's pair seeds.
pub const SEED: u64 = 1;

/// The coarse grid for a table grid: [`COARSE`], no finer than the table on any axis.
pub fn coarse_grid(table: &Grid) -> Grid {
    Grid::new(
        table.n_theta_i.min(COARSE.n_theta_i),
        table.n_phi_i.min(COARSE.n_phi_i),
        table.n_theta_o.min(COARSE.n_theta_o),
        table.n_phi_o.min(COARSE.n_phi_o),
    )
}

/// How the multiple-bounce part is made, for the table's `options_json` (`info` shows it).
pub fn describe(table: &Grid, bounces: u32) -> Value {
    let g = coarse_grid(table);
    json!({
        "orders": format!("2 to {}", bounces_name(bounces)),
        "max_order": max_order(bounces),
        "method": "path tracer on the micro-geometry (radiometric kernel, next-event estimation, \
                   stratified primary rays, uniform hemisphere continuation, roulette from order 4)",
        "coarse_grid": g,
        "paths_per_node": PATHS,
        "rounds": format!("up to {MAX_ROUNDS}, until the standard error is at most {TARGET} of the analytic I_1"),
        "control_variate": "the analytic second bounce (ch. 5, radiometric kernel, full ranges, default orders), added per cell",
        "seed": SEED,
        "interpolation": "quadrilinear in the residual over the analytic I_1, times the cell's I_1; azimuths periodic, polar angles clamped",
    })
}

/// The multiple-bounce part of a bake: the estimator and the coarse grid's nodes.
pub struct Multiple {
    transport: Transport,
    /// The control variate: the analytic second bounce (thesis ch. 5, radiometric kernel),
    /// evaluated per cell; the nodes hold the path-traced part minus it.
    control: Option<SecondaryOptions>,
    /// The analytic model: the control variate and the I_1 the nodes' noise is held to.
    model: AnalyticModel,
    grid: Grid,
    syms: Vec<Symmetry>,
    /// Per node: the residual over I_1, RGB, and its channel mean's standard error over I_1.
    nodes: Vec<OnceLock<[f64; 4]>>,
}

fn angles(w: UnitVec3) -> (f64, f64) {
    let theta = w.z.clamp(-1.0, 1.0).acos().to_degrees();
    let phi = w.y.atan2(w.x).to_degrees();
    (theta, phi)
}

impl Multiple {
    /// The multiple-bounce part of `fabric` for a table on `table` with `bounces` (> 2).
    pub fn new(fabric: &Fabric, facet: FacetModel, table: &Grid, bounces: u32) -> Multiple {
        let grid = coarse_grid(table);
        let syms = usable_symmetries(fabric, &grid);
        let transport = Transport::new(RayTracer::new(fabric, facet), bounces, PATHS, SEED);
        let control = Some(SecondaryOptions {
            kernel: Kernel::Radiometric,
            ..SecondaryOptions::default()
        });
        Multiple {
            transport,
            control,
            model: AnalyticModel::new(fabric, facet),
            grid,
            syms,
            nodes: (0..grid.len()).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The same with `paths` primary rays per node instead of [`PATHS`] (tests, measurements).
    pub fn with_paths(self, paths: usize) -> Multiple {
        let t = &self.transport;
        Multiple {
            transport: Transport::new(t.tracer().clone(), t.bounces(), paths, t.seed()),
            ..self
        }
    }

    /// The same without the control variate: the nodes hold the whole path-traced part.
    pub fn without_control(self) -> Multiple {
        Multiple {
            control: None,
            ..self
        }
    }

    /// The control variate's options, which the bake's analytic model adds per cell (the
    /// second bounce); `None`: no control variate.
    pub fn control(&self) -> Option<SecondaryOptions> {
        self.control
    }

    /// The analytic second bounce I_2 of the control variate at the pair (zero without one).
    fn control_at(&self, wi: UnitVec3, wo: UnitVec3) -> [f64; 3] {
        match &self.control {
            Some(o) if wi.above_horizon() && wo.above_horizon() => self
                .model
                .intensity_with(wi, wo, Some(o))
                .secondary
                .map_or([0.0; 3], |s| s.total()),
            _ => [0.0; 3],
        }
    }

    /// The coarse grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The node whose value node (ti, pi, to, po) takes: its symmetry orbit's representative.
    fn canonical(&self, ti: u32, pi: u32, to: u32, po: u32) -> usize {
        let (ri, ro) = representative(pi as usize, po as usize, &self.syms, &self.grid);
        self.grid.index(ti, ri as u32, to, ro as u32)
    }

    /// The estimate at a canonical node: the residual intensity of orders 2 to N over the
    /// analytic I_1 there, per channel, and the standard error of its channel mean over the
    /// channel mean of I_1.
    fn compute(&self, node: usize) -> [f64; 4] {
        let g = self.grid;
        let (npo, nto, npi) = (g.n_phi_o as usize, g.n_theta_o as usize, g.n_phi_i as usize);
        let po = node % npo;
        let to = node / npo % nto;
        let pi = node / (npo * nto) % npi;
        let ti = node / (npo * nto * npi);
        let wi = direction(ti as u32, g.n_theta_i, pi as u32, g.n_phi_i);
        let wo = direction(to as u32, g.n_theta_o, po as u32, g.n_phi_o);
        // Rounds of `paths` fresh paths until the standard error is at most TARGET of the
        // analytic I_1 there (or MAX_ROUNDS rounds): the mean of the rounds, equally weighted.
        let i1v = self.model.intensity(wi, wo).direct();
        let i1 = mean(i1v);
        let (mut sum, mut var) = ([0.0; 3], 0.0);
        let mut rounds = 0;
        while rounds < MAX_ROUNDS {
            let p = self.transport.multiple_round(wi, wo, rounds);
            rounds += 1;
            for (s, m) in sum.iter_mut().zip(p.multiple) {
                *s += m;
            }
            var += mean(p.multiple_err).powi(2);
            if var.sqrt() / rounds as f64 <= TARGET * i1 {
                break;
            }
        }
        let r = rounds as f64;
        let c = self.control_at(wi, wo);
        // Relative to the direct term, per channel (zero where there is none).
        let ratio = |x: f64, i: f64| if i > 0.0 { x / i } else { 0.0 };
        let m: [f64; 3] = std::array::from_fn(|k| ratio(sum[k] / r - c[k], i1v[k]));
        [m[0], m[1], m[2], ratio(var.sqrt() / r, i1)]
    }

    fn node(&self, node: usize) -> [f64; 4] {
        *self.nodes[node].get_or_init(|| self.compute(node))
    }

    /// The canonical nodes that cells of the rows (ti, pi) of `rows` interpolate from.
    fn needed(&self, table: &Grid, rows: &[usize]) -> Vec<usize> {
        let mut need = vec![false; self.grid.len()];
        let g = self.grid;
        for &row in rows {
            let (ti, pi) = row_cell(table, row);
            let th = table.theta_i().centre_deg(ti);
            let ph = table.phi_i().centre_deg(pi);
            for (a, _) in g.theta_i().coarse_taps_deg(th) {
                for (b, _) in g.phi_i().coarse_taps_deg(ph) {
                    for to in 0..g.n_theta_o {
                        for po in 0..g.n_phi_o {
                            need[self.canonical(a, b, to, po)] = true;
                        }
                    }
                }
            }
        }
        (0..need.len()).filter(|&k| need[k]).collect()
    }

    /// Computes, in parallel on the current rayon pool, every node the rows need that is not
    /// computed yet; false when `cancel` was raised meanwhile.
    pub fn prepare(&self, table: &Grid, rows: &[usize], cancel: &AtomicBool) -> bool {
        let todo: Vec<usize> = self
            .needed(table, rows)
            .into_iter()
            .filter(|&k| self.nodes[k].get().is_none())
            .collect();
        todo.par_iter().for_each(|&k| {
            if !cancel.load(Ordering::Relaxed) {
                self.node(k);
            }
        });
        !cancel.load(Ordering::Relaxed)
    }

    /// The whole multiple-bounce part of f_r (1/sr) at the pair: the control variate plus the
    /// interpolated residual, and the standard error of its channel mean.
    pub fn part(&self, wi: UnitVec3, wo: UnitVec3) -> ([f64; 3], f64) {
        let (r, e) = self.residual(wi, wo);
        let c = clothbake_core::intensity_to_brdf(self.control_at(wi, wo), wi);
        (std::array::from_fn(|k| c[k] + r[k]), e)
    }

    /// The interpolated residual of f_r (1/sr): what the bake adds to the analytic model with
    /// the control variate's second bounce ([`Multiple::control`]).
    pub fn f(&self, wi: UnitVec3, wo: UnitVec3) -> [f64; 3] {
        self.residual(wi, wo).0
    }

    /// [`Multiple::f`] and the standard error of its channel mean (the nodes' errors combined
    /// with the interpolation weights, nodes independent).
    pub fn residual(&self, wi: UnitVec3, wo: UnitVec3) -> ([f64; 3], f64) {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return ([0.0; 3], 0.0);
        }
        let mut var = 0.0;
        let g = self.grid;
        let ((ti, pi), (to, po)) = (angles(wi), angles(wo));
        let mut v = [0.0; 3];
        for (a, wa) in g.theta_i().coarse_taps_deg(ti) {
            for (b, wb) in g.phi_i().coarse_taps_deg(pi) {
                for (c, wc) in g.theta_o().coarse_taps_deg(to) {
                    for (d, wd) in g.phi_o().coarse_taps_deg(po) {
                        let w = wa * wb * wc * wd;
                        if w == 0.0 {
                            continue;
                        }
                        let x = self.node(self.canonical(a, b, c, d));
                        for k in 0..3 {
                            v[k] += w * x[k];
                        }
                        var += (w * x[3]).powi(2);
                    }
                }
            }
        }
        // Back to f_r: times the cell's own I_1, over pi cos(theta_i).
        let i1 = self.model.intensity(wi, wo).direct();
        let to_f = std::f64::consts::PI * wi.z;
        (
            std::array::from_fn(|k| v[k] * i1[k] / to_f),
            var.sqrt() * mean(i1) / to_f,
        )
    }
}

/// The analytic model with every bounce (`--bounces N > 2`, `all`) as a [`Bsdf`]: the analytic
/// direct term and second bounce (the control variate) plus the interpolated path-traced rest
/// of the orders >= 2 ([`Multiple::f`]), the sum a full-transport bake tabulates. Nodes are
/// computed on first use (about 4 minutes of CPU for all of them), each once.
pub struct FullTransport {
    model: AnalyticBsdf,
    multiple: Arc<Multiple>,
}

impl FullTransport {
    /// Full transport of `fabric` with `bounces` (> 2) on the coarse grid [`COARSE`]; refused
    /// where the variant does not take the period.
    pub fn new(
        fabric: &Fabric,
        facet: FacetModel,
        variant: Variant,
        bounces: u32,
    ) -> Result<Self, VariantError> {
        FullTransport::with(
            fabric,
            facet,
            variant,
            Arc::new(Multiple::new(fabric, facet, &COARSE, bounces)),
        )
    }

    /// Full transport with the multiple-bounce part `multiple` (shared with a bake).
    pub fn with(
        fabric: &Fabric,
        facet: FacetModel,
        variant: Variant,
        multiple: Arc<Multiple>,
    ) -> Result<Self, VariantError> {
        let model = AnalyticBsdf::new(
            AnalyticModel::with_variant(fabric, facet, variant)?,
            multiple.control(),
        );
        Ok(FullTransport { model, multiple })
    }
}

impl Bsdf for FullTransport {
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        let (d, r) = (self.model.f(wi, wo), self.multiple.f(wi, wo));
        std::array::from_fn(|k| d[k] + r[k])
    }
}
