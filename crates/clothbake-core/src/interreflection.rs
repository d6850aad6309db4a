//! Secondary reflection between adjacent parallel cylinders (thesis ch. 5).
//!
//! Geometry of one *pair*, in its own frame: cylinder C1 along +y with its axis at (0, h1),
//! radius r1; its neighbour C2 along +y at (d, h2), radius r2 (d > 0: the neighbour on +x; the
//! one on -x is the same problem mirrored). A point of C1 at angle theta (from +x toward +z) is
//! P_i = (r1 cos theta, 0, h1 + r1 sin theta), of C2 at angle beta and axial offset y is
//! P_j = (d + r2 cos beta, y, h2 + r2 sin beta). Light from L reaches P_j, is reflected to P_i
//! and from there to the eye E: I_2 = I_ss + I_sd + I_ds + I_dd (eqs 5.9-5.15), the first letter
//! naming the reflection at P_j (the first one), the second the reflection at P_i.
//!
//! ## The kernel: thesis or radiometric
//!
//! The thesis's intensity is pi times radiance. Its second-bounce sums (5.9-5.14, 5.28-5.31)
//! weight the product of the two facet intensities by the *projected* solid angle
//! (N_i . P_iP_j) dw of the patch at P_j. The rendering equation with the same facets gives
//! radiance at P_i = integral of f(P_i) L(P_j) (N_i . w) dw with L(P_j) = I(P_j) / pi and
//! I(P_i) = pi f (N_i . w): in intensities, I_2 = integral of I_F(P_i) I_F(P_j) dw / pi. The
//! thesis's kernel is larger by pi (N_i . P_iP_j). Both are kept: [`Kernel::Thesis`] reproduces
//! the thesis's numbers, [`Kernel::Radiometric`] is physically right; each is held against the
//! path tracer with the matching weight.
//!
//! ## Two solutions
//!
//! * [`two_level_sampling`] (sec. 5.2): first level, regular samples on the visible arc of C1
//!   as seen by the viewer (eq. 5.1); second level, patches of angle `d_alpha` and length `d_l`
//!   on the arc of C2 that P_i sees (eqs 5.2-5.8: between the tangent from P_i to C2 and the
//!   tangent plane of C1 at P_i) and that is lit, over |y| <= l0, each patch weighted by its
//!   exact (projected) solid angle as seen from P_i (Siegel & Howell's projection; the planar
//!   quadrilateral through the patch corners) or by eq. 5.16.
//! * [`analytic`] (sec. 5.3): the maximum reflection point and the peak line (eqs 5.17-5.19)
//!   locate the specular peak; the triple integral of eqs 5.28-5.31 is evaluated by Gauss-Legendre
//!   panels split at the peak, over the whole visible and lit arcs (default) or over the thesis's
//!   ranges (C_max = 0.3 around the peak, |y| <= l0 = 1.5).

use crate::arc::Arc;
use crate::fabric::Material;
use crate::facet::{Facet, FacetModel};
use crate::vec3::Vec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// Weight of the second bounce (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kernel {
    /// As printed: facet intensities times the projected solid angle (N_i . w) dw.
    Thesis,
    /// The rendering equation: facet intensities times dw / pi.
    #[default]
    Radiometric,
}

/// The four components of the secondary reflection (thesis intensity units), RGB.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Secondary {
    /// Specular at P_j, then specular at P_i.
    pub ss: [f64; 3],
    /// Specular at P_j, then diffuse at P_i.
    pub sd: [f64; 3],
    /// Diffuse at P_j, then specular at P_i.
    pub ds: [f64; 3],
    /// Diffuse at both.
    pub dd: [f64; 3],
}

impl Secondary {
    /// I_2 = I_ss + I_sd + I_ds + I_dd (eq. 5.15).
    pub fn total(&self) -> [f64; 3] {
        std::array::from_fn(|k| self.ss[k] + self.sd[k] + self.ds[k] + self.dd[k])
    }
    /// `self += w * o`.
    pub fn add_scaled(&mut self, o: &Secondary, w: f64) {
        for k in 0..3 {
            self.ss[k] += w * o.ss[k];
            self.sd[k] += w * o.sd[k];
            self.ds[k] += w * o.ds[k];
            self.dd[k] += w * o.dd[k];
        }
    }
    /// Every component times `w`.
    pub fn scaled(mut self, w: f64) -> Secondary {
        for c in [&mut self.ss, &mut self.sd, &mut self.ds, &mut self.dd] {
            for x in c.iter_mut() {
                *x *= w;
            }
        }
        self
    }
}

