//! The openness of the two-faced cloth (docs/science/transmission.md): the share of the light from a
//! direction that passes straight through the gaps between the yarns, in closed form from the
//! threads' cross-sections (the discs of the thesis's shadowing geometry, eqs 3.2-3.9).
//!
//! A thread of the two-faced cloth is, across its axis, the part above z = 0 of its disc
//! (radius r, axis at height h) where it floats on the front, the part below z = 0 of the
//! mirrored disc (axis at -h) where it floats on the back, and both where it passes between the
//! faces. Seen along `w`, each of these shapes shades a strip of the plane z = 0 whose width
//! follows from the shape's support function along the direction's slope across the thread,
//! `t = w_across / w_z`. A thread's strip is the mean of its shapes' widths, weighted by the
//! share of the period each takes along the thread. A group passes the light between its
//! strips, `1 - sum(widths) / period` (at least 0), and the two groups block independently:
//! the openness is the product of the two groups' shares. At normal incidence this is the
//! geometric open area `(1 - d_warp / s_warp)(1 - d_weft / s_weft)` exactly; at an angle it
//! neglects that a ray also runs along the threads (docs/science/transmission.md measures it against
//! the ray tracer).

use crate::fabric::Fabric;
use crate::vec3::UnitVec3;
use crate::weave::{Group, Weave};
use crate::yarn::{float_extent, float_room};

/// max(x - t z) over the part z >= 0 of the disc of radius `r` centred at (0, `h`), |h| < r:
/// the disc's extreme point in the direction (1, -t) where it lies in the half-plane, else the
/// right end of the chord in z = 0.
fn support_above(r: f64, h: f64, t: f64) -> f64 {
    let q = (1.0 + t * t).sqrt();
    if h - r * t / q >= 0.0 {
        -t * h + r * q
    } else {
        (r * r - h * h).max(0.0).sqrt()
    }
}

/// The width of the strip that the part z >= 0 of that disc shades along slope `t`, and the
/// lowest and highest x - t z over it.
fn strip_above(r: f64, h: f64, t: f64) -> (f64, f64) {
    // The shape is symmetric in x: min(x - t z) = -max(x + t z).
    (-support_above(r, h, -t), support_above(r, h, t))
}

/// `intervals` (unwrapped) cut into one period `p`, merged and sorted.
fn wrapped(intervals: impl IntoIterator<Item = (f64, f64)>, p: f64) -> Vec<(f64, f64)> {
    let mut cuts: Vec<(f64, f64)> = Vec::new();
    for (lo, hi) in intervals {
        if hi - lo >= p {
            return vec![(0.0, p)];
        }
        let a = lo.rem_euclid(p);
        let b = a + (hi - lo);
        if b <= p {
            cuts.push((a, b));
        } else {
            cuts.push((a, p));
            cuts.push((0.0, b - p));
        }
    }
    cuts.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (a, b) in cuts {
        match out.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => out.push((a, b)),
        }
    }
    out
}

/// The length of `[a, b]` inside the sorted, disjoint `cover`.
fn inside(cover: &[(f64, f64)], a: f64, b: f64) -> f64 {
    cover
        .iter()
        .map(|&(lo, hi)| (hi.min(b) - lo.max(a)).max(0.0))
        .sum()
}

/// One group's threads: where each floats on the front and on the back along its axis, and
/// the strips its shapes shade across it.
struct Threads {
    /// Axis positions across, and the period across.
    pos: Vec<f64>,
    across: f64,
    /// The period along the threads.
    along: f64,
    /// Per thread: front and back floats (wrapped into the period along).
    front: Vec<Vec<(f64, f64)>>,
    back: Vec<Vec<(f64, f64)>>,
    /// Per thread: the strips (lowest, highest offset from the axis) of its front part, its
    /// back part and both, along the direction's slope across the threads.
    strips: Vec<[(f64, f64); 3]>,
}

impl Threads {
    fn new(fabric: &Fabric, back: &Weave, g: Group, t: f64) -> Threads {
        let (pos, across) = fabric.group(g).positions();
        let (_, along) = fabric.group(g.other()).positions();
        let n = fabric.group(g).threads.len();
        let floats_of = |w: &Weave, k: usize| wrapped(floats(fabric, w, g, k), along);
        Threads {
            pos,
            across,
            along,
            front: (0..n).map(|k| floats_of(fabric.weave(), k)).collect(),
            back: (0..n).map(|k| floats_of(back, k)).collect(),
            strips: fabric
                .group(g)
                .threads
                .iter()
                .map(|y| strips(y.radius, y.height, t))
                .collect(),
        }
    }

