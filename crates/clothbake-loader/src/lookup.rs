//! Render-time lookup: [`Brdf`], quadrilinear interpolation of a baked table.
//!
//! Directions are local-frame vectors (z up, +X weft, +Y warp), `wi` toward the light and `wo`
//! toward the eye; values are `f_r` in 1/sr, RGB. The rules (also in `docs/reference/loader.md`):
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
//! one extra polar row (the pole) on each polar axis, 4 lanes a node and a copied wrap column
//! on the `phi_o` axis, in overlapping tiles of one cache line (`crate::nodes`), so every
//! lookup is the same branch-free gather of 8 runs of two adjacent nodes, from 4 cache lines
//! (f16). The code is chosen once per [`Brdf`] ([`SimdPath`]): AVX2 + FMA +
//! F16C when the processor has them, else portable Rust.

use std::fmt;
use std::path::Path;
use std::sync::OnceLock;

pub use crate::angles::{above_horizon, HORIZON_COS};
pub use crate::simd::SimdPath;

use crate::angles::{direction, has_value, theta_phi};
#[cfg(target_arch = "x86_64")]
use crate::avx2;
use crate::axis::Span;
use crate::error::TableError;
use crate::grid::Grid;
use crate::nodes::{self, Lane, Nodes, Values};
use crate::padding::pad;
use crate::sampling::Sampler;
use crate::spatial_lookup::SpatialLookup;
use crate::stored::{Samples, StoredTable};
use crate::table::{Metadata, Precision, Table};
use clothbake_bsdf::{Footprint, Level, Local};
use half::f16;

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
    /// Importance sampling ([`Brdf::sample`], [`Brdf::pdf`]): its CDFs, 4 bytes per table
    /// cell, are built on the first call. Without it `sample` and `pdf` give a zero pdf.
    pub sampling: bool,
    /// Answer footprints under two crossing cells at the point level where the table carries
    /// its period's yarns (a spatial table of one bounce; docs/science/spatial.md). Off: the crossing
    /// cells answer every footprint under a period, as in a table without yarns.
    pub point_level: bool,
}

