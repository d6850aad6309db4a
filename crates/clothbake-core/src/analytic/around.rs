//! The yarns around a piece in three dimensions ([`Variant::Sliced3d`]): what of a slice's
//! cross-section they hide from a direction, found by following the rays that leave the arc
//! through every float within reach instead of through the 2-D profiles of one row (eqs
//! 3.4-3.6).
//!
//! A slice's side profile ([`Variant::Sliced`]) holds the occluders the micro-geometry has in
//! the slice's own cross-section plane, and the end profile (eq. 3.6) those along the axis,
//! each crossing thread there an endless cylinder. A ray whose direction has components both
//! across and along the axis leaves both planes: beside a crossing float it drifts toward or
//! away from the crossing cylinder's axis, past a neighbour's float end it meets the next row,
//! and past the end of the crossing float over its own thread it escapes where that thread
//! dives under the neighbour. Here the ray from a point of the arc is followed through the
//! floats around the piece, each a finite cylinder with flat ends (docs/science/model.md, "Geometry"):
//! the other threads of its group, its own thread's other floats and every float of the
//! crossing group, the whole period repeated as far as a ray 2 degrees above the horizon can
//! travel below the highest yarn top. The piece's own float is left out (a ray leaving the arc
//! that faces it does not meet its own cylinder again).
//!
//! The arc is sampled at [`SAMPLES`] points; its visible part is taken as the longest run of
//! samples whose rays meet nothing, each end refined by bisection between the last visible and
//! the first hidden sample. A hidden or visible stretch narrower than a sample spacing can be
//! missed.

use super::View;
use crate::arc::ArcTrig;
use crate::geometry::{Geometry, Segment};
use std::f64::consts::FRAC_PI_2;

/// Points the arc is sampled at (its ends included).
const SAMPLES: usize = 16;

/// Bisection steps refining an end of the visible run: a sample spacing / 2^12.
const STEPS: u32 = 12;

/// The most grazing direction whose occluders are all gathered: rays within this elevation of
/// the horizon may travel beyond the floats gathered (tan of 2 degrees).
const TAN_LOWEST: f64 = 0.034_920_769;

/// A float as a finite cylinder in a piece's frame: `c` across the piece's axis (from it), `a`
/// along it, `z` up.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cylinder {
    /// Its axis along `c` (a crossing float) or along `a` (a float of the piece's group).
    across: bool,
    /// The axis's position in the plane perpendicular to it: (c, z) along `a`, (a, z) across.
    at: (f64, f64),
    radius: f64,
    /// Its extent along its axis.
    extent: (f64, f64),
    /// Horizontal distance from the piece's footprint (its order in the list).
    distance: f64,
}

/// The floats around one piece, nearest first, and the highest yarn top.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Around {
    cylinders: Vec<Cylinder>,
    top: f64,
}

/// The distance between intervals `x` and `y` (0 where they overlap).
fn gap(x: (f64, f64), y: (f64, f64)) -> f64 {
    (y.0 - x.1).max(x.0 - y.1).max(0.0)
}

