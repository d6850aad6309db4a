//! The lookup of a two-faced table ([`TwoFacedBrdf`]): reflection and transmission over the
//! whole sphere, and the openness, the light that passes straight through the gaps
//! (docs/science/transmission.md, docs/reference/table-format.md "Two-faced tables").
//!
//! A two-faced table is stored, baked, sharded and compared on one grid whose polar axes cover
//! the sphere ([`crate::Faces::Two`]). The lookup cuts it into four **blocks**, each a
//! one-faced table on the grid of one side ([`Grid::side`]) in that side's own polar angles
//! (from its normal, the azimuth kept: a direction below the cloth is mirrored in z):
//!
//! | block | light (`wi`) | eye (`wo`) | what |
//! |---|---|---|---|
//! | 0 | above | above | front reflection |
//! | 1 | above | below | transmission from the front to the back |
//! | 2 | below | below | back reflection |
//! | 3 | below | above | transmission from the back to the front |
//!
//! Each block is an ordinary [`Brdf`] (the same nodes, kernels, pole padding and horizon rule),
//! so a block's lookup is a one-faced table's to the bit.
//!
//! * **Sampling** picks the block that ends at `wo`'s side: reflection with probability
//!   `A_R / (A_R + A_T)`, the two blocks' albedos at the outgoing cell holding `wo` (summed over
//!   the incident cells of f_r times each cell's integral of |cos theta_i|, mean of RGB; even
//!   odds where both are 0), then samples the block's incident hemisphere by its own
//!   importance sampling. The density is the choice's probability times the block's.
//! * **Openness** (the straight-through part, a delta: light from `wi` leaves along `-wi`) is a
//!   separate term, not sampled: [`TwoFacedBrdf::openness`] interpolates the table's per
//!   incident cell values bilinearly between the centres of `wi`'s side, held at the outer
//!   centres, as a renderer adds it as a lobe of its own (the Mitsuba plugin: a null
//!   interaction of probability O).

use std::path::Path;

use crate::angles::{theta_phi, HORIZON_COS};
use crate::bsdf::f32s;
use crate::error::TableError;
use crate::grid::{Faces, Grid};
use crate::lookup::{Brdf, Options, Sample};
use crate::stored::{Samples, StoredTable};
use crate::table::{Metadata, Table};
use clothbake_bsdf::{Bsdf, BsdfSample, Rgb, UnitVec3};
use half::f16;

/// The sides of the light and the eye of each block (`true`: above the cloth).
const SIDES: [(bool, bool); 4] = [(true, true), (true, false), (false, false), (false, true)];

/// The block of a pair by the sides of `wi` and `wo` (`true`: above).
#[inline(always)]
fn block_of(up_i: bool, up_o: bool) -> usize {
    match (up_i, up_o) {
        (true, true) => 0,
        (true, false) => 1,
        (false, false) => 2,
        (false, true) => 3,
    }
}

/// A direction in its side's frame: z made positive (mirrored below the cloth).
#[inline(always)]
fn side_frame(w: [f32; 3]) -> [f32; 3] {
    [w[0], w[1], w[2].abs()]
}

/// Whether a direction lies off the cloth's plane on either side (not NaN).
#[inline(always)]
fn sided(w: [f32; 3]) -> bool {
    w[2].abs() > HORIZON_COS && !w.iter().any(|x| x.is_nan())
}

/// A two-faced table ready for lookups over the sphere, importance sampling and the openness
/// (module docs).
#[derive(Clone, Debug)]
pub struct TwoFacedBrdf {
    meta: Metadata,
    blocks: [Brdf; 4],
    /// The openness at each incident cell centre of the sphere grid (`ti * n_phi_i + pi`).
    openness: Vec<f32>,
    /// Per side of the eye (0 above, 1 below) and outgoing cell of a side (`to * n_phi_o +
    /// po`): the probability that sampling picks the reflection block.
    reflect_odds: [Vec<f32>; 2],
    reciprocal: bool,
}

