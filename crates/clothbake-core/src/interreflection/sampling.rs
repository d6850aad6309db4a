//! The two-level ray-traced sampling (sec. 5.2): first-level samples on C1 (eq. 5.1),
//! patches of C2 (eqs 5.2-5.8) weighted by their exact solid angle or eq. 5.16.

use super::{normal, Kernel, Pair, Secondary, Setting};
use crate::vec3::Vec3;

/// Parameters of the two-level ray-traced sampling (sec. 5.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    /// First-level samples on the visible arc of C1 (eq. 5.1's n).
    pub first_level: usize,
    /// Angular step on C2 (thesis: 0.2).
    pub d_alpha: f64,
    /// Axial step (thesis: 0.2).
    pub d_l: f64,
    /// Axial half-length (thesis: 1.5 for unit radius).
    pub l0: f64,
    /// Exact projected solid angles (Siegel & Howell) or eq. 5.16.
    pub exact_solid_angle: bool,
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling {
            first_level: 32,
            d_alpha: 0.2,
            d_l: 0.2,
            l0: 1.5,
            exact_solid_angle: true,
        }
    }
}

/// Solid angle of the planar polygon `v` (vertices relative to the viewpoint) and its
/// projected solid angle onto the plane of normal `n` (Lambert's contour formula).
fn polygon_solid_angles(v: &[Vec3], n: Vec3) -> (f64, f64) {
    let k = v.len();
    // Solid angle: sum of the triangles (Van Oosterom & Strackee) of a fan.
    let mut omega = 0.0;
    for i in 1..k - 1 {
        let (a, b, c) = (v[0], v[i], v[i + 1]);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        omega += 2.0 * num.atan2(den);
    }
    // Projected: (1/2) sum over edges of angle(v_i, v_i+1) * n . unit(v_i x v_i+1).
    let mut proj = 0.0;
    for i in 0..k {
        let (a, b) = (v[i], v[(i + 1) % k]);
        let c = a.cross(b);
        let cl = c.length();
        if cl > 0.0 {
            let ang = cl.atan2(a.dot(b));
            proj += 0.5 * ang * n.dot(c) / cl;
        }
    }
    (omega.abs(), proj.abs())
}

/// The two-level ray-traced sampling solution (sec. 5.2), same normalisation as
/// [`analytic()`](super::analytic()).
pub fn two_level_sampling(pair: &Pair, s: &Setting, p: Sampling) -> Secondary {
    let mut out = Secondary::default();
    if s.vis1.is_empty() || s.lit2.is_empty() {
        return out;
    }
    let e = s.e;
    let ep = (e.x.hypot(e.z), e.z.atan2(e.x));
    // First level: regular intervals of the projected width seen by the viewer (eq. 5.1).
    let width = |t: f64| (t - ep.1).sin();
    let (w0, w1) = (width(s.vis1.lo), width(s.vis1.hi));
    let n = p.first_level.max(1);
    // The outer weight: each sample stands for an equal share of the projected width.
    let share = pair.r1 * ep.0 * (w1 - w0) / n as f64;
    for k in 0..n {
        let w = w0 + (w1 - w0) * (k as f64 + 0.5) / n as f64;
        let t = ep.1 + w.clamp(-1.0, 1.0).asin();
        let pi_ = pair.p1(t);
        let ni = normal(t);
        let barc = pair.lit_seen_arc(t, s.lit2).0;
        if barc.is_empty() {
            continue;
        }
        let na = ((barc.hi - barc.lo) / p.d_alpha).ceil().max(1.0) as usize;
        let da = (barc.hi - barc.lo) / na as f64;
        let (ylo, yhi) = (s.axial.0.max(-p.l0), s.axial.1.min(p.l0));
        if ylo >= yhi {
            continue;
        }
        let nl = ((yhi - ylo) / p.d_l).ceil().max(1.0) as usize;
        let dl = (yhi - ylo) / nl as f64;
        for ia in 0..na {
            let (b0, b1) = (barc.lo + ia as f64 * da, barc.lo + (ia + 1) as f64 * da);
            let bm = 0.5 * (b0 + b1);
            for il in 0..nl {
                let (y0, y1) = (ylo + il as f64 * dl, ylo + (il + 1) as f64 * dl);
                let ym = 0.5 * (y0 + y1);
                // The integrand per unit area at the patch centre, times the patch's weight.
                let unit = pair.kernel_at(s, t, bm, ym);
                let pj = pair.p2(bm, ym);
                let v = pj - pi_;
                let r2 = v.dot(v);
                let cj = -normal(bm).dot(v) / r2.sqrt();
                let area = pair.r2 * da * dl;
                // kernel_at already holds dw per unit area = cj / R^2 (and, for the thesis
                // kernel, N_i . w): replace it by the exact patch solid angle when asked.
                let weight = if p.exact_solid_angle && cj > 0.0 {
                    let corners = [
                        pair.p2(b0, y0) - pi_,
                        pair.p2(b1, y0) - pi_,
                        pair.p2(b1, y1) - pi_,
                        pair.p2(b0, y1) - pi_,
                    ];
                    let (omega, proj) = polygon_solid_angles(&corners, ni);
                    let per_area = cj / r2;
                    let ci = ni.dot(v) / r2.sqrt();
                    match pair.kernel {
                        Kernel::Thesis if ci > 0.0 => proj / (ci * per_area),
                        Kernel::Radiometric => omega / per_area,
                        _ => area,
                    }
                } else {
                    area
                };
                out.add_scaled(&unit, weight * share);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn polygon_solid_angle_of_a_face_of_a_cube() {
        // A face of the unit cube seen from its centre: 4 pi / 6; projected onto the face's
        // normal: pi / ... (by symmetry, the 6 faces' projected solid angles onto one axis sum
        // to 2 pi over the two faces crossing it... check the face itself: Lambert).
        let v = [
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(-1.0, 1.0, 1.0),
        ];
        let (o, p) = polygon_solid_angles(&v, Vec3::new(0.0, 0.0, 1.0));
        assert!((o - 4.0 * PI / 6.0).abs() < 1e-12, "{o}");
        // Projected solid angle of a square of half-size a at distance 1 (form factor * pi):
        // F = (2/pi)(a/sqrt(1+a^2) atan(a/sqrt(1+a^2))) * 2 for a = 1 (parallel square).
        let a: f64 = 1.0;
        let q = a / (1.0 + a * a).sqrt();
        let f = 4.0 / PI * q * q.atan();
        assert!((p - PI * f).abs() < 1e-12, "{p} vs {}", PI * f);
    }
}