impl Around {
    /// The floats around the piece of `seg` (one of `geo`'s segments) over the axial range
    /// `range` that can hide part of it from a direction at least 2 degrees above the horizon.
    pub(super) fn of(geo: &Geometry, seg: &Segment, range: (f64, f64)) -> Around {
        let g = seg.group;
        let top = geo.segments.iter().map(Segment::top).fold(0.0f64, f64::max);
        let reach = top / TAN_LOWEST;
        let (pc, pa) = (geo.period_across(g), geo.period_along(g));
        let (nc, na) = (
            (reach / pc).ceil() as i64 + 1,
            (reach / pa).ceil() as i64 + 1,
        );
        let own = (-seg.radius, seg.radius);
        let inf = f64::INFINITY;
        let mut cylinders = Vec::new();
        for s in &geo.segments {
            for i in -nc..=nc {
                for j in -na..=na {
                    let (dc, da) = (i as f64 * pc, j as f64 * pa);
                    let cyl = if s.group == g {
                        let itself = std::ptr::eq(s, seg) && i == 0 && j == 0;
                        if itself || (s.extent.is_none() && j != 0) {
                            continue;
                        }
                        let c = s.axis - seg.axis + dc;
                        let extent = s.extent.map_or((-inf, inf), |(e0, e1)| (e0 + da, e1 + da));
                        Cylinder {
                            across: false,
                            at: (c, s.height),
                            radius: s.radius,
                            extent,
                            distance: gap(own, (c - s.radius, c + s.radius))
                                .hypot(gap(range, extent)),
                        }
                    } else {
                        if s.extent.is_none() && i != 0 {
                            continue;
                        }
                        let extent = s.extent.map_or((-inf, inf), |(e0, e1)| {
                            (e0 - seg.axis + dc, e1 - seg.axis + dc)
                        });
                        let a = s.axis + da;
                        Cylinder {
                            across: true,
                            at: (a, s.height),
                            radius: s.radius,
                            extent,
                            distance: gap(own, extent)
                                .hypot(gap(range, (a - s.radius, a + s.radius))),
                        }
                    };
                    if cyl.distance <= reach {
                        cylinders.push(cyl);
                    }
                }
            }
        }
        // Nearest first; among equally near ones, an order that does not depend on where the
        // piece lies (the unit key compares the lists of translated pieces in order).
        let grid = |x: f64| (x / (1e-6 * seg.radius)).round();
        cylinders.sort_by(|x, y| {
            let k = |q: &Cylinder| {
                let along = if q.across {
                    q.at.0 - range.0
                } else {
                    q.extent.0 - range.0
                };
                [
                    grid(q.distance),
                    f64::from(u8::from(q.across)),
                    grid(q.at.0 * f64::from(u8::from(!q.across))),
                    grid(along),
                    grid(q.at.1),
                ]
            };
            let (a, b) = (k(x), k(y));
            a.iter()
                .zip(&b)
                .map(|(p, q)| p.total_cmp(q))
                .find(|o| o.is_ne())
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        Around { cylinders, top }
    }

    /// The floats' part of a unit key: each float relative to the piece (its axial positions
    /// from `origin`), lengths in units of `unit`, nearest first; an endless extent as a large
    /// number. Two pieces whose keys agree see the same surroundings.
    pub(super) fn key(&self, origin: f64, unit: f64, out: &mut Vec<f64>) {
        let finite = |x: f64| x.clamp(-1e12, 1e12);
        out.extend([self.cylinders.len() as f64, self.top / unit]);
        for q in &self.cylinders {
            let (at, extent) = if q.across {
                ((q.at.0 - origin, q.at.1), q.extent)
            } else {
                (q.at, (q.extent.0 - origin, q.extent.1 - origin))
            };
            out.extend([
                f64::from(u8::from(q.across)),
                at.0 / unit,
                at.1 / unit,
                q.radius / unit,
                finite(extent.0) / unit,
                finite(extent.1) / unit,
            ]);
        }
    }

    /// Whether the ray from `p` = (c, a, z) along `d` (rising: d.z > 0) meets a float.
    #[cfg(test)]
    fn blocks(&self, p: [f64; 3], d: [f64; 3]) -> bool {
        let all: Vec<&Cylinder> = self.cylinders.iter().collect();
        blocks_among(&all, self.top, p, d, d[0].hypot(d[1]))
    }

    /// The floats, nearest first, that a ray along `d` (rising) from a point of the box
    /// `(lo, hi)` (corners (c, a, z)) can meet below the highest top: those whose bounding box
    /// the box swept along `d` meets. Every float [`blocks_among`] can find such a ray to meet
    /// is among them (both boxes grown by a rounding margin). `horizontal` is |(d.c, d.a)|.
    fn candidates(
        &self,
        lo: [f64; 3],
        hi: [f64; 3],
        d: [f64; 3],
        horizontal: f64,
    ) -> Vec<&Cylinder> {
        let margin = 1e-9 * self.top.abs().max(hi[0] - lo[0]).max(hi[2] - lo[2]);
        let s_max = (self.top - lo[2]).max(0.0) / d[2] + margin;
        let reach = s_max * horizontal + margin;
        let inv = d.map(|x| 1.0 / x);
        let mut out = Vec::new();
        for q in &self.cylinders {
            if q.distance > reach {
                break;
            }
            let r = (q.at.0 - q.radius, q.at.0 + q.radius);
            let (c, a) = if q.across {
                (q.extent, r)
            } else {
                (r, q.extent)
            };
            let z = (q.at.1 - q.radius, q.at.1 + q.radius);
            let (mut s0, mut s1) = (0.0f64, s_max);
            for (k, (b0, b1)) in [(2, z), (0, c), (1, a)] {
                let (b0, b1) = (b0 - margin, b1 + margin);
                let (p0, p1) = (lo[k] - margin, hi[k] + margin);
                // The s where [p0, p1] + s d[k] meets [b0, b1].
                let (x, y) = if d[k] > 0.0 {
                    ((b0 - p1) * inv[k], (b1 - p0) * inv[k])
                } else if d[k] < 0.0 {
                    ((b1 - p0) * inv[k], (b0 - p1) * inv[k])
                } else if p0 > b1 || p1 < b0 {
                    (1.0, -1.0)
                } else {
                    continue;
                };
                if x > s0 {
                    s0 = x;
                }
                if y < s1 {
                    s1 = y;
                }
                if s0 > s1 {
                    break;
                }
            }
            if s0 <= s1 {
                out.push(q);
            }
        }
        out
    }

    /// The part of `arc` (of a cross-section of `radius` with its axis at `height`, at axial
    /// position `a`; already facing `v` and above the floor) whose rays toward `v` meet no
    /// float: its longest visible run (module docs), empty where every sample is hidden.
    pub(super) fn open_arc(
        &self,
        radius: f64,
        height: f64,
        a: f64,
        v: &View,
        arc: ArcTrig,
    ) -> ArcTrig {
        if arc.arc.is_empty() || v.p.p.z <= 0.0 {
            return arc;
        }
        let d = [v.p.p.c, v.va, v.p.p.z];
        let (lo, hi) = (arc.arc.lo, arc.arc.hi);
        // The box of the arc's points: its ends, and the extremes of the circle it passes.
        let (mut s_range, mut c_range) = (
            (arc.lo.0.min(arc.hi.0), arc.lo.0.max(arc.hi.0)),
            (arc.lo.1.min(arc.hi.1), arc.lo.1.max(arc.hi.1)),
        );
        for k in -4i32..=8 {
            let t = f64::from(k) * FRAC_PI_2;
            if lo <= t && t <= hi {
                match k.rem_euclid(4) {
                    0 => c_range.1 = 1.0,
                    1 => s_range.1 = 1.0,
                    2 => c_range.0 = -1.0,
                    _ => s_range.0 = -1.0,
                }
            }
        }
        let horizontal = d[0].hypot(d[1]);
        let floats = self.candidates(
            [radius * c_range.0, a, height + radius * s_range.0],
            [radius * c_range.1, a, height + radius * s_range.1],
            d,
            horizontal,
        );
        if floats.is_empty() {
            return arc;
        }
        // Whether the ray from the arc's point at (sin, cos) meets a float.
        let hidden = |(s, c): (f64, f64)| {
            blocks_among(
                &floats,
                self.top,
                [radius * c, a, height + radius * s],
                d,
                horizontal,
            )
        };
        // The samples, by turning the first one a sample spacing at a time.
        let step = (hi - lo) / (SAMPLES - 1) as f64;
        let turn = step.sin_cos();
        let mut points = [(0.0, 0.0); SAMPLES];
        let mut p = arc.lo;
        for (k, point) in points.iter_mut().enumerate() {
            *point = if k + 1 == SAMPLES { arc.hi } else { p };
            p = (p.0 * turn.1 + p.1 * turn.0, p.1 * turn.1 - p.0 * turn.0);
        }
        // The longest run of visible samples: (first, last).
        let (mut best, mut run): (Option<(usize, usize)>, Option<usize>) = (None, None);
        for (k, &point) in points.iter().enumerate() {
            if hidden(point) {
                run = None;
                continue;
            }
            let first = *run.get_or_insert(k);
            if best.is_none_or(|(f, l)| k - first > l - f) {
                best = Some((first, k));
            }
        }
        let mut out = arc;
        let Some((first, last)) = best else {
            out.arc.hi = out.arc.lo;
            out.hi = out.lo;
            return out;
        };
        let at = |k: usize| (lo + step * k as f64, points[k]);
        // Between a visible and a hidden point (angle, (sin, cos)), the visible end of the
        // boundary; the middle of two points less than half a turn apart is their normalised
        // sum.
        let refine = |mut seen: (f64, (f64, f64)), mut hid: (f64, (f64, f64))| {
            for _ in 0..STEPS {
                let (s, c) = (seen.1 .0 + hid.1 .0, seen.1 .1 + hid.1 .1);
                let n = (s * s + c * c).sqrt();
                let m = (0.5 * (seen.0 + hid.0), (s / n, c / n));
                if hidden(m.1) {
                    hid = m;
                } else {
                    seen = m;
                }
            }
            seen
        };
        if first > 0 {
            let (t, sc) = refine(at(first), at(first - 1));
            out.arc.lo = t;
            out.lo = sc;
        }
        if last + 1 < SAMPLES {
            let (t, sc) = refine(at(last), at(last + 1));
            out.arc.hi = t;
            out.hi = sc;
        }
        out
    }
}

/// Whether the ray from `p` = (c, a, z) along `d` (rising: d.z > 0) meets one of `floats`
/// (nearest first) below `top`; `horizontal` is |(d.c, d.a)|.
fn blocks_among(floats: &[&Cylinder], top: f64, p: [f64; 3], d: [f64; 3], horizontal: f64) -> bool {
    // Beyond this horizontal distance the ray is above every yarn.
    let reach = (top - p[2]).max(0.0) / d[2] * horizontal;
    for q in floats {
        if q.distance > reach {
            break;
        }
        // The ray in the plane perpendicular to the cylinder's axis (u, w) and along it (s).
        let (u0, du, s0, ds) = if q.across {
            (p[1] - q.at.0, d[1], p[0], d[0])
        } else {
            (p[0] - q.at.0, d[0], p[1], d[1])
        };
        let (w0, dw) = (p[2] - q.at.1, d[2]);
        // Where the ray is within the cylinder's extent along its axis.
        let (ta, tb) = if ds == 0.0 {
            if q.extent.0 <= s0 && s0 <= q.extent.1 {
                (f64::NEG_INFINITY, f64::INFINITY)
            } else {
                continue;
            }
        } else {
            let (x, y) = ((q.extent.0 - s0) / ds, (q.extent.1 - s0) / ds);
            (x.min(y), x.max(y))
        };
        if tb <= 0.0 {
            continue;
        }
        // Where it is within the cylinder's cross-section: a*t^2 + 2 b t + c <= 0.
        let a = du * du + dw * dw;
        let b = u0 * du + w0 * dw;
        let c = u0 * u0 + w0 * w0 - q.radius * q.radius;
        let disc = b * b - a * c;
        if disc <= 0.0 {
            continue;
        }
        let root = disc.sqrt();
        let (t1, t2) = ((-b - root) / a, (-b + root) / a);
        if t2.min(tb) > t1.max(ta).max(0.0) {
            return true;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fabric::Fabric;
    use crate::rng::Rng;

    /// The pieces of the twill and of an open weave with lifted and sunk threads, each with
    /// the floats around its whole range.
    fn pieces() -> Vec<(Segment, Around)> {
        let fabrics = [
            r#"{"pattern": [[1,1,0],[0,1,1],[1,0,1]],
                "warp": {"radius": 1.5, "spacing": 3.1}, "weft": {"radius": 1.5, "spacing": 3.1}}"#,
            r#"{"pattern": [[1,0],[0,1]],
                "warp": {"radius": 1.0, "height": 0.3, "spacing": 3.0},
                "weft": {"radius": 0.8, "height": -0.2, "spacing": 2.5}}"#,
        ];
        let mut out = Vec::new();
        for json in fabrics {
            let geo = Geometry::new(&Fabric::from_json_str(json, "t").unwrap());
            for seg in &geo.segments {
                out.push((seg.clone(), Around::of(&geo, seg, seg.extent.unwrap())));
            }
        }
        out
    }

    /// Whether `p` lies inside cylinder `q` (its cross-section and its extent).
    fn inside(q: &Cylinder, p: [f64; 3]) -> bool {
        let (u, s) = if q.across { (p[1], p[0]) } else { (p[0], p[1]) };
        (u - q.at.0).hypot(p[2] - q.at.1) < q.radius && q.extent.0 < s && s < q.extent.1
    }

    /// `blocks` against marching the ray in small steps through every float gathered, on
    /// the twill and an open weave with lifted and sunk threads: from random points of each
    /// piece's arc, toward random directions above the horizon. A march can step over a chord
    /// shorter than its step, so a few grazing rays may differ; no more than 0.5% of them.
    #[test]
    fn rays_meet_what_a_march_through_the_floats_meets() {
        let mut rng = Rng::new(3);
        let (mut n, mut differ) = (0, 0);
        for (seg, around) in pieces() {
            let (e0, e1) = seg.extent.unwrap();
            for _ in 0..400 {
                let t = std::f64::consts::PI * rng.next_f64();
                let a = e0 + (e1 - e0) * rng.next_f64();
                let p = [seg.radius * t.cos(), a, seg.height + seg.radius * t.sin()];
                let (ct, phi) = (
                    0.05 + 0.95 * rng.next_f64(),
                    2.0 * std::f64::consts::PI * rng.next_f64(),
                );
                let st = (1.0 - ct * ct).sqrt();
                let d = [st * phi.cos(), st * phi.sin(), ct];
                // Leaving the arc outward only (a ray into its own cylinder is not asked).
                if d[0] * t.cos() + d[2] * t.sin() <= 0.0 {
                    continue;
                }
                let step = 2e-3 * seg.radius;
                let mut hit = false;
                let mut k = 1;
                loop {
                    let q = [
                        p[0] + k as f64 * step * d[0],
                        p[1] + k as f64 * step * d[1],
                        p[2] + k as f64 * step * d[2],
                    ];
                    if q[2] > around.top {
                        break;
                    }
                    if around.cylinders.iter().any(|c| inside(c, q)) {
                        hit = true;
                        break;
                    }
                    k += 1;
                }
                n += 1;
                if hit != around.blocks(p, d) {
                    differ += 1;
                }
            }
        }
        assert!(n > 1000, "{n} rays");
        assert!(differ * 200 <= n, "{differ} of {n} rays differ");
    }

    /// The floats [`Around::candidates`] keeps for a box of start points and a direction
    /// hold every one that a ray from the box meets: `blocks` through them and through all
    /// floats agree, from random points of random boxes within each piece's cross-section
    /// toward random directions (grazing ones included), on the same two fabrics.
    #[test]
    fn the_floats_kept_for_a_box_hold_every_one_its_rays_meet() {
        let mut rng = Rng::new(5);
        let (mut n, mut hits, mut kept, mut all) = (0, 0, 0, 0);
        for (seg, around) in pieces() {
            let (e0, e1) = seg.extent.unwrap();
            for _ in 0..200 {
                let a = e0 + (e1 - e0) * rng.next_f64();
                let mut box_of = |r: f64| {
                    let (x, y) = (
                        r * (2.0 * rng.next_f64() - 1.0),
                        r * (2.0 * rng.next_f64() - 1.0),
                    );
                    (x.min(y), x.max(y))
                };
                let (c, z) = (box_of(seg.radius), box_of(seg.radius));
                let ct = 0.02 + 0.98 * rng.next_f64();
                let phi = 2.0 * std::f64::consts::PI * rng.next_f64();
                let st = (1.0 - ct * ct).sqrt();
                let d = [st * phi.cos(), st * phi.sin(), ct];
                let (lo, hi) = ([c.0, a, seg.height + z.0], [c.1, a, seg.height + z.1]);
                let floats = around.candidates(lo, hi, d, d[0].hypot(d[1]));
                kept += floats.len();
                all += around.cylinders.len();
                for _ in 0..20 {
                    let p = [
                        c.0 + (c.1 - c.0) * rng.next_f64(),
                        a,
                        seg.height + z.0 + (z.1 - z.0) * rng.next_f64(),
                    ];
                    let hit = around.blocks(p, d);
                    n += 1;
                    hits += usize::from(hit);
                    assert_eq!(
                        hit,
                        blocks_among(&floats, around.top, p, d, d[0].hypot(d[1])),
                        "ray from {p:?} along {d:?}"
                    );
                }
            }
        }
        // Not vacuous: many rays meet a float, and the box keeps few of the floats.
        assert!(
            hits * 5 > n && hits * 5 < 4 * n,
            "{hits} of {n} rays meet a float"
        );
        assert!(kept * 10 < all, "kept {kept} of {all}");
    }
}
