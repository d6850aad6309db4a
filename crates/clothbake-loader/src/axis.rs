//! One axis of a table's grid of directions ([`Axis`]): its cells, the angle they cover
//! ([`Span`]) and every rule between angles and cells, in one place: where the cell-centred
//! nodes sit, which cell holds an angle, and the node/weight pairs of the interpolations.
//!
//! A grid ([`crate::Grid`]) has four axes: the polar angles of the incident and the outgoing
//! direction ([`Span::Hemisphere`], 90 degrees from +Z, not periodic) and their azimuths
//! ([`Span::Turn`], 360 degrees from +X toward +Y, periodic). A two-faced table's polar axes
//! cover the whole sphere ([`Span::Sphere`], 180 degrees from +Z to -Z); it is baked, stored,
//! sharded and compared on those axes, and looked up per side, in four hemisphere blocks
//! (`crate::two_faced`), so the lookup's rules ([`Axis::lookup_node`], [`Axis::lookup_lines`])
//! only ever see hemisphere and turn axes.
//!
//! The rules come in the float type and the order of operations each caller has always used,
//! so that tables, lookups and samples keep their bits. Where two rules answer the same
//! question differently, both are here, named for their use:
//!
//! * the node of cell `k`: [`Axis::centre_deg`] (f64, degrees; baking, every cell's
//!   direction), and its formula in words [`Axis::centre_text`] (the OpenEXR file);
//! * the cell holding an angle: [`Axis::cell_of`] (f32 radians; importance sampling, on the
//!   renderer's path) and [`Axis::cell_of_deg`] (f64 degrees; `clothbake info` picking cells
//!   of a baked table);
//! * the node/weight pairs: [`Axis::lookup_node`] (f32, the lookup: a polar axis padded with a
//!   pole node below its first centre, its last centre held to the horizon; the AVX2 kernel's
//!   form of the same rule is [`Axis::lookup_lines`]), [`Axis::clamped_taps_deg`] (f32
//!   degrees; a spatial table's coverage, which has no pole node: clamped to the outer
//!   centres) and [`Axis::coarse_taps_deg`] (f64 degrees; the baker's coarse grid of
//!   path-traced nodes, clamped to the outer centres, in the bake's f64).
//!
//! The lookup and the coverage run in f32 on every render sample; the baker and `info` run in
//! f64 once per cell. They differ in what lies below the first polar centre (the lookup's pole
//! node makes it continuous and independent of the azimuth at the pole; the coverage and the
//! coarse grid hold their first ring) and at a clamped end (the coverage weighs the last node
//! twice, `(1 - t) v + t v`; the coarse grid takes the pair below it with weight 1).

use std::f32::consts as f32c;
use std::f64::consts as f64c;

/// The angle an axis covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Span {
    /// A polar angle from the pole (+Z) to the horizon, [0, 90] degrees; not periodic.
    Hemisphere,
    /// A polar angle from +Z through the horizon to -Z, [0, 180] degrees; not periodic. The
    /// polar axes of a two-faced table (light and eye on either side of the cloth).
    Sphere,
    /// An azimuth from +X toward +Y, [0, 360) degrees; periodic (cell 0 follows the last).
    Turn,
}

impl Span {
    /// The span in degrees (f64): 90, 180 or 360.
    #[inline(always)]
    pub const fn degrees(self) -> f64 {
        match self {
            Span::Hemisphere => 90.0,
            Span::Sphere => 180.0,
            Span::Turn => 360.0,
        }
    }

    /// The span in degrees (f32, exact): 90, 180 or 360.
    #[inline(always)]
    pub const fn degrees_f32(self) -> f32 {
        match self {
            Span::Hemisphere => 90.0,
            Span::Sphere => 180.0,
            Span::Turn => 360.0,
        }
    }

    /// The span in radians (f64): pi/2, pi or 2 pi.
    #[inline(always)]
    pub const fn radians(self) -> f64 {
        match self {
            Span::Hemisphere => f64c::FRAC_PI_2,
            Span::Sphere => f64c::PI,
            Span::Turn => f64c::TAU,
        }
    }

    /// The span in radians (f32): pi/2, pi or 2 pi, each the f32 nearest.
    #[inline(always)]
    pub const fn radians_f32(self) -> f32 {
        match self {
            Span::Hemisphere => f32c::FRAC_PI_2,
            Span::Sphere => f32c::PI,
            Span::Turn => f32c::TAU,
        }
    }

