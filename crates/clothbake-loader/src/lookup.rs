//! Render-time lookup: [`Brdf`], quadrilinear interpolation of a baked table.
//!
//! Directions are local-frame vectors (z up, +X weft, +Y warp), `wi` toward the light and `wo`
//! toward the eye; values are `f_r` in 1/sr, RGB. The rules (also in `docs/loader.md`):
//!
//! * **Azimuth** (either direction): linear between the two nearest cell centres, periodic:
//!   below the first centre (`phi < 180 / n_phi` degrees) and above the last one, cells
//!   `n_phi - 1` and 0 are blended.
//! * **Polar angle**: linear between the two nearest cell centres. Below the first centre
//!   (`theta < 45 / n_theta` degrees) the blend is between the first ring of cells and a
//!   *pole* node at `theta = 0` whose value is the mean of that ring over all azimuths (so the
//!   lookup is continuous at the pole and does not depend on the azimuth there). Above the last
//!   centre (`theta > 90 - 45 / n_theta`) the last ring's value is held (constant
//!   extrapolation to the horizon).
//! * **Horizon**: a direction with `cos theta <= 1e-9` (as in the core), or any NaN, gives 0.
//! * The four axes blend independently: 2 x 2 x 2 x 2 = 16 nodes, weights the products of the
//!   1-D linear weights.
//!
//! The pole nodes are precomputed at load time: the values are stored in a padded copy with
//! one extra polar row (the pole) on each polar axis, so every lookup is the same branch-free
//! gather of 16 nodes.

use std::fmt;
use std::path::Path;

use crate::angles::{direction, theta_phi};
use crate::format::{Grid, Metadata, Precision, Table, TableError};
use crate::sampling::Sampler;
use crate::stored::{f16_to_f32, Samples, StoredTable};

/// Directions with `cos theta` at or below this are on or below the horizon: zero.
pub const HORIZON_COS: f32 = 1e-9;

/// True when a unit vector is above the horizon (`z > 1e-9`); false for NaN.
#[inline(always)]
pub fn above_horizon(w: [f32; 3]) -> bool {
    w[2] > HORIZON_COS
}

/// How values are held in memory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Memory {
    /// As stored: half floats for half-float EXR tables (half the memory), f32 otherwise.
    #[default]
    AsStored,
    /// Always f32 (values widened exactly).
    F32,
}

/// Options of a [`Brdf`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// Precision in memory.
    pub memory: Memory,
    /// Symmetrise every lookup: `0.5 (f(wi, wo) + f(wo, wi))` (Helmholtz reciprocity, for
    /// tables of physically based facet models). Costs two lookups.
    pub reciprocal: bool,
    /// Build the importance-sampling CDFs at load time ([`Brdf::sample`], [`Brdf::pdf`]);
    /// 4 bytes per table cell. Without them `sample` and `pdf` give a zero pdf.
    pub sampling: bool,
}

impl Default for Options {
    /// Values as stored, no symmetrisation, sampling on.
    fn default() -> Self {
        Options {
            memory: Memory::AsStored,
            reciprocal: false,
            sampling: true,
        }
    }
}

/// One importance sample of the incident direction for a given `wo`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// The sampled incident direction (unit, local frame, toward the light).
    pub wi: [f32; 3],
    /// `f_r(wi, wo) cos(theta_i) / pdf`, RGB: the estimator's weight. 0 when `pdf` is 0.
    pub weight: [f32; 3],
    /// The density of `wi`, per unit solid angle; 0 means no sample (`wo` below the horizon,
    /// or sampling not built).
    pub pdf: f32,
}

/// Slices of a batched lookup that do not have the same length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LengthMismatch {
    /// Length of the incident directions.
    pub wi: usize,
    /// Length of the outgoing directions.
    pub wo: usize,
    /// Length of the output.
    pub out: usize,
}

impl fmt::Display for LengthMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "batched lookup: wi has {} directions, wo {} and out {}; give all three the same length",
            self.wi, self.wo, self.out
        )
    }
}

impl std::error::Error for LengthMismatch {}

