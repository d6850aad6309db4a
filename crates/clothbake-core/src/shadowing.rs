//! Shadowing and blocking between thread segments (thesis sec. 3.1-3.2, eqs 3.1-3.9).
//!
//! Every interaction is solved in a 2-D profile: the cross-section plane of a segment (for the
//! arc a neighbour hides, eqs 3.4-3.5) or the plane along its axis (for the length a crossing
//! thread hides at its end, eq. 3.6). In the profile, `u` is the outward distance from the
//! shadowed segment (its axis for a cross-section, its end for an axial profile) and `z` the
//! height above the floor. A direction V arriving from the outward side has elevation `psi`
//! (angle between the floor and the projection V_p).
//!
//! Occluders are discs: a cylinder seen end-on is a disc of its radius; a cylinder seen side-on is
//! the thesis's equal-area rectangle (eq. 3.1), whose only corner that can support a shadow line
//! from the outward side is its near top corner, a disc of radius 0. With that, the three cases of
//! sec. 3.1 and the three common tangents of sec. 3.2 are each one formula:
//!
//! * support line of slope `psi` of a disc, offset `s = rho - u sin(psi) + z cos(psi)` along
//!   the line's normal (-sin psi, cos psi): the numerators of eqs 3.4 and 3.5;
//! * common tangent of two discs: eqs 3.7 (disc-disc), 3.8 (disc-corner), 3.9 (corner-disc).

use crate::arc::{ArcTrig, Projected};
use crate::trig::{atan2, sin_cos};
use std::f64::consts::FRAC_PI_2;

/// An elevation psi with its sine and cosine, computed once per direction and shared by the
/// formulas that need them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elevation {
    /// psi.
    pub psi: f64,
    /// sin(psi).
    pub sin: f64,
    /// cos(psi).
    pub cos: f64,
}

impl Elevation {
    /// Elevation `psi`.
    pub fn new(psi: f64) -> Elevation {
        let (sin, cos) = psi.sin_cos();
        Elevation { psi, sin, cos }
    }

    /// The elevation of a direction that rises `rise` per `run` outward (`run` > 0, not both
    /// zero): psi = atan2(rise, run), the sine and cosine from the components (inline).
    #[inline]
    pub fn of(rise: f64, run: f64) -> Elevation {
        let inv = 1.0 / (rise * rise + run * run).sqrt();
        Elevation {
            psi: atan2(rise, run),
            sin: rise * inv,
            cos: run * inv,
        }
    }
}

/// An occluder in a profile: a disc centred at (`u`, `z`) of radius `rho` (0 for a rectangle corner).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Occluder {
    /// Outward distance of the centre (or corner).
    pub u: f64,
    /// Height of the centre (or corner) above the floor.
    pub z: f64,
    /// Radius; 0 for the near top corner of an equal-area rectangle.
    pub rho: f64,
}

impl Occluder {
    /// Offset of the occluder's support line of elevation `psi` (given by its sine and cosine),
    /// measured along the line's normal (-sin psi, cos psi) from the profile's origin at floor level.
    pub fn support(&self, sin_psi: f64, cos_psi: f64) -> f64 {
        self.rho - self.u * sin_psi + self.z * cos_psi
    }

    /// Near edge of the occluder at floor level (what a vertical scan line meets first).
    fn near_edge(&self) -> f64 {
        self.u - self.rho
    }
}

/// Elevation at which the support lines of `a` and of the farther occluder `b` coincide:
/// their common upper tangent (eqs 3.7, 3.8, 3.9 in one). `None` when no such tangent exists.
pub fn common_tangent(a: &Occluder, b: &Occluder) -> Option<f64> {
    // rho_a - u_a sin + z_a cos = rho_b - u_b sin + z_b cos
    //   <=> (u_b - u_a) sin psi - (z_b - z_a) cos psi = rho_b - rho_a
    let (da, db, c) = (b.u - a.u, b.z - a.z, b.rho - a.rho);
    let r = da.hypot(db);
    if r <= 0.0 || c.abs() > r {
        return None;
    }
    Some(db.atan2(da) + (c / r).asin())
}

/// The active-occluder look-up table of one direction of one unit (Table 3.1): for elevations in
/// `[psi_k, psi_{k-1})` the occluder `k` casts the highest support line.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ActiveTable {
    /// (lower elevation bound, occluder), in order of decreasing elevation; the first entry's
    /// range reaches up to pi/2, the last one's bound is 0.
    pub entries: Vec<(f64, Occluder)>,
}