    /// The ends of every float, and 0 and the period: where some thread's state changes.
    fn breaks(&self) -> Vec<f64> {
        let mut b = vec![0.0, self.along];
        for f in self.front.iter().chain(&self.back) {
            for &(lo, hi) in f {
                b.extend([lo, hi]);
            }
        }
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }

    /// What the threads shade across them where each is in its state at `a` along them.
    fn cover_at(&self, a: f64) -> Vec<(f64, f64)> {
        let on = |f: &[(f64, f64)]| f.iter().any(|&(lo, hi)| lo <= a && a < hi);
        wrapped(
            (0..self.pos.len()).filter_map(|k| {
                let state = match (on(&self.front[k]), on(&self.back[k])) {
                    (true, false) => 0,
                    (false, true) => 1,
                    (true, true) => 2,
                    (false, false) => return None,
                };
                let (lo, hi) = self.strips[k][state];
                Some((self.pos[k] + lo, self.pos[k] + hi))
            }),
            self.across,
        )
    }
}

/// The strips (lowest and highest offset from the axis) that a thread of radius `r` and
/// height `h` shades along slope `t`: floating on the front, on the back (the mirrored disc
/// below z = 0), and passing between the faces (both parts).
fn strips(r: f64, h: f64, t: f64) -> [(f64, f64); 3] {
    let front = strip_above(r, h, t);
    // The back part is the front part mirrored in z = 0: x - t z over it is x + t z over the
    // front part.
    let back = strip_above(r, h, -t);
    [front, back, (front.0.min(back.0), front.1.max(back.1))]
}

/// A thread's floats on one face as intervals along its axis (the whole period when endless).
fn floats(fabric: &Fabric, weave: &Weave, g: Group, t: usize) -> Vec<(f64, f64)> {
    let (pos, period) = fabric.group(g.other()).positions();
    let yarn = &fabric.group(g).threads[t];
    weave
        .floats(g, t)
        .into_iter()
        .map(|fl| {
            if fl.endless {
                (0.0, period)
            } else {
                let room = float_room(fabric.group(g.other()), &pos, period, fl);
                float_extent(room, yarn.segment_length)
            }
        })
        .collect()
}

