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

use crate::arc::{Arc, Projected};
use std::f64::consts::FRAC_PI_2;

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
                if k == j || o.u <= cur.u {
                    continue;
                }
                if let Some(psi) = common_tangent(&cur, o) {
                    if psi > 0.0 && psi < upper && best.is_none_or(|(b, _)| psi > b) {
                        best = Some((psi, k));
                    }
                }
            }
            match best {
                Some((psi, k)) => {
                    entries.push((psi, cur));
                    upper = psi;
                    j = k;
                }
                None => {
                    entries.push((0.0, cur));
                    break;
                }
            }
        }
        ActiveTable { entries }
    }

    /// The active occluder for elevation `psi` in (0, pi/2].
    pub fn active(&self, psi: f64) -> Option<&Occluder> {
        self.entries
            .iter()
            .find(|(lo, _)| psi >= *lo)
            .or(self.entries.last())
            .map(|(_, o)| o)
    }
}

/// What a neighbour hides of a circle's arc on the side it stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ArcOcclusion {
    /// Nothing of the circle is hidden.
    None,
    /// The arc from the floor on that side up to this angle (measured from the outward
    /// horizontal toward +z, the thesis's theta of eqs 3.4-3.5) is hidden.
    UpTo(f64),
    /// The whole circle lies below the support line.
    All,
}

/// Arc of a circle (radius `r1`, axis height `h1`, centred at u = 0) hidden from direction of
/// elevation `psi` by occluder `o` (eqs 3.2-3.5): theta = psi + asin(s / r1) where `s` is the
/// support line's offset from the circle's centre.
pub fn occluded_arc(r1: f64, h1: f64, o: &Occluder, psi: f64) -> ArcOcclusion {
    let (sp, cp) = psi.sin_cos();
    let s = o.support(sp, cp) - h1 * cp;
    if s <= -r1 {
        ArcOcclusion::None
    } else if s >= r1 {
        ArcOcclusion::All
    } else {
        ArcOcclusion::UpTo(psi + (s / r1).asin())
    }
}

/// Length of the flat top (height `top`, starting at u = 0 and running toward -u) of an
/// equal-area rectangle hidden by occluder `o` from direction of elevation `psi` (eq. 3.6):
/// l = (s - top cos psi) / sin psi, at least 0 (infinite at grazing elevation when hidden).
pub fn occluded_length(top: f64, o: &Occluder, psi: f64) -> f64 {
    let (sp, cp) = psi.sin_cos();
    let num = o.support(sp, cp) - top * cp;
    if num <= 0.0 {
        0.0
    } else if sp <= 0.0 {
        f64::INFINITY
    } else {
        num / sp
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
    psi: f64,
    arc: Arc,
    e: Projected,
    max_len: f64,
) -> f64 {
    let (sp, cp) = psi.sin_cos();
    if arc.is_empty() || sp <= 0.0 {
        return occluded_length(crate::geometry::equal_area_height(r, h), o, psi).min(max_len);
    }
    // l(theta) = a - b sin(theta)
    let a = (o.support(sp, cp) - h * cp) / sp;
    let b = r * cp / sp;
    // Break points: sin(theta) = a / b (l = 0) and (a - max_len) / b (l = max_len).
    let mut cuts = [0.0f64; 8];
    cuts[0] = arc.lo;
    let mut n = 1;
    if b > 0.0 {
        for x in [a / b, (a - max_len) / b] {
            if x.abs() < 1.0 {
                let t = x.asin();
                for c in [t, std::f64::consts::PI - t, t - 2.0 * std::f64::consts::PI] {
                    if c > arc.lo && c < arc.hi {
                        cuts[n] = c;
                        n += 1;
                    }
                }
            }
        }
    }
    cuts[n] = arc.hi;
    let cuts = &mut cuts[..=n];
    cuts.sort_unstable_by(f64::total_cmp);
    // Primitives of w = e.c cos + e.z sin and of sin * w.
    let pw = |t: f64| e.c * t.sin() - e.z * t.cos();
    let psw = |t: f64| e.c * 0.5 * t.sin().powi(2) + e.z * (0.5 * t - 0.25 * (2.0 * t).sin());
    let (mut num, mut den) = (0.0, 0.0);
    for w in cuts.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        let l_mid = a - b * (0.5 * (t0 + t1)).sin();
        let wsum = pw(t1) - pw(t0);
        den += wsum;
        num += if l_mid <= 0.0 {
            0.0
        } else if l_mid >= max_len {
            max_len * wsum
        } else {
            a * wsum - b * (psw(t1) - psw(t0))
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
            if let ArcOcclusion::UpTo(t) = occluded_arc(r1, 0.0, &corner, psi) {
                assert!((t - eq_3_4(r1, d, h, psi)).abs() < 1e-12, "{deg}");
            }
            let disc = Occluder {
                u: r1 + d + r2,
                z: 0.0,
                rho: r2,
            };
            if let ArcOcclusion::UpTo(t) = occluded_arc(r1, 0.0, &disc, psi) {
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
                (occluded_length(top, &disc, psi) - want).abs() < 1e-12,
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
        let arc = Arc { lo: 0.1, hi: 2.9 };
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
            let got = mean_occluded_length(r, h, &o, psi, arc, e, max_len);
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
}
