//! Arcs of a cylinder's cross-section (thesis sec. 4.1-4.2): the range a facet normal sweeps,
//! its projected width, and the closed-form arc integrals of the thesis's facet terms.
//!
//! In a segment's cross-section plane, `c` is the horizontal axis across the segment (+X for a
//! warp, +Y for a weft) and the normal at angle `theta` is N = cos(theta) c + sin(theta) z.
//! A direction V projects to V_p = (V.c, V.z) at angle theta_V = atan2(V.z, V.c).
//!
//! The integrals take their arcs as [`ArcTrig`] (the ends' sines and cosines computed once and
//! shared) and their directions as [`Polar`] (angle and length computed once per evaluation):
//! the direct model's cost was mostly these library calls, repeated per unit (issue 22).

use crate::trig::{atan2, sin_cos};
use std::f64::consts::FRAC_PI_2;

/// A direction projected into a cross-section plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projected {
    /// Component along the horizontal axis `c`.
    pub c: f64,
    /// Component along +z.
    pub z: f64,
}

impl Projected {
    /// Angle of the projection from +c toward +z (theta_L, theta_E, theta_H of the thesis).
    pub fn angle(self) -> f64 {
        self.z.atan2(self.c)
    }
    /// Length |V_p|.
    pub fn norm(self) -> f64 {
        self.c.hypot(self.z)
    }
}

/// A projected direction in polar form: V_p with its angle theta_V, its length |V_p| and the
/// angle's cosine and sine (V_p / |V_p|). |V_p| must not be zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polar {
    /// The projection.
    pub p: Projected,
    /// theta_V.
    pub angle: f64,
    /// |V_p|.
    pub norm: f64,
    /// cos(theta_V).
    pub cos: f64,
    /// sin(theta_V).
    pub sin: f64,
}

impl Polar {
    /// The polar form of `p` (inline `atan2`, within 4e-16 of [`Projected::angle`]).
    #[inline]
    pub fn new(p: Projected) -> Polar {
        let norm = (p.c * p.c + p.z * p.z).sqrt();
        let inv = 1.0 / norm;
        Polar {
            p,
            angle: atan2(p.z, p.c),
            norm,
            cos: p.c * inv,
            sin: p.z * inv,
        }
    }
}

/// A projected direction's length |V_p| and its angle's cosine and sine: the polar form
/// without the angle itself (an `atan2` spared where only these are needed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Heading {
    /// |V_p|.
    pub norm: f64,
    /// cos(theta_V).
    pub cos: f64,
    /// sin(theta_V).
    pub sin: f64,
}

impl Heading {
    /// The heading of `p` (not zero).
    #[inline]
    pub fn new(p: Projected) -> Heading {
        let norm = (p.c * p.c + p.z * p.z).sqrt();
        let inv = 1.0 / norm;
        Heading {
            norm,
            cos: p.c * inv,
            sin: p.z * inv,
        }
    }
}

impl From<&Polar> for Heading {
    fn from(p: &Polar) -> Heading {
        Heading {
            norm: p.norm,
            cos: p.cos,
            sin: p.sin,
        }
    }
}

/// An arc with the sine and cosine of each end, `(sin, cos)`, for the closed-form integrals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArcTrig {
    /// The arc.
    pub arc: Arc,
    /// (sin, cos) of `arc.lo`.
    pub lo: (f64, f64),
    /// (sin, cos) of `arc.hi`.
    pub hi: (f64, f64),
}

impl ArcTrig {
    /// The arc with its ends' sines and cosines (inline, within 1e-15).
    #[inline]
    pub fn new(arc: Arc) -> ArcTrig {
        ArcTrig {
            arc,
            lo: sin_cos(arc.lo),
            hi: sin_cos(arc.hi),
        }
    }

    /// The intersection, each end with its sine and cosine.
    #[inline]
    pub fn meet(self, o: &ArcTrig) -> ArcTrig {
        let (lo, slo) = if o.arc.lo > self.arc.lo {
            (o.arc.lo, o.lo)
        } else {
            (self.arc.lo, self.lo)
        };
        let (hi, shi) = if o.arc.hi < self.arc.hi {
            (o.arc.hi, o.hi)
        } else {
            (self.arc.hi, self.hi)
        };
        ArcTrig {
            arc: Arc { lo, hi },
            lo: slo,
            hi: shi,
        }
    }

