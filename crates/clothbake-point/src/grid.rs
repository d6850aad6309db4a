//! Ray casting through the tiled period: a uniform grid over one period listing the yarn
//! copies whose footprint overlaps each cell, a walk over the cells of the unbounded tiling
//! that a ray's xy path crosses (a 2-D DDA), and the entry of a ray into one yarn's solid
//! (cylinder, end-cap slab and the half-space above the floor).

use crate::period::{Along, Period};
use clothbake_bsdf::Vec3;

/// The most grid entries (cell, yarn copy) a grid holds; a finer grid is coarsened to fit.
const MAX_ENTRIES: usize = 1 << 24;
/// The most cells along one side of the grid.
const MAX_SIDE: usize = 256;

/// One copy of a yarn, placed near the base period (its coordinates shifted by whole periods).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Copy {
    /// Index of the yarn in [`Period::yarns`].
    pub(crate) yarn: u32,
    along_y: bool,
    across: f64,
    height: f64,
    radius: f64,
    /// Extent along the axis; (-inf, inf) when endless.
    lo: f64,
    hi: f64,
    /// The shift in periods (x, y); 0 along the axis of an endless yarn.
    shift: (i64, i64),
}

/// Which surface a ray enters a yarn through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Surface {
    /// The curved side.
    Side,
    /// A flat end cap (where the thread dives under its crossing thread).
    Cap,
}

/// A ray's first entry into a yarn copy: its parameter, the copy and the period tile.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Entry {
    pub(crate) t: f64,
    pub(crate) copy: u32,
    pub(crate) tile: (i64, i64),
    pub(crate) surface: Surface,
}

/// The identity of one physical yarn copy of the tiling (an endless yarn is one object along
/// its axis).
pub(crate) type Key = (u32, i64, i64);

impl Copy {
    /// This copy seen from period tile `tile`, as a physical identity.
    pub(crate) fn key(&self, tile: (i64, i64)) -> Key {
        let endless = self.lo == f64::NEG_INFINITY;
        let (mut kx, mut ky) = (tile.0 + self.shift.0, tile.1 + self.shift.1);
        if endless {
            if self.along_y {
                ky = 0;
            } else {
                kx = 0;
            }
        }
        (self.yarn, kx, ky)
    }

    /// The ray `o + t d` (tile coordinates) as (across, along, z) components.
    #[inline]
    fn frame(&self, v: Vec3) -> (f64, f64, f64) {
        if self.along_y {
            (v.x, v.y, v.z)
        } else {
            (v.y, v.x, v.z)
        }
    }

    /// Where `o + t d` (tile coordinates) enters the solid with `t_min < t < t_max`: the last
    /// of the three convex sets' entries, before the first of their exits.
    #[inline]
    fn entry(&self, o: Vec3, d: Vec3, t_min: f64, t_max: f64) -> Option<(f64, Surface)> {
        let (ou, ov, oz) = self.frame(o);
        let (du, dv, dz) = self.frame(d);
        // The slab between the end caps.
        let (mut t_in, mut t_out) = (f64::NEG_INFINITY, f64::INFINITY);
        if self.lo != f64::NEG_INFINITY {
            if dv == 0.0 {
                if !(self.lo..=self.hi).contains(&ov) {
                    return None;
                }
            } else {
                let (a, b) = ((self.lo - ov) / dv, (self.hi - ov) / dv);
                (t_in, t_out) = if a <= b { (a, b) } else { (b, a) };
                if t_in >= t_max || t_out <= t_min {
                    return None;
                }
            }
        }
        // The infinite cylinder: |(u, z) + t (du, dz) - (across, height)| <= r.
        let a = du * du + dz * dz;
        if a == 0.0 {
            return None;
        }
        let (pu, pz) = (ou - self.across, oz - self.height);
        let b = du * pu + dz * pz;
        let c = pu * pu + pz * pz - self.radius * self.radius;
        let disc = b * b - a * c;
        if disc < 0.0 {
            return None;
        }
        let q = -(b + disc.sqrt().copysign(b));
        let (c0, c1) = if q == 0.0 {
            (0.0, 0.0)
        } else {
            let (x, y) = (q / a, c / q);
            if x <= y {
                (x, y)
            } else {
                (y, x)
            }
        };
        let mut surface = Surface::Cap;
        if c0 >= t_in {
            t_in = c0;
            surface = Surface::Side;
        }
        t_out = t_out.min(c1);
        // Above the floor.
        if dz < 0.0 {
            t_out = t_out.min(-oz / dz);
        } else if (dz > 0.0 && -oz / dz > t_in) || (dz == 0.0 && oz < 0.0) {
            return None;
        }
        (t_in < t_out && t_in > t_min && t_in < t_max).then_some((t_in, surface))
    }