/// Values of the padded table, at their precision (`u16` holds half-float bits).
#[derive(Clone, Debug)]
enum Store {
    F16(Vec<u16>),
    F32(Vec<f32>),
}

/// A value type the gather can widen to f32.
trait Value: Copy {
    fn widen(self) -> f32;
}

impl Value for u16 {
    #[inline(always)]
    fn widen(self) -> f32 {
        f16_to_f32(self)
    }
}

impl Value for f32 {
    #[inline(always)]
    fn widen(self) -> f32 {
        self
    }
}

/// Where one axis of a lookup falls: two node indices and the weight of the second.
#[derive(Clone, Copy, Debug)]
struct Span {
    lo: usize,
    hi: usize,
    t: f32,
}

/// A polar axis of `n` cells, at `theta` radians: padded rows `lo` and `lo + 1` (row 0 is the
/// pole, row `k + 1` the centre of cell `k`); see the module documentation.
#[inline(always)]
fn polar_span(theta: f32, n: u32, cells_per_rad: f32) -> Span {
    let c = theta * cells_per_rad; // cell k's centre at k + 0.5
    let s = if c < 0.5 { 2.0 * c } else { c + 0.5 };
    let s = s.max(0.0).min(n as f32); // NaN -> 0; beyond the last centre: hold it
    let lo = (s as u32).min(n - 1);
    Span {
        lo: lo as usize,
        hi: lo as usize + 1,
        t: s - lo as f32,
    }
}

/// An azimuth axis of `n` cells, at `phi` radians in `[-2 pi, 4 pi)` (the vector path gives
/// `[-pi, pi]`; [`Brdf::eval_deg`] wraps first): the two cells whose centres bracket `phi`,
/// wrapping from cell `n - 1` to cell 0. No integer division: two conditional wraps.
#[inline(always)]
fn azimuth_span(phi: f32, n: u32, cells_per_rad: f32) -> Span {
    let c = phi * cells_per_rad - 0.5;
    // floor(c) without the `floorf` library call of baseline x86-64; NaN -> 0.
    let mut lo = c as i32;
    if (lo as f32) > c {
        lo -= 1;
    }
    let t = c - lo as f32;
    let t = if t >= 0.0 { t.min(1.0) } else { 0.0 }; // NaN -> 0
    let n = n as i32;
    if lo < 0 {
        lo += n;
    }
    if lo < 0 {
        lo += n;
    }
    if lo >= n {
        lo -= n;
    }
    if lo >= n {
        lo -= n;
    }
    let lo = lo.clamp(0, n - 1) as usize;
    let hi = if lo + 1 == n as usize { 0 } else { lo + 1 };
    Span { lo, hi, t }
}

/// A baked table ready for render-time lookups and importance sampling.
#[derive(Clone, Debug)]
pub struct Brdf {
    meta: Metadata,
    store: Store,
    /// Padded strides (in values) of theta_i, phi_i, theta_o rows; phi_o's is 3.
    strides: [usize; 3],
    /// Cells per radian of the polar (`90` degrees) and azimuth (`360` degrees) axes: i, o.
    scale: [f32; 4],
    reciprocal: bool,
    sampler: Option<Sampler>,
}

impl Brdf {
    /// Loads a table file (either format, see [`crate::read_table_stored`]).
    pub fn open(path: &Path, options: Options) -> Result<Brdf, TableError> {
        let stored = crate::format::read_table_stored(path)?;
        Brdf::from_stored(stored, options).map_err(|e| match e {
            TableError::InvalidTable { reason } => TableError::Corrupted {
                path: path.to_path_buf(),
                reason,
            },
            other => other,
        })
    }

    /// A lookup of an `f32` table in memory.
    pub fn from_table(table: Table, options: Options) -> Result<Brdf, TableError> {
        Brdf::from_stored(StoredTable::from(table), options)
    }