    /// Whether the axis wraps around: after its last cell comes its first.
    #[inline(always)]
    pub const fn is_periodic(self) -> bool {
        matches!(self, Span::Turn)
    }
}

/// One axis of a grid of directions: `count` cells of equal width over a [`Span`],
/// cell-centred (cell `k` from `k` to `k + 1` widths, its node at `k + 0.5`).
///
/// The count is at least 1 on a valid grid ([`crate::Grid::validate`]); the rules assume it
/// (a debug build checks it on construction).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Axis {
    span: Span,
    count: u32,
}

/// The AVX2 kernel's form of [`Axis::lookup_node`] for one lane: the position in cells of an
/// angle `a` (radians) is `min(a k1 + b1, a k2 + b2)`, clamped to `[0, cap]` (NaN to 0); its
/// low node is the position truncated, at most `top`, less `count` beyond it (the periodic
/// wrap; a polar position never gets there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LookupLines {
    pub(crate) k1: f32,
    pub(crate) b1: f32,
    pub(crate) k2: f32,
    pub(crate) b2: f32,
    pub(crate) cap: f32,
    pub(crate) top: i32,
}

impl Axis {
    /// An axis of `count` (at least 1) cells over `span`.
    #[inline(always)]
    pub const fn new(span: Span, count: u32) -> Axis {
        debug_assert!(count > 0, "an axis has at least one cell");
        Axis { span, count }
    }

    /// A polar axis of `count` cells over the hemisphere ([`Span::Hemisphere`]).
    #[inline(always)]
    pub const fn polar(count: u32) -> Axis {
        Axis::new(Span::Hemisphere, count)
    }

    /// An azimuth axis of `count` cells over a turn ([`Span::Turn`]).
    #[inline(always)]
    pub const fn azimuth(count: u32) -> Axis {
        Axis::new(Span::Turn, count)
    }

    /// The angle the axis covers.
    #[inline(always)]
    pub const fn span(self) -> Span {
        self.span
    }

    /// Its number of cells.
    #[inline(always)]
    pub const fn count(self) -> u32 {
        self.count
    }

    /// The node (centre) of cell `k`, degrees: `(k + 0.5) * span / count` (f64). Every baked
    /// cell's direction.
    #[inline]
    pub fn centre_deg(self, k: u32) -> f64 {
        (f64::from(k) + 0.5) * self.span.degrees() / f64::from(self.count)
    }

    /// [`Axis::centre_deg`] in words for cell index `index`, e.g. `(ti + 0.5) * 90 / 32` (the
    /// OpenEXR file's description of its directions).
    pub fn centre_text(self, index: &str) -> String {
        format!("({index} + 0.5) * {} / {}", self.span.degrees(), self.count)
    }

    /// The width of a cell, radians (f64): `span / count`.
    #[inline]
    pub fn width_rad(self) -> f64 {
        self.span.radians() / f64::from(self.count)
    }

    /// Edge `k` (`0..=count`) of the cells, radians (f64): `k` [`Axis::width_rad`]. The cells'
    /// solid angles and cosine integrals of sampling and of the albedo.
    #[inline]
    pub fn edge_rad(self, k: u32) -> f64 {
        f64::from(k) * self.width_rad()
    }

    /// Cells per radian (f32): `count / span`. An angle times it is its position in cells.
    #[inline(always)]
    pub fn cells_per_radian(self) -> f32 {
        self.count as f32 / self.span.radians_f32()
    }

    /// The angle (radians, f32) at `position` cells from the axis's start: `position * span /
    /// count`. Where importance sampling places an azimuth inside its cell.
    #[inline(always)]
    pub fn angle_at(self, position: f32) -> f32 {
        position * self.span.radians_f32() / self.count as f32
    }

    /// Whether `angle` (degrees, f32) lies in the axis's span, half-open: `[0, span)`. A polar
    /// angle under 90 degrees has a value (every f32 below 90 is above the horizon).
    #[inline(always)]
    pub fn holds_deg(self, angle: f32) -> bool {
        (0.0..self.span.degrees_f32()).contains(&angle)
    }