impl TwoFacedBrdf {
    /// Opens a two-faced table file (either format); a one-faced table is refused.
    pub fn open(path: &Path, options: Options) -> Result<TwoFacedBrdf, TableError> {
        // The readers check the table (StoredTable::new's rules).
        let stored = crate::read::read_table_stored(path)?;
        if stored.meta.grid.faces != Faces::Two {
            return Err(TableError::WrongKind {
                path: path.to_path_buf(),
                found: "one-faced table (reflection over the floor)".into(),
                expected: "two-faced table".into(),
                fix: "open it as a one-faced table (clothbake_loader::Brdf::open)",
            });
        }
        TwoFacedBrdf::from_checked(stored, options).map_err(|e| e.in_file(path))
    }

    /// A lookup of an `f32` two-faced table in memory.
    pub fn from_table(table: Table, options: Options) -> Result<TwoFacedBrdf, TableError> {
        TwoFacedBrdf::from_stored(StoredTable::from(table), options)
    }

    /// A lookup of a two-faced table in memory, after checking it ([`StoredTable::new`]).
    /// [`Options::reciprocal`] symmetrises over the sphere, `0.5 (f(wi, wo) + f(wo, wi))`
    /// (which pairs a transmission block with the other); `point_level` has no use here.
    pub fn from_stored(table: StoredTable, options: Options) -> Result<TwoFacedBrdf, TableError> {
        TwoFacedBrdf::from_checked(StoredTable::new(table.meta, table.samples)?, options)
    }

    /// [`TwoFacedBrdf::from_stored`] of a table [`StoredTable::new`]'s rules have already
    /// passed (a reader's): its values and its blocks' are not checked again.
    pub(crate) fn from_checked(
        table: StoredTable,
        options: Options,
    ) -> Result<TwoFacedBrdf, TableError> {
        let StoredTable { meta, samples } = table;
        let g = meta.grid;
        if g.faces != Faces::Two {
            return Err(TableError::InvalidTable {
                reason: format!("grid {g} is one-faced; open it with Brdf"),
            });
        }
        let side = g.side();
        let openness = meta
            .openness
            .clone()
            .expect("a valid two-faced table has its openness");
        let block_meta = Metadata {
            format_version: crate::table::version_for(side.faces),
            grid: side,
            openness: None,
            ..meta.clone()
        };
        let block_options = Options {
            reciprocal: false,
            point_level: false,
            ..options
        };
        let albedos: [Vec<f32>; 4] = std::array::from_fn(|b| block_albedos(&g, &samples, b));
        let reflect_odds = [0, 2].map(|r| {
            // The eye above: reflection block 0 against transmission 3; below: 2 against 1.
            let t = if r == 0 { 3 } else { 1 };
            albedos[r]
                .iter()
                .zip(&albedos[t])
                .map(|(&a, &b)| if a + b > 0.0 { a / (a + b) } else { 0.5 })
                .collect()
        });
        let mut blocks = Vec::with_capacity(4);
        for b in 0..4 {
            blocks.push(Brdf::from_checked(
                StoredTable {
                    meta: block_meta.clone(),
                    samples: block_samples(&g, &samples, b),
                },
                block_options,
            )?);
        }
        let blocks: [Brdf; 4] = blocks.try_into().expect("four blocks");
        Ok(TwoFacedBrdf {
            meta,
            blocks,
            openness,
            reflect_odds,
            reciprocal: options.reciprocal,
        })
    }

    /// What the table holds (its grid over the sphere).
    pub fn meta(&self) -> &Metadata {
        &self.meta
    }

    /// The table's grid, over the sphere.
    pub fn grid(&self) -> &Grid {
        &self.meta.grid
    }

    /// Block `b` (module docs) as a one-faced lookup in its sides' frames.
    pub fn block(&self, b: usize) -> &Brdf {
        &self.blocks[b]
    }

    /// Bytes held by the four blocks (values and sampling) and the openness.
    pub fn memory_bytes(&self) -> usize {
        self.blocks.iter().map(Brdf::memory_bytes).sum::<usize>() + 4 * self.openness.len()
    }

    /// f_r (1/sr, RGB) for light from `wi` seen from `wo`, anywhere on the sphere: the block of
    /// their sides, looked up in its frame; 0 within 1e-9 of the cloth's plane or for NaN.
    pub fn eval(&self, wi: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
        let f = self.eval_raw(wi, wo);
        if !self.reciprocal {
            return f;
        }
        let r = self.eval_raw(wo, wi);
        [0, 1, 2].map(|k| 0.5 * (f[k] + r[k]))
    }