    /// A lookup of a table in memory, after checking it (see [`StoredTable::new`]).
    pub fn from_stored(table: StoredTable, options: Options) -> Result<Brdf, TableError> {
        let StoredTable { meta, samples } = StoredTable::new(table.meta, table.samples)?;
        let g = meta.grid;
        let value = |ti: u32, pi: u32, to: u32, po: u32| -> [f32; 3] {
            let c = 3 * g.index(ti, pi, to, po);
            [samples.get(c), samples.get(c + 1), samples.get(c + 2)]
        };
        let sampler = options.sampling.then(|| Sampler::new(&g, &value));
        let padded = pad(&g, &value);
        let store = match (&samples, options.memory) {
            (Samples::F16(_), Memory::AsStored) => Store::F16(
                padded
                    .iter()
                    .map(|&v| half::f16::from_f32(v).to_bits())
                    .collect(),
            ),
            _ => Store::F32(padded),
        };
        drop(samples);
        let (npi, nto, npo) = (g.n_phi_i as usize, g.n_theta_o as usize, g.n_phi_o as usize);
        let s_to = 3 * npo;
        let s_pi = s_to * (nto + 1);
        let s_ti = s_pi * npi;
        let polar = |n: u32| n as f32 / std::f32::consts::FRAC_PI_2;
        let azimuth = |n: u32| n as f32 / std::f32::consts::TAU;
        Ok(Brdf {
            meta,
            store,
            strides: [s_ti, s_pi, s_to],
            scale: [
                polar(g.n_theta_i),
                azimuth(g.n_phi_i),
                polar(g.n_theta_o),
                azimuth(g.n_phi_o),
            ],
            reciprocal: options.reciprocal,
            sampler,
        })
    }

    /// The table's metadata.
    pub fn meta(&self) -> &Metadata {
        &self.meta
    }

    /// The table's grid.
    pub fn grid(&self) -> &Grid {
        &self.meta.grid
    }

    /// The precision the values are held in.
    pub fn precision(&self) -> Precision {
        match self.store {
            Store::F16(_) => Precision::F16,
            Store::F32(_) => Precision::F32,
        }
    }

    /// Bytes held by the values and the sampling CDFs.
    pub fn memory_bytes(&self) -> usize {
        let values = match &self.store {
            Store::F16(v) => 2 * v.len(),
            Store::F32(v) => 4 * v.len(),
        };
        values + self.sampler.as_ref().map_or(0, Sampler::memory_bytes)
    }

    /// True when lookups are symmetrised (see [`Options::reciprocal`]).
    pub fn is_reciprocal(&self) -> bool {
        self.reciprocal
    }

    /// `f_r(wi, wo)` in 1/sr, RGB, for local-frame unit vectors; 0 when either is on or below
    /// the horizon (`z <= 1e-9`) or not a number. Symmetrised with [`Options::reciprocal`].
    #[inline]
    pub fn eval(&self, wi: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
        match &self.store {
            Store::F16(v) => self.eval_in(v, wi, wo),
            Store::F32(v) => self.eval_in(v, wi, wo),
        }
    }

    /// `f_r` at polar angles and azimuths in degrees (theta from +Z, phi from +X toward +Y),
    /// as the tables use; 0 unless `0 <= theta < 90` for both directions.
    pub fn eval_deg(&self, theta_i: f32, phi_i: f32, theta_o: f32, phi_o: f32) -> [f32; 3] {
        let ok = |t: f32| (0.0..90.0).contains(&t) && t.to_radians().cos() > HORIZON_COS;
        if !(ok(theta_i) && ok(theta_o)) {
            return [0.0; 3];
        }
        let r = f32::to_radians;
        let wrap = |phi: f32| {
            if phi.is_finite() {
                phi.rem_euclid(360.0)
            } else {
                0.0
            }
        };
        let (ti, pi, to, po) = (r(theta_i), r(wrap(phi_i)), r(theta_o), r(wrap(phi_o)));
        match &self.store {
            Store::F16(v) => self.blend_reciprocal(v, ti, pi, to, po),
            Store::F32(v) => self.blend_reciprocal(v, ti, pi, to, po),
        }
    }

