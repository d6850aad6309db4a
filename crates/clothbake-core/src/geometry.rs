//! The explicit periodic micro-geometry (thesis ch. 2): the cylinder segments that both the
//! analytic model approximates and the ray tracer renders exactly.
//!
//! * The floor is the plane z = 0; every yarn is a circular cylinder of its thread's radius whose
//!   axis lies at the thread's height above the floor, cut by the floor.
//! * Warp thread i runs along +Y at x = X_i; weft thread j runs along +X at y = Y_j, where
//!   X_0 = 0 and X_{i+1} = X_i + spacing_i (likewise Y). The period is Px = sum of warp spacings
//!   by Py = sum of weft spacings and tiles the plane.
//! * Only floats are modelled (the thesis ignores the non-cylindrical parts of threads): a float of
//!   a thread over crossing threads a..=b is one segment. Unless given, its extent along its axis
//!   runs from the surface of the crossing thread before it to the surface of the one after it:
//!   [P_{a-1} + r_{a-1}, P_{b+1} - r_{b+1}] (the rules live in [`crate::yarn`]), so a float over f threads at spacing s between crossing
//!   threads of radius r is (f + 1) s - 2 r long (the thesis's twill: 3 * 3.1 - 3 = 6.3 and
//!   2 * 3.1 - 3 = 3.2). A given `segment_length` is centred in that room.
//! * Segment ends are flat caps (discs cut by the floor). A thread that never goes under is an
//!   endless cylinder.

use crate::fabric::Fabric;
use crate::weave::{Float, Group};
use crate::yarn::{float_extent, float_room, unwrapped_position};
use std::f64::consts::PI;

/// One cylinder segment (a float) of the period.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    /// Warp (along +Y) or weft (along +X).
    pub group: Group,
    /// Thread index within its group in the period.
    pub thread: usize,
    /// The float in the weave this segment realises.
    pub float: Float,
    /// Coordinate of the axis across the segment: x for a warp, y for a weft.
    pub axis: f64,
    /// Cylinder radius.
    pub radius: f64,
    /// Height of the axis above the floor.
    pub height: f64,
    /// Extent along the axis (y for a warp, x for a weft), `None` when endless.
    pub extent: Option<(f64, f64)>,
}

impl Segment {
    /// Highest point of the segment above the floor.
    pub fn top(&self) -> f64 {
        self.height + self.radius
    }
}

/// The periodic micro-geometry of a fabric.
#[derive(Clone, Debug)]
pub struct Geometry {
    /// The fabric it was built from.
    pub fabric: Fabric,
    /// X_i of each warp thread.
    pub warp_pos: Vec<f64>,
    /// Y_j of each weft thread.
    pub weft_pos: Vec<f64>,
    /// Period size (Px, Py).
    pub period: (f64, f64),
    /// All segments of one period.
    pub segments: Vec<Segment>,
    /// Per group, the segment covering each (thread, crossing) cell: `at[g][thread * n_c + c]`,
    /// or [`NOT_ON_TOP`]; built once so that [`Geometry::segment_at`] is O(1).
    at: [Vec<u32>; 2],
}

/// Marks a cell of [`Geometry`]'s index where the thread is under.
const NOT_ON_TOP: u32 = u32::MAX;

/// Area of a cylinder's cross-section above the floor, for radius `r` and axis height `h`.
pub fn area_above_floor(r: f64, h: f64) -> f64 {
    let h = h.clamp(-r, r);
    r * r * (PI / 2.0 + (h / r).asin()) + h * (r * r - h * h).sqrt()
}

/// Height of the equal-area rectangle of width 2r standing for a cylinder seen side-on
/// (thesis eq. 3.1, h = pi r / 4 for a half cylinder; generalised to an axis at height `h`).
pub fn equal_area_height(r: f64, h: f64) -> f64 {
    area_above_floor(r, h) / (2.0 * r)
}