/// One pair of adjacent parallel cylinders and everything the integrals need.
#[derive(Clone, Copy, Debug)]
pub struct Pair {
    /// Radius and axis height of C1 (the one seen by the eye).
    pub r1: f64,
    /// Axis height of C1.
    pub h1: f64,
    /// Radius of C2 (the neighbour the light arrives from).
    pub r2: f64,
    /// Axis height of C2.
    pub h2: f64,
    /// Distance between the axes (> r1 + r2 or equal: touching).
    pub d: f64,
    /// Facet material of C1.
    pub m1: Material,
    /// Facet material of C2.
    pub m2: Material,
    /// Facet model of both.
    pub facet: FacetModel,
    /// Second-bounce weight.
    pub kernel: Kernel,
}

/// Directions (unit, pair frame) and the arcs that limit the integration.
#[derive(Clone, Copy, Debug)]
pub struct Setting {
    /// Toward the light.
    pub l: Vec3,
    /// Toward the eye.
    pub e: Vec3,
    /// Arc of C1 visible to the eye (self-blocking, blocking, floor).
    pub vis1: Arc,
    /// Arc of C2 lit by the light (self-shadowing, shadowing, floor).
    pub lit2: Arc,
    /// Extent of C2 along y relative to P_i's cross-section (infinite for endless cylinders).
    pub axial: (f64, f64),
}

/// Normal at angle `t` in the cross-section (no axial component).
fn normal(t: f64) -> Vec3 {
    Vec3::new(t.cos(), 0.0, t.sin())
}

impl Pair {
    fn p1(&self, t: f64) -> Vec3 {
        Vec3::new(self.r1 * t.cos(), 0.0, self.h1 + self.r1 * t.sin())
    }
    fn p2(&self, b: f64, y: f64) -> Vec3 {
        Vec3::new(self.d + self.r2 * b.cos(), y, self.h2 + self.r2 * b.sin())
    }

    /// The arc of C2 (angles beta) that the point of C1 at angle `t` sees (eqs 5.2-5.8):
    /// between the tangents from P_i to C2 (theta_u, eq. 5.4) and the tangent plane of C1 at P_i
    /// (theta_l, eq. 5.7). Angles are returned in (-pi/2, 3pi/2].
    pub fn seen_arc(&self, t: f64) -> Arc {
        let p = self.p1(t);
        let (dx, dz) = (p.x - self.d, p.z - self.h2);
        let dist = dx.hypot(dz);
        if dist <= self.r2 {
            return Arc { lo: 0.0, hi: 0.0 };
        }
        // Facing P_i: |P_i - O_2| cos(beta - gamma) > r2.
        let gamma = wrap(dz.atan2(dx));
        let half = (self.r2 / dist).acos();
        let tangent = Arc {
            lo: gamma - half,
            hi: gamma + half,
        };
        // Above C1's tangent plane at P_i: r2 cos(beta - t) > r1 - d cos t - (h2 - h1) sin t.
        let c = (self.r1 - self.d * t.cos() - (self.h2 - self.h1) * t.sin()) / self.r2;
        if c >= 1.0 {
            return Arc { lo: 0.0, hi: 0.0 };
        }
        let w = c.max(-1.0).acos();
        let plane = shift_near(
            Arc {
                lo: t - w,
                hi: t + w,
            },
            gamma,
        );
        tangent.meet(plane)
    }

    /// Everything reflected toward `e` by the point of C1 at angle `t` via the patch of C2 at
    /// (`b`, `y`), per unit area of C2 (the integrand of eqs 5.28-5.31 without the outer
    /// cos(theta - theta_E) weight). Zero where the two points do not face each other.
    fn kernel_at(&self, s: &Setting, t: f64, b: f64, y: f64) -> Secondary {
        let (pi_, pj) = (self.p1(t), self.p2(b, y));
        self.kernel_points(s, pi_, normal(t), pj, normal(b))
    }