    /// The outward normal at the point `p` (tile coordinates) of a surface.
    pub(crate) fn normal(&self, p: Vec3, surface: Surface, d: Vec3) -> Vec3 {
        let (u, _, z) = self.frame(p);
        let (nu, nv, nz) = match surface {
            Surface::Side => {
                let (a, b) = (u - self.across, z - self.height);
                let l = (a * a + b * b).sqrt();
                (a / l, 0.0, b / l)
            }
            // The cap the ray meets faces against it along the axis.
            Surface::Cap => (0.0, -self.frame(d).1.signum(), 0.0),
        };
        if self.along_y {
            Vec3::new(nu, nv, nz)
        } else {
            Vec3::new(nv, nu, nz)
        }
    }
}

/// The copies over one period, sorted into a uniform grid of cells.
#[derive(Clone, Debug)]
pub(crate) struct Grid {
    period: (f64, f64),
    n: (usize, usize),
    cell: (f64, f64),
    /// Cell k's copies are `copies[entries[starts[k]..starts[k + 1]]]`.
    starts: Vec<u32>,
    entries: Vec<u32>,
    pub(crate) copies: Vec<Copy>,
}

/// The cells `lo..=hi` of a grid of `n` cells of size `c` that the range [a, b] overlaps,
/// clamped to the grid; `None` when it misses [0, n c).
fn cell_range(a: f64, b: f64, c: f64, n: usize) -> Option<(usize, usize)> {
    let top = n as f64 * c;
    if b < 0.0 || a >= top {
        return None;
    }
    let lo = (a / c).floor().max(0.0) as usize;
    let hi = ((b / c).floor().max(0.0) as usize).min(n - 1);
    Some((lo.min(n - 1), hi))
}

impl Grid {
    /// The grid of a period: cells about as wide as the thinnest yarn, at most [`MAX_SIDE`] a
    /// side and [`MAX_ENTRIES`] entries in all.
    pub(crate) fn new(p: &Period) -> Grid {
        let (px, py) = p.size();
        let mut copies = Vec::new();
        for (k, y) in p.yarns().iter().enumerate() {
            let along_y = y.along == Along::Y;
            let (pa, pl) = if along_y { (px, py) } else { (py, px) };
            let (lo, hi) = y.extent.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
            // Shifts whose copy's footprint meets [0, pa) x [0, pl).
            let across_shifts = ((-(y.across + y.radius) / pa).floor() as i64)
                ..=(((pa - (y.across - y.radius)) / pa).ceil() as i64);
            let along_shifts = if y.extent.is_some() {
                ((-hi / pl).floor() as i64)..=(((pl - lo) / pl).ceil() as i64)
            } else {
                0..=0
            };
            for sa in across_shifts {
                for sl in along_shifts.clone() {
                    let (across, lo, hi) = (
                        y.across + sa as f64 * pa,
                        lo + sl as f64 * pl,
                        hi + sl as f64 * pl,
                    );
                    let meets =
                        across + y.radius >= 0.0 && across - y.radius < pa && hi >= 0.0 && lo < pl;
                    if meets {
                        copies.push(Copy {
                            yarn: k as u32,
                            along_y,
                            across,
                            height: y.height,
                            radius: y.radius,
                            lo,
                            hi,
                            shift: if along_y { (sa, sl) } else { (sl, sa) },
                        });
                    }
                }
            }
        }
        let thinnest = p
            .yarns()
            .iter()
            .map(|y| 2.0 * y.radius)
            .fold(f64::INFINITY, f64::min);
        let side = |len: f64| ((len / thinnest).ceil() as usize).clamp(1, MAX_SIDE);
        let mut n = (side(px), side(py));
        loop {
            let cell = (px / n.0 as f64, py / n.1 as f64);
            let count: usize = copies
                .iter()
                .map(|c| Grid::cells_of(c, n, cell).len())
                .sum();
            if count <= MAX_ENTRIES || n == (1, 1) {
                break;
            }
            n = ((n.0 / 2).max(1), (n.1 / 2).max(1));
        }
        let cell = (px / n.0 as f64, py / n.1 as f64);
        let mut lists = vec![Vec::new(); n.0 * n.1];
        for (id, c) in copies.iter().enumerate() {
            for k in Grid::cells_of(c, n, cell) {
                lists[k].push(id as u32);
            }
        }
        let mut starts = Vec::with_capacity(lists.len() + 1);
        let mut entries = Vec::new();
        for l in &lists {
            starts.push(entries.len() as u32);
            entries.extend_from_slice(l);
        }
        starts.push(entries.len() as u32);
        Grid {
            period: (px, py),
            n,
            cell,
            starts,
            entries,
            copies,
        }
    }