    /// [`Brdf::eval`] of every pair `(wi[k], wo[k])` into `out[k]`; the three slices must have
    /// the same length.
    pub fn eval_batch(
        &self,
        wi: &[[f32; 3]],
        wo: &[[f32; 3]],
        out: &mut [[f32; 3]],
    ) -> Result<(), LengthMismatch> {
        if wi.len() != wo.len() || wi.len() != out.len() {
            return Err(LengthMismatch {
                wi: wi.len(),
                wo: wo.len(),
                out: out.len(),
            });
        }
        match &self.store {
            Store::F16(v) => self.batch_in(v, wi, wo, out),
            Store::F32(v) => self.batch_in(v, wi, wo, out),
        }
        Ok(())
    }

    /// Samples an incident direction for `wo` with `u1, u2` uniform in [0, 1): the density is
    /// piecewise constant per unit solid angle over the table's incident cells, proportional
    /// to `f_r cos theta_i` at the cell centres of the outgoing cell holding `wo` (see
    /// `docs/loader.md`). The weight is `eval(wi, wo) cos theta_i / pdf`.
    pub fn sample(&self, wo: [f32; 3], u1: f32, u2: f32) -> Sample {
        let none = Sample {
            wi: [0.0, 0.0, 1.0],
            weight: [0.0; 3],
            pdf: 0.0,
        };
        let Some(sampler) = &self.sampler else {
            return none;
        };
        if !above_horizon(wo) {
            return none;
        }
        let (theta_o, phi_o) = theta_phi(wo);
        let (theta, phi) = sampler.sample(theta_o, phi_o, u1, u2);
        let wi = direction(theta, phi);
        let pdf = self.pdf(wo, wi);
        if pdf.is_nan() || pdf <= 0.0 {
            return Sample { wi, ..none };
        }
        let f = self.eval(wi, wo);
        let k = wi[2] / pdf;
        Sample {
            wi,
            weight: [f[0] * k, f[1] * k, f[2] * k],
            pdf,
        }
    }

    /// The density of [`Brdf::sample`] drawing `wi` for `wo`, per unit solid angle; 0 when
    /// either is below the horizon or sampling was not built.
    pub fn pdf(&self, wo: [f32; 3], wi: [f32; 3]) -> f32 {
        let Some(sampler) = &self.sampler else {
            return 0.0;
        };
        if !(above_horizon(wo) && above_horizon(wi)) {
            return 0.0;
        }
        let (theta_o, phi_o) = theta_phi(wo);
        let (theta_i, phi_i) = theta_phi(wi);
        sampler.pdf(theta_o, phi_o, theta_i, phi_i)
    }

    #[inline(always)]
    fn eval_in<V: Value>(&self, v: &[V], wi: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
        if !(above_horizon(wi) && above_horizon(wo)) {
            return [0.0; 3];
        }
        let (ti, pi) = theta_phi(wi);
        let (to, po) = theta_phi(wo);
        self.blend_reciprocal(v, ti, pi, to, po)
    }

    fn batch_in<V: Value>(&self, v: &[V], wi: &[[f32; 3]], wo: &[[f32; 3]], out: &mut [[f32; 3]]) {
        for ((a, b), o) in wi.iter().zip(wo).zip(out.iter_mut()) {
            *o = self.eval_in(v, *a, *b);
        }
    }

    #[inline(always)]
    fn blend_reciprocal<V: Value>(&self, v: &[V], ti: f32, pi: f32, to: f32, po: f32) -> [f32; 3] {
        let f = self.blend(v, ti, pi, to, po);
        if !self.reciprocal {
            return f;
        }
        let r = self.blend(v, to, po, ti, pi);
        [
            0.5 * (f[0] + r[0]),
            0.5 * (f[1] + r[1]),
            0.5 * (f[2] + r[2]),
        ]
    }