/// The scan's choice of the next active occluder (sec. 3.2): `o`, at index `k` and farther out
/// than `cur`, becomes `best` when its common tangent with `cur` lies in (0, `upper`) and is
/// steeper than best's.
fn consider(cur: &Occluder, o: &Occluder, k: usize, upper: f64, best: &mut Option<(f64, usize)>) {
    if let Some(psi) = common_tangent(cur, o) {
        if psi > 0.0 && psi < upper && best.is_none_or(|(b, _)| psi > b) {
            *best = Some((psi, k));
        }
    }
}

/// One step of the scan: enters `cur` for the elevations down to the tangent to `best` (or to
/// 0 when there is none, which ends the table); returns the next occluder's index.
fn advance(
    entries: &mut Vec<(f64, Occluder)>,
    cur: Occluder,
    best: Option<(f64, usize)>,
    upper: &mut f64,
) -> Option<usize> {
    match best {
        Some((psi, k)) => {
            entries.push((psi, cur));
            *upper = psi;
            Some(k)
        }
        None => {
            entries.push((0.0, cur));
            None
        }
    }
}

impl ActiveTable {
    /// The cylinder scan of sec. 3.2: start from the nearest occluder (met first by a vertical
    /// scan line), then repeatedly swing the scan line toward the horizon, tangent to the current
    /// active occluder, until it meets the next one (largest common-tangent elevation), as in the
    /// thesis's pseudocode. `occluders` should cover one period plus the unit's own repetition.
    pub fn scan(occluders: &[Occluder]) -> ActiveTable {
        let mut entries = Vec::new();
        let Some(mut j) = (0..occluders.len()).min_by(|&a, &b| {
            occluders[a]
                .near_edge()
                .total_cmp(&occluders[b].near_edge())
        }) else {
            return ActiveTable { entries };
        };
        let mut upper = FRAC_PI_2;
        loop {
            let cur = occluders[j];
            // The next active occluder: the farther one whose common tangent with the current
            // one is steepest below the current range.
            let mut best: Option<(f64, usize)> = None;
            for (k, o) in occluders.iter().enumerate() {
                if k != j && o.u > cur.u {
                    consider(&cur, o, k, upper, &mut best);
                }
            }
            match advance(&mut entries, cur, best, &mut upper) {
                Some(k) => j = k,
                None => break,
            }
        }
        ActiveTable { entries }
    }

    /// The same table as [`ActiveTable::scan`], bit for bit, for a profile whose occluders
    /// `source` yields in order of non-decreasing `u`, reading it only as far as needed: cost
    /// that grows with the table and the width of the neighbourhood that decides it, not with
    /// the period. `shapes` lists every (rho, z) an occluder of the source can have and `u_max`
    /// bounds every `u` from above; they bound what the occluders not yet read can do.
    ///
    /// Why it may stop reading: a common tangent of elevation psi in (0, pi/2) between the
    /// current occluder c and a farther one o solves du sin psi = d_rho + dz cos psi (eq. 3.7's
    /// form), so sin psi <= max(rho_o - rho_c, top_o - top_c) / du; an occluder of c's own shape
    /// gives exactly psi = 0. Once no shape can beat the best tangent found (or 0) by a margin of
    /// 1e-9 in sin psi, far beyond rounding, the rest cannot change the table. A source that is
    /// not ordered after all is read to its end and scanned whole.
    pub fn scan_ordered(
        source: impl Iterator<Item = Occluder>,
        shapes: &[(f64, f64)],
        u_max: f64,
    ) -> ActiveTable {
        let mut lazy = Lazy {
            source,
            shapes,
            buf: Vec::with_capacity(16),
            ordered: true,
        };
        let r_max = shapes.iter().map(|s| s.0).fold(0.0, f64::max);
        // First occluder met by the vertical scan line: the first smallest near edge. For k
        // onward, u_k - rho_k >= u_k - r_max.
        let mut first: Option<(f64, usize)> = None;
        let mut k = 0;
        while let Some(o) = lazy.get(k) {
            if first.is_some_and(|(m, _)| o.u - r_max >= m) {
                break;
            }
            if first.is_none_or(|(m, _)| o.near_edge() < m) {
                first = Some((o.near_edge(), k));
            }
            k += 1;
        }
        let Some((_, mut j)) = first else {
            return ActiveTable::scan(&lazy.rest());
        };
        let mut entries = Vec::with_capacity(4);
        let mut upper = FRAC_PI_2;
        loop {
            if !lazy.ordered {
                return ActiveTable::scan(&lazy.rest());
            }
            let cur = lazy.buf[j];
            let mut best: Option<(f64, usize)> = None;
            // sin of the best elevation so far (0 while there is none), less a margin.
            let mut threshold = -BEAT_MARGIN;
            // Occluders before j lie no farther out than cur (order): never candidates.
            let mut k = j + 1;
            while let Some(o) = lazy.get(k) {
                let du = o.u - cur.u;
                if du > 0.0 && !beatable(&cur, du, u_max, shapes, threshold) {
                    break;
                }
                if o.u > cur.u {
                    let before = best;
                    consider(&cur, &o, k, upper, &mut best);
                    if best != before {
                        threshold = best.map_or(0.0, |b| b.0.sin()) - BEAT_MARGIN;
                    }
                }
                k += 1;
            }
            if !lazy.ordered {
                return ActiveTable::scan(&lazy.rest());
            }
            match advance(&mut entries, cur, best, &mut upper) {
                Some(k) => j = k,
                None => break,
            }
        }
        ActiveTable { entries }
    }