    fn eval_raw(&self, wi: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
        if !(sided(wi) && sided(wo)) {
            return [0.0; 3];
        }
        let b = block_of(wi[2] > 0.0, wo[2] > 0.0);
        self.blocks[b].eval(side_frame(wi), side_frame(wo))
    }

    /// The openness along `wi` (either side): the share of the light from `wi` that passes
    /// straight through the gaps and leaves along `-wi`; bilinear between the incident cell
    /// centres of `wi`'s side (polar angle from that side's normal), held at the outer ones;
    /// 0 within 1e-9 of the plane or for NaN.
    pub fn openness(&self, wi: [f32; 3]) -> f32 {
        if !sided(wi) {
            return 0.0;
        }
        let g = self.grid();
        let (theta, phi) = theta_phi(side_frame(wi));
        let (theta, phi) = (theta.to_degrees(), phi.to_degrees());
        let n = g.n_theta_i as usize;
        let up = wi[2] > 0.0;
        let rows = g.side().theta_i().clamped_taps_deg(theta);
        let cols = g.phi_i().clamped_taps_deg(phi);
        let mut o = 0.0;
        for (k, wk) in rows {
            let row = if up { k } else { n - 1 - k };
            for (m, wm) in cols {
                o += wk * wm * self.openness[row * g.n_phi_i as usize + m];
            }
        }
        o
    }

    /// The probability that sampling for `wo` picks the reflection block (module docs).
    fn reflect_odds(&self, wo: [f32; 3]) -> f32 {
        let side = self.grid().side();
        let (theta, phi) = theta_phi(side_frame(wo));
        let to = side.theta_o().cell_of(theta);
        let po = side.phi_o().cell_of(phi);
        self.reflect_odds[usize::from(wo[2] < 0.0)][to * side.n_phi_o as usize + po]
    }

    /// Samples an incident direction over the sphere for `wo` with `u1, u2` uniform in [0, 1)
    /// (module docs); the weight is `eval(wi, wo) |cos theta_i| / pdf`. The openness is not
    /// sampled. A zero pdf means no sample (`wo` in the plane, or sampling not built).
    pub fn sample(&self, wo: [f32; 3], u1: f32, u2: f32) -> Sample {
        let none = Sample {
            wi: [0.0, 0.0, 1.0],
            weight: [0.0; 3],
            pdf: 0.0,
        };
        if !sided(wo) || !self.blocks[0].has_sampling() {
            return none;
        }
        let up_o = wo[2] > 0.0;
        let p = self.reflect_odds(wo);
        let (reflect, u) = if u1 < p {
            (true, u1 / p)
        } else {
            (false, ((u1 - p) / (1.0 - p)).min(1.0 - f32::EPSILON))
        };
        let up_i = if reflect { up_o } else { !up_o };
        let b = block_of(up_i, up_o);
        let s = self.blocks[b].sample(side_frame(wo), u.min(1.0 - f32::EPSILON), u2);
        if s.pdf <= 0.0 {
            return none;
        }
        let wi = if up_i {
            s.wi
        } else {
            [s.wi[0], s.wi[1], -s.wi[2]]
        };
        let pdf = self.pdf(wi, wo);
        if pdf.is_nan() || pdf <= 0.0 {
            return Sample { wi, ..none };
        }
        let f = self.eval(wi, wo);
        let k = wi[2].abs() / pdf;
        Sample {
            wi,
            weight: f.map(|x| x * k),
            pdf,
        }
    }

    /// The density of [`TwoFacedBrdf::sample`] drawing `wi` for `wo`, per unit solid angle.
    pub fn pdf(&self, wi: [f32; 3], wo: [f32; 3]) -> f32 {
        if !(sided(wo) && sided(wi) && self.blocks[0].has_sampling()) {
            return 0.0;
        }
        let (up_i, up_o) = (wi[2] > 0.0, wo[2] > 0.0);
        let p = self.reflect_odds(wo);
        let choice = if up_i == up_o { p } else { 1.0 - p };
        choice * self.blocks[block_of(up_i, up_o)].pdf(side_frame(wi), side_frame(wo))
    }
}

/// The row of the sphere grid's polar axis holding row `k` of a side's (`up`: above).
#[inline(always)]
fn sphere_row(n: u32, k: u32, up: bool) -> u32 {
    if up {
        k
    } else {
        n - 1 - k
    }
}