    /// The cell holding `angle` (radians, f32), importance sampling's rule: the position in
    /// cells truncated, a polar one clamped into the axis (NaN: cell 0), an azimuth one
    /// wrapped (any angle; not finite: cell 0).
    #[inline]
    pub fn cell_of(self, angle: f32) -> usize {
        match self.span {
            Span::Hemisphere | Span::Sphere => {
                let c = angle * self.cells_per_radian();
                (c.max(0.0) as usize).min(self.count as usize - 1)
            }
            Span::Turn => {
                let c = (angle * self.cells_per_radian()).floor();
                let c = if c.is_finite() { c as i64 } else { 0 };
                c.rem_euclid(i64::from(self.count)) as usize
            }
        }
    }

    /// The cell holding `angle` (degrees, f64), the rule of `clothbake info`: the cell whose
    /// node is nearest (on a cell edge the upper one), a polar angle clamped into the axis, an
    /// azimuth wrapped first.
    pub fn cell_of_deg(self, angle: f64) -> u32 {
        let n = f64::from(self.count);
        let k = match self.span {
            Span::Hemisphere | Span::Sphere => (angle * n / self.span.degrees()).floor(),
            Span::Turn => (angle.rem_euclid(self.span.degrees()) * n / self.span.degrees()).floor(),
        };
        (k.max(0.0) as u32).min(self.count - 1)
    }

    /// The lookup's node and weight at position `c` = angle in cells (cell `k`'s node at
    /// `k + 0.5`): the padded node `lo <= count - 1` and the weight of node `lo + 1`. A
    /// [`Span::Sphere`] axis is looked up per hemisphere block, never here (its polar arm is
    /// the hemisphere's).
    ///
    /// * Polar: the nodes are padded with a pole node, node 0 at the pole and node `k + 1` cell
    ///   `k`'s. Below the first centre the blend is between the pole node and the first cell
    ///   (`2 c`); beyond the last centre the last node is held (to the horizon); NaN gives 0.
    /// * Azimuth, `c` in `[-count/2, count)`: node `count` repeats node 0 (between the last
    ///   centre and the first, cells `count - 1` and 0 are blended). No division: shifted by
    ///   `count` to be positive, truncated, one conditional wrap; NaN gives node 0 and anything
    ///   outside the range some node of the axis.
    #[inline(always)]
    pub fn lookup_node(self, c: f32) -> (u32, f32) {
        let n = self.count;
        match self.span {
            Span::Hemisphere | Span::Sphere => {
                let s = if c < 0.5 { 2.0 * c } else { c + 0.5 };
                let s = s.max(0.0).min(n as f32); // NaN -> 0
                let lo = (s as u32).min(n - 1);
                (lo, s - lo as f32)
            }
            Span::Turn => {
                let s = (c + (n as f32 - 0.5)).max(0.0); // NaN -> 0
                let lo = s as u32; // s >= 0: truncation is floor; saturates
                let t = (s - lo as f32).min(1.0);
                let lo = if lo >= n { lo - n } else { lo };
                (lo.min(n - 1), t)
            }
        }
    }

    /// [`Axis::lookup_node`] as the AVX2 kernel computes it, from the angle in radians: polar
    /// `k1 = 2 s, b1 = 0` and `k2 = s, b2 = 1/2` (the `2 c` or `c + 1/2`), `cap = count`,
    /// `top = count - 1`; azimuth `k1 = k2 = s`, `b1 = b2 = count - 1/2`, `cap = 2 count`,
    /// `top = 2 count - 1`; `s` = [`Axis::cells_per_radian`].
    pub(crate) fn lookup_lines(self) -> LookupLines {
        let (s, n) = (self.cells_per_radian(), self.count);
        match self.span {
            Span::Hemisphere | Span::Sphere => LookupLines {
                k1: 2.0 * s,
                b1: 0.0,
                k2: s,
                b2: 0.5,
                cap: n as f32,
                top: n as i32 - 1,
            },
            Span::Turn => LookupLines {
                k1: s,
                b1: n as f32 - 0.5,
                k2: s,
                b2: n as f32 - 0.5,
                cap: 2.0 * n as f32,
                top: 2 * n as i32 - 1,
            },
        }
    }

