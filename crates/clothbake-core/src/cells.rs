//! The weave period's crossing cells: how finely the model resolves a position in the period
//! (docs/science/spatial.md).
//!
//! Warp thread i lies at x = X_i, weft thread j at y = Y_j ([`crate::geometry`]). Cell (i, j) is
//! the rectangle between the midpoints of neighbouring threads: x from (X_{i-1} + X_i) / 2 to
//! (X_i + X_{i+1}) / 2, y likewise. Exactly one thread lies on top at each crossing, and its
//! float's piece over that crossing (the thesis's unit, sec. 4.1) is what the cell shows.

use crate::weave::Group;

/// A position in the weave period, in period fractions: `u` along the weft (+X), `v` along the
/// warp (+Y); (0, 0) is the crossing of warp 0 and weft 0. Every finite value is valid and
/// wraps: (u + 1, v) is the same point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeriodPoint {
    u: f64,
    v: f64,
}

impl PeriodPoint {
    /// The point (u, v); `None` unless both are finite.
    pub fn new(u: f64, v: f64) -> Option<PeriodPoint> {
        (u.is_finite() && v.is_finite()).then_some(PeriodPoint { u, v })
    }

    /// The fraction of the period along the weft (+X), as given.
    pub fn u(self) -> f64 {
        self.u
    }

    /// The fraction of the period along the warp (+Y), as given.
    pub fn v(self) -> f64 {
        self.v
    }
}

/// One crossing of the period: warp thread `warp` over or under weft thread `weft`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Cell {
    /// Warp thread index (pattern column, x).
    pub warp: usize,
    /// Weft thread index (pattern row, y).
    pub weft: usize,
}

/// The cell edges of one axis: n + 1 increasing edges spanning exactly one period.
#[derive(Clone, Debug, PartialEq)]
struct Edges {
    edges: Vec<f64>,
    period: f64,
}

impl Edges {
    fn new(pos: &[f64], period: f64) -> Edges {
        let n = pos.len();
        let mut edges = Vec::with_capacity(n + 1);
        edges.push(0.5 * (pos[n - 1] - period + pos[0]));
        for k in 1..n {
            edges.push(0.5 * (pos[k - 1] + pos[k]));
        }
        edges.push(edges[0] + period);
        Edges { edges, period }
    }

    /// The cell index holding fraction `t` of the period (wrapped).
    fn locate(&self, t: f64) -> usize {
        let e0 = self.edges[0];
        let x = e0 + (t * self.period - e0).rem_euclid(self.period);
        let n = self.edges.len() - 1;
        self.edges
            .partition_point(|&e| e <= x)
            .saturating_sub(1)
            .min(n - 1)
    }

    fn width(&self, k: usize) -> f64 {
        self.edges[k + 1] - self.edges[k]
    }

    /// Cells overlapping [t0, t1] (fractions, t1 - t0 < 1), each with the overlap's length in
    /// fractions of the period, in order.
    fn overlaps(&self, t0: f64, t1: f64, out: &mut Vec<(usize, f64)>) {
        out.clear();
        let n = self.edges.len() - 1;
        let (x0, x1) = (t0 * self.period, t1 * self.period);
        let mut k = self.locate(t0);
        // Unwrapped start of cell k at or before x0.
        let shift = ((x0 - self.edges[k]) / self.period).floor() * self.period;
        let mut lo = self.edges[k] + shift;
        loop {
            let hi = lo + self.width(k);
            let len = hi.min(x1) - lo.max(x0);
            if len > 0.0 {
                out.push((k, len / self.period));
            }
            if hi >= x1 || out.len() > 2 * n + 2 {
                break;
            }
            lo = hi;
            k = (k + 1) % n;
        }
    }
}

/// The crossing cells of a period, for locating positions.
#[derive(Clone, Debug, PartialEq)]
pub struct CellGrid {
    x: Edges,
    y: Edges,
}

impl CellGrid {
    /// The cells of threads at `warp_pos` (x, period `px`) and `weft_pos` (y, period `py`),
    /// each list increasing within one period and non-empty.
    pub fn new(warp_pos: &[f64], px: f64, weft_pos: &[f64], py: f64) -> CellGrid {
        CellGrid {
            x: Edges::new(warp_pos, px),
            y: Edges::new(weft_pos, py),
        }
    }

    /// Number of warp and weft threads (columns and rows of cells).
    pub fn dims(&self) -> (usize, usize) {
        (self.x.edges.len() - 1, self.y.edges.len() - 1)
    }

    /// The period (Px, Py).
    pub fn period(&self) -> (f64, f64) {
        (self.x.period, self.y.period)
    }

