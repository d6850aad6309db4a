//! The bake: evaluate f_r on every cell of a (theta_i, phi_i, theta_o, phi_o) grid.
//!
//! * Cell-centred grid (see `clothbake_loader::Grid`); values are f_r = I / (pi cos theta_i) in
//!   1/sr, RGB, from the analytic model (or the ray tracer, for small ground-truth tables). With
//!   `bounces: 2` the analytic model adds the secondary reflection I_2 (thesis ch. 5); with more
//!   (or all) it adds the path-traced orders 2 to N on a coarse grid ([`crate::transport`]).
//! * Symmetry: where the fabric's micro-geometry is invariant under mirror x, mirror y or a
//!   rotation by 180 degrees ([`clothbake_core::symmetry`]), so is its BRDF, exactly. Only one
//!   cell of each orbit of the symmetry group on the (phi_i, phi_o) indices is evaluated; the
//!   others receive a copy of its value.
//! * Deterministic: every cell is a pure function of the inputs; the parallel sweep collects in
//!   cell order, so the table is bit-identical for any number of threads.

pub use crate::directions::{direction, incident, outgoing, row_cell};
pub use crate::orbit::{representative, usable_symmetries};
use crate::transport::Multiple;
use crate::two_faced::TwoFaced;
use clothbake_core::interreflection::{Orders, Ranges, Sampling};
use clothbake_core::symmetry::Symmetry;
use clothbake_core::{
    AnalyticBsdf, AnalyticModel, Bsdf, ClassTerms, Fabric, FacetModel, SecondaryMethod,
    SecondaryOptions, UnitVec3, Variant, VariantError,
};
use clothbake_loader::spatial::value_index;
use clothbake_loader::{Faces, Grid, Metadata, Table};
use clothbake_truth::{Caps, RayTracer};
use rayon::prelude::*;
use serde_json::{json, Value};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// The most eye rays per node of a two-faced bake's rest (`--paths`): 2^24.
pub const MAX_PATHS: usize = 1 << 24;

/// The default grid: 32 x 64 x 32 x 64 cells (2.8 degrees in theta, 5.6 in phi).
pub const DEFAULT_GRID: Grid = Grid::new(32, 64, 32, 64);

/// How each cell is evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// The analytic model (thesis ch. 3-4, and ch. 5 with two bounces).
    Analytic {
        /// Analytic variant.
        variant: Variant,
    },
    /// The ray-traced ground truth of the direct reflection, `samples` rays per cell, seeded
    /// per cell.
    Raytrace {
        /// Primary rays per cell.
        samples: usize,
        /// Base seed; cell c uses seed + c.
        seed: u64,
        /// End-cap convention.
        caps: Caps,
    },
}

/// Everything that determines a table besides the fabric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeOptions {
    /// The grid.
    pub grid: Grid,
    /// Facet model.
    pub facet: FacetModel,
    /// Evaluation method.
    pub method: Method,
    /// What the bake adds to the direct reflection, with the settings only that kind has.
    pub bounces: BakeBounces,
    /// A spatially varying table (docs/science/spatial.md): the classes of the period's cells beside
    /// the average. Analytic model, one or two bounces.
    pub spatial: bool,
    /// A two-faced bake's eye rays per node of its path-traced rest
    /// ([`crate::two_faced::PATHS`] by default); unused by one-faced bakes.
    pub paths: usize,
}

/// The bounces a bake follows (docs/science/transport.md): each kind carries the settings that
/// apply to it, so that a bake of one bounce cannot hold second-bounce options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BakeBounces {
    /// The direct reflection I_1 alone (thesis ch. 4).
    One,
    /// I_1 plus the thesis's secondary reflection I_2 (ch. 5), computed as these options say.
    Two(SecondaryOptions),
    /// I_1 plus the path-traced orders 2 to N: N > 2, or
    /// [`ALL_BOUNCES`](crate::transport::ALL_BOUNCES) for every order ([`crate::transport`]).
    Paths(u32),
}

impl BakeBounces {
    /// The kind for a bounce count (1, 2, N > 2 or `ALL_BOUNCES`); `secondary` is used for 2.
    /// A count of 0 gives `Paths(0)`, which the bake refuses.
    pub fn of(count: u32, secondary: SecondaryOptions) -> BakeBounces {
        match count {
            1 => BakeBounces::One,
            2 => BakeBounces::Two(secondary),
            n => BakeBounces::Paths(n),
        }
    }

    /// The bounce count: 1, 2, N or `ALL_BOUNCES`.
    pub fn count(self) -> u32 {
        match self {
            BakeBounces::One => 1,
            BakeBounces::Two(_) => 2,
            BakeBounces::Paths(n) => n,
        }
    }

