//! The analytic solution (sec. 5.3): the triple integral of eqs 5.28-5.31 over C1's visible
//! arc, C2's seen and lit arc and the axis, by Gauss-Legendre panels split at the kinks and
//! at the maximum reflection point (eqs 5.17-5.19), or adaptively along C1.

use super::axial::{
    axial_capacity, axial_nodes, int_cos2, int_cos3, line_integral, lobe_width, AxialEnd,
    AxialNodes, Line, Lobe, Parts,
};
use super::peak::{peak, peak_in, shift_near};
use super::rules::{cut_points, graded_panels, share, Orders, Ranges};
use super::{normal, Kernel, Pair, Secondary, Setting};
use crate::arc::Arc;
use crate::facet::CosineFacet;
use crate::quad::{adapt, gk15_components, Components};
use crate::vec3::Vec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// Angles of C1 where the arc of C2 that P_i sees and that is lit changes which bound limits it:
/// where the integrand along C1 has a kink. All in closed form, in the cross-section with
/// o = O2 - O1: the tangent from P_i to C2 meets a lit-arc end beta* when
/// r1 cos(theta - beta*) = r2 + o . N(beta*); C1's tangent plane at P_i passes through beta*
/// when N(theta) . (o + r2 N(beta*)) = r1; and it is tangent to C2 (the tangent and the plane
/// bounds swap) when N(theta) . o = r1 -+ r2 (the common tangents). Returned unsorted, each at
/// every 2 pi shift inside `range`.
fn theta_kinks(pair: &Pair, lit: Arc, range: Arc, out: &mut Vec<f64>) {
    let o = Vec3::new(pair.d, 0.0, pair.h2 - pair.h1);
    let mut push = |t: f64| {
        if !t.is_finite() {
            return;
        }
        let mut x = t - 2.0 * PI * ((t - range.lo) / (2.0 * PI)).floor();
        while x < range.hi {
            if x > range.lo {
                out.push(x);
            }
            x += 2.0 * PI;
        }
    };
    let mut both = |centre: f64, c: f64| {
        if c.abs() <= 1.0 {
            let w = c.acos();
            push(centre - w);
            push(centre + w);
        }
    };
    for b in [lit.lo, lit.hi] {
        let n = normal(b);
        both(b, (pair.r2 + o.dot(n)) / pair.r1);
        let v = o + n * pair.r2;
        both(v.z.atan2(v.x), pair.r1 / v.length());
    }
    let (lo, ang) = (o.length(), o.z.atan2(o.x));
    for k in [pair.r1 - pair.r2, pair.r1 + pair.r2] {
        both(ang, k / lo);
    }
}

/// The analytic solution (sec. 5.3): integral over the visible arc of C1 of
/// (N_i . E) times the second-bounce intensity at P_i, i.e. the numerator of eqs 5.28-5.31
/// before division by the projected width L (eq. 5.22) times r1.
pub fn analytic(pair: &Pair, s: &Setting, ranges: Ranges, orders: Orders) -> Secondary {
    if s.vis1.is_empty() || s.lit2.is_empty() {
        return Secondary::default();
    }
    let mut kinks = Vec::with_capacity(16);
    theta_kinks(pair, s.lit2, s.vis1, &mut kinks);
    let (live, n_live) = live_panels(pair, s, &kinks);
    if n_live == 0 {
        return Secondary::default();
    }
    let live = &live[..n_live];
    let support = Arc {
        lo: live[0].0,
        hi: live[n_live - 1].1,
    };
    let pk = match ranges {
        Ranges::Full => peak_in(pair, s, support),
        Ranges::Thesis { .. } => peak(pair, s),
    };
    let (nt, nb, nu) = scaled_orders(pair, orders);
    let Some(window) = Window::of(s, ranges, pk) else {
        return Secondary::default();
    };
    if window.theta.is_empty() {
        return Secondary::default();
    }
    let (ylo, yhi) = (s.axial.0.max(-window.l0), s.axial.1.min(window.l0));
    if ylo >= yhi {
        return Secondary::default();
    }
    let over_c2 = OverC2::new(pair, s, window.beta, pk, (nb, nu), (ylo, yhi));
    let inner = |t: f64| over_c2.at(t);
    let out = if orders.tol > 0.0 {
        adaptive_along_c1(pair, window.theta, &kinks, pk, orders.tol, &inner)
    } else {
        panels_along_c1(pair, live, window.theta, pk, nt, &inner)
    };
    out.colour(pair.m1.albedo, pair.m2.albedo)
}