impl Default for Options {
    /// Values as stored, no symmetrisation, sampling on, the point level where the table has it.
    fn default() -> Self {
        Options {
            memory: Memory::AsStored,
            reciprocal: false,
            sampling: true,
            point_level: true,
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

/// What [`Brdf::open_either`] found in a table file.
pub(crate) enum Opened {
    /// A one-faced table's lookup (boxed, as `crate::Lookup` holds it).
    One(Box<Brdf>),
    /// A two-faced table, as stored and checked (boxed: its metadata is large).
    Two(Box<StoredTable>),
}

/// A baked table ready for render-time lookups and importance sampling.
#[derive(Clone, Debug)]
pub struct Brdf {
    meta: Metadata,
    nodes: Nodes,
    simd: SimdPath,
    reciprocal: bool,
    /// Whether [`Options::sampling`] asked for importance sampling.
    sampling: bool,
    /// The sampling CDFs, built from the nodes on the first [`Brdf::sample`] or
    /// [`Brdf::pdf`] (`Brdf::sampler`).
    sampler: OnceLock<Sampler>,
    /// The classes of a spatially varying table (`crate::spatial_lookup`).
    spatial: Option<SpatialLookup>,
    /// The point level, where the table carries its yarns and the options ask for it.
    point: Option<PointLevel>,
}

/// The point level of a table: its period's yarns sorted for tracing, and the crossing cell's
/// side in periods that the level rule measures footprints in.
#[derive(Clone, Debug)]
struct PointLevel {
    yarns: clothbake_point::Yarns,
    cell: f64,
}

/// An f32 direction as a unit vector (the horizon tests are the point level's own).
fn unit(w: [f32; 3]) -> Option<clothbake_bsdf::UnitVec3> {
    clothbake_bsdf::UnitVec3::new(clothbake_bsdf::Vec3::new(
        f64::from(w[0]),
        f64::from(w[1]),
        f64::from(w[2]),
    ))
}

impl Brdf {
    /// Loads a table file (either format, see [`crate::read_table_stored`]). An averaged
    /// half-float OpenEXR table opened as stored goes from the file's lines straight into the
    /// lookup's nodes (the same nodes, with the same checks). A two-faced table is refused,
    /// naming [`crate::TwoFacedBrdf`].
    pub fn open(path: &Path, options: Options) -> Result<Brdf, TableError> {
        match Brdf::open_either(path, options)? {
            Opened::One(b) => Ok(*b),
            Opened::Two(_) => Err(TableError::WrongKind {
                path: path.to_path_buf(),
                found: format!(
                    "{} (reflection and transmission over the sphere)",
                    crate::TWO_FACED
                ),
                expected: "one-faced table".into(),
                fix: "open it with clothbake_loader::TwoFacedBrdf (or clothbake_loader::Lookup, \
                      which opens either kind)",
            }),
        }
    }

    /// A table file of either kind, read and checked once: a one-faced table as its lookup
    /// ([`Brdf::open`]'s paths), a two-faced one as stored (for [`crate::TwoFacedBrdf`]).
    pub(crate) fn open_either(path: &Path, options: Options) -> Result<Opened, TableError> {
        if options.memory == Memory::AsStored && crate::read::is_exr(path)? {
            if let Some((meta, nodes)) = crate::exr::read_half_nodes(path)? {
                return Ok(Opened::One(Box::new(Brdf::assemble(
                    meta, nodes, None, options,
                ))));
            }
        }
        // The readers check the table (StoredTable::new's rules).
        let stored = crate::read::read_table_stored(path)?;
        if stored.meta.grid.faces == crate::Faces::Two {
            return Ok(Opened::Two(Box::new(stored)));
        }
        Brdf::from_checked(stored, options)
            .map(|b| Opened::One(Box::new(b)))
            .map_err(|e| e.in_file(path))
    }

    /// A lookup of an `f32` table in memory.
    pub fn from_table(table: Table, options: Options) -> Result<Brdf, TableError> {
        Brdf::from_stored(StoredTable::from(table), options)
    }

    /// A lookup of a table in memory, after checking it (see [`StoredTable::new`]).
    pub fn from_stored(table: StoredTable, options: Options) -> Result<Brdf, TableError> {
        Brdf::from_checked(StoredTable::new(table.meta, table.samples)?, options)
    }

    /// A lookup of a table that [`StoredTable::new`]'s rules have already passed (a reader's,
    /// or a two-faced table's block), without checking its values again.
    pub(crate) fn from_checked(table: StoredTable, options: Options) -> Result<Brdf, TableError> {
        let StoredTable { meta, mut samples } = table;
        let g = meta.grid;
        if g.faces == crate::Faces::Two {
            return Err(TableError::InvalidTable {
                reason: format!(
                    "grid {g} is a two-faced table's; open it with clothbake_loader::TwoFacedBrdf"
                ),
            });
        }
        let f16 = matches!(
            (&samples, options.memory),
            (Samples::F16(_), Memory::AsStored)
        );
        let spatial = meta.spatial.clone().map(|layout| {
            let classes = samples.split_off(3 * g.len());
            SpatialLookup::new(layout, g, &classes, f16)
        });
        let nodes = pad(&g, &samples, f16);
        drop(samples);
        Ok(Brdf::assemble(meta, nodes, spatial, options))
    }

    /// The lookup of `nodes` (and `spatial`'s classes) with the options' kernel, sampling and
    /// point level.
    fn assemble(
        meta: Metadata,
        nodes: Nodes,
        spatial: Option<SpatialLookup>,
        options: Options,
    ) -> Brdf {
        let simd = if nodes.lanes.exact {
            SimdPath::best()
        } else {
            SimdPath::Portable
        };
        let point = match (&meta.yarns, &spatial) {
            (Some(p), Some(s)) if options.point_level => Some(PointLevel {
                yarns: clothbake_point::Yarns::new(p.clone()),
                cell: s.cell_width(),
            }),
            _ => None,
        };
        Brdf {
            meta,
            nodes,
            simd,
            reciprocal: options.reciprocal,
            sampling: options.sampling,
            sampler: OnceLock::new(),
            spatial,
            point,
        }
    }

    /// The table this lookup was built from, for an averaged table: its values read back from
    /// the nodes, at the precision they are held in (exactly the stored values when opened
    /// [`Memory::AsStored`]). `None` for a spatial table, whose classes are held merged.
    pub fn to_stored(&self) -> Option<StoredTable> {
        if self.spatial.is_some() {
            return None;
        }
        let g = *self.grid();
        let cells = (0..g.n_theta_i).flat_map(move |ti| {
            (0..g.n_phi_i).flat_map(move |pi| {
                (0..g.n_theta_o).flat_map(move |to| (0..g.n_phi_o).map(move |po| (ti, pi, to, po)))
            })
        });
        let samples = match &self.nodes.values {
            Values::F16(_) => Samples::F16(
                cells
                    .flat_map(|(a, b, c, d)| self.nodes.cell(a, b, c, d))
                    .map(f16::from_f32)
                    .collect(),
            ),
            Values::F32(_) => Samples::F32(
                cells
                    .flat_map(|(a, b, c, d)| self.nodes.cell(a, b, c, d))
                    .collect(),
            ),
        };
        Some(StoredTable {
            meta: self.meta.clone(),
            samples,
        })
    }

    /// The spatial part of a spatially varying table, `None` for an averaged table.
    pub fn spatial(&self) -> Option<&SpatialLookup> {
        self.spatial.as_ref()
    }

    /// Whether this table answers footprints under two crossing cells at the point level (it
    /// carries its yarns and was opened with [`Options::point_level`]).
    pub fn has_point_level(&self) -> bool {
        self.point.is_some()
    }

    /// f_r and coverage at the point level where the level rule ([`Footprint::level`]) gives
    /// it a share: the yarns' look over the footprint, blended with the cells' box filter
    /// between one and two cells wide (`Local::blend`). Without `wi`, the coverage alone (the
    /// eye rays alone; f_r 0). `None` where the cells or the period answer alone.
    fn point_local(
        &self,
        wi: Option<[f32; 3]>,
        wo: [f32; 3],
        u: f64,
        v: f64,
        width: f64,
    ) -> Option<([f32; 3], f32)> {
        let p = self.point.as_ref()?;
        let Level::Local {
            point,
            width,
            points,
        } = (Footprint { u, v, width }).level(p.cell)
        else {
            return None;
        };
        if point <= 0.0 {
            return None;
        }
        let Some(o) = unit(wo) else {
            return Some(([0.0; 3], 0.0));
        };
        // The coverage does not depend on the light: with none above the horizon, the eye
        // rays alone give it.
        let seen = match wi.and_then(unit).filter(|i| i.above_horizon()) {
            Some(i) => {
                let l = p.yarns.look_within(u, v, width, points, i, o);
                Local {
                    f: l.f,
                    coverage: l.coverage,
                }
            }
            None => Local {
                f: [0.0; 3],
                coverage: p.yarns.coverage_within(u, v, width, points, o),
            },
        };
        let l = if point >= 1.0 {
            seen
        } else {
            let s = self.spatial.as_ref()?;
            let cells = Local {
                f: match wi {
                    Some(wi) => s.eval_within(self.simd, wi, wo, u, v, width).map(f64::from),
                    None => [0.0; 3],
                },
                coverage: f64::from(s.coverage_at(wo, u, v, width).unwrap_or(1.0)),
            };
            Local::blend(point, seen, cells)
        };
        Some((l.f.map(|x| x as f32), l.coverage as f32))
    }

    /// f_r through a footprint of the weave period (docs/science/spatial.md): at (u, v) in period
    /// fractions (wrapped), over a square of side `width` periods, at the level of detail
    /// [`Footprint::level`] gives it. A spatial table that carries its yarns answers
    /// footprints under a crossing cell at the point level (the yarns traced), blends it with
    /// its cells up to two cells wide, and answers the coverage-weighted mean of its cells'
    /// f_r over the square beyond; its averaged f_r ([`Brdf::eval`]) once `width` reaches 1;
    /// an averaged table always answers [`Brdf::eval`].
    #[inline]
    pub fn eval_at(&self, wi: [f32; 3], wo: [f32; 3], u: f64, v: f64, width: f64) -> [f32; 3] {
        if self.point.is_some() {
            if let Some((f, _)) = self.point_local(Some(wi), wo, u, v, width) {
                return f;
            }
        }
        // One call takes the directions on each path (no copies kept for another).
        match &self.spatial {
            Some(s) if SpatialLookup::answers(u, v, width) => {
                s.eval_within(self.simd, wi, wo, u, v, width)
            }
            _ => self.eval(wi, wo),
        }
    }

    /// [`Brdf::eval_at`] and [`Brdf::coverage_at`] from one call: at the point level the
    /// yarns are traced once for both.
    pub fn local_at(
        &self,
        wi: [f32; 3],
        wo: [f32; 3],
        u: f64,
        v: f64,
        width: f64,
    ) -> ([f32; 3], f32) {
        if self.point.is_some() {
            if let Some(l) = self.point_local(Some(wi), wo, u, v, width) {
                return l;
            }
        }
        (
            self.eval_at(wi, wo, u, v, width),
            self.coverage_at(wo, u, v, width),
        )
    }

    /// The share of a footprint's projected area in which the eye meets yarn, seen from `wo`
    /// (see [`Brdf::eval_at`]); for a footprint of a whole period or more, or a point not
    /// finite (where `eval_at` answers the average), the directional coverage C(wo). An
    /// averaged table carries no coverage and answers 1 (opaque).
    pub fn coverage_at(&self, wo: [f32; 3], u: f64, v: f64, width: f64) -> f32 {
        if self.point.is_some() {
            if let Some((_, c)) = self.point_local(None, wo, u, v, width) {
                return c;
            }
        }
        // Where `eval_at` answers the average, the whole period (just under, which the
        // spatial table still answers).
        let (u, v, width) = if SpatialLookup::answers(u, v, width) {
            (u, v, width)
        } else {
            (0.0, 0.0, 0.999_999)
        };
        self.spatial
            .as_ref()
            .and_then(|s| s.coverage_at(wo, u, v, width))
            .unwrap_or(1.0)
    }

    /// The same table looked up by `path`; `None` when this processor cannot run it (or,
    /// for [`SimdPath::Avx2`], an axis has more than 2^22 cells).
    pub fn with_simd_path(mut self, path: SimdPath) -> Option<Brdf> {
        let fits = path == SimdPath::Portable || self.nodes.lanes.exact;
        (fits && path.is_available()).then(|| {
            self.simd = path;
            self
        })
    }

    /// The code path running the lookups ([`SimdPath::best`] unless chosen by
    /// [`Brdf::with_simd_path`], or an axis has more than 2^22 cells).
    pub fn simd_path(&self) -> SimdPath {
        self.simd
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
        match self.nodes.values {
            Values::F16(_) => Precision::F16,
            Values::F32(_) => Precision::F32,
        }
    }

    /// Bytes held by the values and the sampling CDFs (counted with [`Options::sampling`]
    /// also before the first [`Brdf::sample`] or [`Brdf::pdf`] builds them).
    pub fn memory_bytes(&self) -> usize {
        let lane = match self.nodes.values {
            Values::F16(_) => 2,
            Values::F32(_) => 4,
        };
        let values = lane * self.nodes.len();
        values
            + if self.sampling {
                Sampler::bytes_of(self.grid())
            } else {
                0
            }
            + self.spatial.as_ref().map_or(0, SpatialLookup::memory_bytes)
    }

    /// True when the table was opened with importance sampling ([`Options::sampling`]).
    pub fn has_sampling(&self) -> bool {
        self.sampling
    }

    /// The sampling CDFs, built on the first call from the values the lookups read (so an
    /// open does not wait for them); `None` without [`Options::sampling`].
    fn sampler(&self) -> Option<&Sampler> {
        self.sampling.then(|| {
            self.sampler.get_or_init(|| {
                Sampler::new(self.grid(), |ti, pi, to, po| {
                    self.nodes.cell(ti, pi, to, po)
                })
            })
        })
    }

    /// True when lookups are symmetrised (see [`Options::reciprocal`]).
    pub fn is_reciprocal(&self) -> bool {
        self.reciprocal
    }

    /// `f_r(wi, wo)` in 1/sr, RGB, for local-frame unit vectors; 0 when either is on or below
    /// the horizon (`z <= 1e-9`) or not a number. Symmetrised with [`Options::reciprocal`].
    #[inline]
    pub fn eval(&self, wi: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
        let (n, r) = (&self.nodes, self.reciprocal);
        match (&n.values, self.simd) {
            // SAFETY: the kernel is AVX2 only when the processor has AVX2, FMA and F16C
            // (`with_simd_path`, `SimdPath::best`); the lane type picks the loads.
            #[cfg(target_arch = "x86_64")]
            (Values::F16(v), SimdPath::Avx2) => unsafe { avx2::eval(n, v, r, wi, wo) },
            #[cfg(target_arch = "x86_64")]
            (Values::F32(v), SimdPath::Avx2) => unsafe { avx2::eval(n, v, r, wi, wo) },
            (Values::F16(v), _) => self.eval_portable(v, wi, wo),
            (Values::F32(v), _) => self.eval_portable(v, wi, wo),
        }
    }

    /// The portable single lookup, out of line: inlined, its registers would be saved and
    /// restored on every [`Brdf::eval`], whatever the kernel.
    #[inline(never)]
    fn eval_portable<V: Lane>(&self, v: &[V], wi: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
        self.eval_in(v, wi, wo)
    }

    /// `f_r` at polar angles and azimuths in degrees (theta from +Z, phi from +X toward +Y),
    /// as the tables use; 0 unless `0 <= theta < 90` (the polar axes' span) for both
    /// directions.
    pub fn eval_deg(&self, theta_i: f32, phi_i: f32, theta_o: f32, phi_o: f32) -> [f32; 3] {
        let g = self.grid();
        // Every f32 below 90 has cos(theta) > HORIZON_COS (tested), so no cosine is needed.
        if !(g.theta_i().holds_deg(theta_i) && g.theta_o().holds_deg(theta_o)) {
            return [0.0; 3];
        }
        let r = f32::to_radians;
        let turn = Span::Turn.degrees_f32();
        let wrap = |phi: f32| {
            if (0.0..turn).contains(&phi) {
                phi
            } else if phi.is_finite() {
                phi.rem_euclid(turn)
            } else {
                0.0
            }
        };
        let ang = [r(theta_i), r(wrap(phi_i)), r(theta_o), r(wrap(phi_o))];
        let (n, rc) = (&self.nodes, self.reciprocal);
        match (&n.values, self.simd) {
            // SAFETY: as in `eval`.
            #[cfg(target_arch = "x86_64")]
            (Values::F16(v), SimdPath::Avx2) => unsafe { avx2::at_angles_of(n, v, rc, ang) },
            #[cfg(target_arch = "x86_64")]
            (Values::F32(v), SimdPath::Avx2) => unsafe { avx2::at_angles_of(n, v, rc, ang) },
            (Values::F16(v), _) => self.blend_reciprocal(v, ang),
            (Values::F32(v), _) => self.blend_reciprocal(v, ang),
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
        let (n, r) = (&self.nodes, self.reciprocal);
        match (&n.values, self.simd) {
            // SAFETY: as in `eval`.
            #[cfg(target_arch = "x86_64")]
            (Values::F16(v), SimdPath::Avx2) => unsafe { avx2::batch(n, v, r, wi, wo, out) },
            #[cfg(target_arch = "x86_64")]
            (Values::F32(v), SimdPath::Avx2) => unsafe { avx2::batch(n, v, r, wi, wo, out) },
            (Values::F16(v), _) => self.batch_in(v, wi, wo, out),
            (Values::F32(v), _) => self.batch_in(v, wi, wo, out),
        }
        Ok(())
    }

    /// Samples an incident direction for `wo` with `u1, u2` uniform in [0, 1): the density is
    /// piecewise constant per unit solid angle over the table's incident cells, proportional
    /// to `f_r cos theta_i` at the cell centres of the outgoing cell holding `wo` (see
    /// `docs/reference/loader.md`). The weight is `eval(wi, wo) cos theta_i / pdf`.
    pub fn sample(&self, wo: [f32; 3], u1: f32, u2: f32) -> Sample {
        let none = Sample {
            wi: [0.0, 0.0, 1.0],
            weight: [0.0; 3],
            pdf: 0.0,
        };
        let Some(sampler) = self.sampler() else {
            return none;
        };
        if !above_horizon(wo) {
            return none;
        }
        let (theta_o, phi_o) = theta_phi(wo);
        let (theta, phi) = sampler.sample(theta_o, phi_o, u1, u2);
        let wi = direction(theta, phi);
        let pdf = self.pdf(wi, wo);
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
    pub fn pdf(&self, wi: [f32; 3], wo: [f32; 3]) -> f32 {
        let Some(sampler) = self.sampler() else {
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
    fn eval_in<V: Lane>(&self, v: &[V], wi: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
        if !has_value(wi, wo) {
            return [0.0; 3];
        }
        self.blend_reciprocal(v, nodes::angles(wi, wo))
    }

    /// The portable batch, one pair after the other (grouping pairs as the AVX2 kernel does
    /// was measured slower here: SSE2 has too few registers for 4 corners).
    fn batch_in<V: Lane>(&self, v: &[V], wi: &[[f32; 3]], wo: &[[f32; 3]], out: &mut [[f32; 3]]) {
        for ((a, b), o) in wi.iter().zip(wo).zip(out.iter_mut()) {
            *o = self.eval_in(v, *a, *b);
        }
    }

    #[inline(always)]
    fn blend_reciprocal<V: Lane>(&self, v: &[V], ang: [f32; 4]) -> [f32; 3] {
        let f = self.nodes.blend(v, ang);
        if !self.reciprocal {
            return f;
        }
        let r = self.nodes.blend(v, [ang[2], ang[3], ang[0], ang[1]]);
        [
            0.5 * (f[0] + r[0]),
            0.5 * (f[1] + r[1]),
            0.5 * (f[2] + r[2]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::HORIZON_COS;
    use crate::axis::Span;

    #[test]
    fn every_f32_polar_angle_below_90_degrees_is_above_the_horizon() {
        // The 100 000 largest f32 below 90 (the polar span, which `eval_deg` holds angles
        // to); below those cos exceeds 0.008.
        let mut t = Span::Hemisphere.degrees_f32();
        assert_eq!(t, 90.0);
        for _ in 0..100_000 {
            t = f32::from_bits(t.to_bits() - 1);
            assert!(t.to_radians().cos() > HORIZON_COS, "{t}");
        }
        assert!(t < 89.5); // below, cos > 0.008
    }
}