    /// [`Pair::kernel_at`] for given points and normals.
    fn kernel_points(&self, s: &Setting, pi_: Vec3, ni: Vec3, pj: Vec3, nj: Vec3) -> Secondary {
        let v = pj - pi_;
        let r2 = v.dot(v);
        let r = r2.sqrt();
        let w = v * (1.0 / r);
        let (ci, cj) = (ni.dot(w), -nj.dot(w));
        if ci <= 0.0 || cj <= 0.0 {
            return Secondary::default();
        }
        // dw = (N_j . w_ji) dA / R^2 (eq. 5.25) with dA = r2 dbeta dy (r2 folded in by the caller).
        let dw = cj / r2;
        let k = match self.kernel {
            Kernel::Thesis => ci * dw,
            Kernel::Radiometric => dw / PI,
        };
        let fj = self.facet.intensity(&self.m2, nj, s.l, -w);
        let fi = self.facet.intensity(&self.m1, ni, w, s.e);
        let (a1, a2) = (self.m1.albedo, self.m2.albedo);
        Secondary {
            ss: [k * fi.specular * fj.specular; 3],
            sd: std::array::from_fn(|c| k * fi.diffuse * a1[c] * fj.specular),
            ds: std::array::from_fn(|c| k * fi.specular * fj.diffuse * a2[c]),
            dd: std::array::from_fn(|c| k * fi.diffuse * a1[c] * fj.diffuse * a2[c]),
        }
    }
}

fn wrap(a: f64) -> f64 {
    // into (-pi/2, 3pi/2]
    if a <= -FRAC_PI_2 {
        a + 2.0 * PI
    } else {
        a
    }
}

/// The 2-pi shift of `a` whose middle is closest to `near`.
fn shift_near(a: Arc, near: f64) -> Arc {
    let mid = 0.5 * (a.lo + a.hi);
    let k = ((near - mid) / (2.0 * PI)).round() * 2.0 * PI;
    Arc {
        lo: a.lo + k,
        hi: a.hi + k,
    }
}

/// The maximum reflection point theta_1 on C1 and the peak line theta_2 on C2 (eqs 5.17-5.19):
/// the 2-D projected path L -> P2 -> P1 -> E is a mirror reflection at both points. Eq. 5.18
/// gives theta_2 = theta_1 + pi/2 + (theta_L - theta_E)/2, and eq. 5.19 becomes one equation in
/// theta_1 (a quartic in tan(theta_1 / 2)); it is solved by bracketing every sign change on a
/// fine grid of the arc of C1 that faces C2 and bisecting, which finds all real roots without
/// the quartic's ill-conditioning. The physical root is the one whose points face each other,
/// with P1 visible and P2 lit, and whose reflected ray from P1 actually travels toward P2.
pub fn peak(pair: &Pair, s: &Setting) -> Option<(f64, f64)> {
    let te = s.e.z.atan2(s.e.x);
    let tl = s.l.z.atan2(s.l.x);
    let t2 = |t1: f64| t1 + FRAC_PI_2 + 0.5 * (tl - te);
    // Eq. 5.19 (with axis heights): the chord P1P2 has direction 2 theta_1 - theta_E.
    let f = |t1: f64| {
        let b = t2(t1);
        let dz = pair.h2 + pair.r2 * b.sin() - pair.h1 - pair.r1 * t1.sin();
        let dx = pair.d + pair.r2 * b.cos() - pair.r1 * t1.cos();
        let a = 2.0 * t1 - te;
        dz * a.cos() - dx * a.sin()
    };
    let (lo, hi) = (s.vis1.lo, s.vis1.hi.min(PI));
    if lo >= hi {
        return None;
    }
    let n = 96;
    let mut best = None;
    let mut prev = (lo, f(lo));
    for k in 1..=n {
        let x = lo + (hi - lo) * k as f64 / n as f64;
        let fx = f(x);
        if prev.1 == 0.0 || prev.1.signum() != fx.signum() {
            let (mut a, mut b, mut fa) = (prev.0, x, prev.1);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                let fm = f(m);
                if fm.signum() == fa.signum() {
                    a = m;
                    fa = fm;
                } else {
                    b = m;
                }
            }
            let t1 = 0.5 * (a + b);
            let b2 = wrap(t2(t1).rem_euclid(2.0 * PI));
            let p1 = pair.p1(t1);
            let p2 = pair.p2(b2, 0.0);
            let v = p2 - p1;
            let dir = 2.0 * t1 - te;
            let travels = v.x * dir.cos() + v.z * dir.sin() > 0.0;
            let faces = normal(t1).dot(v) > 0.0 && normal(b2).dot(-v) > 0.0;
            let b2l = shift_near(Arc { lo: b2, hi: b2 }, 0.5 * (s.lit2.lo + s.lit2.hi)).lo;
            if travels && faces && b2l >= s.lit2.lo && b2l <= s.lit2.hi {
                best = Some((t1, b2l));
            }
        }
        prev = (x, fx);
    }
    best
}