    /// The active occluder for elevation `psi` in (0, pi/2].
    pub fn active(&self, psi: f64) -> Option<&Occluder> {
        // The first entry with psi >= its bound: the bounds decrease, so that is the number of
        // bounds above psi (counted without branches: random directions mispredict a search).
        let above: usize = self
            .entries
            .iter()
            .map(|(lo, _)| usize::from(*lo > psi))
            .sum();
        let last = self.entries.len().checked_sub(1)?;
        Some(&self.entries[above.min(last)].1)
    }
}

/// Occluders read on demand from an iterator, checking that `u` never decreases and that
/// each has one of the shapes given.
struct Lazy<'a, I> {
    source: I,
    shapes: &'a [(f64, f64)],
    buf: Vec<Occluder>,
    /// False once an occluder read breaks the order or has a shape not listed.
    ordered: bool,
}

impl<I: Iterator<Item = Occluder>> Lazy<'_, I> {
    /// Occluder `k`, reading the source up to it.
    fn get(&mut self, k: usize) -> Option<Occluder> {
        while self.buf.len() <= k {
            let o = self.source.next()?;
            if self.buf.last().is_some_and(|p| o.u < p.u)
                || !self.shapes.iter().any(|&(rho, z)| rho == o.rho && z == o.z)
            {
                self.ordered = false;
            }
            self.buf.push(o);
        }
        Some(self.buf[k])
    }

    /// Every occluder of the source.
    fn rest(mut self) -> Vec<Occluder> {
        self.buf.extend(self.source);
        self.buf
    }
}

/// Slack in sin psi below which [`beatable`] rules a farther occluder out.
const BEAT_MARGIN: f64 = 1e-9;

/// Whether an occluder at least `du` (> 0) beyond `cur`, of one of `shapes`, at `u` at most
/// `u_max`, may have a common tangent with `cur` whose sine exceeds `threshold` (the best
/// elevation's sine, or 0, less [`BEAT_MARGIN`]): see [`ActiveTable::scan_ordered`].
fn beatable(cur: &Occluder, du: f64, u_max: f64, shapes: &[(f64, f64)], threshold: f64) -> bool {
    shapes.iter().any(|&(rho, z)| {
        if rho == cur.rho && z == cur.z {
            // Same shape: dz = d_rho = 0 give exactly psi = 0 (atan2(0, du) + asin(0)).
            return false;
        }
        let numer = (rho - cur.rho).max(rho + z - (cur.rho + cur.z));
        // sin psi <= numer / du' for every du' in [du, u_max - cur.u].
        let sup = if numer >= 0.0 {
            numer / du
        } else {
            numer / (u_max - cur.u).max(du)
        };
        sup >= threshold || sup.is_nan()
    })
}