    /// The lookup's position in cells of `angle` (radians) exactly as documented, in f64,
    /// before clamping: polar `min(2 c, c + 1/2)`, azimuth `c + count - 1/2`, `c` the angle in
    /// cells. What the tests hold both kernels' f32 positions to.
    #[cfg(test)]
    pub(crate) fn lookup_position(self, angle: f64) -> f64 {
        let n = f64::from(self.count);
        let c = angle * n / self.span.radians();
        match self.span {
            Span::Hemisphere | Span::Sphere => (2.0 * c).min(c + 0.5),
            Span::Turn => c + n - 0.5,
        }
    }

    /// The two nodes a coverage lookup blends at `angle` (degrees, f32), with their weights:
    /// linear between the nearest centres, a polar angle clamped to the outer centres (no
    /// pole node: below the first centre, or beyond the last, that node with weight 1 split
    /// `(1 - t, t)` over itself), an azimuth wrapped. Not finite: as 0 degrees.
    #[inline]
    pub fn clamped_taps_deg(self, angle: f32) -> [(usize, f32); 2] {
        let n = self.count;
        let x = angle * n as f32 / self.span.degrees_f32() - 0.5;
        let x = if x.is_finite() { x } else { 0.0 };
        let (lo, hi, t) = match self.span {
            Span::Hemisphere | Span::Sphere => {
                let lo = x.floor().clamp(0.0, (n - 1) as f32);
                (
                    lo as usize,
                    (lo as usize + 1).min(n as usize - 1),
                    (x - lo).clamp(0.0, 1.0),
                )
            }
            Span::Turn => {
                let f = x.floor();
                let lo = (f as i64).rem_euclid(i64::from(n)) as usize;
                (lo, (lo + 1) % n as usize, (x - f).clamp(0.0, 1.0))
            }
        };
        [(lo, 1.0 - t), (hi, t)]
    }

    /// The two nodes of the baker's coarse grid at `angle` (degrees, f64), with their
    /// weights: linear between the nearest centres, a polar angle clamped to the outer
    /// centres (the pair below the last centre, weight 1 on it; one cell: its node, weight 1,
    /// twice), an azimuth wrapped.
    pub fn coarse_taps_deg(self, angle: f64) -> [(u32, f64); 2] {
        let n = self.count;
        match self.span {
            Span::Hemisphere | Span::Sphere => {
                let x =
                    (angle * f64::from(n) / self.span.degrees() - 0.5).clamp(0.0, f64::from(n - 1));
                let k = (x.floor() as u32).min(n.saturating_sub(2));
                let t = x - f64::from(k);
                if n == 1 {
                    return [(0, 1.0), (0, 0.0)];
                }
                [(k, 1.0 - t), (k + 1, t)]
            }
            Span::Turn => {
                let span = self.span.degrees();
                let x =
                    (angle.rem_euclid(span) * f64::from(n) / span - 0.5).rem_euclid(f64::from(n));
                let k = (x.floor() as u32).min(n - 1);
                let t = x - f64::from(k);
                [(k, 1.0 - t), ((k + 1) % n, t)]
            }
        }
    }

    /// The node of rank `k` of a grid whose first node stands at the axis's start (the pole of
    /// a polar axis), degrees: `k * span / count` (f64). The two-faced cloth's coarse grid
    /// (`clothbake_bake::two_faced`), whose datasheet figures are read at the normal.
    #[inline]
    pub fn start_node_deg(self, k: u32) -> f64 {
        f64::from(k) * self.span.degrees() / f64::from(self.count)
    }