    /// The normals facing the direction `v` (N.V > 0, [`Arc::facing`]): theta_V -+ pi/2, whose
    /// sines and cosines are -+cos(theta_V) and +-sin(theta_V).
    #[inline]
    pub fn facing(v: &Polar) -> ArcTrig {
        ArcTrig {
            arc: Arc {
                lo: v.angle - FRAC_PI_2,
                hi: v.angle + FRAC_PI_2,
            },
            lo: (-v.cos, v.sin),
            hi: (v.cos, -v.sin),
        }
    }
}

/// A closed arc [lo, hi] of normal angles; empty when lo >= hi.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arc {
    /// Lower angle.
    pub lo: f64,
    /// Upper angle.
    pub hi: f64,
}

impl Arc {
    /// The part of the cylinder above the floor: z = h + r sin(theta) >= 0.
    pub fn above_floor(r: f64, h: f64) -> Arc {
        let t = (h / r).clamp(-1.0, 1.0).asin();
        Arc {
            lo: -t,
            hi: std::f64::consts::PI + t,
        }
    }
    /// Normals facing `v` (N.V > 0): no self-shadowing or self-blocking (Poulin & Fournier).
    pub fn facing(v: Projected) -> Arc {
        let t = v.angle();
        Arc {
            lo: t - FRAC_PI_2,
            hi: t + FRAC_PI_2,
        }
    }
    /// Intersection.
    pub fn meet(self, o: Arc) -> Arc {
        Arc {
            lo: self.lo.max(o.lo),
            hi: self.hi.min(o.hi),
        }
    }
    /// True when the arc has no length.
    pub fn is_empty(self) -> bool {
        self.lo >= self.hi
    }
}

/// Projected width of the arc seen along `e` (eq. 4.2 times |E_p|): the integral of N.E over the
/// arc, r * |E_p| (sin(hi - theta_E) - sin(lo - theta_E)) for radius `r`. Eq. 4.10 is the same
/// integral without r |E_p|: it normalises the cos(theta - theta_E) correction of eqs 4.7 and 4.9.
pub fn projected_width(r: f64, arc: &ArcTrig, e: Projected) -> f64 {
    if arc.arc.is_empty() {
        return 0.0;
    }
    // int (e.c cos + e.z sin) = e.c sin - e.z cos
    let f = |(s, c): (f64, f64)| e.c * s - e.z * c;
    r * (f(arc.hi) - f(arc.lo))
}

/// Diffuse integral with the cos(theta - theta_E) correction (eq. 4.7 times |E_p|), in closed
/// form: the integral of (N.L)(N.E) over the arc.
pub fn diffuse_integral(arc: &ArcTrig, l: Projected, e: Projected) -> f64 {
    if arc.arc.is_empty() {
        return 0.0;
    }
    // cos^2 -> t/2 + sin 2t / 4; sin^2 -> t/2 - sin 2t / 4; sin cos -> sin^2 t / 2, with
    // sin 2t / 4 = sin t cos t / 2.
    let half_t = 0.5 * (arc.arc.hi - arc.arc.lo);
    let sc2 = 0.5 * (arc.hi.0 * arc.hi.1 - arc.lo.0 * arc.lo.1);
    let s2 = 0.5 * (arc.hi.0 * arc.hi.0 - arc.lo.0 * arc.lo.0);
    l.c * e.c * (half_t + sc2) + (l.c * e.z + l.z * e.c) * s2 + l.z * e.z * (half_t - sc2)
}

/// The thesis's specular integral with the correction (eq. 4.9 times |E_p|): the integral of
/// (N.H)^n (N.E) over the arc, where N.H = |H_p| cos(theta - theta_H) with H the full 3-D half
/// vector. Closed form for integer n (reduction formula for the integral of cos^m); `None` for a
/// non-integer or very large exponent (use quadrature). The arc must lie where N.H >= 0.
pub fn huo_specular_integral(arc: &ArcTrig, h: &Heading, e: &Heading, n: f64) -> Option<f64> {
    if n.fract() != 0.0 || !(0.0..=4096.0).contains(&n) {
        return None;
    }
    if arc.arc.is_empty() {
        return Some(0.0);
    }
    let n = n as u32;
    // delta = theta_H - theta_E by the angle-difference formulas.
    let sd = h.sin * e.cos - h.cos * e.sin;
    let cd = h.cos * e.cos + h.sin * e.sin;
    // int cos^n(u) cos(u + delta) du = cos(delta) C_{n+1}(u) + sin(delta) cos^{n+1}(u) / (n + 1),
    // u = t - theta_H, its sine and cosine from the end's and theta_H's.
    let su_cu = |(st, ct): (f64, f64)| [st * h.cos - ct * h.sin, ct * h.cos + st * h.sin];
    let ([s0, c0], [s1, c1]) = (su_cu(arc.lo), su_cu(arc.hi));
    // u itself only for an even power (theta_H's atan2 only then).
    let u = if (n + 1).is_multiple_of(2) {
        let th = atan2(h.sin, h.cos);
        [arc.arc.lo - th, arc.arc.hi - th]
    } else {
        [0.0; 2]
    };
    let ([p0, p1], [q0, q1]) = cos_power_integral(n + 1, [s0, s1], [c0, c1], u);
    let prim = |p: f64, q: f64| cd * p + sd * q / (n as f64 + 1.0);
    let v = prim(p1, q1) - prim(p0, q0);
    Some(h.norm.powi(n as i32) * e.norm * v)
}