    /// The cells (row-major indices) a copy's footprint overlaps.
    fn cells_of(c: &Copy, n: (usize, usize), cell: (f64, f64)) -> Vec<usize> {
        let (a0, a1) = (c.across - c.radius, c.across + c.radius);
        let (l0, l1) = (c.lo.max(-1.0), c.hi.min(1e300));
        let (xr, yr) = if c.along_y {
            (
                cell_range(a0, a1, cell.0, n.0),
                cell_range(l0, l1, cell.1, n.1),
            )
        } else {
            (
                cell_range(l0, l1, cell.0, n.0),
                cell_range(a0, a1, cell.1, n.1),
            )
        };
        let (Some((x0, x1)), Some((y0, y1))) = (xr, yr) else {
            return Vec::new();
        };
        (y0..=y1)
            .flat_map(|y| (x0..=x1).map(move |x| y * n.0 + x))
            .collect()
    }

    /// The first yarn surface the ray `o + t d` enters with `t_min < t < t_max`, walking the
    /// tiling's cells in order; with `any`, the first one found. `skip` is a physical copy not
    /// to hit (the one a shadow ray leaves).
    pub(crate) fn first(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f64,
        any: bool,
        skip: Option<Key>,
    ) -> Option<Entry> {
        let (px, py) = self.period;
        let (nx, ny) = (self.n.0 as i64, self.n.1 as i64);
        let (cx, cy) = self.cell;
        // The unwrapped cell of the origin.
        let (mut ix, mut iy) = ((o.x / cx).floor() as i64, (o.y / cy).floor() as i64);
        let axis = |i: i64, o: f64, d: f64, c: f64| -> (i64, f64, f64) {
            if d > 0.0 {
                (1, ((i + 1) as f64 * c - o) / d, c / d)
            } else if d < 0.0 {
                (-1, (i as f64 * c - o) / d, -c / d)
            } else {
                (0, f64::INFINITY, f64::INFINITY)
            }
        };
        let (sx, mut next_x, dx) = axis(ix, o.x, d.x, cx);
        let (sy, mut next_y, dy) = axis(iy, o.y, d.y, cy);
        let mut best: Option<Entry> = None;
        let mut best_t = t_max;
        loop {
            let (tx, ty) = (ix.div_euclid(nx), iy.div_euclid(ny));
            let k = (iy.rem_euclid(ny) * nx + ix.rem_euclid(nx)) as usize;
            let local = Vec3::new(o.x - tx as f64 * px, o.y - ty as f64 * py, o.z);
            let (s, e) = (self.starts[k] as usize, self.starts[k + 1] as usize);
            for &id in &self.entries[s..e] {
                let c = &self.copies[id as usize];
                if let Some((t, surface)) = c.entry(local, d, 0.0, best_t) {
                    if skip.is_some_and(|key| key == c.key((tx, ty))) {
                        continue;
                    }
                    best_t = t;
                    best = Some(Entry {
                        t,
                        copy: id,
                        tile: (tx, ty),
                        surface,
                    });
                    if any {
                        return best;
                    }
                }
            }
            let t_exit = next_x.min(next_y);
            if best_t <= t_exit || t_exit >= t_max {
                return best;
            }
            if next_x <= next_y {
                ix += sx;
                next_x += dx;
            } else {
                iy += sy;
                next_y += dy;
            }
        }
    }
}