/// The panels of C1's visible arc between the kinks of the integrand where P_i sees a lit
/// part of C2 (the support's ends are kinks): only they get nodes, and the maximum reflection
/// point is searched there. Returns the panels and how many.
fn live_panels(pair: &Pair, s: &Setting, kinks: &[f64]) -> ([(f64, f64); 20], usize) {
    let lit_at = |t: f64| normal(t).dot(s.e) > 0.0 && !pair.lit_seen_arc(t, s.lit2).0.is_empty();
    let mut buf = [0.0f64; 20];
    let n = cut_points(s.vis1.lo, s.vis1.hi, kinks, &mut buf);
    let mut live = [(0.0f64, 0.0f64); 20];
    let mut n_live = 0;
    for w in buf[..n].windows(2) {
        if w[1] > w[0] && lit_at(0.5 * (w[0] + w[1])) {
            live[n_live] = (w[0], w[1]);
            n_live += 1;
        }
    }
    (live, n_live)
}

/// The most any scaled order may be: 2^40. The orders are node *budgets* shared by panels in
/// proportion to their lengths, and every panel's rule has at most [`crate::quad::GL_MAX`]
/// nodes, so a budget past 2^40 changes only panels thinner than 16 / 2^40 of their range
/// (none of the rules makes such panels). It is reached beyond an exponent of about 1.5e23
/// (11 sqrt(n / 15) = 2^40); below that the orders, and so the results, are those of the
/// unbounded rule. It keeps every size made from an order finite for any exponent the fabric
/// schema takes (finite, up to 1.8e308).
pub(super) const MAX_ORDER: usize = 1 << 40;

/// The orders (theta, beta, axial) for the sharper of the two lobes: sharper lobes need more
/// nodes across C2 and along the axis, so the orders scale by sqrt(n / 15) beyond n = 15 (the
/// lobe width goes as 1 / sqrt(n)), up to [`MAX_ORDER`].
pub(super) fn scaled_orders(pair: &Pair, orders: Orders) -> (usize, usize, usize) {
    let boost = (pair.m1.exponent.max(pair.m2.exponent) / 15.0)
        .sqrt()
        .max(1.0);
    let scaled = |o: usize| ((o as f64 * boost).ceil() as usize).min(MAX_ORDER);
    (
        scaled(orders.theta),
        scaled(orders.beta),
        scaled(orders.axial),
    )
}

/// Where the integral runs: the range of theta on C1, the window of beta on C2 (thesis ranges
/// only) and the axial half-length.
struct Window {
    theta: Arc,
    beta: Option<Arc>,
    l0: f64,
}

impl Window {
    /// The whole visible arc for [`Ranges::Full`]; for [`Ranges::Thesis`], the pseudocode after
    /// eq. 5.31: c_max around the maximum reflection point and the peak line `pk` (none without
    /// a peak), on one side of the top of each cylinder (fig. 5.7).
    fn of(s: &Setting, ranges: Ranges, pk: Option<(f64, f64)>) -> Option<Window> {
        match ranges {
            Ranges::Full => Some(Window {
                theta: s.vis1,
                beta: None,
                l0: f64::INFINITY,
            }),
            Ranges::Thesis { c_max, l0 } => {
                let (t1, b2) = pk?;
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
                Some(Window {
                    theta: ta,
                    beta: Some(bw),
                    l0,
                })
            }
        }
    }
}

/// The inner double integral over C2 (across its arc, then along its generator lines) for one
/// point of C1, with everything that does not depend on that point.
struct OverC2<'a> {
    pair: &'a Pair,
    s: &'a Setting,
    /// The thesis ranges' window of beta.
    beta_window: Option<Arc>,
    /// The maximum reflection point and the peak line.
    pk: Option<(f64, f64)>,
    /// Nodes across C2 and per axial lobe panel.
    nb: usize,
    nu: usize,
    /// The axial extent.
    ylo: f64,
    yhi: f64,
    /// The lobe centres along every line, in u.
    centres: [Lobe; 2],
    /// Whether the lines are endless (one shared axial rule).
    endless: bool,
    /// The diffuse-diffuse part's cos^2 u or cos^3 u integrated over an endless line.
    whole: f64,
    facets: (CosineFacet, CosineFacet),
    /// The axial rule of endless lines.
    shared: AxialNodes,
    /// The rule of a line of finite extent, rebuilt for every line: one buffer for the call
    /// ([`OverC2::at`] runs one point at a time, so the borrow never overlaps).
    own_rule: std::cell::RefCell<AxialNodes>,
}