    /// The cell edges in fractions of the period: along u (warp columns, `nx + 1` values) and
    /// along v (weft rows, `ny + 1`), increasing, the last one more than the first by 1.
    pub fn edge_fractions(&self) -> (Vec<f64>, Vec<f64>) {
        let f = |e: &Edges| e.edges.iter().map(|x| x / e.period).collect();
        (f(&self.x), f(&self.y))
    }

    /// Row-major index (weft row, then warp column) of a cell.
    pub fn index(&self, c: Cell) -> usize {
        c.weft * self.dims().0 + c.warp
    }

    /// The cell containing `p`.
    pub fn cell_at(&self, p: PeriodPoint) -> Cell {
        Cell {
            warp: self.x.locate(p.u),
            weft: self.y.locate(p.v),
        }
    }

    /// The cell's share of the period's area.
    pub fn area_fraction(&self, c: Cell) -> f64 {
        self.x.width(c.warp) * self.y.width(c.weft) / (self.x.period * self.y.period)
    }

    /// The cells that the box of `width` x `width` period fractions centred on `p` overlaps,
    /// each with the overlap's share of the period's area (`width` in (0, 1)).
    pub fn overlaps(&self, p: PeriodPoint, width: f64) -> Vec<(Cell, f64)> {
        let h = 0.5 * width;
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        self.x.overlaps(p.u - h, p.u + h, &mut xs);
        self.y.overlaps(p.v - h, p.v + h, &mut ys);
        let mut out = Vec::with_capacity(xs.len() * ys.len());
        for &(j, wy) in &ys {
            for &(i, wx) in &xs {
                out.push((Cell { warp: i, weft: j }, wx * wy));
            }
        }
        out
    }

    /// The cell over which thread `thread` of group `g` crosses thread `cross` of the other
    /// group (`cross` any integer, wrapped).
    pub fn crossing(&self, g: Group, thread: usize, cross: isize) -> Cell {
        let (nx, ny) = self.dims();
        match g {
            Group::Warp => Cell {
                warp: thread,
                weft: cross.rem_euclid(ny as isize) as usize,
            },
            Group::Weft => Cell {
                warp: cross.rem_euclid(nx as isize) as usize,
                weft: thread,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> CellGrid {
        // Irregular warp spacing 1, 2, 3 (positions 0, 1, 3; period 6); weft 2, 2.
        CellGrid::new(&[0.0, 1.0, 3.0], 6.0, &[0.0, 2.0], 4.0)
    }

    #[test]
    fn cells_lie_between_thread_midpoints_and_wrap() {
        let g = grid();
        // x edges: -1.5, 0.5, 2, 4.5 (= -1.5 + 6).
        let at = |x: f64, y: f64| g.cell_at(PeriodPoint::new(x / 6.0, y / 4.0).unwrap());
        assert_eq!(at(0.0, 0.0), Cell { warp: 0, weft: 0 });
        assert_eq!(at(0.49, 0.0).warp, 0);
        assert_eq!(at(0.51, 0.0).warp, 1);
        assert_eq!(at(2.01, 0.0).warp, 2);
        assert_eq!(at(4.49, 0.0).warp, 2);
        assert_eq!(at(4.51, 0.0).warp, 0);
        assert_eq!(at(-1.49, 0.0).warp, 0);
        assert_eq!(at(-7.49, 0.0).warp, 0);
        assert_eq!(at(6.0 * 1e6 + 1.0, 2.9).weft, 1);
        assert_eq!(at(0.0, 3.1).weft, 0);
        assert_eq!(at(0.0, -1.1).weft, 1);
    }

    #[test]
    fn areas_and_overlaps_sum_to_the_whole() {
        let g = grid();
        let total: f64 = (0..2)
            .flat_map(|j| (0..3).map(move |i| Cell { warp: i, weft: j }))
            .map(|c| g.area_fraction(c))
            .sum();
        assert!((total - 1.0).abs() < 1e-15);
        assert!((g.area_fraction(Cell { warp: 2, weft: 1 }) - 2.5 / 6.0 * 0.5).abs() < 1e-15);
        for (u, w) in [(0.3, 0.999), (0.95, 0.5), (-3.2, 0.01), (0.0, 0.3)] {
            let p = PeriodPoint::new(u, 0.7).unwrap();
            let o = g.overlaps(p, w);
            let s: f64 = o.iter().map(|x| x.1).sum();
            assert!((s - w * w).abs() < 1e-12, "{u} {w}: {s}");
            assert!(o.iter().any(|(c, _)| *c == g.cell_at(p)));
        }
    }

    #[test]
    fn non_finite_points_are_refused() {
        assert!(PeriodPoint::new(f64::NAN, 0.0).is_none());
        assert!(PeriodPoint::new(0.0, f64::INFINITY).is_none());
    }
}