/// What a neighbour hides of a circle's arc on the side it stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ArcOcclusion {
    /// Nothing of the circle is hidden.
    None,
    /// The arc from the floor on that side up to this angle (measured from the outward
    /// horizontal toward +z, the thesis's theta of eqs 3.4-3.5) is hidden; with the angle's
    /// (sine, cosine).
    UpTo(f64, (f64, f64)),
    /// The whole circle lies below the support line.
    All,
}

/// Arc of a circle (radius `r1`, axis height `h1`, centred at u = 0) hidden from direction of
/// elevation `psi` by occluder `o` (eqs 3.2-3.5): theta = psi + asin(s / r1) where `s` is the
/// support line's offset from the circle's centre.
pub fn occluded_arc(r1: f64, h1: f64, o: &Occluder, psi: f64) -> ArcOcclusion {
    occluded_arc_at(r1, h1, o, &Elevation::new(psi))
}

/// [`occluded_arc`] with the elevation's sine and cosine given.
#[inline]
pub fn occluded_arc_at(r1: f64, h1: f64, o: &Occluder, psi: &Elevation) -> ArcOcclusion {
    let s = o.support(psi.sin, psi.cos) - h1 * psi.cos;
    if s <= -r1 {
        ArcOcclusion::None
    } else if s >= r1 {
        ArcOcclusion::All
    } else {
        // theta = psi + alpha, sin(alpha) = s / r1, cos(alpha) >= 0.
        let sa = s / r1;
        let ca = ((1.0 - sa) * (1.0 + sa)).sqrt();
        ArcOcclusion::UpTo(
            psi.psi + atan2(sa, ca),
            (psi.sin * ca + psi.cos * sa, psi.cos * ca - psi.sin * sa),
        )
    }
}

/// Length of the flat top (height `top`, starting at u = 0 and running toward -u) of an
/// equal-area rectangle hidden by occluder `o` from direction of elevation `psi` (eq. 3.6):
/// l = (s - top cos psi) / sin psi, at least 0 (infinite at grazing elevation when hidden).
pub fn occluded_length(top: f64, o: &Occluder, psi: &Elevation) -> f64 {
    let num = o.support(psi.sin, psi.cos) - top * psi.cos;
    if num <= 0.0 {
        0.0
    } else if psi.sin <= 0.0 {
        f64::INFINITY
    } else {
        num / psi.sin
    }
}