/// The openness of the fabric's two-faced cloth along `w` (either side): the share of the
/// light from `w` that crosses the cloth between its yarns; 0 within
/// [`crate::vec3::HORIZON_COS`] of the plane.
///
/// The period is cut into rectangles at the float ends of both groups; within one, every
/// thread keeps its state (front, back, both or none), so the warps shade fixed strips across
/// x and the wefts across y, and the open area is the product of the two open lengths.
pub fn openness(fabric: &Fabric, w: UnitVec3) -> f64 {
    if !(w.above_horizon() || w.below_horizon()) {
        return 0.0;
    }
    let v = w.get();
    let back = fabric.weave().inverted();
    let warp = Threads::new(fabric, &back, Group::Warp, v.x / v.z);
    let weft = Threads::new(fabric, &back, Group::Weft, v.y / v.z);
    // Warps change state along y (breaks in y), wefts along x.
    let (ys, xs) = (warp.breaks(), weft.breaks());
    let warp_cover: Vec<_> = ys
        .windows(2)
        .map(|y| warp.cover_at(0.5 * (y[0] + y[1])))
        .collect();
    let weft_cover: Vec<_> = xs
        .windows(2)
        .map(|x| weft.cover_at(0.5 * (x[0] + x[1])))
        .collect();
    let mut open = 0.0;
    for (j, y) in ys.windows(2).enumerate() {
        for (i, x) in xs.windows(2).enumerate() {
            let ox = (x[1] - x[0]) - inside(&warp_cover[j], x[0], x[1]);
            let oy = (y[1] - y[0]) - inside(&weft_cover[i], y[0], y[1]);
            open += ox * oy;
        }
    }
    (open / (warp.across * weft.across)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_disc_above_its_chord_shades_its_projection() {
        // h = 0: a half disc. Straight down it shades its diameter; along slope t its shadow
        // runs from the far end of the arc, -r sqrt(1 + t^2), to the chord's end r.
        let widths = |r, h, t| strips(r, h, t).map(|(lo, hi)| hi - lo);
        let [f, b, both] = widths(1.0, 0.0, 0.0);
        assert!((f - 2.0).abs() < 1e-15 && (b - 2.0).abs() < 1e-15 && (both - 2.0).abs() < 1e-15);
        let t = 0.75f64;
        let [f, b, both] = widths(1.0, 0.0, t);
        assert!((f - (1.0 + (1.0 + t * t).sqrt())).abs() < 1e-14, "{f}");
        assert!((b - f).abs() < 1e-14);
        // Both halves: the whole disc, 2 r sqrt(1 + t^2).
        assert!((both - 2.0 * (1.0 + t * t).sqrt()).abs() < 1e-14, "{both}");
        // Axis above the plane: the whole arc's extreme points are in the half-plane at small
        // slopes, so the front part shades like the whole disc, 2 r sqrt(1 + t^2).
        let [f, _, _] = widths(1.0, 0.5, 0.2);
        assert!((f - 2.0 * (1.0f64 + 0.04).sqrt()).abs() < 1e-14, "{f}");
    }

    /// The truth's openness of the same cloth (independent geometry and ray casting).
    fn truth(json: &str, w: UnitVec3) -> f64 {
        let f = Fabric::from_json_str(json, "t").unwrap();
        clothbake_truth::RayTracer::two_faced(&f, crate::facet::FacetModel::Lewis)
            .openness(w, 40_000, 3)
    }

    #[test]
    fn the_closed_form_against_the_ray_tracer() {
        let open = |pattern: &str, r: f64, s: f64, h: f64| {
            format!(
                r#"{{"pattern": {pattern}, "warp": {{"radius": {r}, "spacing": {s}, "height": {h}}},
                    "weft": {{"radius": {r}, "spacing": {s}, "height": {h}}}}}"#
            )
        };
        let cases = [
            ("plain", open("[[1,0],[0,1]]", 0.5, 2.0, 0.0)),
            ("plain h", open("[[1,0],[0,1]]", 0.6, 2.0, 0.3)),
            ("twill", open("[[1,1,0],[0,1,1],[1,0,1]]", 0.5, 2.0, 0.0)),
            (
                "satin",
                open(
                    "[[1,0,0,0,0],[0,0,1,0,0],[0,0,0,0,1],[0,1,0,0,0],[0,0,0,1,0]]",
                    0.5,
                    1.6,
                    0.2,
                ),
            ),
        ];
        let mut worst: f64 = 0.0;
        for (name, json) in &cases {
            let f = Fabric::from_json_str(json, "t").unwrap();
            for (theta, phi) in [
                (0.0, 0.0),
                (20.0, 0.0),
                (20.0, 45.0),
                (40.0, 0.0),
                (40.0, 30.0),
                (40.0, 90.0),
                (60.0, 0.0),
                (60.0, 45.0),
                (75.0, 10.0),
            ] {
                let w = UnitVec3::from_degrees(theta, phi);
                let (m, t) = (openness(&f, w), truth(json, w));
                // The truth's binomial noise (40 000 rays) and a margin for what the closed
                // form leaves out (a ray's run along the threads as it crosses them).
                let p = m.max(t);
                let tol = 4.0 * (p * (1.0 - p) / 40_000.0).sqrt() + 0.002;
                assert!(
                    (m - t).abs() < tol,
                    "{name} at ({theta}, {phi}): model {m}, truth {t}"
                );
                worst = worst.max((m - t).abs());
            }
        }
        eprintln!("worst absolute difference {worst}");
    }

    #[test]
    fn intervals_are_measured_once_within_the_period() {
        let covered = |v: &[(f64, f64)], p| inside(&wrapped(v.iter().copied(), p), 0.0, p);
        assert_eq!(covered(&[(1.0, 3.0), (2.0, 4.0)], 10.0), 3.0);
        assert_eq!(covered(&[(9.0, 11.0), (-0.5, 0.5)], 10.0), 2.0);
        assert_eq!(covered(&[(9.0, 11.0), (2.0, 2.5)], 10.0), 2.5);
        assert_eq!(covered(&[(0.0, 12.0)], 10.0), 10.0);
        assert_eq!(
            wrapped([(9.0, 11.0), (-0.5, 0.5)], 10.0),
            [(0.0, 1.0), (9.0, 10.0)]
        );
    }
}
