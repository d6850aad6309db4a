//! Ground truth: an orthographic ray caster over the explicit micro-geometry ([`crate::geometry`]).
//!
//! [`RayTracer::render`] estimates the thesis's averaged intensity (eq. 4.11 and its pseudocode,
//! `I_total /= S_total`): the facet intensity averaged over the *visible projected area of the
//! yarns* of one weave period, seen from `wo` and lit from `wi`, with exact visibility and exact
//! shadowing by every yarn of the periodic tiling.
//!
//! * Primary rays are parallel to `-wo`. Their origins are spread uniformly (stratified jitter)
//!   over one period `[0, Px) x [0, Py)` of a horizontal plane just above the highest yarn, i.e.
//!   uniformly over the period's projected area seen from `wo`.
//! * A ray's first hit is searched among all segments of all period copies its path crosses
//!   between that plane and the floor z = 0 (a 2-D grid walk over the tiling, see [`CellWalk`]),
//!   and the floor itself. Rays whose first hit is the floor are not counted at all, neither in
//!   the numerator nor in the denominator: the thesis averages over the yarns only.
//! * The surfaces are the cylinder sides (above the floor, within the segment's extent) and the
//!   flat end caps (discs of the cylinder's radius cut by the floor), whose normals are -+ the
//!   axis direction. By default ([`Caps::Excluded`]) rays ending on a cap are not counted either
//!   (caps stand for the thread diving under its crossing thread, which the thesis leaves out);
//!   [`Caps::Shaded`] counts them as shaded yarn.
//! * At a yarn hit with outward normal N, the facet intensity `facet.intensity(material, N, wi,
//!   wo)` is taken when the shadow ray toward `wi` leaves the top plane without hitting anything
//!   (zero otherwise): its diffuse factor times the thread's RGB albedo goes to `i_d`, its specular
//!   part to `i_s`.
//! * The estimate is the ratio (sum of shading) / (number of yarn hits). Its standard error comes
//!   from [`BATCHES`] independent batches, each a stratified set of its own, see [`Estimate`].
//!
//! Everything is deterministic for a given seed: no threads, and a SplitMix64 stream
//! ([`crate::rng`]) per batch.

use crate::fabric::{Fabric, Material};
use crate::facet::{Facet, FacetModel};
use crate::geometry::Geometry;
use crate::reflect::Reflection;
use crate::rng::Rng;
use crate::vec3::{UnitVec3, Vec3};
use crate::weave::Group;

/// Number of independent batches the samples are split into to estimate the standard error.
pub const BATCHES: usize = 16;

/// First sample count of [`RayTracer::render_to_error`] (before doubling).
const FIRST_ROUND: usize = 16 * 256;

/// A Monte Carlo estimate of the reflected intensity.
///
/// The standard error is that of the ratio estimator R = sum(S_b) / sum(H_b) over the batches b
/// (S_b: summed shading, H_b: yarn hits): with B non-empty batches, R_b = S_b / H_b and weights
/// w_b = H_b / mean(H),
/// `std_err^2 = sum_b w_b^2 (R_b - R)^2 / (B (B - 1))`,
/// i.e. the standard error of the mean of the batch ratios, each weighted by its share of the
/// hits (the usual delta-method variance of a ratio estimator; batches without hits contribute
/// their zero weight instead of an undefined ratio). It is infinite when fewer than two batches
/// received rays and zero when there were no yarn hits.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    /// The estimated intensity (diffuse and specular parts).
    pub reflection: Reflection,
    /// Standard error of the total intensity I = I_d + I_s, per channel.
    pub std_err: [f64; 3],
    /// Primary rays whose first hit was a yarn (the denominator).
    pub yarn_hits: usize,
    /// Primary rays traced.
    pub rays: usize,
}

/// Which surface of a segment a ray enters through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Surface {
    /// The curved side of the cylinder.
    Side,
    /// The end cap at the low end of the extent (outward normal: minus the axis direction).
    CapLo,
    /// The end cap at the high end of the extent (outward normal: plus the axis direction).
    CapHi,
}

/// Parameter interval `(t_in, t_out)` in which the line `o + t d` lies inside the infinite
/// cylinder of radius `radius` whose axis is parallel to the v axis through (u, z) =
/// (`axis`, `height`); arguments are the u and z components of origin and direction. `None`
/// when the line misses it or runs parallel to the axis (`du = dz = 0`).
pub fn cylinder_interval(
    ou: f64,
    oz: f64,
    du: f64,
    dz: f64,
    axis: f64,
    height: f64,
    radius: f64,
) -> Option<(f64, f64)> {
    let a = du * du + dz * dz;
    if a == 0.0 {
        return None;
    }
    let (pu, pz) = (ou - axis, oz - height);
    let b = du * pu + dz * pz; // half the linear coefficient
    let c = pu * pu + pz * pz - radius * radius;
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    // Numerically stable roots of a t^2 + 2 b t + c = 0.
    let q = -(b + disc.sqrt().copysign(b));
    if q == 0.0 {
        return Some((0.0, 0.0));
    }
    let (t0, t1) = (q / a, c / q);
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// Parameter interval in which the line `ov + t dv` (the component along a segment's axis)
/// lies between the planes of its two end caps, `lo <= v <= hi`. `None` when it never does.
/// Entering this slab while inside the cylinder and above the floor is exactly hitting a cap
/// disc (cut at z >= 0): the low cap when `dv > 0`, the high cap when `dv < 0`.
pub fn cap_slab_interval(ov: f64, dv: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
    if dv == 0.0 {
        return (lo..=hi)
            .contains(&ov)
            .then_some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let (ta, tb) = ((lo - ov) / dv, (hi - ov) / dv);
    Some(if ta <= tb { (ta, tb) } else { (tb, ta) })
}

/// A ray in a segment's own frame: u across the axis (horizontal), v along it, z up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalRay {
    /// Origin (u, v, z).
    pub o: [f64; 3],
    /// Direction (u, v, z), not necessarily normalised.
    pub d: [f64; 3],
}

/// The solid of one segment in its own frame: the cylinder about the axis at u = `axis`, z =
/// `height`, within `extent` along v (`None`: endless), cut by the floor (z >= 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentShape {
    /// Across coordinate of the axis.
    pub axis: f64,
    /// Height of the axis above the floor.
    pub height: f64,
    /// Cylinder radius.
    pub radius: f64,
    /// Extent along the axis, `None` when endless.
    pub extent: Option<(f64, f64)>,
}