    /// The two nodes of [`Axis::start_node_deg`]'s grid at `angle` (degrees, f64), with their
    /// weights: linear between nodes, clamped to the last node beyond it (a polar angle toward
    /// the horizon), wrapped over a turn.
    pub fn start_taps_deg(self, angle: f64) -> [(u32, f64); 2] {
        // The same clamp and wrap as the cell-centred grid, half a cell earlier.
        self.coarse_taps_deg(angle + 0.5 * self.span.degrees() / f64::from(self.count))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_nodes_begin_at_the_pole_and_clamp_at_the_last() {
        let a = Axis::polar(5);
        assert_eq!([0, 1, 4].map(|k| a.start_node_deg(k)), [0.0, 18.0, 72.0]);
        assert_eq!(a.start_taps_deg(0.0), [(0, 1.0), (1, 0.0)]);
        let [(k, w0), (k1, w1)] = a.start_taps_deg(27.0);
        assert_eq!((k, k1), (1, 2));
        assert!((w0 - 0.5).abs() < 1e-12 && (w1 - 0.5).abs() < 1e-12);
        let [(_, w0), (k1, w1)] = a.start_taps_deg(85.0);
        assert_eq!(k1, 4);
        assert!(w0.abs() < 1e-12 && (w1 - 1.0).abs() < 1e-12, "clamped");
        let t = Axis::azimuth(8);
        assert_eq!(t.start_node_deg(1), 45.0);
        let [(k, w0), (k1, _)] = t.start_taps_deg(350.0);
        assert_eq!((k, k1), (7, 0));
        assert!((w0 - (360.0 - 350.0) / 45.0).abs() < 1e-12);
    }

    #[test]
    fn spans_are_the_same_angle_in_every_unit() {
        for s in [Span::Hemisphere, Span::Sphere, Span::Turn] {
            assert_eq!(s.degrees_f32() as f64, s.degrees());
            assert_eq!(s.degrees().to_radians() as f32, s.radians_f32());
            assert!((s.degrees().to_radians() - s.radians()).abs() < 1e-15);
            assert_eq!(s.radians() as f32, s.radians_f32());
        }
        assert!(Span::Turn.is_periodic() && !Span::Hemisphere.is_periodic());
        assert!(!Span::Sphere.is_periodic());
    }

    #[test]
    fn centres_sit_in_the_middle_of_their_cells() {
        let a = Axis::polar(4);
        assert_eq!(
            [0, 1, 2, 3].map(|k| a.centre_deg(k)),
            [11.25, 33.75, 56.25, 78.75]
        );
        assert_eq!(Axis::azimuth(5).centre_deg(4), 324.0);
        assert_eq!(a.centre_text("ti"), "(ti + 0.5) * 90 / 4");
        assert_eq!(Axis::azimuth(64).centre_text("po"), "(po + 0.5) * 360 / 64");
        for n in [1, 3, 32, 90] {
            for ax in [Axis::polar(n), Axis::azimuth(n)] {
                for k in 0..n {
                    let c = ax.centre_deg(k).to_radians();
                    assert!(ax.edge_rad(k) < c && c < ax.edge_rad(k + 1), "{ax:?} {k}");
                    // The cell of a centre is its own, by both rules.
                    assert_eq!(ax.cell_of(c as f32), k as usize, "{ax:?} {k}");
                    assert_eq!(ax.cell_of_deg(ax.centre_deg(k)), k, "{ax:?} {k}");
                }
                assert!((ax.edge_rad(n) - ax.span().radians()).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn cells_of_angles_clamp_polar_and_wrap_azimuth() {
        let p = Axis::polar(32);
        assert_eq!(
            [0.0, 30.0, 60.0, 80.0, 90.0].map(|d| p.cell_of_deg(d)),
            [0, 10, 21, 28, 31]
        );
        assert_eq!(p.cell_of_deg(-5.0), 0);
        assert_eq!(p.cell_of(-0.1), 0);
        assert_eq!(p.cell_of(2.0), 31);
        assert_eq!(p.cell_of(f32::NAN), 0);
        let a = Axis::azimuth(8);
        assert_eq!(a.cell_of_deg(-10.0), 7);
        assert_eq!(a.cell_of_deg(90.0), 2);
        assert_eq!(a.cell_of(-0.1), 7);
        assert_eq!(a.cell_of(7.0), 0); // 401 degrees
        assert_eq!(a.cell_of(f32::INFINITY), 0);
    }

    #[test]
    fn lookup_nodes_pad_the_pole_and_hold_the_horizon() {
        let p = Axis::polar(4);
        // Cell k's node is padded node k + 1: at its centre, weight 1 on it.
        assert_eq!(p.lookup_node(0.5), (1, 0.0));
        assert_eq!(p.lookup_node(2.5), (3, 0.0));
        // The pole node 0 at the pole, half way to the first centre at a quarter cell.
        assert_eq!(p.lookup_node(0.0), (0, 0.0));
        assert_eq!(p.lookup_node(0.25), (0, 0.5));
        // Held beyond the last centre; NaN at the pole.
        assert_eq!(p.lookup_node(3.9), (3, 1.0));
        assert_eq!(p.lookup_node(f32::NAN), (0, 0.0));
        let a = Axis::azimuth(4);
        // Between the last centre and the first: nodes 3 and 4 (= 0).
        assert_eq!(a.lookup_node(0.0), (3, 0.5));
        assert_eq!(a.lookup_node(0.5), (0, 0.0));
        assert_eq!(a.lookup_node(-1.5), (2, 0.0));
        assert_eq!(a.lookup_node(f32::NAN), (0, 0.0));
    }

    #[test]
    fn lookup_lines_are_the_scalar_rule() {
        // The lines' position, clamped and split, is lookup_node's to the bit with plain
        // products (the kernel fuses them) at angles over and beyond each axis (an azimuth
        // over the lookup's range, [-pi, 2 pi)).
        for ax in [
            Axis::polar(7),
            Axis::azimuth(12),
            Axis::polar(1),
            Axis::azimuth(1),
        ] {
            let l = ax.lookup_lines();
            let s = ax.cells_per_radian();
            for k in -400..800 {
                let a = k as f32 * 0.01;
                let pos = (a * l.k1 + l.b1).min(a * l.k2 + l.b2);
                let pos = pos.max(0.0).min(l.cap);
                let lo = (pos as i32).min(l.top);
                let t = pos - lo as f32;
                let lo = if lo > ax.count() as i32 - 1 {
                    lo - ax.count() as i32
                } else {
                    lo
                };
                let in_range = (-std::f32::consts::PI..std::f32::consts::TAU).contains(&a);
                if in_range || !ax.span().is_periodic() {
                    assert_eq!((lo as u32, t), ax.lookup_node(a * s), "{ax:?} {a}");
                }
            }
        }
    }

    #[test]
    fn clamped_and_coarse_taps_interpolate_between_centres() {
        let p = Axis::polar(4);
        assert_eq!(p.clamped_taps_deg(0.0), [(0, 1.0), (1, 0.0)]);
        assert_eq!(p.clamped_taps_deg(90.0), [(3, 0.5), (3, 0.5)]);
        let [(lo, _), (hi, t)] = p.clamped_taps_deg(22.5);
        assert_eq!((lo, hi), (0, 1));
        assert!((t - 0.5).abs() < 1e-6);
        let a = Axis::azimuth(4);
        assert_eq!(a.clamped_taps_deg(359.0)[0].0, 3);
        assert_eq!(a.clamped_taps_deg(359.0)[1].0, 0);
        assert_eq!(a.clamped_taps_deg(1.0)[0].0, 3);
        // 8 polar cells: centres at 5.625 + 11.25 k.
        let p = Axis::polar(8);
        assert_eq!(p.coarse_taps_deg(5.625), [(0, 1.0), (1, 0.0)]);
        let [(k, wk), (_, wl)] = p.coarse_taps_deg(89.0);
        assert_eq!(k, 6);
        assert!(wk.abs() < 1e-12 && (wl - 1.0).abs() < 1e-12, "clamped");
        assert_eq!(p.coarse_taps_deg(0.0), [(0, 1.0), (1, 0.0)]);
        assert_eq!(Axis::polar(1).coarse_taps_deg(40.0), [(0, 1.0), (0, 0.0)]);
        // 16 azimuth cells: centres at 11.25 + 22.5 k; 0 degrees lies between 15 and 0.
        let [(k, wk), (l, wl)] = Axis::azimuth(16).coarse_taps_deg(0.0);
        assert_eq!((k, l), (15, 0));
        assert!((wk - 0.5).abs() < 1e-12 && (wl - 0.5).abs() < 1e-12);
        let [(k, _), (l, wl)] = Axis::azimuth(16).coarse_taps_deg(-11.25 + 360.0 * 3.0);
        assert_eq!((k, l), (15, 0));
        assert!(wl.abs() < 1e-9);
    }

    #[test]
    fn angles_at_positions_and_the_span_test() {
        let a = Axis::azimuth(8);
        assert_eq!(a.angle_at(2.0), std::f32::consts::FRAC_PI_2);
        assert!(Axis::polar(3).holds_deg(0.0) && Axis::polar(3).holds_deg(89.99));
        assert!(!Axis::polar(3).holds_deg(90.0) && !Axis::polar(3).holds_deg(f32::NAN));
        assert!(!Axis::polar(3).holds_deg(-0.1));
    }
}
