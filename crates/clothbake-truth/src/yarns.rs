//! The truth's own micro-geometry, built from a [`Description`] by the rules of thesis ch. 2 as
//! `docs/science/geometry.md` states them (written here independently of the model's `geometry`):
//!
//! * the floor is z = 0; each yarn is a circular cylinder of its thread's radius with its axis
//!   horizontal at the thread's height, cut by the floor;
//! * warp thread i runs along +Y at x = X_i, weft thread j along +X at y = Y_j, with X_0 = 0 and
//!   X_{i+1} = X_i + spacing_i (likewise Y); the period Px x Py (the sums of the spacings)
//!   tiles the plane;
//! * only floats exist: a thread on top of the crossing threads a..=b (a maximal run, taken
//!   cyclically over the period) is one segment from the surface of crossing thread a-1 to that
//!   of b+1, `[P_{a-1} + r_{a-1}, P_{b+1} - r_{b+1}]` in unwrapped coordinates, or a given
//!   length centred in that room; a thread that is never under is one endless cylinder, one that
//!   is never on top does not appear;
//! * the two-faced cloth (docs/science/transmission.md) has no floor: its back is built by the same
//!   rules from the inverted weave (a thread's floats under its crossing threads), mirrored
//!   below z = 0 (axis at minus the thread's height, cut by z <= 0).

use super::description::{Description, Finish, Thread};
use clothbake_fabric::weave::Group;

/// One cylinder segment of the period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    /// Warp (axis along +Y) or weft (axis along +X).
    pub group: Group,
    /// Thread index within its group.
    pub thread: usize,
    /// Across coordinate of the axis: x for a warp, y for a weft.
    pub axis: f64,
    /// Radius.
    pub radius: f64,
    /// Height of the axis above the floor.
    pub height: f64,
    /// Extent along the axis (y for a warp, x for a weft), `None` when endless.
    pub extent: Option<(f64, f64)>,
    /// Facet material.
    pub finish: Finish,
    /// The face it belongs to, and what the plane z = 0 is to it.
    pub face: Face,
}

/// Which side of the plane z = 0 a segment lies on, and what that plane is to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Face {
    /// The thesis's cloth: above z = 0, which is the opaque floor.
    OverFloor,
    /// The two-faced cloth's front: above z = 0, its flat underside a surface of the yarn.
    Front,
    /// The two-faced cloth's back: below z = 0 (the inverted weave mirrored), its flat top a
    /// surface of the yarn.
    Back,
}

/// The segments of one period and the period's size.
#[derive(Clone, Debug, PartialEq)]
pub struct Yarns {
    /// Period (Px, Py).
    pub period: (f64, f64),
    /// Every segment of one period: warp threads in order, then weft threads, each thread's
    /// floats in the order of their first crossing.
    pub cylinders: Vec<Cylinder>,
    /// Axis positions of the warp threads (x) and of the weft threads (y) in one period,
    /// increasing from 0.
    pub threads: (Vec<f64>, Vec<f64>),
}

/// Positions of threads along the direction they are spaced in, and the period length.
struct Row<'a> {
    threads: &'a [Thread],
    start: Vec<f64>,
    period: f64,
}

impl<'a> Row<'a> {
    fn new(threads: &'a [Thread]) -> Row<'a> {
        let mut start = Vec::with_capacity(threads.len());
        let mut x = 0.0;
        for t in threads {
            start.push(x);
            x += t.spacing;
        }
        Row {
            threads,
            start,
            period: x,
        }
    }

    /// The thread and the unwrapped position of index `k` (any integer).
    fn at(&self, k: i64) -> (&Thread, f64) {
        let n = self.threads.len() as i64;
        let i = k.rem_euclid(n) as usize;
        let copies = (k - i as i64) / n;
        (
            &self.threads[i],
            self.start[i] + copies as f64 * self.period,
        )
    }
}

impl Yarns {
    /// The micro-geometry of a description.
    pub fn build(d: &Description) -> Yarns {
        Yarns::faces(d, &[Face::OverFloor])
    }

    /// The two-faced cloth of a description: the front by the rules of [`Yarns::build`], the
    /// back the floats of the inverted weave mirrored below z = 0; no floor.
    pub fn build_two_faced(d: &Description) -> Yarns {
        Yarns::faces(d, &[Face::Front, Face::Back])
    }

    fn faces(d: &Description, faces: &[Face]) -> Yarns {
        let warp = Row::new(&d.warp);
        let weft = Row::new(&d.weft);
        let mut cylinders = Vec::new();
        for &face in faces {
            let back = face == Face::Back;
            for (group, own, crossing) in [(Group::Warp, &warp, &weft), (Group::Weft, &weft, &warp)]
            {
                let n = crossing.threads.len();
                for (t, thread) in own.threads.iter().enumerate() {
                    // on_top[c]: this thread lies over crossing thread c.
                    let on_top: Vec<bool> = (0..n)
                    .map(|c| match group {
                        Group::Warp => d.weave.warp_over(t, c),
                        Group::Weft => !d.weave.warp_over(c, t),
                    } != back)
                    .collect();
                    let place = |extent| Cylinder {
                        group,
                        thread: t,
                        axis: own.start[t],
                        radius: thread.radius,
                        height: if back { -thread.height } else { thread.height },
                        extent,
                        finish: thread.finish,
                        face,
                    };
                    if on_top.iter().all(|&o| o) {
                        cylinders.push(place(None));
                        continue;
                    }
                    for a in 0..n {
                        // A float begins where the thread comes up from under the previous crossing.
                        if !on_top[a] || on_top[(a + n - 1) % n] {
                            continue;
                        }
                        let len = (a..a + n).take_while(|&c| on_top[c % n]).count();
                        let (before, p_before) = crossing.at(a as i64 - 1);
                        let (after, p_after) = crossing.at((a + len) as i64);
                        let (lo, hi) = (p_before + before.radius, p_after - after.radius);
                        let extent = match thread.length {
                            Some(l) => {
                                let mid = 0.5 * (lo + hi);
                                (mid - 0.5 * l, mid + 0.5 * l)
                            }
                            None => (lo, hi),
                        };
                        cylinders.push(place(Some(extent)));
                    }
                }
            }
        }
        Yarns {
            period: (warp.period, weft.period),
            threads: (warp.start.clone(), weft.start.clone()),
            cylinders,
        }
    }