/// The first point where the ray enters the segment's solid with `t_min < t < t_max`, and the
/// surface it enters through. The solid is the intersection of three convex sets (infinite
/// cylinder, cap slab, half-space z >= 0), so the ray enters it at the last of their entries
/// and must do so before the first of their exits. An entry through the floor plane (a ray
/// coming from below the floor) is the floor's hit, not the yarn's, and gives `None`.
pub fn segment_entry(
    ray: &LocalRay,
    s: &SegmentShape,
    t_min: f64,
    t_max: f64,
) -> Option<(f64, Surface)> {
    let [ou, ov, oz] = ray.o;
    let [du, dv, dz] = ray.d;
    let (mut t_in, mut t_out) = cylinder_interval(ou, oz, du, dz, s.axis, s.height, s.radius)?;
    let mut surface = Surface::Side;
    if let Some((lo, hi)) = s.extent {
        let (a, b) = cap_slab_interval(ov, dv, lo, hi)?;
        if a > t_in {
            t_in = a;
            surface = if dv > 0.0 {
                Surface::CapLo
            } else {
                Surface::CapHi
            };
        }
        t_out = t_out.min(b);
    }
    // Half-space z >= 0.
    if dz < 0.0 {
        t_out = t_out.min(-oz / dz);
    } else if dz > 0.0 {
        if -oz / dz > t_in {
            return None;
        }
    } else if oz < 0.0 {
        return None;
    }
    (t_in < t_out && t_in > t_min && t_in < t_max).then_some((t_in, surface))
}

/// One cell of the walk over the periodic grid: unwrapped cell indices and the ray parameter at
/// which the ray leaves it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellVisit {
    /// Unwrapped cell index along x (cell `ix` covers `[ix cx, (ix + 1) cx)`).
    pub ix: i64,
    /// Unwrapped cell index along y.
    pub iy: i64,
    /// Ray parameter at which the ray leaves the cell (capped at `t_max`).
    pub t_exit: f64,
}

/// The period-copy enumeration: the cells of an unbounded grid of cell size (`cx`, `cy`) that
/// the xy path `(ox, oy) + t (dx, dy)`, `0 <= t <= t_max`, crosses, in order (a 2-D DDA after
/// Amanatides & Woo). With cells that divide the period, cell (ix, iy) belongs to period copy
/// (ix div nx, iy div ny) and is that copy's local cell (ix mod nx, iy mod ny), so every
/// copy of every segment the path could hit is visited, however long (grazing) the path is.
#[derive(Clone, Debug)]
pub struct CellWalk {
    ix: i64,
    iy: i64,
    step_x: i64,
    step_y: i64,
    next_x: f64,
    next_y: f64,
    delta_x: f64,
    delta_y: f64,
    t_max: f64,
    done: bool,
}

impl CellWalk {
    /// Starts the walk at the cell containing (`ox`, `oy`).
    pub fn new(ox: f64, oy: f64, dx: f64, dy: f64, cx: f64, cy: f64, t_max: f64) -> CellWalk {
        let ix = (ox / cx).floor() as i64;
        let iy = (oy / cy).floor() as i64;
        let axis = |i: i64, o: f64, d: f64, c: f64| -> (i64, f64, f64) {
            if d > 0.0 {
                (1, ((i + 1) as f64 * c - o) / d, c / d)
            } else if d < 0.0 {
                (-1, (i as f64 * c - o) / d, -c / d)
            } else {
                (0, f64::INFINITY, f64::INFINITY)
            }
        };
        let (step_x, next_x, delta_x) = axis(ix, ox, dx, cx);
        let (step_y, next_y, delta_y) = axis(iy, oy, dy, cy);
        CellWalk {
            ix,
            iy,
            step_x,
            step_y,
            next_x: next_x.max(0.0),
            next_y: next_y.max(0.0),
            delta_x,
            delta_y,
            t_max,
            done: false,
        }
    }
}

impl Iterator for CellWalk {
    type Item = CellVisit;

    fn next(&mut self) -> Option<CellVisit> {
        if self.done {
            return None;
        }
        let t_exit = self.next_x.min(self.next_y);
        let visit = CellVisit {
            ix: self.ix,
            iy: self.iy,
            t_exit: t_exit.min(self.t_max),
        };
        if t_exit >= self.t_max {
            self.done = true;
        } else if self.next_x <= self.next_y {
            self.ix += self.step_x;
            self.next_x += self.delta_x;
        } else {
            self.iy += self.step_y;
            self.next_y += self.delta_y;
        }
        Some(visit)
    }
}

/// One copy of a segment of the period, placed so that it overlaps the period's base cell.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Prim {
    /// Index of the segment in `geometry.segments`.
    pub(crate) seg: u32,
    /// Warp (axis along y; u = x, v = y) or weft (axis along x; u = y, v = x).
    warp: bool,
    /// The solid, in coordinates of the base period.
    shape: SegmentShape,
    /// Offset of this copy in periods (x, y); the along-axis part is 0 for endless segments.
    shift: (i64, i64),
}

impl Prim {
    fn local(&self, o: Vec3, d: Vec3) -> LocalRay {
        if self.warp {
            LocalRay {
                o: [o.x, o.y, o.z],
                d: [d.x, d.y, d.z],
            }
        } else {
            LocalRay {
                o: [o.y, o.x, o.z],
                d: [d.y, d.x, d.z],
            }
        }
    }

    /// Outward normal at the point `p` (base-period coordinates) of the given surface.
    pub(crate) fn normal(&self, p: Vec3, surface: Surface) -> Vec3 {
        let s = &self.shape;
        let (u, z) = if self.warp { (p.x, p.z) } else { (p.y, p.z) };
        let (nu, nv, nz) = match surface {
            Surface::Side => {
                let (a, b) = (u - s.axis, z - s.height);
                let l = (a * a + b * b).sqrt();
                (a / l, 0.0, b / l)
            }
            Surface::CapLo => (0.0, -1.0, 0.0),
            Surface::CapHi => (0.0, 1.0, 0.0),
        };
        if self.warp {
            Vec3::new(nu, nv, nz)
        } else {
            Vec3::new(nv, nu, nz)
        }
    }