/// Gauss-Legendre nodes and weights on [-1, 1] (Golub-Welsch by Newton on P_n).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                if n == 1 {
                    p0 = 1.0;
                    p1 = x;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Integration ranges of the analytic solution.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Ranges {
    /// The whole visible arc of C1, the whole seen and lit arc of C2, all y (default).
    #[default]
    Full,
    /// The thesis's pseudocode after eq. 5.31: |alpha|, |beta| <= c_max around the maximum
    /// reflection point and the peak line, on one side of the top of each cylinder, |y| <= l0.
    Thesis {
        /// Half-width of the angular ranges (thesis: 0.3).
        c_max: f64,
        /// Half-length along the axis (thesis: 1.5).
        l0: f64,
    },
}

/// Quadrature orders of the analytic solution (Gauss-Legendre nodes per panel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orders {
    /// Along the arc of C1, when `tol` is 0 (fixed Gauss-Legendre panels).
    pub theta: usize,
    /// Relative tolerance of the adaptive G7/K15 quadrature along the arc of C1 (0: fixed).
    pub tol: f64,
    /// Along the arc of C2.
    pub beta: usize,
    /// Along the axis (after y = D tan u).
    pub axial: usize,
}

impl Default for Orders {
    fn default() -> Self {
        Orders {
            theta: 8,
            tol: 2e-3,
            beta: 5,
            axial: 4,
        }
    }
}

/// Composite Gauss-Legendre over [a, b] split at the `cuts` inside it.
fn panels(a: f64, b: f64, cuts: &[f64], rule: &[(f64, f64)], mut f: impl FnMut(f64, f64)) {
    let mut pts = [0.0f64; 6];
    pts[0] = a;
    let mut n = 1;
    for &c in cuts.iter().take(4) {
        if c > a && c < b {
            pts[n] = c;
            n += 1;
        }
    }
    pts[n] = b;
    let pts = &mut pts[..=n];
    pts.sort_unstable_by(f64::total_cmp);
    for w in pts.windows(2) {
        let (lo, hi) = (w[0], w[1]);
        for &(x, wt) in rule {
            f(lo + (hi - lo) * 0.5 * (x + 1.0), 0.5 * wt * (hi - lo));
        }
    }
}