    /// Highest point of any yarn above the floor (0 without yarns).
    pub fn top(&self) -> f64 {
        self.cylinders
            .iter()
            .map(|c| c.height + c.radius)
            .fold(0.0, f64::max)
    }

    /// Lowest point of any yarn (0 over the floor or without yarns below z = 0).
    pub fn bottom(&self) -> f64 {
        self.cylinders
            .iter()
            .filter(|c| c.face == Face::Back)
            .map(|c| c.height - c.radius)
            .fold(0.0, f64::min)
    }

    /// Whether the cloth has two faces and no floor.
    pub fn two_faced(&self) -> bool {
        self.cylinders.iter().any(|c| c.face != Face::OverFloor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_fabric::fabric::Fabric;

    fn yarns(json: &str) -> Yarns {
        Yarns::build(&Description::of(
            &Fabric::from_json_str(json, "test").unwrap(),
        ))
    }

    #[test]
    fn thesis_twill_lengths_and_places() {
        // Fig. 4.7: warp floats over two wefts are 3 * 3.1 - 2 * 1.5 = 6.3 long, weft floats over
        // one warp 2 * 3.1 - 3 = 3.2; the period is 3 x 3.1 each way.
        let y = yarns(
            r#"{"pattern": [[1,1,0],[0,1,1],[1,0,1]],
                "warp": {"radius": 1.5, "spacing": 3.1}, "weft": {"radius": 1.5, "spacing": 3.1}}"#,
        );
        assert!((y.period.0 - 9.3).abs() < 1e-12 && (y.period.1 - 9.3).abs() < 1e-12);
        assert_eq!(y.cylinders.len(), 6);
        for c in &y.cylinders {
            let (lo, hi) = c.extent.unwrap();
            let want = if c.group == Group::Warp { 6.3 } else { 3.2 };
            assert!((hi - lo - want).abs() < 1e-12, "{c:?}");
            assert!((c.axis - 3.1 * c.thread as f64).abs() < 1e-12);
        }
        // Warp 0 is over wefts 2 and 0 (column 0 reads 1, 0, 1): from weft 1's surface
        // (3.1 + 1.5) to the next period's weft 1 (9.3 + 3.1 - 1.5).
        let w0 = y.cylinders[0];
        assert_eq!((w0.group, w0.thread), (Group::Warp, 0));
        let (lo, hi) = w0.extent.unwrap();
        assert!(
            (lo - 4.6).abs() < 1e-12 && (hi - 10.9).abs() < 1e-12,
            "{lo} {hi}"
        );
    }

    #[test]
    fn endless_given_lengths_and_uneven_spacings() {
        // Warp 0 is never under: endless. Warp 1 is over weft 1 only, between weft 0 (y = 0,
        // radius 0.4) and weft 2 (y = 1 + 3 = 4, radius 0.7): room [0.4, 3.3], length 2 centred.
        let y = yarns(
            r#"{"pattern": [[1,0],[1,1],[1,0]],
                "warp": {"radius": [1, 0.8], "height": [0.2, -0.1], "spacing": [2, 2.5], "segment_length": [2, 2]},
                "weft": {"radius": [0.4, 0.5, 0.7], "spacing": [1, 3, 2]}}"#,
        );
        assert_eq!(y.period, (4.5, 6.0));
        let warps: Vec<&Cylinder> = y
            .cylinders
            .iter()
            .filter(|c| c.group == Group::Warp)
            .collect();
        assert_eq!(warps.len(), 2);
        assert_eq!(warps[0].extent, None);
        assert_eq!((warps[0].radius, warps[0].height), (1.0, 0.2));
        let (lo, hi) = warps[1].extent.unwrap();
        assert!(
            (lo - 0.85).abs() < 1e-12 && (hi - 2.85).abs() < 1e-12,
            "{lo} {hi}"
        );
        assert_eq!((warps[1].axis, warps[1].height), (2.0, -0.1));
        // Wefts 0 and 2 float over warp 1 (x = 2) between warp 0 at x = 0 (radius 1) and the
        // next period's warp 0 at x = 4.5; weft 1 is always under.
        let wefts: Vec<&Cylinder> = y
            .cylinders
            .iter()
            .filter(|c| c.group == Group::Weft)
            .collect();
        assert_eq!(wefts.iter().map(|c| c.thread).collect::<Vec<_>>(), [0, 2]);
        for c in wefts {
            assert_eq!(c.extent, Some((1.0, 3.5)));
        }
        assert!((y.top() - 1.2).abs() < 1e-15);
    }
}