    /// The secondary reflection's options, with two bounces.
    pub fn secondary(self) -> Option<SecondaryOptions> {
        match self {
            BakeBounces::Two(s) => Some(s),
            _ => None,
        }
    }
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            grid: DEFAULT_GRID,
            facet: FacetModel::Huo,
            method: Method::Analytic {
                variant: Variant::default(),
            },
            bounces: BakeBounces::One,
            spatial: false,
            paths: crate::two_faced::PATHS,
        }
    }
}

fn orders_json(o: Orders) -> Value {
    json!({"theta": o.theta, "beta": o.beta, "axial": o.axial})
}

fn sampling_json(s: Sampling) -> Value {
    json!({
        "first_level": s.first_level,
        "d_alpha": s.d_alpha,
        "d_l": s.d_l,
        "l0": s.l0,
        "exact_solid_angle": s.exact_solid_angle,
    })
}

fn ranges_json(r: Ranges) -> Value {
    serde_json::to_value(r).unwrap_or_else(|_| Value::String(format!("{r:?}")))
}

impl BakeOptions {
    /// The options as stored in the table's `options_json`: the grid, the facet model, the
    /// method with its parameters, the bounces and, with two bounces, the secondary reflection's
    /// method, parameters and kernel. Not the thread count: it does not change the table.
    pub fn to_json(&self) -> Value {
        let mut v = json!({
            "grid": self.grid,
            "facet": self.facet,
        });
        match self.method {
            Method::Analytic { variant } => {
                v["method"] = json!("analytic");
                v["variant"] = json!(variant);
            }
            Method::Raytrace {
                samples,
                seed,
                caps,
            } => {
                v["method"] = json!("raytrace");
                v["samples"] = json!(samples);
                v["seed"] = json!(seed);
                v["caps"] = json!(caps.name());
            }
        }
        v["bounces"] = json!(self.bounces.count());
        if let BakeBounces::Paths(n) = self.bounces {
            v["bounces"] = json!(crate::transport::bounces_name(n));
            v["transport"] = crate::transport::describe(&self.grid, n);
        }
        if let BakeBounces::Two(s) = self.bounces {
            let mut sec = match s.method {
                SecondaryMethod::Analytic { ranges, orders } => json!({
                    "method": "analytic",
                    "ranges": ranges_json(ranges),
                    "orders": orders_json(orders),
                }),
                SecondaryMethod::Sampling(p) => json!({
                    "method": "sampling",
                    "sampling": sampling_json(p),
                }),
            };
            sec["kernel"] = json!(s.kernel.name());
            v["secondary"] = sec;
        }
        if self.spatial {
            v["spatial"] = json!(true);
        }
        if self.grid.faces == Faces::Two {
            v["two_faced"] = crate::two_faced::describe(self.paths);
        }
        v
    }
}

/// Why a bake stopped without a table.
#[derive(Debug, Clone, PartialEq)]
pub enum BakeError {
    /// The cancel flag was raised (Ctrl-C).
    Cancelled,
    /// The options cannot be baked (message says why and how to fix it).
    Invalid(String),
}

/// A variant that does not take the fabric's period (the model's constructor refuses it).
impl From<VariantError> for BakeError {
    fn from(e: VariantError) -> Self {
        BakeError::Invalid(e.line())
    }
}