/// Eq. 3.6 at the true height z = h + r sin(theta) of each point of `arc` on a cylinder of
/// radius `r` and axis height `h`, clamped to [0, `max_len`] point by point and averaged with the
/// projected-width weight N.E = e.c cos(theta) + e.z sin(theta) (closed form, split where the
/// clamps switch). Falls back to the hidden length at the arc's mean height for an empty arc.
pub fn mean_occluded_length(
    r: f64,
    h: f64,
    o: &Occluder,
    psi: &Elevation,
    arc: &ArcTrig,
    e: Projected,
    max_len: f64,
) -> f64 {
    let (sp, cp) = (psi.sin, psi.cos);
    // The arc faces E: at most pi long.
    if arc.arc.is_empty() || sp <= 0.0 {
        return occluded_length(crate::geometry::equal_area_height(r, h), o, psi).min(max_len);
    }
    // l(theta) = a - b sin(theta); the divisions independent of one another (their latency
    // dominated this function).
    let num0 = o.support(sp, cp) - h * cp;
    let rc = r * cp;
    let inv_sp = 1.0 / sp;
    let inv_rc = 1.0 / rc;
    let (a, b) = (num0 * inv_sp, rc * inv_sp);
    // Points of the arc as (key, sin, cos, theta): the arc is at most pi long (it faces E), so
    // a point's angle phi from arc.lo is in [0, pi], ordered by key = -cos(phi); theta is
    // computed only where needed (NaN until then).
    let (s0, c0) = arc.lo;
    let from_lo = |(s, c): (f64, f64)| (s * c0 - c * s0, c * c0 + s * s0);
    let cos_len = from_lo(arc.hi).1;
    let mut cuts = [(0.0f64, 0.0f64, 0.0f64, f64::NAN); 6];
    cuts[0] = (-1.0, s0, c0, arc.arc.lo);
    let mut n = 1;
    if b > 0.0 {
        // Break points: sin(theta) = a / b (l = 0) and (a - max_len) / b (l = max_len), the
        // two points of the circle with that sine, where they lie inside the arc.
        for x in [num0 * inv_rc, (num0 - max_len * sp) * inv_rc] {
            if x.abs() < 1.0 {
                let c = ((1.0 - x) * (1.0 + x)).sqrt();
                for point in [(x, c), (x, -c)] {
                    let (sf, cf) = from_lo(point);
                    if sf > 0.0 && cf > cos_len {
                        cuts[n] = (-cf, point.0, point.1, f64::NAN);
                        n += 1;
                    }
                }
            }
        }
    }
    cuts[n] = (-cos_len, arc.hi.0, arc.hi.1, arc.arc.hi);
    let cuts = &mut cuts[..=n];
    // Insertion sort by key (at most 6 entries, most often 2).
    for i in 1..cuts.len() {
        let mut j = i;
        while j > 0 && cuts[j - 1].0 > cuts[j].0 {
            cuts.swap(j - 1, j);
            j -= 1;
        }
    }
    let theta = |cuts: &mut [(f64, f64, f64, f64)], k: usize| {
        if cuts[k].3.is_nan() {
            let (sf, cf) = from_lo((cuts[k].1, cuts[k].2));
            cuts[k].3 = arc.arc.lo + atan2(sf, cf);
        }
        cuts[k]
    };
    // Primitives of w = e.c cos + e.z sin and of sin * w (sin 2t / 4 = sin t cos t / 2).
    let pw = |(_, s, c, _): (f64, f64, f64, f64)| e.c * s - e.z * c;
    let psw = |(_, s, c, t): (f64, f64, f64, f64)| e.c * 0.5 * s * s + e.z * 0.5 * (t - s * c);
    // Which clamp holds on a window: l at an end of the arc, where l is known from the end's
    // sine, if it is clearly off both switch values there (no switch lies inside a window),
    // else at the window's middle.
    let tol = 1e-9 * (a.abs() + b.abs() + max_len);
    let clear = |l: f64| (l.abs() > tol && (l - max_len).abs() > tol).then_some(l);
    let last = n - 1;
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..n {
        let (q0, q1) = (cuts[k], cuts[k + 1]);
        let l_end = (k == 0)
            .then(|| clear(a - b * q0.1))
            .flatten()
            .or_else(|| (k == last).then(|| clear(a - b * q1.1)).flatten());
        let l_mid = l_end.unwrap_or_else(|| {
            let (p0, p1) = (theta(cuts, k), theta(cuts, k + 1));
            a - b * sin_cos(0.5 * (p0.3 + p1.3)).0
        });
        let wsum = pw(q1) - pw(q0);
        den += wsum;
        num += if l_mid <= 0.0 {
            0.0
        } else if l_mid >= max_len {
            max_len * wsum
        } else {
            let (p0, p1) = (theta(cuts, k), theta(cuts, k + 1));
            a * wsum - b * (psw(p1) - psw(p0))
        };
    }
    if den <= 0.0 {
        0.0
    } else {
        (num / den).clamp(0.0, max_len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Eq. 3.4 as printed: segment 1 (radius r1) hidden by the rectangle of height h at gap d.
    fn eq_3_4(r1: f64, d: f64, h: f64, psi: f64) -> f64 {
        psi + (psi.sin() / r1 * (h / psi.tan() - r1 - d)).asin()
    }
    /// Eq. 3.5 as printed: segment 1 hidden by a parallel cylinder of radius r2 at gap d.
    fn eq_3_5(r1: f64, r2: f64, d: f64, psi: f64) -> f64 {
        psi + (psi.sin() / r1 * (r2 / psi.sin() - r1 - d - r2)).asin()
    }
    /// Eq. 3.6 as printed: shadow of a cylinder (r2, gap d) on a rectangle of height h = pi r1 / 4.
    fn eq_3_6(r2: f64, d: f64, h: f64, psi: f64) -> f64 {
        (r2 - h / psi.cos()) / psi.sin() - (d + r2) + h * psi.tan()
    }

    #[test]
    fn printed_cases_1_to_3() {
        let (r1, r2, d) = (1.5, 1.2, 0.3);
        for deg in [10.0, 25.0, 40.0, 60.0, 80.0] {
            let psi = f64::to_radians(deg);
            let h = PI * r2 / 4.0;
            let corner = Occluder {
                u: r1 + d,
                z: h,
                rho: 0.0,
            };
            if let ArcOcclusion::UpTo(t, (s, c)) = occluded_arc(r1, 0.0, &corner, psi) {
                assert!((t - eq_3_4(r1, d, h, psi)).abs() < 1e-12, "{deg}");
                assert!((s - t.sin()).abs() < 1e-15 && (c - t.cos()).abs() < 1e-15);
            }
            let disc = Occluder {
                u: r1 + d + r2,
                z: 0.0,
                rho: r2,
            };
            if let ArcOcclusion::UpTo(t, _) = occluded_arc(r1, 0.0, &disc, psi) {
                assert!((t - eq_3_5(r1, r2, d, psi)).abs() < 1e-12, "{deg}");
            }
            let top = PI * r1 / 4.0;
            let disc = Occluder {
                u: d + r2,
                z: 0.0,
                rho: r2,
            };
            let want = eq_3_6(r2, d, top, psi).max(0.0);
            assert!(
                (occluded_length(top, &disc, &Elevation::new(psi)) - want).abs() < 1e-12,
                "{deg}"
            );
        }
    }

    #[test]
    fn printed_common_tangents() {
        let (r1, r2, d) = (1.0, 1.6, 0.4);
        // Eq. 3.7: two cylinders on the floor.
        let a = Occluder {
            u: 0.0,
            z: 0.0,
            rho: r1,
        };
        let b = Occluder {
            u: r1 + d + r2,
            z: 0.0,
            rho: r2,
        };
        let want = ((r2 - r1) / (r2 + r1 + d)).asin();
        assert!((common_tangent(&a, &b).unwrap() - want).abs() < 1e-12);
        // Eq. 3.8: from a cylinder to the corner of the rectangle standing for segment 2.
        let h = PI * r2 / 4.0;
        let corner = Occluder {
            u: r1 + d,
            z: h,
            rho: 0.0,
        };
        let psi = common_tangent(&a, &corner).unwrap();
        let qa = r1 * r1 + d * d + 2.0 * r1 * d + h * h;
        let qb = 2.0 * r1 * (r1 + d);
        let qc = r1 * r1 - h * h;
        let s38 = ((qb * qb - 4.0 * qa * qc).sqrt() - qb) / (2.0 * qa);
        assert!((psi.sin() - s38).abs() < 1e-12, "{} {}", psi.sin(), s38);
        // Eq. 3.9: from the rectangle corner of segment 1 (length l1) to a cylinder beyond it.
        let l1 = 3.2;
        let h1 = PI * r1 / 4.0;
        let c1 = Occluder {
            u: 0.0,
            z: h1,
            rho: 0.0,
        };
        let c2 = Occluder {
            u: l1 + d + r2,
            z: 0.0,
            rho: r2,
        };
        let psi = common_tangent(&c1, &c2).unwrap();
        let qa = (l1 + d + r2).powi(2) + h1 * h1;
        let qb = 2.0 * r2 * (l1 + d + r2);
        let qc = r2 * r2 - h1 * h1;
        let s39 = (qb - (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
        assert!((psi.sin() - s39).abs() < 1e-12, "{} {}", psi.sin(), s39);
    }

    #[test]
    fn mean_length_matches_pointwise_quadrature() {
        let o = Occluder {
            u: 1.5,
            z: 0.0,
            rho: 1.5,
        };
        let e = Projected { c: 0.4, z: 0.8 };
        let arc = crate::arc::Arc { lo: 0.1, hi: 2.9 };
        for deg in [15.0, 30.0, 50.0, 75.0] {
            let psi = f64::to_radians(deg);
            let (r, h, max_len) = (1.5, 0.2, 2.0);
            let pointwise = |t: f64| {
                let z = h + r * t.sin();
                let (sp, cp) = psi.sin_cos();
                ((o.support(sp, cp) - z * cp) / sp).clamp(0.0, max_len)
            };
            let w = |t: f64| e.c * t.cos() + e.z * t.sin();
            let num = crate::quad::integrate(&mut |t| pointwise(t) * w(t), arc.lo, arc.hi, 1e-12);
            let den = crate::quad::integrate(&mut |t| w(t), arc.lo, arc.hi, 1e-12);
            let got = mean_occluded_length(
                r,
                h,
                &o,
                &Elevation::new(psi),
                &ArcTrig::new(arc),
                e,
                max_len,
            );
            assert!(
                (got - num / den).abs() < 1e-6,
                "{deg}: {got} vs {}",
                num / den
            );
        }
    }

    #[test]
    fn scan_agrees_with_brute_force_maximum() {
        // A ragged profile: low corners, tall and short discs, one period plus repetition.
        let occ = vec![
            Occluder {
                u: 1.6,
                z: 0.9,
                rho: 0.0,
            },
            Occluder {
                u: 4.0,
                z: 0.0,
                rho: 2.2,
            },
            Occluder {
                u: 6.5,
                z: 0.4,
                rho: 0.0,
            },
            Occluder {
                u: 9.0,
                z: 0.0,
                rho: 0.8,
            },
            Occluder {
                u: 12.0,
                z: 0.5,
                rho: 2.5,
            },
            Occluder {
                u: 15.0,
                z: 0.0,
                rho: 1.0,
            },
        ];
        let t = ActiveTable::scan(&occ);
        assert!(t.entries.len() >= 2);
        for i in 1..200 {
            let psi = i as f64 / 200.0 * FRAC_PI_2;
            let (sp, cp) = psi.sin_cos();
            let best = occ
                .iter()
                .map(|o| o.support(sp, cp))
                .fold(f64::MIN, f64::max);
            let got = t.active(psi).unwrap().support(sp, cp);
            assert!((got - best).abs() < 1e-9, "psi {psi}: {got} vs {best}");
        }
    }

    #[test]
    fn ordered_scan_is_the_full_scan() {
        // Profiles of a few shapes (discs of two sizes and heights, corners of two heights) at
        // increasing u, some neighbours touching, long runs of equal shapes as in cloth: the
        // scan that stops reading early gives the full scan's table bit for bit.
        let mut rng = crate::rng::Rng::new(3);
        let shapes = [
            (1.5, 0.0),
            (0.0, 1.178),
            (1.2, 0.3),
            (0.0, 0.5),
            (2.0, -0.5),
        ];
        let mut longest = 0;
        let mut entries = 0;
        let (mut read, mut total) = (0, 0);
        for case in 0..4000 {
            let k = 1 + (case % 5);
            let used = &shapes[..k];
            let n = 1 + (rng.next_u64() % 60) as usize;
            let mut u = 1.0 + rng.next_f64();
            let mut occ = Vec::new();
            for _ in 0..n {
                let (rho, z) = used[(rng.next_u64() % k as u64) as usize];
                occ.push(Occluder { u, z, rho });
                // Mostly whole spacings, sometimes touching, sometimes the same u.
                u += match rng.next_u64() % 8 {
                    0 => 0.0,
                    1 => 3.0,
                    _ => 3.1 * (1 + rng.next_u64() % 3) as f64,
                };
            }
            let full = ActiveTable::scan(&occ);
            let mut count = 0;
            let source = occ.iter().copied().inspect(|_| count += 1);
            let ordered = ActiveTable::scan_ordered(source, used, u + 10.0);
            if k == 2 {
                // One yarn size: discs and the crossing thread's corners.
                read += count;
                total += occ.len();
            }
            assert_eq!(full, ordered, "case {case}: {occ:?}");
            longest = longest.max(full.entries.len());
            entries += full.entries.len();
        }
        assert!(longest >= 3 && entries > 4000, "{longest} {entries}");
        // ... while reading a fraction of the profiles of cloth-like shapes.
        assert!(read * 3 < total, "read {read} of {total}");
    }

    #[test]
    fn ordered_scan_falls_back_on_a_source_out_of_order() {
        let occ = [
            Occluder {
                u: 5.0,
                z: 0.0,
                rho: 1.0,
            },
            Occluder {
                u: 2.0,
                z: 0.0,
                rho: 1.5,
            },
            Occluder {
                u: 9.0,
                z: 1.0,
                rho: 0.0,
            },
        ];
        let shapes = [(1.0, 0.0), (1.5, 0.0), (0.0, 1.0)];
        let full = ActiveTable::scan(&occ);
        assert_eq!(
            ActiveTable::scan_ordered(occ.iter().copied(), &shapes, 20.0),
            full
        );
        // A shape not listed also makes it read everything.
        assert_eq!(
            ActiveTable::scan_ordered(occ.iter().copied(), &shapes[..2], 20.0),
            full
        );
    }
}
