//! Acceleration over the periodic tiling: `CellIndex` (a uniform grid over one period listing
//! the segment copies, `Prim`s, whose bounding boxes overlap each cell) and `CellWalk` (the
//! 2-D DDA that visits, in order, every cell of the unbounded tiling a ray's xy path crosses).

use super::intersect::{LocalRay, SegmentShape, Surface};
use super::yarns::{Face, Yarns};
use clothbake_bsdf::vec3::Vec3;
use clothbake_fabric::weave::Group;

/// One cell of the walk over the periodic grid: the period copy it lies in, its index within
/// that copy's cells, and the ray parameter at which the ray leaves it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellVisit {
    /// The period copy (tx, ty): unwrapped cell (ix, iy) lies in copy (ix div nx, iy div ny).
    pub tile: (i64, i64),
    /// The cell within its copy, ly * nx + lx with (lx, ly) = (ix mod nx, iy mod ny).
    pub cell: usize,
    /// Ray parameter at which the ray leaves the cell (capped at `t_max`).
    pub t_exit: f64,
}

/// The period-copy enumeration: the cells of an unbounded grid of cell size (`cx`, `cy`),
/// `nx` by `ny` cells to a period, that the xy path `(ox, oy) + t (dx, dy)`, `0 <= t <= t_max`,
/// crosses, in order (a 2-D DDA after Amanatides & Woo). Cell (ix, iy) belongs to period copy
/// (ix div nx, iy div ny) and is that copy's local cell (ix mod nx, iy mod ny): the walk keeps
/// the copy and the local cell as it steps (no division per cell), so every copy of every
/// segment the path could hit is visited, however long (grazing) the path is.
#[derive(Clone, Debug)]
pub struct CellWalk {
    /// Local cell (lx, ly) within the copy (tx, ty).
    lx: i64,
    ly: i64,
    tx: i64,
    ty: i64,
    nx: i64,
    ny: i64,
    step_x: i64,
    step_y: i64,
    next_x: f64,
    next_y: f64,
    delta_x: f64,
    delta_y: f64,
    t_max: f64,
    done: bool,
}

/// One axis of a walk's start: the step (-1, 0 or 1), the parameter of the first cell border
/// crossed and the parameter between borders, for cell `i` of size `c`, origin `o`, direction `d`.
fn axis_start(i: i64, o: f64, d: f64, c: f64) -> (i64, f64, f64) {
    if d > 0.0 {
        (1, ((i + 1) as f64 * c - o) / d, c / d)
    } else if d < 0.0 {
        (-1, (i as f64 * c - o) / d, -c / d)
    } else {
        (0, f64::INFINITY, f64::INFINITY)
    }
}

/// Steps local cell `l` of a copy `t` with `n` cells by `step`, wrapping into the next copy.
#[inline]
fn wrap_step(l: &mut i64, t: &mut i64, step: i64, n: i64) {
    *l += step;
    if *l >= n {
        *l = 0;
        *t += 1;
    } else if *l < 0 {
        *l = n - 1;
        *t -= 1;
    }
}

impl Iterator for CellWalk {
    type Item = CellVisit;

    #[inline]
    fn next(&mut self) -> Option<CellVisit> {
        if self.done {
            return None;
        }
        let t_exit = self.next_x.min(self.next_y);
        let visit = CellVisit {
            tile: (self.tx, self.ty),
            cell: (self.ly * self.nx + self.lx) as usize,
            t_exit: t_exit.min(self.t_max),
        };
        if t_exit >= self.t_max {
            self.done = true;
        } else if self.next_x <= self.next_y {
            wrap_step(&mut self.lx, &mut self.tx, self.step_x, self.nx);
            self.next_x += self.delta_x;
        } else {
            wrap_step(&mut self.ly, &mut self.ty, self.step_y, self.ny);
            self.next_y += self.delta_y;
        }
        Some(visit)
    }
}

/// One copy of a segment of the period, placed so that it overlaps the period's base cell.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Prim {
    /// Index of the segment in [`Yarns::cylinders`].
    pub(crate) seg: u32,
    /// Warp (axis along y; u = x, v = y) or weft (axis along x; u = y, v = x).
    warp: bool,
    /// The solid, in coordinates of the base period.
    pub(crate) shape: SegmentShape,
    /// Offset of this copy in periods (x, y); the along-axis part is 0 for endless segments.
    shift: (i64, i64),
}

impl Prim {
    /// The ray `o + t d` (base-period coordinates) in this segment's own frame.
    pub(crate) fn local(&self, o: Vec3, d: Vec3) -> LocalRay {
        LocalRay::in_frame(self.warp, o, d)
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
            Surface::Cut if s.face == Face::Back => (0.0, 0.0, 1.0),
            Surface::Cut => (0.0, 0.0, -1.0),
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

/// Uniform grid of cells over one period: for each cell the prims whose bounding boxes overlap
/// it (the acceleration structure; not the table grid of the baker).
#[derive(Clone, Debug)]
pub(crate) struct CellIndex {
    nx: i64,
    ny: i64,
    /// Cell size (x, y).
    cx: f64,
    cy: f64,
    period: (f64, f64),
    pub(crate) prims: Vec<Prim>,
    /// `items[starts[c]..starts[c + 1]]` are the prims of cell c = ly * nx + lx.
    starts: Vec<u32>,
    items: Vec<u32>,
}

/// Most cells the index may have.
const MAX_CELLS: usize = 1 << 20;

impl CellIndex {
    /// The index of the segments of `g`, cells about the smallest radius wide.
    pub(crate) fn new(g: &Yarns) -> CellIndex {
        let (px, py) = g.period;
        let target = g
            .cylinders
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
        for (k, s) in g.cylinders.iter().enumerate() {
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
                            face: s.face,
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
        CellIndex {
            nx,
            ny,
            cx,
            cy,
            period: (px, py),
            prims,
            starts,
            items,
        }
    }

    /// The walk over the cells that the xy path of `o + t d`, `0 <= t <= t_max`, crosses,
    /// starting at the cell containing (o.x, o.y).
    #[inline]
    pub(crate) fn walk(&self, o: Vec3, d: Vec3, t_max: f64) -> CellWalk {
        let ix = (o.x / self.cx).floor() as i64;
        let iy = (o.y / self.cy).floor() as i64;
        let (step_x, next_x, delta_x) = axis_start(ix, o.x, d.x, self.cx);
        let (step_y, next_y, delta_y) = axis_start(iy, o.y, d.y, self.cy);
        // (copy, local cell) of an unwrapped index; no division for the base period's cells,
        // where primary rays start.
        let split = |i: i64, n: i64| {
            if (0..n).contains(&i) {
                (0, i)
            } else {
                (i.div_euclid(n), i.rem_euclid(n))
            }
        };
        let ((tx, lx), (ty, ly)) = (split(ix, self.nx), split(iy, self.ny));
        CellWalk {
            lx,
            ly,
            tx,
            ty,
            nx: self.nx,
            ny: self.ny,
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

    /// The ray origin `o` moved into the base period by the offset of the visit's copy, and
    /// the ids of the prims listed in its cell.
    #[inline]
    pub(crate) fn visit(&self, cell: &CellVisit, o: Vec3) -> (Vec3, &[u32]) {
        let items =
            &self.items[self.starts[cell.cell] as usize..self.starts[cell.cell + 1] as usize];
        let local = Vec3::new(
            o.x - cell.tile.0 as f64 * self.period.0,
            o.y - cell.tile.1 as f64 * self.period.1,
            o.z,
        );
        (local, items)
    }
}