    /// Identity of the physical segment copy when this prim is seen from period copy (tx, ty).
    pub(crate) fn copy_key(&self, tx: i64, ty: i64) -> (u32, i64, i64) {
        let endless = self.shape.extent.is_none();
        let kx = if endless && !self.warp {
            0
        } else {
            tx + self.shift.0
        };
        let ky = if endless && self.warp {
            0
        } else {
            ty + self.shift.1
        };
        (self.seg, kx, ky)
    }
}

/// Uniform grid over one period: for each cell the prims whose bounding boxes overlap it.
#[derive(Clone, Debug)]
pub(crate) struct Grid {
    nx: i64,
    ny: i64,
    cx: f64,
    cy: f64,
    pub(crate) prims: Vec<Prim>,
    /// `items[starts[c]..starts[c + 1]]` are the prims of cell c = ly * nx + lx.
    starts: Vec<u32>,
    items: Vec<u32>,
}

/// Most cells the grid may have.
const MAX_CELLS: usize = 1 << 20;

impl Grid {
    fn new(g: &Geometry) -> Grid {
        let (px, py) = g.period;
        let target = g
            .segments
            .iter()
            .map(|s| s.radius)
            .fold(f64::INFINITY, f64::min);
        let count = |p: f64| -> i64 {
            if target.is_finite() {
                ((p / target).ceil() as i64).clamp(1, 4096)
            } else {
                1
            }
        };
        let (mut nx, mut ny) = (count(px), count(py));
        while (nx * ny) as usize > MAX_CELLS {
            nx = (nx / 2).max(1);
            ny = (ny / 2).max(1);
        }
        let (cx, cy) = (px / nx as f64, py / ny as f64);
        let eps = 1e-9 * (px + py);
        let mut prims = Vec::new();
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); (nx * ny) as usize];
        for (k, s) in g.segments.iter().enumerate() {
            let warp = s.group == Group::Warp;
            let (p_across, p_along) = if warp { (px, py) } else { (py, px) };
            let across = (s.axis - s.radius - eps, s.axis + s.radius + eps);
            let along = match s.extent {
                Some((lo, hi)) => (lo - eps, hi + eps),
                None => (0.0, p_along), // one copy covers the whole period along the axis
            };
            let shifts = |(lo, hi): (f64, f64), p: f64, endless: bool| -> Vec<i64> {
                if endless {
                    return vec![0];
                }
                let first = ((-hi) / p).floor() as i64;
                let last = ((p - lo) / p).ceil() as i64;
                (first..=last)
                    .filter(|&i| lo + i as f64 * p < p && hi + i as f64 * p > 0.0)
                    .collect()
            };
            for sa in shifts(across, p_across, false) {
                for sl in shifts(along, p_along, s.extent.is_none()) {
                    let (off_a, off_l) = (sa as f64 * p_across, sl as f64 * p_along);
                    let (xr, yr, shift) = if warp {
                        (
                            (across.0 + off_a, across.1 + off_a),
                            (along.0 + off_l, along.1 + off_l),
                            (sa, sl),
                        )
                    } else {
                        (
                            (along.0 + off_l, along.1 + off_l),
                            (across.0 + off_a, across.1 + off_a),
                            (sl, sa),
                        )
                    };
                    let id = prims.len() as u32;
                    prims.push(Prim {
                        seg: k as u32,
                        warp,
                        shape: SegmentShape {
                            axis: s.axis + off_a,
                            height: s.height,
                            radius: s.radius,
                            extent: s.extent.map(|(lo, hi)| (lo + off_l, hi + off_l)),
                        },
                        shift,
                    });
                    let cells = |(lo, hi): (f64, f64), c: f64, n: i64| {
                        let a = ((lo / c).floor() as i64).clamp(0, n - 1);
                        let b = ((hi / c).floor() as i64).clamp(0, n - 1);
                        a..=b
                    };
                    for ly in cells(yr, cy, ny) {
                        for lx in cells(xr, cx, nx) {
                            lists[(ly * nx + lx) as usize].push(id);
                        }
                    }
                }
            }
        }
        let mut starts = Vec::with_capacity(lists.len() + 1);
        let mut items = Vec::new();
        for l in &lists {
            starts.push(items.len() as u32);
            items.extend_from_slice(l);
        }
        starts.push(items.len() as u32);
        Grid {
            nx,
            ny,
            cx,
            cy,
            prims,
            starts,
            items,
        }
    }
}

/// A ray's first yarn hit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    pub(crate) t: f64,
    pub(crate) prim: u32,
    pub(crate) tile: (i64, i64),
    pub(crate) surface: Surface,
}

/// Per-batch sums of the estimator.
#[derive(Clone, Copy, Debug, Default)]
struct BatchSums {
    /// Sum of diffuse factor times albedo, per channel.
    diffuse: [f64; 3],
    /// Sum of the specular intensity.
    specular: f64,
    hits: u64,
    rays: u64,
}

impl BatchSums {
    /// Summed shading of the quantity selected by `f(diffuse, specular)`.
    fn shade(&self, f: impl Fn(&[f64; 3], f64) -> f64) -> f64 {
        f(&self.diffuse, self.specular)
    }
}

/// Ratio estimate and its standard error (see [`Estimate`]) of the per-hit mean of `f`.
fn ratio_and_error(sums: &[BatchSums], f: impl Fn(&[f64; 3], f64) -> f64) -> (f64, f64) {
    let batches: Vec<(f64, u64, u64)> =
        sums.iter().map(|b| (b.shade(&f), b.hits, b.rays)).collect();
    batch_ratio(&batches)
}