impl std::fmt::Display for BakeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BakeError::Cancelled => f.write_str("the bake was cancelled"),
            BakeError::Invalid(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for BakeError {}

/// A finished bake.
#[derive(Debug, Clone)]
pub struct Baked {
    /// The table with its metadata.
    pub table: Table,
    /// The symmetries used.
    pub symmetries: Vec<Symmetry>,
    /// Cells actually evaluated (the rest are copies).
    pub evaluated: usize,
}

/// Checks that `opts` can be baked: a valid grid, at least one bounce, more than one only with
/// the analytic model.
pub fn check_options(opts: &BakeOptions) -> Result<(), BakeError> {
    opts.grid
        .validate()
        .map_err(|e| BakeError::Invalid(e.to_string()))?;
    if opts.grid.faces == Faces::Two
        && (opts.spatial
            || opts.bounces != BakeBounces::One
            || !matches!(opts.method, Method::Analytic { .. }))
    {
        return Err(BakeError::Invalid(
            "--faces two bakes the two-faced cloth's model (docs/science/transmission.md): the analytic \
             direct reflection with every other bounce path-traced, averaged over the period; \
             drop --spatial, --bounces and --method raytrace"
                .into(),
        ));
    }
    if opts.grid.faces == Faces::Two && !(1..=MAX_PATHS).contains(&opts.paths) {
        return Err(BakeError::Invalid(format!(
            "--paths {} is out of range; give a whole number from 1 to {MAX_PATHS} (2^24)",
            opts.paths
        )));
    }
    if opts.spatial
        && (matches!(opts.bounces, BakeBounces::Paths(_))
            || !matches!(opts.method, Method::Analytic { .. }))
    {
        return Err(BakeError::Invalid(
            "--spatial bakes the analytic model's direct and secondary reflection; give \
             --bounces 1 or 2 and --method analytic with --spatial (the path-traced orders of \
             --bounces all and the ray tracer's tables are averaged over the period)"
                .into(),
        ));
    }
    match (opts.bounces.count(), opts.method) {
        (1, _) | (2.., Method::Analytic { .. }) => Ok(()),
        (2.., Method::Raytrace { .. }) => Err(BakeError::Invalid(
            "the ray tracer bakes the direct reflection only; use --bounces 1 with --method \
             raytrace, or --method analytic with --bounces 2 or all"
                .into(),
        )),
        (n, _) => Err(BakeError::Invalid(format!(
            "{n} bounces is not supported; use --bounces 1 (direct reflection), 2 (direct and \
             secondary reflection, thesis ch. 5) or all (every bounce, docs/science/transport.md)"
        ))),
    }
}

/// The number of cells [`bake`] evaluates on grid `g` (the others are copies): the total its
/// `progress` counts up to.
pub fn evaluations(fabric: &Fabric, g: &Grid) -> usize {
    Orbits::new(g, &usable_symmetries(fabric, g)).evaluations()
}

/// The canonical values of one (theta_i, phi_i) row: one RGB triple per evaluated cell, in
/// cell order (theta_o, then phi_o); the row's other cells are copies (see [`Orbits`]).
pub type Row = Vec<[f32; 3]>;

/// Which cells of a grid are evaluated and where the others copy from: the orbits of the
/// symmetry group on the (phi_i, phi_o) cells, shared by every theta_i and theta_o.
#[derive(Clone, Debug)]
pub struct Orbits {
    grid: Grid,
    /// Shared: a [`crate::assembly::Assembly`] keeps a copy of the orbits.
    reps: Arc<[(u32, u32)]>,
    /// Canonical phi_o cells per phi_i cell.
    per_phi_i: Vec<usize>,
    /// Row entries per evaluated cell: 1, or a spatial bake's [`crate::spatial::stride`].
    stride: usize,
    /// A spatial bake's classes (0 otherwise).
    classes: usize,
    /// A spatial bake's values per class and grid cell (`Spatial::lanes`).
    lanes: usize,
}

impl Orbits {
    /// The orbits of `syms` (usable on `g`, see [`usable_symmetries`]).
    pub fn new(g: &Grid, syms: &[Symmetry]) -> Orbits {
        let (npi, npo) = (g.n_phi_i as usize, g.n_phi_o as usize);
        let reps: Vec<(u32, u32)> = (0..npi)
            .flat_map(|pi| (0..npo).map(move |po| (pi, po)))
            .map(|(pi, po)| {
                let (ri, ro) = representative(pi, po, syms, g);
                (ri as u32, ro as u32)
            })
            .collect();
        let per_phi_i = (0..npi)
            .map(|pi| {
                (0..npo)
                    .filter(|&po| reps[pi * npo + po] == (pi as u32, po as u32))
                    .count()
            })
            .collect();
        Orbits {
            grid: *g,
            reps: reps.into(),
            per_phi_i,
            stride: 1,
            classes: 0,
            lanes: 2,
        }
    }

    /// The orbits of a spatial bake of `classes` classes of `lanes` values per grid cell: no
    /// symmetry (it would map cells of the period onto others), [`crate::spatial::stride`] row
    /// entries per cell.
    pub fn spatial(g: &Grid, classes: usize, lanes: usize) -> Orbits {
        Orbits {
            stride: crate::spatial::stride(lanes * classes),
            classes,
            lanes,
            ..Orbits::new(g, &[])
        }
    }

    /// Row entries per evaluated cell.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Number of (theta_i, phi_i) rows.
    pub fn rows(&self) -> usize {
        (self.grid.n_theta_i * self.grid.n_phi_i) as usize
    }

    /// The representative of (pi, po).
    pub fn rep(&self, pi: usize, po: usize) -> (usize, usize) {
        let (ri, ro) = self.reps[pi * self.grid.n_phi_o as usize + po];
        (ri as usize, ro as usize)
    }

    fn canonical(&self, pi: usize, po: usize) -> bool {
        self.rep(pi, po) == (pi, po)
    }

    /// Whether cell (pi, po) of every (theta_i, theta_o) is evaluated (its orbit's
    /// representative) rather than copied.
    pub fn is_canonical(&self, pi: usize, po: usize) -> bool {
        self.canonical(pi, po)
    }

    /// Cells of a (theta_i, phi_i) row: n_theta_o * n_phi_o.
    pub fn cells_per_row(&self) -> usize {
        self.grid.n_theta_o as usize * self.grid.n_phi_o as usize
    }

    /// A spatial bake's classes (0 otherwise).
    pub fn classes(&self) -> usize {
        self.classes
    }

    /// A spatial bake's values per class and grid cell.
    pub fn lanes(&self) -> usize {
        self.lanes
    }

    /// A spatial bake's class values per grid cell (0 otherwise).
    pub fn class_values(&self) -> usize {
        self.lanes * self.classes
    }

    /// Entries of `row`'s [`Row`]: the cells it evaluates times [`Orbits::stride`].
    pub fn row_evaluations(&self, row: usize) -> usize {
        let (_, pi) = row_cell(&self.grid, row);
        self.per_phi_i[pi as usize] * self.grid.n_theta_o as usize * self.stride
    }

    /// The cell `(ti, pi, to, po)` of value `k` of `row`'s [`Row`] (its `k`-th canonical
    /// cell, in cell order).
    pub fn evaluated_cell(&self, row: usize, k: usize) -> Option<(u32, u32, u32, u32)> {
        let (ti, pi) = row_cell(&self.grid, row);
        let npo = self.grid.n_phi_o;
        let canon: Vec<u32> = (0..npo)
            .filter(|&po| self.canonical(pi as usize, po as usize))
            .collect();
        let per_to = canon.len().max(1);
        let k = k / self.stride;
        let to = u32::try_from(k / per_to).ok()?;
        let po = *canon.get(k % per_to)?;
        (to < self.grid.n_theta_o).then_some((ti, pi, to, po))
    }

    /// Row entries of the whole grid (the cells evaluated times [`Orbits::stride`]).
    pub fn evaluations(&self) -> usize {
        (0..self.rows()).map(|r| self.row_evaluations(r)).sum()
    }

    /// The table's values (RGB interleaved, cell order) from every row's canonical values:
    /// canonical cells first, then the copies from their representatives, which may lie in
    /// another row. `rows[r]` must hold [`Orbits::row_evaluations`]`(r)` values. The
    /// straightforward assembly of [`bake`], which the tests hold the job's one buffer
    /// ([`crate::assembly::Assembly`]) against.
    pub fn assemble(&self, rows: &[Row]) -> Vec<f32> {
        let g = self.grid;
        let (nti, npi, nto, npo) = (g.n_theta_i, g.n_phi_i, g.n_theta_o, g.n_phi_o);
        assert_eq!(rows.len(), self.rows(), "one Row per grid row");
        let n = g.len();
        // A spatial table's classes: lanes K values per cell after the averaged RGB (the
        // cell's last row entry may end in padding).
        let class_values = self.class_values();
        let mut values = vec![f32::NAN; n * 3 + n * class_values];
        for (row, vals) in rows.iter().enumerate() {
            assert_eq!(vals.len(), self.row_evaluations(row), "row {row}'s length");
            let (ti, pi) = row_cell(&g, row);
            let mut it = vals.chunks_exact(self.stride);
            for to in 0..nto {
                for po in 0..npo {
                    if self.canonical(pi as usize, po as usize) {
                        let v = it.next().expect("one entry per canonical cell");
                        let c = g.index(ti, pi, to, po);
                        values[3 * c..][..3].copy_from_slice(&v[0]);
                        for (m, x) in v[1..].iter().flatten().take(class_values).enumerate() {
                            values[value_index(3 + m, c, n, self.lanes)] = *x;
                        }
                    }
                }
            }
        }
        for ti in 0..nti {
            for pi in 0..npi {
                for po in 0..npo {
                    let (ri, ro) = self.rep(pi as usize, po as usize);
                    if (ri, ro) == (pi as usize, po as usize) {
                        continue;
                    }
                    for to in 0..nto {
                        let src = 3 * g.index(ti, ri as u32, to, ro as u32);
                        let dst = 3 * g.index(ti, pi, to, po);
                        values.copy_within(src..src + 3, dst);
                    }
                }
            }
        }
        values
    }
}

/// The symmetry as stored in the table's metadata: the names joined by ", ", or "none".
pub fn symmetry_name(syms: &[Symmetry]) -> String {
    if syms.is_empty() {
        "none".to_string()
    } else {
        syms.iter().map(|s| s.name()).collect::<Vec<_>>().join(", ")
    }
}

/// The tool name stored in tables and shard files: `clothbake <version>`.
pub fn tool_name() -> String {
    format!("clothbake {}", env!("CARGO_PKG_VERSION"))
}

/// Appends the row entries (see [`Orbits::stride`]) of cells of one row, given its wi and
/// each cell's index and wo, in that order.
type CellFn = Box<dyn Fn(UnitVec3, &[(usize, UnitVec3)], &mut Row) + Sync + Send>;

/// Cells a row hands its evaluator at once (the cancel flag is read between them).
const CELLS_AT_ONCE: usize = 256;

/// The evaluator of a row's cells from that of one cell (index, wi, wo).
fn per_cell(f: impl Fn(usize, UnitVec3, UnitVec3, &mut Row) + Sync + Send + 'static) -> CellFn {
    Box::new(move |wi, cells, out| {
        for &(c, wo) in cells {
            f(c, wi, wo, out);
        }
    })
}

/// The evaluator of a row's cells by `bsdf`'s [`Bsdf::f_batch`] (the row's wi with each cell's
/// wo), a group of cells at a time.
fn batched(bsdf: Arc<dyn Bsdf + Send + Sync>) -> CellFn {
    Box::new(move |wi, cells, out| {
        let pairs: Vec<_> = cells.iter().map(|&(_, wo)| (wi, wo)).collect();
        let mut f = vec![[0.0; 3]; pairs.len()];
        bsdf.f_batch(&pairs, &mut f);
        out.extend(f.iter().map(|f| f.map(|x| x as f32)));
    })
}

/// The most memory a bake gives to a [`Variant::Sliced3d`] model's open arcs kept for the
/// grid's directions (docs/guide/baking.md).
pub const OPEN_ARCS_BUDGET: usize = 256 << 20;

/// Model `m` with the open arcs of every direction of grid `g` kept
/// ([`AnalyticModel::keep_open_arcs`], found in parallel), where they fit in
/// [`OPEN_ARCS_BUDGET`]: the same bits, each direction's arcs found once rather than once a
/// pair. Other variants' models are given back as they are.
fn with_grid_arcs(mut m: AnalyticModel, g: &Grid) -> AnalyticModel {
    let slices = m.open_arc_slices();
    if slices == 0 {
        return m;
    }
    let incident = (0..g.n_theta_i).flat_map(|t| (0..g.n_phi_i).map(move |p| incident(g, t, p)));
    let outgoing = (0..g.n_theta_o).flat_map(|t| (0..g.n_phi_o).map(move |p| outgoing(g, t, p)));
    let mut dirs: Vec<UnitVec3> = incident.chain(outgoing).collect();
    let key = |w: &UnitVec3| {
        let v = w.get();
        [v.x, v.y, v.z].map(f64::to_bits)
    };
    dirs.sort_by_key(key);
    dirs.dedup_by_key(|w| key(w));
    if dirs.len().saturating_mul(slices) > OPEN_ARCS_BUDGET / 48 {
        return m;
    }
    let arcs: Vec<_> = dirs.par_iter().map(|&w| m.open_arcs(w)).collect();
    m.keep_open_arcs(arcs);
    m
}

/// A prepared bake: the cell evaluator, the orbits and the metadata of the table it makes.
/// Rows are evaluated independently ([`Baker::eval_row`]), by one process ([`bake`]) or by
/// several (shards, `clothbake merge`), with the same values.
pub struct Baker {
    orbits: Orbits,
    syms: Vec<Symmetry>,
    eval: CellFn,
    meta: Metadata,
    /// With more than two bounces: the path-traced part's coarse nodes.
    multiple: Option<Arc<Multiple>>,
    /// A two-faced bake's model, whose path-traced nodes [`Baker::sweep`] prepares first.
    two_faced: Option<Arc<TwoFaced>>,
}

impl Baker {
    /// Checks the options and prepares the model (or the ray tracer).
    pub fn new(fabric: &Fabric, opts: &BakeOptions) -> Result<Baker, BakeError> {
        check_options(opts)?;
        let g = opts.grid;
        let mut syms = usable_symmetries(fabric, &g);
        let secondary = opts.bounces.secondary();
        let mut spatial = None;
        let multiple = match opts.bounces {
            BakeBounces::Paths(n) => Some(Arc::new(Multiple::new(fabric, opts.facet, &g, n))),
            _ => None,
        };
        let two_faced = match (g.faces, opts.method) {
            (Faces::Two, Method::Analytic { variant }) => Some(Arc::new(
                TwoFaced::with_grid(
                    fabric,
                    opts.facet,
                    variant,
                    crate::two_faced::NODES,
                    opts.paths,
                )
                .map_err(|e| BakeError::Invalid(e.to_string()))?,
            )),
            _ => None,
        };
        let eval: CellFn = match (opts.method, multiple.clone()) {
            _ if two_faced.is_some() => batched(two_faced.clone().expect("matched")),
            (Method::Analytic { variant }, None) if opts.spatial => {
                let m = with_grid_arcs(
                    AnalyticModel::with_variant(fabric, opts.facet, variant)?,
                    &g,
                );
                let layout = crate::spatial::layout(&m, &g, secondary.is_some())
                    .map_err(BakeError::Invalid)?;
                syms.clear();
                let classes = layout.classes as usize;
                let cells = secondary.map(|_| m.cell_classes_with(true));
                spatial = Some(layout);
                Box::new(move |wi, group, out| {
                    // The average from the classes: each unit (with the second bounce, each
                    // unit beside each neighbour pair) is evaluated once; with one bounce, four
                    // pairs at a time (class_terms_batch, the same bits).
                    let mut terms = vec![ClassTerms::default(); classes * group.len()];
                    match &cells {
                        Some(_) => {
                            for (t, &(_, wo)) in terms.chunks_mut(classes).zip(group) {
                                m.class_terms_with(wi, wo, secondary.as_ref(), t);
                            }
                        }
                        None => {
                            let pairs: Vec<_> = group.iter().map(|&(_, wo)| (wi, wo)).collect();
                            m.class_terms_batch(&pairs, &mut terms);
                        }
                    }
                    for t in terms.chunks(classes) {
                        let average = match &cells {
                            Some(cells) => m.average_of_cells(cells, t),
                            None => m.average_of_classes(t),
                        };
                        out.push(average.map(|x| x as f32));
                        crate::spatial::class_values(t, cells.is_some(), out);
                    }
                })
            }
            (Method::Analytic { variant }, Some(mb)) => {
                let ft = crate::transport::FullTransport::with(fabric, opts.facet, variant, mb)?;
                per_cell(move |_, wi, wo, out| out.push(ft.f(wi, wo).map(|x| x as f32)))
            }
            (Method::Analytic { variant }, None) => {
                let m = with_grid_arcs(
                    AnalyticModel::with_variant(fabric, opts.facet, variant)?,
                    &g,
                );
                // One bounce: four pairs at a time (AnalyticBsdf::f_batch), the same bits.
                batched(Arc::new(AnalyticBsdf::new(m, secondary)))
            }
            (
                Method::Raytrace {
                    samples,
                    seed,
                    caps,
                },
                _,
            ) => {
                let rt = RayTracer::new(fabric, opts.facet).with_caps(caps);
                per_cell(move |c, wi, wo, out| {
                    let f = rt
                        .render(wi, wo, samples, seed.wrapping_add(c as u64))
                        .reflection
                        .brdf(wi);
                    out.push(f.map(|x| x as f32));
                })
            }
        };
        let meta = Metadata {
            format_version: clothbake_loader::version_for(g.faces),
            tool: tool_name(),
            grid: g,
            centring: "cell".into(),
            quantity: "f_r".into(),
            units: "1/sr".into(),
            fabric_json: fabric.to_json().to_string(),
            options_json: opts.to_json().to_string(),
            symmetry: symmetry_name(&syms),
            spatial: None,
            yarns: None,
            openness: two_faced.as_ref().map(|tf| {
                (0..g.n_theta_i)
                    .flat_map(|ti| (0..g.n_phi_i).map(move |pi| (ti, pi)))
                    .map(|(ti, pi)| tf.openness(incident(&g, ti, pi)) as f32)
                    .collect()
            }),
        };
        let orbits = match &spatial {
            Some(l) => Orbits::spatial(&g, l.classes as usize, l.lanes()),
            None => Orbits::new(&g, &syms),
        };
        // A spatial table of one bounce carries its period's yarns: its point level.
        let yarns = (spatial.is_some() && opts.bounces == BakeBounces::One)
            .then(|| clothbake_core::point::period(fabric, opts.facet))
            .flatten()
            .filter(|p| p.yarns().len() <= clothbake_core::point::TABLE_YARNS);
        let meta = Metadata {
            spatial,
            yarns,
            ..meta
        };
        Ok(Baker {
            orbits,
            syms,
            eval,
            meta,
            multiple,
            two_faced,
        })
    }

    /// The orbits (which cells are evaluated).
    pub fn orbits(&self) -> &Orbits {
        &self.orbits
    }

    /// The symmetries used.
    pub fn symmetries(&self) -> &[Symmetry] {
        &self.syms
    }

    /// The metadata of the table this bake makes.
    pub fn metadata(&self) -> &Metadata {
        &self.meta
    }

    /// Evaluates the canonical cells of `row`; `None` when `cancel` was raised meanwhile.
    pub fn eval_row(&self, row: usize, cancel: &AtomicBool) -> Option<Row> {
        let g = self.orbits.grid;
        let (nto, npo) = (g.n_theta_o, g.n_phi_o);
        let (ti, pi) = row_cell(&g, row);
        let wi = incident(&g, ti, pi);
        let mut out = Vec::with_capacity(self.orbits.row_evaluations(row));
        let mut canonical = (0..nto)
            .flat_map(|to| (0..npo).map(move |po| (to, po)))
            .filter(|&(_, po)| self.orbits.canonical(pi as usize, po as usize))
            .map(|(to, po)| (g.index(ti, pi, to, po), outgoing(&g, to, po)));
        let mut cells = Vec::with_capacity(CELLS_AT_ONCE);
        loop {
            cells.clear();
            cells.extend(canonical.by_ref().take(CELLS_AT_ONCE));
            if cells.is_empty() {
                return Some(out);
            }
            // Checked between groups of cells: a row may hold millions of them.
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            (self.eval)(wi, &cells, &mut out);
        }
    }

    /// Evaluates `rows` in parallel on the current rayon pool, handing each finished row to
    /// `sink` (from worker threads, in no particular order). `progress` receives the number of
    /// cells evaluated so far by this call, after each row. Stops with
    /// [`BakeError::Cancelled`] when `cancel` is raised; rows finished before are delivered.
    pub fn sweep(
        &self,
        rows: &[usize],
        progress: &(dyn Fn(u64) + Sync),
        cancel: &AtomicBool,
        sink: &(dyn Fn(usize, Row) + Sync),
    ) -> Result<(), BakeError> {
        if let Some(m) = &self.multiple {
            if !m.prepare(&self.orbits.grid, rows, cancel) {
                return Err(BakeError::Cancelled);
            }
        }
        if let Some(tf) = &self.two_faced {
            if !tf.prepare_or_cancel(cancel) {
                return Err(BakeError::Cancelled);
            }
        }
        let done = AtomicU64::new(0);
        rows.par_iter().for_each(|&row| {
            if let Some(vals) = self.eval_row(row, cancel) {
                let n = vals.len() as u64;
                sink(row, vals);
                progress(done.fetch_add(n, Ordering::Relaxed) + n);
            }
        });
        if cancel.load(Ordering::Relaxed) {
            return Err(BakeError::Cancelled);
        }
        Ok(())
    }

    /// The finished table from every row's canonical values.
    pub fn table(&self, rows: &[Row]) -> Result<Table, BakeError> {
        Table::new(self.meta.clone(), self.orbits.assemble(rows))
            .map_err(|e| BakeError::Invalid(e.to_string()))
    }
}

/// Bakes `fabric` on `opts.grid`. `progress` receives the number of cells evaluated so far, up
/// to [`evaluations`] (copied cells do not count: they cost nothing; it is called from worker
/// threads, once per (theta_i, phi_i) row, not necessarily in increasing order); raising
/// `cancel` stops the sweep with [`BakeError::Cancelled`]. Runs on the current rayon pool (use
/// `ThreadPool::install` to choose the thread count); the result does not depend on the number
/// of threads.
pub fn bake(
    fabric: &Fabric,
    opts: &BakeOptions,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) -> Result<Baked, BakeError> {
    let baker = Baker::new(fabric, opts)?;
    let all: Vec<usize> = (0..baker.orbits.rows()).collect();
    let slots: Vec<Mutex<Row>> = all.iter().map(|_| Mutex::new(Vec::new())).collect();
    baker.sweep(&all, progress, cancel, &|row, vals| {
        *slots[row].lock().expect("no panics while held") = vals;
    })?;
    let rows: Vec<Row> = slots
        .into_iter()
        .map(|m| m.into_inner().expect("no panics while held"))
        .collect();
    let table = baker.table(&rows)?;
    Ok(Baked {
        table,
        evaluated: baker.orbits.evaluations(),
        symmetries: baker.syms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_core::Kernel;

    fn twill() -> Fabric {
        Fabric::from_path(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/twill.json"),
        )
        .unwrap()
    }

    #[test]
    fn options_json_names_everything_that_changes_the_table() {
        let o = BakeOptions::default();
        let v = o.to_json();
        assert_eq!(v["method"], "analytic");
        assert_eq!(v["variant"], "refined");
        assert_eq!(v["facet"], "huo");
        assert_eq!(v["bounces"], 1);
        assert_eq!(v["grid"]["n_phi_o"], 64);
        assert!(v.get("secondary").is_none());
        let o = BakeOptions {
            bounces: BakeBounces::Two(SecondaryOptions::default()),
            ..BakeOptions::default()
        };
        let v = o.to_json();
        assert_eq!(v["secondary"]["method"], "analytic");
        assert_eq!(v["secondary"]["kernel"], "radiometric");
        assert_eq!(v["secondary"]["ranges"], "full");
        assert_eq!(v["secondary"]["orders"]["theta"], Orders::default().theta);
        let o = BakeOptions {
            bounces: BakeBounces::Two(SecondaryOptions {
                method: SecondaryMethod::Sampling(Sampling::default()),
                kernel: Kernel::Thesis,
            }),
            ..BakeOptions::default()
        };
        let v = o.to_json();
        assert_eq!(v["secondary"]["method"], "sampling");
        assert_eq!(v["secondary"]["kernel"], "thesis");
        assert_eq!(v["secondary"]["sampling"]["first_level"], 32);
        let o = BakeOptions {
            method: Method::Raytrace {
                samples: 10,
                seed: 3,
                caps: Caps::Shaded,
            },
            ..BakeOptions::default()
        };
        let v = o.to_json();
        assert_eq!(
            (&v["method"], &v["samples"], &v["seed"], &v["caps"]),
            (&json!("raytrace"), &json!(10), &json!(3), &json!("shaded"))
        );
    }

    #[test]
    fn invalid_options_are_refused() {
        let f = twill();
        let none = AtomicBool::new(false);
        for (o, needle) in [
            (
                BakeOptions {
                    bounces: BakeBounces::Paths(0),
                    ..BakeOptions::default()
                },
                "--bounces 1",
            ),
            (
                BakeOptions {
                    bounces: BakeBounces::Two(SecondaryOptions::default()),
                    method: Method::Raytrace {
                        samples: 1,
                        seed: 1,
                        caps: Caps::Excluded,
                    },
                    ..BakeOptions::default()
                },
                "--method analytic",
            ),
            (
                BakeOptions {
                    grid: Grid {
                        n_theta_i: 0,
                        ..DEFAULT_GRID
                    },
                    ..BakeOptions::default()
                },
                "n_theta_i is 0",
            ),
        ] {
            match bake(&f, &o, &|_| {}, &none) {
                Err(BakeError::Invalid(m)) => assert!(m.contains(needle), "{m}"),
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn cancel_stops_the_bake() {
        let cancel = AtomicBool::new(true);
        let r = bake(&twill(), &BakeOptions::default(), &|_| {}, &cancel);
        assert_eq!(r.unwrap_err(), BakeError::Cancelled);
    }

    #[test]
    fn orbits() {
        let g = Grid::new(1, 8, 1, 8);
        let all = [Symmetry::MirrorX, Symmetry::MirrorY, Symmetry::Rotate180];
        // Each orbit of the full group has 4 elements (no cell centre is on a mirror line).
        let canonical = (0..8)
            .flat_map(|a| (0..8).map(move |b| (a, b)))
            .filter(|&(a, b)| representative(a, b, &all, &g) == (a, b))
            .count();
        assert_eq!(canonical, 16);
        assert_eq!(representative(5, 3, &[], &g), (5, 3));
        assert_eq!(representative(5, 3, &[Symmetry::Rotate180], &g), (1, 7));
    }

    /// A sliced3d bake keeps the open arcs of every direction of its grid, and its model gives
    /// the bits of one that keeps none at every pair of the grid (with and without I_2).
    #[test]
    fn a_sliced3d_bake_keeps_its_grids_arcs_with_the_same_bits() {
        let f = twill();
        let g = Grid::new(5, 8, 4, 12);
        let plain = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Sliced3d)
            .expect("the variant takes the period");
        let kept = with_grid_arcs(plain.clone(), &g);
        // 5 x 8 incident and 4 x 12 outgoing directions, none shared.
        assert_eq!(kept.open_arcs_kept(), 5 * 8 + 4 * 12);
        let (plain, kept) = (
            AnalyticBsdf::new(plain, None),
            AnalyticBsdf::new(kept, Some(SecondaryOptions::default())),
        );
        let both = AnalyticBsdf::new(
            AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Sliced3d)
                .expect("the variant takes the period"),
            Some(SecondaryOptions::default()),
        );
        let direct = AnalyticBsdf::new(with_grid_arcs(both.model().clone(), &g), None);
        for (ti, pi) in (0..5).flat_map(|t| (0..8).map(move |p| (t, p))) {
            for (to, po) in (0..4).flat_map(|t| (0..12).map(move |p| (t, p))) {
                let (wi, wo) = (incident(&g, ti, pi), outgoing(&g, to, po));
                assert_eq!(direct.f(wi, wo), plain.f(wi, wo));
                assert_eq!(kept.f(wi, wo), both.f(wi, wo));
            }
        }
        let refined = with_grid_arcs(AnalyticModel::new(&f, FacetModel::Huo), &g);
        assert_eq!(refined.open_arcs_kept(), 0);
    }
}