impl<'a> OverC2<'a> {
    fn new(
        pair: &'a Pair,
        s: &'a Setting,
        beta_window: Option<Arc>,
        pk: Option<(f64, f64)>,
        (nb, nu): (usize, usize),
        (ylo, yhi): (f64, f64),
    ) -> OverC2<'a> {
        // The lobe centres along every line, in u: reflection on a cylinder keeps the axial
        // component, so the mirror direction of E at P_i has w_y = -E_y, that of L at P_j
        // w_y = L_y.
        let centres = [
            Lobe {
                centre: (-s.e.y).clamp(-1.0, 1.0).asin(),
                width: lobe_width(pair.facet, pair.m1.exponent),
            },
            Lobe {
                centre: s.l.y.clamp(-1.0, 1.0).asin(),
                width: lobe_width(pair.facet, pair.m2.exponent),
            },
        ];
        // Endless lines share one rule; lines of finite extent get their own (per line).
        let endless = ylo == f64::NEG_INFINITY && yhi == f64::INFINITY;
        let mut shared = AxialNodes::new();
        if endless {
            axial_nodes(-FRAC_PI_2, FRAC_PI_2, centres, nu, true, &mut shared);
        }
        let own_rule = std::cell::RefCell::new(AxialNodes::with_capacity(if endless {
            0
        } else {
            axial_capacity(nu)
        }));
        let mut c2 = OverC2 {
            pair,
            s,
            beta_window,
            pk,
            nb,
            nu,
            ylo,
            yhi,
            centres,
            endless,
            whole: 0.0,
            facets: (
                crate::facet::cosine_facet(pair.facet, &pair.m1),
                crate::facet::cosine_facet(pair.facet, &pair.m2),
            ),
            shared,
            own_rule,
        };
        c2.whole = c2.cos_power(AxialEnd::of(f64::NEG_INFINITY), AxialEnd::of(f64::INFINITY));
        c2
    }

    /// The integral of the diffuse-diffuse part's cos^2 u (radiometric) or cos^3 u (thesis).
    #[inline]
    fn cos_power(&self, a: AxialEnd, b: AxialEnd) -> f64 {
        match self.pair.kernel {
            Kernel::Radiometric => int_cos2(a, b),
            Kernel::Thesis => int_cos3(a, b),
        }
    }

    /// J(theta) times (N_i . E) r1: the inner double integral over C2 for the point of C1 at
    /// angle `t`.
    #[inline]
    fn at(&self, t: f64) -> Parts {
        let (pair, s) = (self.pair, self.s);
        let mut acc = Parts::default();
        let ni = normal(t);
        let ne = ni.dot(s.e);
        if ne <= 0.0 {
            return acc;
        }
        let (mut barc, gamma, dist) = pair.lit_seen_arc(t, s.lit2);
        if let Some(bw) = self.beta_window {
            barc = barc.meet(shift_near(bw, 0.5 * (barc.lo + barc.hi)));
        }
        if barc.is_empty() {
            return acc;
        }
        let pi_ = Vec3::new(pair.r1 * ni.x, 0.0, pair.h1 + pair.r1 * ni.z);
        // Cuts: the peak line, and the point of C2 nearest P_i (where the kernel peaks when
        // P_i is close to C2).
        let mid = 0.5 * (barc.lo + barc.hi);
        let near = |a: f64| shift_near(Arc { lo: a, hi: a }, mid).lo;
        let nearest = near(gamma);
        // Grade toward the nearest point by its angular distance: the kernel there is a peak
        // of width ~ the gap between P_i and C2.
        let gap = (dist - pair.r2).max(0.0) / pair.r2;
        let bcuts = [self.pk.map_or(f64::NAN, |p| near(p.1))];
        let mut own = self.own_rule.borrow_mut();
        graded_panels(
            barc.lo,
            barc.hi,
            nearest,
            gap.clamp(1e-9, 4.0),
            &bcuts,
            self.nb,
            1,
            |b, wb| {
                if let Some(line) = self.line((ni, ne, pi_), b, &mut own) {
                    acc.add_scaled(&line, wb);
                }
            },
        );
        acc.scaled(ne * pair.r1 * pair.r2)
    }

    /// The generator line of C2 at angle `b` seen from P_i (normal `ni`, N_i . E = `ne`,
    /// position `pi_`): its integral ([`line_integral`]), none where the two do not face each
    /// other or C2 is not lit there. `own` holds the rule of a line of finite extent.
    #[inline]
    fn line(
        &self,
        (ni, ne, pi_): (Vec3, f64, Vec3),
        b: f64,
        own: &mut AxialNodes,
    ) -> Option<Parts> {
        let (pair, s) = (self.pair, self.s);
        let nj = normal(b);
        let (dx, dz) = (
            pair.d + pair.r2 * nj.x - pi_.x,
            pair.h2 + pair.r2 * nj.z - pi_.z,
        );
        let d = (dx * dx + dz * dz).sqrt();
        if d <= 0.0 {
            return None;
        }
        let wp = Vec3::new(dx / d, 0.0, dz / d);
        let ln = Line {
            a: ni.dot(wp),
            c: -nj.dot(wp),
            ne,
            nl: nj.dot(s.l),
            pe: wp.dot(s.e),
            pl: wp.dot(s.l),
            d,
        };
        if ln.a <= 0.0 || ln.c <= 0.0 || ln.nl <= 0.0 {
            return None;
        }
        let (cos_int, nodes) = if self.endless {
            (self.whole, &self.shared)
        } else {
            let (a, b) = (AxialEnd::of(self.ylo / d), AxialEnd::of(self.yhi / d));
            axial_nodes(a.u, b.u, self.centres, self.nu, false, own);
            (self.cos_power(a, b), &*own)
        };
        Some(line_integral(pair, s, &ln, self.facets, cos_int, nodes))
    }
}