/// The analytic solution (sec. 5.3): integral over the visible arc of C1 of
/// (N_i . E) times the second-bounce intensity at P_i, i.e. the numerator of eqs 5.28-5.31
/// before division by the projected width L (eq. 5.22) times r1.
pub fn analytic(pair: &Pair, s: &Setting, ranges: Ranges, orders: Orders) -> Secondary {
    let mut out = Secondary::default();
    if s.vis1.is_empty() || s.lit2.is_empty() {
        return out;
    }
    let pk = peak(pair, s);
    // Sharper lobes need more nodes across C2 and along the axis: scale the orders by
    // sqrt(n / 15) beyond n = 15 (the lobe width goes as 1 / sqrt(n)).
    let boost = (pair.m1.exponent.max(pair.m2.exponent) / 15.0)
        .sqrt()
        .max(1.0);
    let scaled = |o: usize| (o as f64 * boost).ceil() as usize;
    let (gt, gb, gu) = (
        gauss_legendre(orders.theta),
        gauss_legendre(scaled(orders.beta)),
        gauss_legendre(scaled(orders.axial)),
    );
    let (theta_range, beta_window, l0) = match ranges {
        Ranges::Full => (s.vis1, None, f64::INFINITY),
        Ranges::Thesis { c_max, l0 } => {
            let Some((t1, b2)) = pk else { return out };
            // Stay on one side of the top of each cylinder (fig. 5.7).
            let side = |a: f64| {
                if a <= FRAC_PI_2 {
                    Arc {
                        lo: -PI,
                        hi: FRAC_PI_2,
                    }
                } else {
                    Arc {
                        lo: FRAC_PI_2,
                        hi: 2.0 * PI,
                    }
                }
            };
            let (side1, side2) = (side(t1), side(b2));
            let ta = Arc {
                lo: t1 - c_max,
                hi: t1 + c_max,
            }
            .meet(s.vis1)
            .meet(side1);
            let bw = Arc {
                lo: b2 - c_max,
                hi: b2 + c_max,
            }
            .meet(side2);
            (ta, Some(bw), l0)
        }
    };
    if theta_range.is_empty() {
        return out;
    }
    let tcuts: Vec<f64> = pk.map(|p| vec![p.0]).unwrap_or_default();
    let e = s.e;
    // J(theta) times (N_i . E) r1: the inner double integral over C2 for one point of C1.
    let inner = |t: f64| -> Secondary {
        let mut acc = Secondary::default();
        let ne = normal(t).dot(e);
        if ne <= 0.0 {
            return acc;
        }
        let mut barc = pair.seen_arc(t);
        barc = barc.meet(shift_near(s.lit2, 0.5 * (barc.lo + barc.hi)));
        if let Some(bw) = beta_window {
            barc = barc.meet(shift_near(bw, 0.5 * (barc.lo + barc.hi)));
        }
        if barc.is_empty() {
            return acc;
        }
        // Peak line for this P_i: mirror direction of E at P_i, and of L at P_j.
        let (pi_, ni) = (pair.p1(t), normal(t));
        // Cuts: the peak line, and the point of C2 nearest P_i (where the kernel peaks when
        // P_i is close to C2).
        let nearest = shift_near(
            Arc {
                lo: (pi_.z - pair.h2).atan2(pi_.x - pair.d),
                hi: 0.0,
            },
            0.5 * (barc.lo + barc.hi),
        )
        .lo;
        let nearest = wrap(nearest);
        let mut bcuts: Vec<f64> = pk.map(|p| vec![p.1]).unwrap_or_default();
        bcuts.push(
            shift_near(
                Arc {
                    lo: nearest,
                    hi: nearest,
                },
                0.5 * (barc.lo + barc.hi),
            )
            .lo,
        );
        panels(barc.lo, barc.hi, &bcuts, &gb, |b, wb| {
            let pj0 = pair.p2(b, 0.0);
            let nj = normal(b);
            let dd = (pj0.x - pi_.x).hypot(pj0.z - pi_.z);
            // Axial peaks of the two specular lobes (y-components are kept by reflection
            // on a cylinder): y_E = -D E_y / |E_p|, y_L = D L_y / |L_p|.
            let ye = -dd * e.y / e.x.hypot(e.z);
            let yl = dd * s.l.y / s.l.x.hypot(s.l.z);
            let (ylo, yhi) = (s.axial.0.max(-l0), s.axial.1.min(l0));
            if ylo >= yhi {
                return;
            }
            // y = D tau / sqrt(1 - tau^2) maps tau in (-1, 1) onto the whole axis (the tan
            // substitution without trigonometry); dy = D (1 - tau^2)^(-3/2) dtau.
            let tau = |y: f64| {
                if y.is_finite() {
                    y / dd.hypot(y)
                } else {
                    y.signum()
                }
            };
            let tcut = [tau(ye), tau(yl)];
            panels(tau(ylo), tau(yhi), &tcut, &gu, |x: f64, wx: f64| {
                let q = 1.0 - x * x;
                if q <= 0.0 {
                    return;
                }
                let sq = q.sqrt();
                let y = dd * x / sq;
                let jac = dd / (q * sq);
                let k = pair.kernel_points(s, pi_, ni, Vec3::new(pj0.x, y, pj0.z), nj);
                acc.add_scaled(&k, wb * wx * jac * ne * pair.r1 * pair.r2);
            });
        });
        acc
    };
    if orders.tol > 0.0 {
        // Adaptive G7/K15 along C1, split at the maximum reflection point. Where the arc starts
        // near the point of C1 closest to C2 and the cylinders (nearly) touch, a point there sees
        // C2 under almost a hemisphere and the integrand grows like a logarithm: the first panel
        // is integrated in s with theta = lo + (hi - lo) s^2, which removes that.
        let closest = (pair.h2 - pair.h1).atan2(pair.d);
        let near_contact = theta_range.lo < closest + 0.5
            && pair.d - pair.r1 - pair.r2 < 0.5 * pair.r1.min(pair.r2);
        let mut pts = vec![theta_range.lo];
        pts.extend(
            tcuts
                .iter()
                .copied()
                .filter(|&c| c > theta_range.lo && c < theta_range.hi),
        );
        pts.push(theta_range.hi);
        let (lo0, hi0) = (pts[0], pts[1]);
        let graded = |x: f64| inner(lo0 + (hi0 - lo0) * x * x).scaled(2.0 * (hi0 - lo0) * x);
        let first: Vec<(Secondary, f64, f64, f64)> = pts
            .windows(2)
            .enumerate()
            .map(|(i, w)| {
                if i == 0 && near_contact {
                    let (v, e) = gk15_secondary(&graded, 0.0, 1.0);
                    (v, e, 0.0, 1.0)
                } else {
                    let (v, e) = gk15_secondary(&inner, w[0], w[1]);
                    (v, e, w[0], w[1])
                }
            })
            .collect();
        let scale: f64 = first
            .iter()
            .map(|(v, ..)| v.total().iter().sum::<f64>())
            .sum::<f64>()
            .abs();
        let tol = orders.tol * scale.max(1e-12);
        for (i, (v, err, a, b)) in first.into_iter().enumerate() {
            let part = if i == 0 && near_contact {
                adapt(&graded, a, b, v, err, tol, 6)
            } else {
                adapt(&inner, a, b, v, err, tol, 6)
            };
            out.add_scaled(&part, 1.0);
        }
    } else {
        panels(theta_range.lo, theta_range.hi, &tcuts, &gt, |t, wt| {
            out.add_scaled(&inner(t), wt)
        });
    }
    out
}