/// C_m(u) = integral of cos^m from 0 to u, by C_m = cos^{m-1} sin / m + (m - 1)/m C_{m-2}, and
/// cos^m(u), at two points at once (the ends of an arc: one division per step for both).
fn cos_power_integral(m: u32, su: [f64; 2], cu: [f64; 2], u: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    let even = m.is_multiple_of(2);
    let mut acc = if even { u } else { su };
    let mut k = if even { 2 } else { 3 };
    // cos^{k-1}, advanced by cos^2 per step.
    let c2 = cu.map(|c| c * c);
    let mut cp = if even { cu } else { c2 };
    // cos^m: cos^0 or cos^1 when no step is taken, else cos^{m-1} cos at the last step.
    let mut power = if even { [1.0; 2] } else { cu };
    while k <= m {
        let inv = 1.0 / k as f64;
        let w = (k as f64 - 1.0) * inv;
        for j in 0..2 {
            acc[j] = cp[j] * su[j] * inv + w * acc[j];
            power[j] = cp[j] * cu[j];
            cp[j] *= c2[j];
        }
        k += 2;
    }
    (acc, power)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quad::integrate;

    fn p(t: f64, s: f64) -> Projected {
        Projected {
            c: s * t.cos(),
            z: s * t.sin(),
        }
    }

    #[test]
    fn closed_forms_match_quadrature() {
        let l = p(0.9, 0.8);
        let e = p(1.9, 0.95);
        let arc = Arc { lo: 0.5, hi: 2.2 };
        let n_dot = |t: f64, v: Projected| v.c * t.cos() + v.z * t.sin();
        let at = ArcTrig::new(arc);
        let q = integrate(&mut |t| n_dot(t, e), arc.lo, arc.hi, 1e-13);
        assert!((projected_width(1.0, &at, e) - q).abs() < 1e-12);
        let q = integrate(&mut |t| n_dot(t, l) * n_dot(t, e), arc.lo, arc.hi, 1e-13);
        assert!((diffuse_integral(&at, l, e) - q).abs() < 1e-12);
        let h = p(1.4, 0.9);
        for n in [0.0, 1.0, 2.0, 7.0, 10.0, 55.0] {
            let q = integrate(
                &mut |t| n_dot(t, h).max(0.0).powf(n) * n_dot(t, e),
                arc.lo,
                arc.hi,
                1e-14,
            );
            let c = huo_specular_integral(&at, &Heading::new(h), &Heading::new(e), n).unwrap();
            assert!(
                (c - q).abs() < 1e-11 * q.abs().max(1.0),
                "n={n}: {c} vs {q}"
            );
        }
        assert!(huo_specular_integral(&at, &Heading::new(h), &Heading::new(e), 2.5).is_none());
        // An arc met with another keeps the sines and cosines of the ends it keeps.
        let m = at.meet(&ArcTrig::new(Arc { lo: 0.7, hi: 3.0 }));
        assert_eq!(m, ArcTrig::new(Arc { lo: 0.7, hi: 2.2 }));
        let f = ArcTrig::facing(&Polar::new(l));
        let g = ArcTrig::new(Arc::facing(l));
        assert!((f.arc.lo - g.arc.lo).abs() < 1e-15 && (f.arc.hi - g.arc.hi).abs() < 1e-15);
        for (x, y) in [(f.lo, g.lo), (f.hi, g.hi)] {
            assert!((x.0 - y.0).abs() < 1e-15 && (x.1 - y.1).abs() < 1e-15);
        }
        let pl = Polar::new(l);
        assert!((pl.angle - 0.9).abs() < 1e-15 && (pl.norm - 0.8).abs() < 1e-15);
        assert!((pl.cos - 0.9f64.cos()).abs() < 1e-15 && (pl.sin - 0.9f64.sin()).abs() < 1e-15);
    }
}