    /// The quadrilinear blend of the 16 nodes around (theta_i, phi_i, theta_o, phi_o), radians.
    #[inline(always)]
    fn blend<V: Value>(&self, v: &[V], ti: f32, pi: f32, to: f32, po: f32) -> [f32; 3] {
        let g = &self.meta.grid;
        let [s_ti, s_pi, s_to] = self.strides;
        let a = polar_span(ti, g.n_theta_i, self.scale[0]);
        let b = azimuth_span(pi, g.n_phi_i, self.scale[1]);
        let c = polar_span(to, g.n_theta_o, self.scale[2]);
        let d = azimuth_span(po, g.n_phi_o, self.scale[3]);
        let incident = [
            (a.lo * s_ti + b.lo * s_pi, (1.0 - a.t) * (1.0 - b.t)),
            (a.lo * s_ti + b.hi * s_pi, (1.0 - a.t) * b.t),
            (a.hi * s_ti + b.lo * s_pi, a.t * (1.0 - b.t)),
            (a.hi * s_ti + b.hi * s_pi, a.t * b.t),
        ];
        let outgoing = [
            (c.lo * s_to + 3 * d.lo, (1.0 - c.t) * (1.0 - d.t)),
            (c.lo * s_to + 3 * d.hi, (1.0 - c.t) * d.t),
            (c.hi * s_to + 3 * d.lo, c.t * (1.0 - d.t)),
            (c.hi * s_to + 3 * d.hi, c.t * d.t),
        ];
        let mut acc = [0f32; 3];
        for (oi, wi) in incident {
            let mut inner = [0f32; 3];
            for (oo, wo) in outgoing {
                let k = oi + oo;
                let node = &v[k..k + 3];
                inner[0] += node[0].widen() * wo;
                inner[1] += node[1].widen() * wo;
                inner[2] += node[2].widen() * wo;
            }
            acc[0] += inner[0] * wi;
            acc[1] += inner[1] * wi;
            acc[2] += inner[2] * wi;
        }
        acc
    }
}

/// The padded values: rows `0..=n_theta_i` x `n_phi_i` x rows `0..=n_theta_o` x `n_phi_o`, RGB,
/// where polar row 0 is the pole node (the mean over the azimuths of the first ring) and row
/// `k + 1` is cell `k`.
fn pad(g: &Grid, value: &dyn Fn(u32, u32, u32, u32) -> [f32; 3]) -> Vec<f32> {
    let (nti, npi, nto, npo) = (g.n_theta_i, g.n_phi_i, g.n_theta_o, g.n_phi_o);
    // Mean of `value` over the listed azimuth pairs, in f64, in a fixed order.
    let mean = |pairs: &mut dyn Iterator<Item = [f32; 3]>| -> [f32; 3] {
        let (mut sum, mut n) = ([0f64; 3], 0f64);
        for x in pairs {
            for k in 0..3 {
                sum[k] += f64::from(x[k]);
            }
            n += 1.0;
        }
        sum.map(|s| (s / n) as f32)
    };
    let pole_i: Vec<[f32; 3]> = (0..nto)
        .flat_map(|to| (0..npo).map(move |po| (to, po)))
        .map(|(to, po)| mean(&mut (0..npi).map(|pi| value(0, pi, to, po))))
        .collect();
    let pole_o: Vec<[f32; 3]> = (0..nti)
        .flat_map(|ti| (0..npi).map(move |pi| (ti, pi)))
        .map(|(ti, pi)| mean(&mut (0..npo).map(|po| value(ti, pi, 0, po))))
        .collect();
    let pole_io = mean(&mut (0..npi).flat_map(|pi| (0..npo).map(move |po| value(0, pi, 0, po))));
    let mut out = Vec::with_capacity(3 * ((nti + 1) * npi * (nto + 1) * npo) as usize);
    for ri in 0..=nti {
        for pi in 0..npi {
            for ro in 0..=nto {
                for po in 0..npo {
                    let node = match (ri, ro) {
                        (0, 0) => pole_io,
                        (0, _) => pole_i[((ro - 1) * npo + po) as usize],
                        (_, 0) => pole_o[((ri - 1) * npi + pi) as usize],
                        _ => value(ri - 1, pi, ro - 1, po),
                    };
                    out.extend_from_slice(&node);
                }
            }
        }
    }
    out
}