impl Geometry {
    /// Builds the micro-geometry of a validated fabric.
    pub fn new(fabric: &Fabric) -> Geometry {
        let (warp_pos, px) = fabric.warp().positions();
        let (weft_pos, py) = fabric.weft().positions();
        let weave = fabric.weave();
        let mut segments = Vec::new();
        let mut at = [
            vec![NOT_ON_TOP; weave.n_warp() * weave.n_weft()],
            vec![NOT_ON_TOP; weave.n_warp() * weave.n_weft()],
        ];
        for g in [Group::Warp, Group::Weft] {
            let nc = weave.n(g.other());
            let (cross_pos, cross_period) = match g {
                Group::Warp => (&weft_pos, py),
                Group::Weft => (&warp_pos, px),
            };
            let pos = match g {
                Group::Warp => &warp_pos,
                Group::Weft => &weft_pos,
            };
            for (t, yarn) in fabric.group(g).threads.iter().enumerate() {
                for fl in fabric.weave().floats(g, t) {
                    let extent = (!fl.endless).then(|| {
                        let room = float_room(fabric.group(g.other()), cross_pos, cross_period, fl);
                        float_extent(room, yarn.segment_length)
                    });
                    let id = u32::try_from(segments.len()).expect("period within MAX_CELLS");
                    for k in 0..fl.len {
                        at[g as usize][t * nc + (fl.start + k) % nc] = id;
                    }
                    segments.push(Segment {
                        group: g,
                        thread: t,
                        float: fl,
                        axis: pos[t],
                        radius: yarn.radius,
                        height: yarn.height,
                        extent,
                    });
                }
            }
        }
        Geometry {
            fabric: fabric.clone(),
            warp_pos,
            weft_pos,
            period: (px, py),
            segments,
            at,
        }
    }

    /// Unwrapped position of thread `k` of group `g`.
    pub fn position(&self, g: Group, k: isize) -> f64 {
        let (pos, p) = match g {
            Group::Warp => (&self.warp_pos, self.period.0),
            Group::Weft => (&self.weft_pos, self.period.1),
        };
        unwrapped_position(pos, p, k)
    }

    /// Period length along the axis of group `g` (the direction its threads run).
    pub fn period_along(&self, g: Group) -> f64 {
        match g {
            Group::Warp => self.period.1,
            Group::Weft => self.period.0,
        }
    }

    /// Period length across group `g` (the direction its threads are spaced in).
    pub fn period_across(&self, g: Group) -> f64 {
        match g {
            Group::Warp => self.period.0,
            Group::Weft => self.period.1,
        }
    }

    /// Index into `segments` of the float of thread `thread` (group `g`) covering crossing
    /// `cross` (any integer), or `None` when the thread is under there.
    pub fn segment_at(&self, g: Group, thread: usize, cross: isize) -> Option<usize> {
        let n = self.fabric.weave().n(g.other());
        let c = cross.rem_euclid(n as isize) as usize;
        match self.at[g as usize][thread * n + c] {
            NOT_ON_TOP => None,
            i => Some(i as usize),
        }
    }

    /// Highest point of any yarn above the floor.
    pub fn max_top(&self) -> f64 {
        self.segments.iter().map(Segment::top).fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn twill() -> Fabric {
        crate::fabric::thesis_twill()
    }

    #[test]
    fn thesis_twill_segment_lengths() {
        // Fig. 4.7: lengths 6.3 (float over two) and 3.2 (float over one), spacing 3.1, radius 1.5.
        let g = Geometry::new(&twill());
        for s in &g.segments {
            let (a, b) = s.extent.unwrap();
            let want = if s.group == Group::Warp { 6.3 } else { 3.2 };
            assert!((b - a - want).abs() < 1e-12, "{s:?}");
        }
        assert_eq!(g.segments.len(), 6);
    }

    #[test]
    fn equal_area_rectangle_of_half_cylinder() {
        assert!((equal_area_height(2.0, 0.0) - PI * 2.0 / 4.0).abs() < 1e-15);
        assert!((area_above_floor(1.0, 0.999999999) - PI).abs() < 1e-4);
        assert!(area_above_floor(1.0, -1.0).abs() < 1e-15);
    }

    #[test]
    fn segment_lookup() {
        let g = Geometry::new(&twill());
        let s = g.segment_at(Group::Warp, 0, 3).unwrap(); // crossing 0 (= 3 mod 3), warp 0 over weft 0
        assert_eq!(g.segments[s].float.start, 2);
        assert!(g.segment_at(Group::Warp, 0, 1).is_none()); // warp 0 under weft 1
    }
}