/// The outer integral along C1 by adaptive G7/K15 to relative tolerance `tol`, over `range`
/// split at the `kinks` (those inside it) and the maximum reflection point of `pk`. Where the
/// arc starts near the point of C1 closest to C2 and the cylinders (nearly) touch, a point there
/// sees C2 under almost a hemisphere and the integrand grows like a logarithm: the first panel
/// is integrated in s with theta = lo + (hi - lo) s^2, which removes that.
fn adaptive_along_c1(
    pair: &Pair,
    range: Arc,
    kinks: &[f64],
    pk: Option<(f64, f64)>,
    tol: f64,
    inner: &impl Fn(f64) -> Parts,
) -> Parts {
    let mut out = Parts::default();
    let mut tcuts = kinks.to_vec();
    tcuts.extend(pk.map(|p| p.0));
    let closest = (pair.h2 - pair.h1).atan2(pair.d);
    let near_contact =
        range.lo < closest + 0.5 && pair.d - pair.r1 - pair.r2 < 0.5 * pair.r1.min(pair.r2);
    let mut buf = [0.0f64; 20];
    let n = cut_points(range.lo, range.hi, &tcuts, &mut buf);
    let pts = &buf[..n];
    let (lo0, hi0) = (pts[0], pts[1]);
    let graded = |x: f64| inner(lo0 + (hi0 - lo0) * x * x).scaled(2.0 * (hi0 - lo0) * x);
    let first: Vec<(Parts, f64, f64, f64)> = pts
        .windows(2)
        .enumerate()
        .map(|(i, w)| {
            if i == 0 && near_contact {
                let (v, e) = gk15_components(&graded, 0.0, 1.0);
                (v, e, 0.0, 1.0)
            } else {
                let (v, e) = gk15_components(inner, w[0], w[1]);
                (v, e, w[0], w[1])
            }
        })
        .collect();
    let scale: f64 = first.iter().map(|(v, ..)| v.sum()).sum::<f64>().abs();
    let tol = tol * scale.max(1e-12);
    for (i, (v, err, a, b)) in first.into_iter().enumerate() {
        let part = if i == 0 && near_contact {
            adapt(&graded, a, b, v, err, tol, 6)
        } else {
            adapt(inner, a, b, v, err, tol, 6)
        };
        out.add_scaled(&part, 1.0);
    }
    out
}

/// The outer integral along C1 by fixed Gauss-Legendre panels: the `live` panels (their part
/// inside `range`), split at the maximum reflection point of `pk`; `nt` nodes shared in
/// proportion to their lengths, each panel graded toward that point by the in-plane width of
/// the lobes (the mirror direction turns twice as fast as the normal).
fn panels_along_c1(
    pair: &Pair,
    live: &[(f64, f64)],
    range: Arc,
    pk: Option<(f64, f64)>,
    nt: usize,
    inner: &impl Fn(f64) -> Parts,
) -> Parts {
    let mut out = Parts::default();
    let mut panels_t = [(0.0f64, 0.0f64); 21];
    let mut m_t = 0;
    for &(a, b) in live {
        let (a, b) = (a.max(range.lo), b.min(range.hi));
        if b <= a {
            continue;
        }
        match pk {
            Some((t, _)) if t > a + 1e-9 * (b - a) && t < b - 1e-9 * (b - a) => {
                panels_t[m_t] = (a, t);
                panels_t[m_t + 1] = (t, b);
                m_t += 2;
            }
            _ => {
                panels_t[m_t] = (a, b);
                m_t += 1;
            }
        }
    }
    let live = &panels_t[..m_t];
    let total: f64 = live.iter().map(|(a, b)| b - a).sum();
    let n = pair.m1.exponent.max(pair.m2.exponent);
    let (c, w) = match pk {
        Some(p) => (p.0, 0.5 * lobe_width(pair.facet, n)),
        None => (0.0, 1e3),
    };
    for &(a, b) in live {
        let m = share(nt as f64 * (b - a) / total).max(2);
        graded_panels(a, b, c, w, &[], m, m, |t, wt| out.add_scaled(&inner(t), wt));
    }
    out
}