/// The sphere grid's cell of block `b`'s cell (`ti, pi, to, po` on the side grid).
fn sphere_cell(g: &Grid, b: usize, ti: u32, pi: u32, to: u32, po: u32) -> usize {
    let (up_i, up_o) = SIDES[b];
    g.index(
        sphere_row(g.n_theta_i, ti, up_i),
        pi,
        sphere_row(g.n_theta_o, to, up_o),
        po,
    )
}

/// The start of each run of `3 n_phi_o` values block `b` takes from the sphere table, in the
/// block's cell order (ti, pi, to): a run is one outgoing ring's azimuths, contiguous in both.
fn block_runs(g: &Grid, b: usize) -> impl Iterator<Item = usize> + '_ {
    let side = g.side();
    (0..side.n_theta_i).flat_map(move |ti| {
        (0..side.n_phi_i).flat_map(move |pi| {
            (0..side.n_theta_o).map(move |to| 3 * sphere_cell(g, b, ti, pi, to, 0))
        })
    })
}

/// Block `b`'s values on the side grid, in its cell order, at the samples' precision.
fn block_samples(g: &Grid, samples: &Samples, b: usize) -> Samples {
    let run = 3 * g.n_phi_o as usize;
    let len = 3 * g.side().len();
    match samples {
        Samples::F16(v) => {
            let mut out: Vec<f16> = Vec::with_capacity(len);
            for at in block_runs(g, b) {
                out.extend_from_slice(&v[at..at + run]);
            }
            Samples::F16(out)
        }
        Samples::F32(v) => {
            let mut out: Vec<f32> = Vec::with_capacity(len);
            for at in block_runs(g, b) {
                out.extend_from_slice(&v[at..at + run]);
            }
            Samples::F32(out)
        }
    }
}

/// Block `b`'s albedo at each outgoing cell of its side (`to * n_phi_o + po`): the sum over
/// its incident cells of f_r (mean of RGB) times the cell's integral of cos theta over its
/// solid angle, in the block's frame.
fn block_albedos(g: &Grid, samples: &Samples, b: usize) -> Vec<f32> {
    let side = g.side();
    let (ti_axis, pi_axis) = (side.theta_i(), side.phi_i());
    let (nto, npo) = (side.n_theta_o as usize, side.n_phi_o as usize);
    let mut out = vec![0f64; nto * npo];
    let per_ring = side.n_phi_i as usize * nto;
    for (k, at) in block_runs(g, b).enumerate() {
        let ti = (k / per_ring) as u32;
        let to = k % nto;
        let (s0, s1) = (ti_axis.edge_rad(ti).sin(), ti_axis.edge_rad(ti + 1).sin());
        // The integral of cos theta over the cell: (sin^2 hi - sin^2 lo) / 2 times its azimuth.
        let weight = 0.5 * (s1 * s1 - s0 * s0) * pi_axis.width_rad();
        for po in 0..npo {
            let i = at + 3 * po;
            let mean = (samples.get(i) + samples.get(i + 1) + samples.get(i + 2)) / 3.0;
            out[to * npo + po] += weight * f64::from(mean);
        }
    }
    out.into_iter().map(|a| a as f32).collect()
}

impl Bsdf for TwoFacedBrdf {
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        self.eval(f32s(wi), f32s(wo)).map(f64::from)
    }

    fn openness(&self, wi: UnitVec3) -> f64 {
        f64::from(TwoFacedBrdf::openness(self, f32s(wi)))
    }

    fn sample(&self, wo: UnitVec3, u: [f64; 2]) -> Option<BsdfSample> {
        if !self.blocks[0].has_sampling() {
            return clothbake_bsdf::two_sided_sample(self, wo, u);
        }
        let s = TwoFacedBrdf::sample(self, f32s(wo), u[0] as f32, u[1] as f32);
        crate::bsdf::bsdf_sample(self, s, wo)
    }

    fn pdf(&self, wi: UnitVec3, wo: UnitVec3) -> f64 {
        if !self.blocks[0].has_sampling() {
            return clothbake_bsdf::two_sided_pdf(wi, wo);
        }
        f64::from(TwoFacedBrdf::pdf(self, f32s(wo), f32s(wi)))
    }
}