/// One G7/K15 panel of a vector-valued integrand: (Kronrod estimate, error estimate on the sum
/// of the total's channels).
fn gk15_secondary(f: &impl Fn(f64) -> Secondary, a: f64, b: f64) -> (Secondary, f64) {
    let mut k = Secondary::default();
    let mut g = Secondary::default();
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let fc = f(c);
    k.add_scaled(&fc, crate::quad::WK[7] * h);
    g.add_scaled(&fc, crate::quad::WG[3] * h);
    for i in 0..7 {
        let x = h * crate::quad::XK[i];
        let (f1, f2) = (f(c - x), f(c + x));
        k.add_scaled(&f1, crate::quad::WK[i] * h);
        k.add_scaled(&f2, crate::quad::WK[i] * h);
        if i % 2 == 1 {
            g.add_scaled(&f1, crate::quad::WG[i / 2] * h);
            g.add_scaled(&f2, crate::quad::WG[i / 2] * h);
        }
    }
    let sum = |v: &Secondary| v.total().iter().sum::<f64>();
    let err = (sum(&k) - sum(&g)).abs();
    (k, err)
}

/// Bisects [a, b] until the G7/K15 error estimate is below `tol` (absolute, shared by halves).
fn adapt(
    f: &impl Fn(f64) -> Secondary,
    a: f64,
    b: f64,
    v: Secondary,
    err: f64,
    tol: f64,
    depth: u32,
) -> Secondary {
    if err <= tol || depth == 0 {
        return v;
    }
    let m = 0.5 * (a + b);
    let (l, el) = gk15_secondary(f, a, m);
    let (r, er) = gk15_secondary(f, m, b);
    let mut out = adapt(f, a, m, l, el, 0.5 * tol, depth - 1);
    out.add_scaled(&adapt(f, m, b, r, er, 0.5 * tol, depth - 1), 1.0);
    out
}

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