/// The ratio estimate (sum of shading) / (yarn hits) over batches given as (sum, hits, rays),
/// and its standard error from the spread of the batches: the estimator of [`Estimate`],
/// shared with the path tracer.
pub(crate) fn batch_ratio(batches: &[(f64, u64, u64)]) -> (f64, f64) {
    let h: u64 = batches.iter().map(|b| b.1).sum();
    if h == 0 {
        return (0.0, 0.0);
    }
    let h = h as f64;
    let r = batches.iter().map(|b| b.0).sum::<f64>() / h;
    let nb = batches.iter().filter(|b| b.2 > 0).count();
    if nb < 2 {
        return (r, f64::INFINITY);
    }
    let mean_h = h / nb as f64;
    // (w_b (R_b - R))^2 = ((S_b - R H_b) / mean(H))^2.
    let ss: f64 = batches
        .iter()
        .filter(|b| b.2 > 0)
        .map(|b| ((b.0 - r * b.1 as f64) / mean_h).powi(2))
        .sum();
    (r, (ss / (nb * (nb - 1)) as f64).sqrt())
}

fn estimate(sums: &[BatchSums]) -> Estimate {
    let mut e = Estimate {
        yarn_hits: sums.iter().map(|b| b.hits as usize).sum(),
        rays: sums.iter().map(|b| b.rays as usize).sum(),
        ..Estimate::default()
    };
    for k in 0..3 {
        e.reflection.i_d[k] = ratio_and_error(sums, |d, _| d[k]).0;
        e.std_err[k] = ratio_and_error(sums, |d, s| d[k] + s).1;
    }
    e.reflection.i_s = [ratio_and_error(sums, |_, s| s).0; 3];
    e
}

/// How the flat end caps of the segments count in the average.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Caps {
    /// Caps occlude (they hide and shadow) but, like the floor, rays ending on them are not
    /// counted: they stand for the part of a thread that dives under its crossing thread, which
    /// the thesis does not model and the analytic model does not average over (default).
    #[default]
    Excluded,
    /// Caps are shaded yarn surface with normal along the axis and counted like the sides.
    Shaded,
}

/// The exact orthographic ray caster of a fabric's micro-geometry (the ground truth).
#[derive(Clone, Debug)]
pub struct RayTracer {
    pub(crate) geometry: Geometry,
    pub(crate) facet: FacetModel,
    pub(crate) caps: Caps,
    pub(crate) grid: Grid,
    /// Facet material of each segment.
    pub(crate) materials: Vec<Material>,
    /// Height of the plane the primary rays start from, just above the highest yarn.
    pub(crate) z_top: f64,
}

impl RayTracer {
    /// Builds the tracer (geometry and acceleration grid) of a validated fabric.
    pub fn new(fabric: &Fabric, facet: FacetModel) -> Self {
        Self::from_geometry(Geometry::new(fabric), facet)
    }

    /// Builds the tracer of an explicit geometry (materials from `geometry.fabric`). The
    /// segments must be disjoint solids and the period positive.
    pub fn from_geometry(geometry: Geometry, facet: FacetModel) -> Self {
        let grid = Grid::new(&geometry);
        let materials = geometry
            .segments
            .iter()
            .map(|s| geometry.fabric.thread_material(s.group, s.thread))
            .collect();
        let top = geometry.max_top();
        let z_top = top + 1e-6 * top.max(1e-3);
        RayTracer {
            geometry,
            facet,
            caps: Caps::default(),
            grid,
            materials,
            z_top,
        }
    }

    /// The same tracer with end caps counted as `caps` says.
    pub fn with_caps(mut self, caps: Caps) -> Self {
        self.caps = caps;
        self
    }

    /// How end caps count.
    pub fn caps(&self) -> Caps {
        self.caps
    }

    /// The micro-geometry being rendered.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The facet model in use.
    pub fn facet(&self) -> FacetModel {
        self.facet
    }

    /// The first yarn surface the ray `o + t d` enters with `t_min < t < t_max`; with `any`, the
    /// first one found (for shadow rays). `skip` excludes one physical segment copy.
    pub(crate) fn trace(
        &self,
        o: Vec3,
        d: Vec3,
        t_min: f64,
        t_max: f64,
        any: bool,
        skip: Option<(u32, i64, i64)>,
    ) -> Option<Hit> {
        let g = &self.grid;
        let (px, py) = self.geometry.period;
        let mut best: Option<Hit> = None;
        let mut best_t = t_max;
        for cell in CellWalk::new(o.x, o.y, d.x, d.y, g.cx, g.cy, t_max) {
            let (tx, ty) = (cell.ix.div_euclid(g.nx), cell.iy.div_euclid(g.ny));
            let c = (cell.iy.rem_euclid(g.ny) * g.nx + cell.ix.rem_euclid(g.nx)) as usize;
            let items = &g.items[g.starts[c] as usize..g.starts[c + 1] as usize];
            if !items.is_empty() {
                let ol = Vec3::new(o.x - tx as f64 * px, o.y - ty as f64 * py, o.z);
                for &id in items {
                    let p = &g.prims[id as usize];
                    if let Some((t, surface)) =
                        segment_entry(&p.local(ol, d), &p.shape, t_min, best_t)
                    {
                        if skip.is_some_and(|k| k == p.copy_key(tx, ty)) {
                            continue;
                        }
                        best_t = t;
                        best = Some(Hit {
                            t,
                            prim: id,
                            tile: (tx, ty),
                            surface,
                        });
                        if any {
                            return best;
                        }
                    }
                }
            }
            if best_t <= cell.t_exit {
                break;
            }
        }
        best
    }

    /// Shading of one primary ray from `o` along `d = -wo`: `None` for a floor hit, otherwise
    /// the facet intensity's (diffuse factor, specular, segment) at the first yarn hit (zero
    /// when shadowed).
    fn shade(&self, o: Vec3, wi: UnitVec3, wo: UnitVec3) -> Option<(f64, f64, u32)> {
        let d = -wo.get();
        let t_floor = o.z / -d.z;
        let hit = self.trace(o, d, 0.0, t_floor, false, None)?;
        if self.caps == Caps::Excluded && hit.surface != Surface::Side {
            return None;
        }
        let p = &self.grid.prims[hit.prim as usize];
        let (px, py) = self.geometry.period;
        let world = o + d * hit.t;
        let local = Vec3::new(
            world.x - hit.tile.0 as f64 * px,
            world.y - hit.tile.1 as f64 * py,
            world.z,
        );
        let n = p.normal(local, hit.surface);
        let fi = self
            .facet
            .intensity(&self.materials[p.seg as usize], n, wi.get(), wo.get());
        if fi.diffuse == 0.0 && fi.specular == 0.0 {
            return Some((0.0, 0.0, p.seg));
        }
        let t_out = (self.z_top - world.z) / wi.z;
        let key = p.copy_key(hit.tile.0, hit.tile.1);
        if self
            .trace(world, wi.get(), 0.0, t_out, true, Some(key))
            .is_some()
        {
            return Some((0.0, 0.0, p.seg));
        }
        Some((fi.diffuse, fi.specular, p.seg))
    }

