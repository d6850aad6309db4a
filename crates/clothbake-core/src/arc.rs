//! Arcs of a cylinder's cross-section (thesis sec. 4.1-4.2): the range a facet normal sweeps,
//! its projected width, and the closed-form arc integrals of the thesis's facet terms.
//!
//! In a segment's cross-section plane, `c` is the horizontal axis across the segment (+X for a
//! warp, +Y for a weft) and the normal at angle `theta` is N = cos(theta) c + sin(theta) z.
//! A direction V projects to V_p = (V.c, V.z) at angle theta_V = atan2(V.z, V.c).

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
pub fn projected_width(r: f64, arc: Arc, e: Projected) -> f64 {
    if arc.is_empty() {
        return 0.0;
    }
    // int (e.c cos + e.z sin) = e.c sin - e.z cos
    let f = |t: f64| e.c * t.sin() - e.z * t.cos();
    r * (f(arc.hi) - f(arc.lo))
}

/// Diffuse integral with the cos(theta - theta_E) correction (eq. 4.7 times |E_p|), in closed
/// form: the integral of (N.L)(N.E) over the arc.
pub fn diffuse_integral(arc: Arc, l: Projected, e: Projected) -> f64 {
    if arc.is_empty() {
        return 0.0;
    }
    // cos^2 -> t/2 + sin 2t / 4; sin^2 -> t/2 - sin 2t / 4; sin cos -> sin^2 t / 2
    let cc = |t: f64| 0.5 * t + 0.25 * (2.0 * t).sin();
    let ss = |t: f64| 0.5 * t - 0.25 * (2.0 * t).sin();
    let sc = |t: f64| 0.5 * t.sin().powi(2);
    let d = |f: &dyn Fn(f64) -> f64| f(arc.hi) - f(arc.lo);
    l.c * e.c * d(&cc) + (l.c * e.z + l.z * e.c) * d(&sc) + l.z * e.z * d(&ss)
}

/// The thesis's specular integral with the correction (eq. 4.9 times |E_p|): the integral of
/// (N.H)^n (N.E) over the arc, where N.H = |H_p| cos(theta - theta_H) with H the full 3-D half
/// vector. Closed form for integer n (reduction formula for the integral of cos^m); `None` for a
/// non-integer or very large exponent (use quadrature). The arc must lie where N.H >= 0.
pub fn huo_specular_integral(arc: Arc, h: Projected, e: Projected, n: f64) -> Option<f64> {
    if n.fract() != 0.0 || !(0.0..=4096.0).contains(&n) {
        return None;
    }
    if arc.is_empty() {
        return Some(0.0);
    }
    let n = n as u32;
    let th = h.angle();
    let delta = th - e.angle();
    let (sd, cd) = delta.sin_cos();
    // int cos^n(u) cos(u + delta) du = cos(delta) C_{n+1}(u) + sin(delta) cos^{n+1}(u) / (n + 1)
    let prim = |u: f64| {
        let (su, cu) = u.sin_cos();
        cd * cos_power_integral(n + 1, su, cu, u) + sd * cu.powi(n as i32 + 1) / (n as f64 + 1.0)
    };
    let v = prim(arc.hi - th) - prim(arc.lo - th);
    Some(h.norm().powi(n as i32) * e.norm() * v)
}

/// C_m(u) = integral of cos^m from 0 to u, by C_m = cos^{m-1} sin / m + (m - 1)/m C_{m-2}.
fn cos_power_integral(m: u32, su: f64, cu: f64, u: f64) -> f64 {
    let even = m.is_multiple_of(2);
    let mut acc = if even { u } else { su };
    let mut k = if even { 2 } else { 3 };
    // cos^{k-1}, advanced by cos^2 per step.
    let mut cp = if even { cu } else { cu * cu };
    let c2 = cu * cu;
    while k <= m {
        acc = cp * su / k as f64 + (k as f64 - 1.0) / k as f64 * acc;
        cp *= c2;
        k += 2;
    }
    acc
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
        let q = integrate(&mut |t| n_dot(t, e), arc.lo, arc.hi, 1e-13);
        assert!((projected_width(1.0, arc, e) - q).abs() < 1e-12);
        let q = integrate(&mut |t| n_dot(t, l) * n_dot(t, e), arc.lo, arc.hi, 1e-13);
        assert!((diffuse_integral(arc, l, e) - q).abs() < 1e-12);
        let h = p(1.4, 0.9);
        for n in [0.0, 1.0, 2.0, 7.0, 10.0, 55.0] {
            let q = integrate(
                &mut |t| n_dot(t, h).max(0.0).powf(n) * n_dot(t, e),
                arc.lo,
                arc.hi,
                1e-14,
            );
            let c = huo_specular_integral(arc, h, e, n).unwrap();
            assert!(
                (c - q).abs() < 1e-11 * q.abs().max(1.0),
                "n={n}: {c} vs {q}"
            );
        }
        assert!(huo_specular_integral(arc, h, e, 2.5).is_none());
    }
}