/// The two-level ray-traced sampling solution (sec. 5.2), same normalisation as [`analytic`].
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
        let mut barc = pair.seen_arc(t);
        barc = barc.meet(shift_near(s.lit2, 0.5 * (barc.lo + barc.hi)));
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
    use crate::vec3::UnitVec3;

    fn pf_pair(kernel: Kernel, n: f64) -> Pair {
        let m = Material {
            albedo: [0.4; 3],
            specular: 0.7,
            exponent: n,
        };
        Pair {
            r1: 1.0,
            h1: 0.0,
            r2: 1.0,
            h2: 0.0,
            d: 2.0,
            m1: m,
            m2: m,
            facet: FacetModel::Huo,
            kernel,
        }
    }

    /// Arcs of the parallel-cylinder surface (d = 2, r = 1, h = 0), with the neighbours'
    /// shadowing and blocking (eq. 3.5) as the direct model computes them.
    fn setting(l: UnitVec3, e: UnitVec3) -> Setting {
        use crate::shadowing::{occluded_arc, ArcOcclusion, Occluder};
        let nb = Occluder {
            u: 2.0,
            z: 0.0,
            rho: 1.0,
        };
        let arc = |v: UnitVec3| {
            let mut a =
                Arc::facing(crate::arc::Projected { c: v.x, z: v.z }).meet(Arc { lo: 0.0, hi: PI });
            let th = v.z.atan2(v.x);
            if v.x > 0.0 {
                if let ArcOcclusion::UpTo(t) = occluded_arc(1.0, 0.0, &nb, th) {
                    a.lo = a.lo.max(t);
                }
            } else if let ArcOcclusion::UpTo(t) = occluded_arc(1.0, 0.0, &nb, PI - th) {
                a.hi = a.hi.min(PI - t);
            }
            a
        };
        Setting {
            l: l.get(),
            e: e.get(),
            vis1: arc(e),
            lit2: arc(l),
            axial: (f64::NEG_INFINITY, f64::INFINITY),
        }
    }

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        for n in [1, 3, 8, 16] {
            let r = gauss_legendre(n);
            let s: f64 = r.iter().map(|(x, w)| w * x.powi(2 * n as i32 - 2)).sum();
            assert!((s - 2.0 / (2 * n - 1) as f64).abs() < 1e-13, "{n}: {s}");
        }
    }

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

    #[test]
    fn peak_satisfies_mirror_conditions() {
        let pair = pf_pair(Kernel::Radiometric, 10.0);
        let s = setting(
            UnitVec3::from_degrees(30.0, 180.0),
            UnitVec3::from_degrees(40.0, 0.0),
        );
        let (t1, t2) = peak(&pair, &s).expect("a peak");
        let p1 = pair.p1(t1);
        let p2 = pair.p2(t2, 0.0);
        let w = p2 - p1;
        let w = w * (1.0 / w.length());
        // Mirror at P1: reflect(E) parallel to w (2-D, E has no y component here).
        let n1 = normal(t1);
        let r = n1 * (2.0 * n1.dot(s.e)) - s.e;
        assert!((r.x * w.z - r.z * w.x).abs() < 1e-9 && r.dot(w) > 0.0);
        let n2 = normal(t2);
        let r = n2 * (2.0 * n2.dot(s.l)) - s.l;
        assert!((r.x * w.z - r.z * w.x).abs() < 1e-9 && r.dot(-w) > 0.0);
    }

    #[test]
    fn analytic_converges_to_two_level_sampling() {
        for kernel in [Kernel::Thesis, Kernel::Radiometric] {
            let pair = pf_pair(kernel, 10.0);
            let mut s = setting(
                UnitVec3::from_degrees(40.0, 180.0),
                UnitVec3::from_degrees(35.0, 20.0),
            );
            s.axial = (-10.0, 10.0);
            let fine = Sampling {
                first_level: 100,
                d_alpha: 0.02,
                d_l: 0.05,
                l0: 10.0,
                exact_solid_angle: true,
            };
            let reference = analytic(
                &pair,
                &s,
                Ranges::Full,
                Orders {
                    theta: 24,
                    tol: 0.0,
                    beta: 24,
                    axial: 24,
                },
            )
            .total()[0];
            let a = analytic(&pair, &s, Ranges::Full, Orders::default()).total()[0];
            let b = two_level_sampling(&pair, &s, fine).total()[0];
            assert!(a > 0.0);
            assert!(
                (a - reference).abs() < 3e-3 * a,
                "{kernel:?}: default orders {a} vs {reference}"
            );
            assert!(
                (a - b).abs() < 0.005 * a,
                "{kernel:?}: analytic {a} vs sampling {b}"
            );
        }
    }
}