    /// Traces `m` stratified primary rays over one period into `sums`.
    /// The origins of `m` stratified primary rays over one period (jittered with `rng`).
    pub(crate) fn origins(&self, m: usize, rng: &mut Rng) -> impl Iterator<Item = Vec3> + '_ {
        let (px, py) = self.geometry.period;
        // sx * sy <= m strata of aspect ~ Px:Py, the remaining (< sx) samples uniform.
        let sx = ((m as f64 * px / py).sqrt().round() as usize).clamp(1, m.max(1));
        let sy = (m / sx).max(1);
        let strata = (sx * sy).min(m);
        let jitter: Vec<(f64, f64)> = (0..m).map(|_| (rng.next_f64(), rng.next_f64())).collect();
        jitter.into_iter().enumerate().map(move |(k, (u, v))| {
            let (x, y) = if k < strata {
                (
                    ((k % sx) as f64 + u) / sx as f64,
                    ((k / sx) as f64 + v) / sy as f64,
                )
            } else {
                (u, v)
            };
            Vec3::new(x * px, y * py, self.z_top)
        })
    }

    fn batch(&self, wi: UnitVec3, wo: UnitVec3, m: usize, rng: &mut Rng, sums: &mut BatchSums) {
        for o in self.origins(m, rng) {
            sums.rays += 1;
            if let Some((diffuse, specular, seg)) = self.shade(o, wi, wo) {
                sums.hits += 1;
                let albedo = self.materials[seg as usize].albedo;
                for (s, a) in sums.diffuse.iter_mut().zip(albedo) {
                    *s += diffuse * a;
                }
                sums.specular += specular;
            }
        }
    }

    /// Adds round `round` of `samples` rays (spread over the batches) to `sums`.
    fn accumulate(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        samples: usize,
        seed: u64,
        round: u64,
        sums: &mut [BatchSums; BATCHES],
    ) {
        for (b, s) in sums.iter_mut().enumerate() {
            let m = samples / BATCHES + usize::from(b < samples % BATCHES);
            let mut rng = Rng::stream(seed, round * BATCHES as u64 + b as u64);
            self.batch(wi, wo, m, &mut rng, s);
        }
    }

    /// Estimates the intensity reflected toward `wo` (unit vector toward the eye) for unit light
    /// from `wi` with `samples` primary rays; deterministic for a given `seed`. Zero, with no
    /// rays, when either direction is at or below the horizon.
    pub fn render(&self, wi: UnitVec3, wo: UnitVec3, samples: usize, seed: u64) -> Estimate {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return Estimate::default();
        }
        let mut sums = [BatchSums::default(); BATCHES];
        self.accumulate(wi, wo, samples, seed, 0, &mut sums);
        estimate(&sums)
    }

    /// As [`RayTracer::render`], doubling the number of samples (each round adds as many fresh
    /// rays as all the rounds before it) until the standard error of the channel-mean total
    /// intensity is at most `rel_err` times that mean, or `max_samples` rays have been traced.
    pub fn render_to_error(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        rel_err: f64,
        max_samples: usize,
        seed: u64,
    ) -> Estimate {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return Estimate::default();
        }
        let mut sums = [BatchSums::default(); BATCHES];
        let mut total = 0usize;
        let mut next = FIRST_ROUND.min(max_samples);
        for round in 0.. {
            self.accumulate(wi, wo, next, seed, round, &mut sums);
            total += next;
            let hits: u64 = sums.iter().map(|b| b.hits).sum();
            let (mean, se) = ratio_and_error(&sums, |d, s| (d[0] + d[1] + d[2]) / 3.0 + s);
            if (hits > 0 && se <= rel_err * mean) || total >= max_samples {
                break;
            }
            next = total.min(max_samples - total);
        }
        estimate(&sums)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Segment;
    use crate::weave::Float;
    use std::f64::consts::PI;

    fn fabric(json: &str) -> Fabric {
        Fabric::from_json_str(json, "test").unwrap()
    }

    /// One endless warp cylinder (radius 1, axis on the floor), neighbours 1000 away.
    fn lone(material: &str) -> RayTracer {
        let json = format!(
            r#"{{"pattern": [[1]], "warp": {{"radius": 1, "spacing": 1000, "material": {material}}},
                "weft": {{"radius": 0.5, "spacing": 1}}}}"#
        );
        RayTracer::new(&fabric(&json), FacetModel::Huo)
    }

    fn twill() -> RayTracer {
        RayTracer::new(
            &fabric(
                r#"{"pattern": [[1,1,0],[0,1,1],[1,0,1]],
                    "warp": {"radius": 1.5, "spacing": 3.1}, "weft": {"radius": 1.5, "spacing": 3.1}}"#,
            ),
            FacetModel::Huo,
        )
    }

    fn dir(theta_deg: f64, phi_deg: f64) -> UnitVec3 {
        UnitVec3::from_degrees(theta_deg, phi_deg)
    }

    /// Thesis eqs 4.7 / 4.10 for one cylinder cross-section in the XZ plane: the average of
    /// `f(theta)` over the visible upper half circle, points N = (cos t, 0, sin t) with
    /// cos(t - tE) > 0, weighted by the correction factor cos(t - tE). Midpoint quadrature.
    fn arc_average(e_angle: f64, f: impl Fn(f64) -> f64) -> f64 {
        let n = 200_000;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            let t = (i as f64 + 0.5) / n as f64 * PI;
            let w = (t - e_angle).cos();
            if w > 0.0 {
                num += f(t) * w;
                den += w;
            }
        }
        num / den
    }

    /// Elevation angle, measured from +X in the XZ plane, of a direction in that plane.
    fn xz_angle(d: UnitVec3) -> f64 {
        assert!(d.y.abs() < 1e-12);
        d.z.atan2(d.x)
    }

    const XZ_CASES: [(f64, f64, f64, f64); 7] = [
        // (theta_i, phi_i, theta_o, phi_o), degrees; phi 0 or 180 keeps both in the XZ plane.
        (30.0, 0.0, 50.0, 180.0),
        (0.0, 0.0, 60.0, 0.0),
        (70.0, 180.0, 20.0, 0.0),
        (45.0, 0.0, 45.0, 0.0),
        (60.0, 0.0, 85.0, 180.0),
        (85.0, 0.0, 30.0, 180.0),
        (80.0, 180.0, 85.0, 0.0),
    ];

    #[test]
    fn lone_cylinder_diffuse_matches_quadrature() {
        let albedo = [0.2, 0.5, 0.8];
        let rt = lone(r#"{"albedo": [0.2, 0.5, 0.8], "specular": 0}"#);
        for (k, &(ti, pi, to, po)) in XZ_CASES.iter().enumerate() {
            let (wi, wo) = (dir(ti, pi), dir(to, po));
            let (tl, te) = (xz_angle(wi), xz_angle(wo));
            let want = arc_average(te, |t| (t - tl).cos().max(0.0));
            let est = rt.render(wi, wo, 1 << 22, k as u64);
            assert!(est.yarn_hits > 5000, "{est:?}");
            for (c, rho) in albedo.into_iter().enumerate() {
                let got = est.reflection.i_d[c];
                let tol = 4.0 * est.std_err[c] + 0.002 * rho * want;
                assert!(
                    (got - rho * want).abs() < tol,
                    "case {k} channel {c}: got {got}, want {}, tol {tol}, {est:?}",
                    rho * want
                );
                assert_eq!(est.reflection.i_s[c], 0.0);
            }
        }
    }

    #[test]
    fn lone_cylinder_specular_matches_quadrature() {
        let rt = lone(r#"{"albedo": 0, "specular": 1, "exponent": 10}"#);
        for (k, &(ti, pi, to, po)) in XZ_CASES.iter().enumerate() {
            let (wi, wo) = (dir(ti, pi), dir(to, po));
            let (tl, te) = (xz_angle(wi), xz_angle(wo));
            // Half vector angle in the XZ plane: bisector of the light and eye angles.
            let th = 0.5 * (tl + te);
            let want = arc_average(te, |t| {
                if (t - tl).cos() > 0.0 {
                    (t - th).cos().powi(10)
                } else {
                    0.0
                }
            });
            let est = rt.render(wi, wo, 1 << 22, 100 + k as u64);
            let got = est.reflection.i_s[0];
            let tol = 4.0 * est.std_err[0] + 0.002 * want;
            assert!(
                (got - want).abs() < tol,
                "case {k}: got {got}, want {want}, tol {tol}, {est:?}"
            );
        }
    }

    #[test]
    fn overhead_light_and_eye_give_pi_over_four() {
        // I_d = rho_d int_0^pi sin^2 / int_0^pi sin = rho_d pi / 4; with the axis at height h the
        // floor cuts the visible arc to [a, pi - a], sin a = max(0, -h) / r.
        for (h, seed) in [(0.0, 1), (0.5, 2), (-0.5, 3)] {
            let json = format!(
                r#"{{"pattern": [[1]], "warp": {{"radius": 1, "height": {h}, "spacing": 1000,
                    "material": {{"albedo": 0.4, "specular": 0}}}}, "weft": {{"radius": 0.5, "spacing": 1}}}}"#
            );
            let rt = RayTracer::new(&fabric(&json), FacetModel::Huo);
            let a = f64::max(-h, 0.0).asin();
            let want = 0.4 * (PI / 2.0 - a + a.sin() * a.cos()) / (2.0 * a.cos());
            if h == 0.0 {
                assert!((want - 0.4 * PI / 4.0).abs() < 1e-15);
            }
            let est = rt.render(UnitVec3::Z, UnitVec3::Z, 1 << 22, seed);
            let got = est.reflection.i_d[1];
            let tol = 4.0 * est.std_err[1] + 0.002 * want;
            assert!(
                (got - want).abs() < tol,
                "h {h}: got {got}, want {want}, tol {tol}, {est:?}"
            );
        }
    }

    #[test]
    fn end_cap_is_seen_and_shaded() {
        // A lone finite warp segment, axis on the floor along y in [0, 4], seen (and lit) from
        // (0, -sin t, cos t): the side contributes int (N.E)^2 = r L cos^2 t pi / 2 over
        // projected area 2 r L cos t, the low cap (half disc, normal -y) (pi r^2 / 2) sin^2 t
        // over (pi r^2 / 2) sin t.
        let mut g = Geometry::new(&fabric(
            r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 20, "material": {"specular": 0}},
                "weft": {"radius": 1, "spacing": 20}}"#,
        ));
        let (r, len) = (1.0, 4.0);
        g.segments = vec![Segment {
            group: Group::Warp,
            thread: 0,
            float: Float {
                start: 0,
                len: 1,
                endless: false,
            },
            axis: 10.0,
            radius: r,
            height: 0.0,
            extent: Some((8.0, 8.0 + len)),
        }];
        let rt = RayTracer::from_geometry(g, FacetModel::Huo).with_caps(Caps::Shaded);
        let excluded = rt.clone().with_caps(Caps::Excluded);
        for (t_deg, seed) in [(30.0, 1), (60.0, 2), (80.0, 3)] {
            let t = f64::to_radians(t_deg);
            let e = dir(t_deg, 270.0);
            let half_disc = PI * r * r / 2.0;
            let num = r * len * t.cos().powi(2) * PI / 2.0 + half_disc * t.sin().powi(2);
            let den = 2.0 * r * len * t.cos() + half_disc * t.sin();
            let want = 0.4 * num / den;
            let est = rt.render(e, e, 1 << 20, seed);
            let got = est.reflection.i_d[0];
            let tol = 4.0 * est.std_err[0] + 0.002 * want;
            assert!(
                (got - want).abs() < tol,
                "theta {t_deg}: got {got}, want {want}, tol {tol}, {est:?}"
            );
            // Without the cap the answer would differ by far more than the tolerance.
            let no_cap = 0.4 * (r * len * t.cos().powi(2) * PI / 2.0) / (2.0 * r * len * t.cos());
            if t_deg >= 60.0 {
                assert!((no_cap - want).abs() > 5.0 * tol);
            }
            // With caps excluded (the default) only the side is averaged.
            let est = excluded.render(e, e, 1 << 18, seed);
            let got = est.reflection.i_d[0];
            let tol = 4.0 * est.std_err[0] + 0.002 * no_cap;
            assert!(
                (got - no_cap).abs() < tol,
                "excluded, theta {t_deg}: {got} vs {no_cap}"
            );
        }
    }

    #[test]
    fn packed_cylinders_cover_the_projected_period_at_grazing_angles() {
        // Endless cylinders of radius r, axis on the floor, spacing s. Seen along d, the
        // cross-section sees the ray at tan t' = |d_across| / |d_z|; each half cylinder covers
        // r (1 + sec t') of the floor, so the yarn-hit fraction is min(1, r (1 + sec t') / s).
        // A grazing ray crosses several periods, testing the period-copy enumeration.
        let warp = RayTracer::new(
            &fabric(
                r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 4}, "weft": {"radius": 0.5, "spacing": 1.3}}"#,
            ),
            FacetModel::Huo,
        );
        let weft = RayTracer::new(
            &fabric(
                r#"{"pattern": [[0]], "warp": {"radius": 0.5, "spacing": 1.3}, "weft": {"radius": 1, "spacing": 4}}"#,
            ),
            FacetModel::Huo,
        );
        let n = 1 << 16;
        for (t, p) in [
            (0.0, 0.0),
            (45.0, 10.0),
            (60.0, 0.0),
            (60.0, 200.0),
            (75.0, 60.0),
            (85.0, 85.0),
            (85.0, 0.0),
            (89.0, 45.0),
        ] {
            for (rt, across) in [(&warp, 0usize), (&weft, 1)] {
                let wo = dir(t, p + 90.0 * across as f64);
                let d = [wo.x, wo.y];
                let tan = d[across].abs() / wo.z;
                let want = ((1.0 + (1.0 + tan * tan).sqrt()) / 4.0).min(1.0);
                let est = rt.render(dir(30.0, 40.0), wo, n, 9);
                let got = est.yarn_hits as f64 / est.rays as f64;
                let tol = 4.0 * (want * (1.0 - want) / n as f64).sqrt() + 1e-4;
                assert!(
                    (got - want).abs() <= tol,
                    "theta {t} phi {p} across {across}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn neighbours_cast_shadows() {
        // Endless warp half cylinders (r = 1, spacing s = 2.5), eye overhead: the whole upper
        // half circle N = (cos p, 0, sin p) is visible with weight sin p. Light at angle a from
        // the zenith toward +x: the point P = r (cos p, sin p) is lit when N.L > 0 and the ray
        // P + t L (t > 0) passes no neighbour centre C_k = (k s, 0) closer than r, i.e.
        // |(C_k - P) x L| = |k s cos a - r cos(p + a)| >= r or C_k lies behind.
        let (r, s) = (1.0, 2.5);
        let rt = RayTracer::new(
            &fabric(
                r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 2.5, "material": {"specular": 0}},
                    "weft": {"radius": 0.5, "spacing": 1}}"#,
            ),
            FacetModel::Huo,
        );
        for (a_deg, seed) in [(40.0, 1), (65.0, 2), (85.0, 3)] {
            let a = f64::to_radians(a_deg);
            let l = [a.sin(), a.cos()];
            let n = 100_000;
            let (mut num, mut den, mut free) = (0.0, 0.0, 0.0);
            for i in 0..n {
                let p = (i as f64 + 0.5) / n as f64 * PI;
                let pt = [r * p.cos(), r * p.sin()];
                let nl = p.cos() * l[0] + p.sin() * l[1];
                let lit = nl > 0.0
                    && (1..200).all(|k| {
                        let c = [k as f64 * s - pt[0], -pt[1]];
                        let ahead = c[0] * l[0] + c[1] * l[1] > 0.0;
                        !ahead || (c[0] * l[1] - c[1] * l[0]).abs() >= r
                    });
                den += p.sin();
                free += nl.max(0.0) * p.sin();
                if lit {
                    num += nl * p.sin();
                }
            }
            let want = 0.4 * num / den;
            let est = rt.render(dir(a_deg, 0.0), UnitVec3::Z, 1 << 18, seed);
            let got = est.reflection.i_d[0];
            let tol = 4.0 * est.std_err[0] + 0.002 * want;
            assert!(
                (got - want).abs() < tol,
                "light {a_deg}: got {got}, want {want}, tol {tol}"
            );
            // The neighbours' shadows matter far beyond the tolerance at oblique light.
            if a_deg > 60.0 {
                assert!(0.4 * free / den - want > 5.0 * tol, "{}", 0.4 * free / den);
            }
        }
    }

    /// Brute force first hit: every segment of every period copy within `k` periods.
    fn brute_first_hit(rt: &RayTracer, o: Vec3, d: Vec3, t_max: f64, k: i64) -> Option<f64> {
        let (px, py) = rt.geometry.period;
        let mut best: Option<f64> = None;
        for s in &rt.geometry.segments {
            let shape = SegmentShape {
                axis: s.axis,
                height: s.height,
                radius: s.radius,
                extent: s.extent,
            };
            for i in -k..=k {
                for j in -k..=k {
                    let ol = Vec3::new(o.x - i as f64 * px, o.y - j as f64 * py, o.z);
                    let ray = if s.group == Group::Warp {
                        LocalRay {
                            o: [ol.x, ol.y, ol.z],
                            d: [d.x, d.y, d.z],
                        }
                    } else {
                        LocalRay {
                            o: [ol.y, ol.x, ol.z],
                            d: [d.y, d.x, d.z],
                        }
                    };
                    if let Some((t, _)) = segment_entry(&ray, &shape, 0.0, best.unwrap_or(t_max)) {
                        best = Some(t);
                    }
                }
            }
        }
        best
    }

    #[test]
    fn grid_walk_finds_the_same_first_hit_as_brute_force() {
        let rt = twill();
        let mut rng = Rng::new(5);
        let (px, py) = rt.geometry.period;
        for i in 0..4000 {
            let theta = if i % 2 == 0 {
                85.0
            } else {
                90.0 * rng.next_f64()
            };
            let wo = dir(theta, 360.0 * rng.next_f64());
            let o = Vec3::new(rng.next_f64() * px, rng.next_f64() * py, rt.z_top);
            let d = -wo.get();
            let t_floor = o.z / -d.z;
            let fast = rt.trace(o, d, 0.0, t_floor, false, None).map(|h| h.t);
            let brute = brute_first_hit(&rt, o, d, t_floor, 4);
            let same = match (fast, brute) {
                (Some(a), Some(b)) => (a - b).abs() < 1e-9,
                (None, None) => true,
                _ => false,
            };
            assert!(
                same,
                "ray {i}: theta {theta} {o:?} {d:?}: {fast:?} vs {brute:?}"
            );
        }
    }

    #[test]
    fn zero_below_horizon_and_deterministic() {
        let rt = twill();
        let below = UnitVec3::from_degrees(95.0, 20.0);
        let up = dir(40.0, 30.0);
        let horizon = UnitVec3::new(Vec3::new(1.0, 0.0, 0.0)).unwrap();
        for (wi, wo) in [(below, up), (up, below), (horizon, up), (up, horizon)] {
            let e = rt.render(wi, wo, 1000, 1);
            assert_eq!(e, Estimate::default());
            assert_eq!(
                rt.render_to_error(wi, wo, 0.01, 1000, 1),
                Estimate::default()
            );
        }
        let a = rt.render(dir(30.0, 80.0), dir(50.0, 200.0), 20_000, 42);
        let b = rt.render(dir(30.0, 80.0), dir(50.0, 200.0), 20_000, 42);
        let c = rt.render(dir(30.0, 80.0), dir(50.0, 200.0), 20_000, 43);
        assert_eq!(a, b);
        assert_eq!(format!("{a:?}"), format!("{b:?}")); // bit-identical, NaN-free
        assert_ne!(a.reflection, c.reflection);
        assert_eq!(a.rays, 20_000);
        for e in [a, c] {
            for k in 0..3 {
                for v in [e.reflection.i_d[k], e.reflection.i_s[k], e.std_err[k]] {
                    assert!(v.is_finite() && v >= 0.0, "{e:?}");
                }
            }
            assert!(e.yarn_hits > 0 && e.yarn_hits <= e.rays);
        }
    }

    #[test]
    fn std_err_shrinks_like_inverse_sqrt_and_is_honest() {
        let rt = twill();
        let (wi, wo) = (dir(40.0, 30.0), dir(60.0, 250.0));
        // Quadrupling the samples 4x (16x samples) should shrink the error ~4x (stratification
        // may do somewhat better); a broken or constant error estimate fails.
        let small = rt.render(wi, wo, 4096, 1).std_err[0];
        let large = rt.render(wi, wo, 65_536, 1).std_err[0];
        let ratio = small / large;
        assert!((2.5..12.0).contains(&ratio), "{small} / {large} = {ratio}");
        // The reported error matches the actual scatter of independent estimates.
        let runs: Vec<Estimate> = (0..24).map(|s| rt.render(wi, wo, 4096, 1000 + s)).collect();
        let m = runs.iter().map(|e| e.reflection.total()[0]).sum::<f64>() / runs.len() as f64;
        let sd = (runs
            .iter()
            .map(|e| (e.reflection.total()[0] - m).powi(2))
            .sum::<f64>()
            / (runs.len() - 1) as f64)
            .sqrt();
        let se = runs.iter().map(|e| e.std_err[0]).sum::<f64>() / runs.len() as f64;
        assert!(
            (0.5..2.0).contains(&(sd / se)),
            "scatter {sd} vs reported {se}"
        );
    }

    #[test]
    fn render_to_error_reaches_target() {
        let rt = twill();
        let (wi, wo) = (dir(20.0, 0.0), dir(35.0, 120.0));
        let e = rt.render_to_error(wi, wo, 0.002, 1 << 24, 3);
        let t = e.reflection.total();
        let mean = (t[0] + t[1] + t[2]) / 3.0;
        assert!(e.std_err[0] <= 0.002 * mean * 1.0001, "{e:?}");
        assert!(e.rays > FIRST_ROUND && e.rays < 1 << 24, "{e:?}");
        assert!(e.rays.is_power_of_two());
        let capped = rt.render_to_error(wi, wo, 1e-9, 3 * FIRST_ROUND, 3);
        assert_eq!(capped.rays, 3 * FIRST_ROUND);
    }

    #[test]
    fn plain_weave_is_mirror_symmetric() {
        let rt = RayTracer::new(
            &fabric(
                r#"{"pattern": [[1,0],[0,1]],
                    "warp": {"radius": 1.5, "spacing": 3.1}, "weft": {"radius": 1.5, "spacing": 3.1}}"#,
            ),
            FacetModel::Huo,
        );
        for (k, (wi, wo)) in [
            (dir(30.0, 20.0), dir(50.0, 200.0)),
            (dir(60.0, 45.0), dir(20.0, 135.0)),
            (dir(10.0, 300.0), dir(75.0, 10.0)),
            (dir(80.0, 170.0), dir(40.0, 60.0)),
        ]
        .into_iter()
        .enumerate()
        {
            let a = rt.render(wi, wo, 1 << 18, 2 * k as u64);
            let b = rt.render(wi.mirror_x(), wo.mirror_x(), 1 << 18, 2 * k as u64 + 1);
            let (ta, tb) = (a.reflection.total()[0], b.reflection.total()[0]);
            let tol = 4.0 * a.std_err[0].hypot(b.std_err[0]);
            assert!((ta - tb).abs() < tol, "case {k}: {ta} vs {tb} (tol {tol})");
        }
    }
}
