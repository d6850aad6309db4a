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
use crate::facet::{CosineFacet, Facet, FacetModel};
use crate::lanes::{F64x2, Real};
use crate::quad::{adapt, gk15_components, Components};
use crate::trig::{round_nearest, sin_cos};
use crate::vec3::Vec3;
use crate::yarn::Material;
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
    let (s, c) = sin_cos(t);
    Vec3::new(c, 0.0, s)
}

impl Pair {
    fn p1(&self, t: f64) -> Vec3 {
        let (s, c) = sin_cos(t);
        Vec3::new(self.r1 * c, 0.0, self.h1 + self.r1 * s)
    }
    fn p2(&self, b: f64, y: f64) -> Vec3 {
        let (s, c) = sin_cos(b);
        Vec3::new(self.d + self.r2 * c, y, self.h2 + self.r2 * s)
    }

    /// The arc of C2 (angles beta) that the point of C1 at angle `t` sees (eqs 5.2-5.8):
    /// between the tangents from P_i to C2 (theta_u, eq. 5.4) and the tangent plane of C1 at P_i
    /// (theta_l, eq. 5.7). Angles are returned in (-pi/2, 3pi/2].
    pub fn seen_arc(&self, t: f64) -> Arc {
        self.seen_arc_from(t).0
    }

    /// The part of [`Pair::seen_arc`] that is also in the lit arc `lit` of C2 (shifted by 2 pi
    /// next to it), with the nearest point's angle and the distance of [`Pair::seen_arc_from`]:
    /// where the patches of C2 that light P_i lie.
    fn lit_seen_arc(&self, t: f64, lit: Arc) -> (Arc, f64, f64) {
        let (arc, gamma, dist) = self.seen_arc_from(t);
        (
            arc.meet(shift_near(lit, 0.5 * (arc.lo + arc.hi))),
            gamma,
            dist,
        )
    }

    /// [`Pair::seen_arc`], with the angle gamma of the point of C2 nearest P_i (in
    /// (-pi/2, 3pi/2]) and the distance |P_i - O_2|.
    fn seen_arc_from(&self, t: f64) -> (Arc, f64, f64) {
        let (st, ct) = sin_cos(t);
        let (dx, dz) = (self.r1 * ct - self.d, self.h1 + self.r1 * st - self.h2);
        let dist = (dx * dx + dz * dz).sqrt();
        let gamma = wrap(dz.atan2(dx));
        let none = Arc { lo: 0.0, hi: 0.0 };
        if dist <= self.r2 {
            return (none, gamma, dist);
        }
        // Facing P_i: |P_i - O_2| cos(beta - gamma) > r2.
        let half = (self.r2 / dist).acos();
        let tangent = Arc {
            lo: gamma - half,
            hi: gamma + half,
        };
        // Above C1's tangent plane at P_i: r2 cos(beta - t) > r1 - d cos t - (h2 - h1) sin t.
        let c = (self.r1 - self.d * ct - (self.h2 - self.h1) * st) / self.r2;
        if c >= 1.0 {
            return (none, gamma, dist);
        }
        let w = c.max(-1.0).acos();
        let plane = shift_near(
            Arc {
                lo: t - w,
                hi: t + w,
            },
            gamma,
        );
        (tangent.meet(plane), gamma, dist)
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
    let k = round_nearest((near - mid) / (2.0 * PI)) * 2.0 * PI;
    Arc {
        lo: a.lo + k,
        hi: a.hi + k,
    }
}

/// The maximum reflection point theta_1 on C1 and the peak line theta_2 on C2 (eqs 5.17-5.19):
/// the 2-D projected path L -> P2 -> P1 -> E is a mirror reflection at both points. Eq. 5.18
/// gives theta_2 = theta_1 + pi/2 + (theta_L - theta_E)/2, and eq. 5.19 becomes one equation in
/// theta_1 (a quartic in tan(theta_1 / 2)); it is solved by bracketing every sign change on a
/// grid of the arc of C1 that faces C2 and bisecting, which finds all real roots without
/// the quartic's ill-conditioning. The physical root is the one whose points face each other,
/// with P1 visible and P2 lit, and whose reflected ray from P1 actually travels toward P2.
pub fn peak(pair: &Pair, s: &Setting) -> Option<(f64, f64)> {
    peak_in(pair, s, s.vis1)
}

/// [`peak`] with theta_1 searched in `range` only (within C1's visible arc).
fn peak_in(pair: &Pair, s: &Setting, range: Arc) -> Option<(f64, f64)> {
    let te = s.e.z.atan2(s.e.x);
    let tl = s.l.z.atan2(s.l.x);
    let t2 = |t1: f64| t1 + FRAC_PI_2 + 0.5 * (tl - te);
    // Eq. 5.19 (with axis heights): the chord P1P2 has direction 2 theta_1 - theta_E.
    // One sine and cosine per evaluation: theta_2 = theta_1 + k and 2 theta_1 - theta_E by the
    // angle-addition formulas.
    let (sk, ck) = (FRAC_PI_2 + 0.5 * (tl - te)).sin_cos();
    let (se, ce) = te.sin_cos();
    let f = |t1: f64| {
        let (s1, c1) = sin_cos(t1);
        let (sb, cb) = (s1 * ck + c1 * sk, c1 * ck - s1 * sk);
        let dz = pair.h2 + pair.r2 * sb - pair.h1 - pair.r1 * s1;
        let dx = pair.d + pair.r2 * cb - pair.r1 * c1;
        let (s2, c2) = (2.0 * s1 * c1, c1 * c1 - s1 * s1);
        let (sa, ca) = (s2 * ce - c2 * se, c2 * ce + s2 * se);
        dz * ca - dx * sa
    };
    let range = range.meet(s.vis1);
    let (lo, hi) = (range.lo, range.hi.min(PI));
    if lo >= hi {
        return None;
    }
    let n = 24;
    let mut best = None;
    let mut prev = (lo, f(lo));
    for k in 1..=n {
        let x = lo + (hi - lo) * k as f64 / n as f64;
        let fx = f(x);
        if prev.1 == 0.0 || prev.1.signum() != fx.signum() {
            let t1 = illinois(&f, prev, (x, fx));
            let b2 = wrap(t2(t1).rem_euclid(2.0 * PI));
            let p1 = pair.p1(t1);
            let p2 = pair.p2(b2, 0.0);
            let v = p2 - p1;
            let dir = 2.0 * t1 - te;
            let (sd, cd) = sin_cos(dir);
            let travels = v.x * cd + v.z * sd > 0.0;
            let faces = normal(t1).dot(v) > 0.0 && normal(b2).dot(-v) > 0.0;
            let b2l = shift_near(Arc { lo: b2, hi: b2 }, 0.5 * (s.lit2.lo + s.lit2.hi)).lo;
            // (with a margin, so that a peak on the lit arc's end is taken on both sides of a mirror
            // symmetry)
            if travels && faces && b2l >= s.lit2.lo - 1e-9 && b2l <= s.lit2.hi + 1e-9 {
                best = Some((t1, b2l));
            }
        }
        prev = (x, fx);
    }
    best
}

/// The root of `f` in the bracket [a, b] (values of opposite signs, or one zero) by the
/// Illinois variant of regula falsi (superlinear, never leaves the bracket), to 1e-12.
fn illinois(f: &impl Fn(f64) -> f64, a: (f64, f64), b: (f64, f64)) -> f64 {
    let ((mut a, mut fa), (mut b, mut fb)) = (a, b);
    if fa == 0.0 {
        return a;
    }
    for _ in 0..60 {
        if fb == 0.0 || (b - a).abs() < 1e-12 {
            break;
        }
        let c = (a * fb - b * fa) / (fb - fa);
        let fc = f(c);
        if fc.signum() != fb.signum() {
            // The root lies between b and c: b becomes the other end.
            a = b;
            fa = fb;
        } else {
            // a stays an end a second time: halve its value so the next step moves toward it.
            fa *= 0.5;
        }
        b = c;
        fb = fc;
    }
    b
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

/// Quadrature orders of the analytic solution (Gauss-Legendre nodes; all scaled by
/// sqrt(n / 15) beyond exponent n = 15).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orders {
    /// Along the arc of C1 when `tol` is 0: nodes in all, shared by the panels between its
    /// kinks in proportion to their lengths (at least 2 each).
    pub theta: usize,
    /// Relative tolerance of the adaptive G7/K15 quadrature along the arc of C1 (0: fixed).
    pub tol: f64,
    /// Across the arc of C2: nodes in all (at least 1 per panel).
    pub beta: usize,
    /// Along the axis: nodes per lobe panel in u = atan(y / D).
    pub axial: usize,
}

/// Cheaper orders for percent-level accuracy (under 2% mean error of I_2 on the table of
/// `docs/interreflection.md`): the analytic side of the comparison with the two-level
/// sampling at equal accuracy.
pub const ORDERS_FAST: Orders = Orders {
    theta: 7,
    tol: 0.0,
    beta: 3,
    axial: 3,
};

impl Default for Orders {
    fn default() -> Self {
        Orders {
            theta: 11,
            tol: 0.0,
            beta: 5,
            axial: 3,
        }
    }
}

/// A panel's share of a node budget, `x` rounded to the nearest integer with ties (which
/// mirror-symmetric panels produce, up to rounding) always up, so mirrored directions get the
/// same rule.
fn share(x: f64) -> usize {
    (x + 1e-9).round() as usize
}

/// The sorted end points of the panels of [a, b] split at `cuts` (at most `out.len() - 2` of
/// them), into `out`; returns how many. Cuts within 1e-9 (b - a) of an end or of each other
/// are dropped, so that rounding does not create slivers (and change the rule) on one side of
/// a mirror symmetry but not on the other.
fn cut_points(a: f64, b: f64, cuts: &[f64], out: &mut [f64]) -> usize {
    let eps = 1e-9 * (b - a);
    let cap = out.len() - 1;
    let mut n = 0;
    for &c in cuts {
        if n + 1 < cap && c > a + eps && c < b - eps {
            out[n] = c;
            n += 1;
        }
    }
    out[..n].sort_unstable_by(f64::total_cmp);
    // a, the cuts apart from each other, b.
    let mut k = 1;
    let mut prev = a;
    let mut kept = [0.0f64; 20];
    kept[0] = a;
    for &c in &out[..n] {
        if c - prev > eps {
            kept[k] = c;
            k += 1;
            prev = c;
        }
    }
    kept[k] = b;
    out[..=k].copy_from_slice(&kept[..=k]);
    k + 1
}

/// Composite Gauss-Legendre over [a, b] split at the `cuts` inside it: `nodes` in all, shared
/// by the panels in proportion to their lengths, at least `min` and at most
/// [`crate::quad::GL_MAX`] each.
fn panels(a: f64, b: f64, cuts: &[f64], nodes: usize, min: usize, mut f: impl FnMut(f64, f64)) {
    let mut pts = [0.0f64; 20];
    let n = cut_points(a, b, cuts, &mut pts);
    let pts = &pts[..n];
    let per = nodes as f64 / (b - a);
    for w in pts.windows(2) {
        let (lo, hi) = (w[0], w[1]);
        let m = share(per * (hi - lo)).max(min);
        for &(x, wt) in crate::quad::gl_rule(m) {
            f(lo + (hi - lo) * 0.5 * (x + 1.0), 0.5 * wt * (hi - lo));
        }
    }
}

/// Composite Gauss-Legendre over [a, b], split at the `cuts` inside it, in s = atan((x - c) / w):
/// x = c + w tan s puts the nodes where a peak of centre `c` and width `w` (a Lorentzian-like
/// kernel, e.g. 1 / ((x - c)^2 + w^2)) lives and keeps its tails; a wide `w` gives nearly
/// uniform panels.
#[allow(clippy::too_many_arguments)]
fn graded_panels(
    a: f64,
    b: f64,
    c: f64,
    w: f64,
    cuts: &[f64],
    nodes: usize,
    min: usize,
    mut f: impl FnMut(f64, f64),
) {
    let to_s = |x: f64| ((x - c) / w).atan();
    let mut sc = [f64::NAN; 9];
    for (k, &x) in cuts.iter().take(8).enumerate() {
        sc[k] = to_s(x);
    }
    sc[8] = 0.0; // the centre itself
    panels(to_s(a), to_s(b), &sc, nodes, min, |s, ws| {
        let (sn, cs) = sin_cos(s);
        f(c + w * sn / cs, ws * w / (cs * cs));
    });
}

/// The four components of one integrand before their albedos, `[ss, sd, ds, dd]`: sd is to be
/// multiplied by C1's albedo (diffuse at P_i), ds by C2's, dd by both.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Parts([f64; 4]);

impl Components for Parts {
    fn add_scaled(&mut self, o: &Parts, w: f64) {
        for k in 0..4 {
            self.0[k] += w * o.0[k];
        }
    }
    fn sum(&self) -> f64 {
        self.0.iter().sum()
    }
}

impl Parts {
    fn scaled(mut self, w: f64) -> Parts {
        self.0.iter_mut().for_each(|x| *x *= w);
        self
    }
    /// The four components with their albedos.
    fn colour(&self, a1: [f64; 3], a2: [f64; 3]) -> Secondary {
        let [ss, sd, ds, dd] = self.0;
        Secondary {
            ss: [ss; 3],
            sd: a1.map(|a| a * sd),
            ds: a2.map(|a| a * ds),
            dd: std::array::from_fn(|c| a1[c] * a2[c] * dd),
        }
    }
}

/// Nodes `(sin u, cos u, weight)` of a rule along one generator line of C2 in u = atan(y / D)
/// (y measured from P_i's cross-section, D the distance in the cross-section).
type AxialNodes = Vec<(f64, f64, f64)>;

/// A specular lobe along the axis: centre and width in u.
#[derive(Clone, Copy, Debug)]
struct Lobe {
    centre: f64,
    width: f64,
}

/// Gauss-Legendre panels over [u0, u1] cut at the lobe centres inside it (a panel between two
/// centres is halved). With `graded`, each panel is graded toward its nearest lobe
/// ([`graded_panels`]; each half toward its own end): endless lines, whose range runs to
/// u = +-pi/2 where cos u and the lobes' tails vanish. Lines of finite extent get plain panels:
/// there the grading leaves the far part of an end panel, where the diffuse-specular parts still
/// matter, with too few nodes (on the twill, the worst error of I_2 at the default orders drops
/// from 16% to 4.9%, the mean from 0.64% to 0.60%), and it costs two more trigonometric calls a
/// node.
fn axial_nodes(
    u0: f64,
    u1: f64,
    lobes: [Lobe; 2],
    order: usize,
    graded: bool,
    out: &mut AxialNodes,
) {
    out.clear();
    let mut push = |a: f64, b: f64, l: Lobe| {
        if graded {
            graded_panels(a, b, l.centre, l.width, &[], order, order, |u, w| {
                let (s, c) = sin_cos(u);
                out.push((s, c, w));
            })
        } else {
            // Nodes m -+ h x in pairs, by the angle-addition formulas from the sines and
            // cosines of m and h x: one trigonometric call a pair (and the centre's).
            let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
            let (sm, cm) = sin_cos(m);
            let rule = crate::quad::gl_rule(order);
            let half = rule.len() / 2;
            if rule.len() % 2 == 1 {
                out.push((sm, cm, rule[half].1 * h));
            }
            for &(x, wt) in &rule[rule.len() - half..] {
                let (sd, cd) = sin_cos(h * x);
                let w = wt * h;
                out.push((sm * cd - cm * sd, cm * cd + sm * sd, w));
                out.push((sm * cd + cm * sd, cm * cd - sm * sd, w));
            }
        }
    };
    let inside = |l: &Lobe| l.centre > u0 && l.centre < u1;
    let mut pts = [(u0, None), (0.0, None), (0.0, None), (u1, None)];
    let mut n = 1;
    for l in lobes.iter().filter(|l| inside(l)) {
        pts[n] = (l.centre, Some(*l));
        n += 1;
    }
    pts[n] = (u1, None);
    let pts = &mut pts[..=n];
    pts.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    // Distance from a lobe's centre to [a, b].
    let dist = |l: &Lobe, a: f64, b: f64| (a - l.centre).max(l.centre - b).max(0.0);
    for w in pts.windows(2) {
        let ((a, la), (b, lb)) = (w[0], w[1]);
        match (la, lb) {
            (Some(x), Some(y)) => {
                let m = 0.5 * (a + b);
                push(a, m, x);
                push(m, b, y);
            }
            (Some(x), None) | (None, Some(x)) => push(a, b, x),
            (None, None) => {
                let l = if dist(&lobes[0], a, b) <= dist(&lobes[1], a, b) {
                    lobes[0]
                } else {
                    lobes[1]
                };
                push(a, b, l);
            }
        }
    }
}

/// Width in u = atan(y / D) of a specular lobe of exponent `n` along the axis: a cosine-power
/// lobe cos^n x falls as exp(-n x^2 / 2), width 1 / sqrt(n) (Lewis, R.E); Huo's N.H holds the
/// half angle, which doubles it.
fn lobe_width(facet: FacetModel, n: f64) -> f64 {
    let w = match facet {
        FacetModel::Huo => 2.0,
        FacetModel::Lewis => 1.0,
    };
    (w / n.max(1e-3).sqrt()).min(4.0)
}

/// The end of a line's range in u = atan(q), q = y / D, with its sine and cosine from q
/// (q / sqrt(1 + q^2) and 1 / sqrt(1 + q^2): no trigonometric call).
#[derive(Clone, Copy, Debug)]
struct AxialEnd {
    u: f64,
    sin: f64,
    cos: f64,
}

impl AxialEnd {
    fn of(q: f64) -> AxialEnd {
        let u = q.atan();
        if !q.is_finite() {
            // q = +-inf (an endless side): u = +-pi/2; NaN stays NaN.
            return AxialEnd {
                u,
                sin: q.signum(),
                cos: 0.0,
            };
        }
        let r = 1.0 / (1.0 + q * q).sqrt();
        AxialEnd {
            u,
            sin: q * r,
            cos: r,
        }
    }
}

/// Integral of cos^2 u over [u0, u1]: (u + sin u cos u) / 2.
fn int_cos2(a: AxialEnd, b: AxialEnd) -> f64 {
    let f = |e: AxialEnd| 0.5 * (e.u + e.sin * e.cos);
    f(b) - f(a)
}

/// Integral of cos^3 u over [u0, u1]: sin u - sin^3 u / 3.
fn int_cos3(a: AxialEnd, b: AxialEnd) -> f64 {
    let f = |e: AxialEnd| e.sin - e.sin * e.sin * e.sin / 3.0;
    f(b) - f(a)
}

/// What one generator line of C2 (fixed beta) needs for a point P_i of C1, with
/// `w_p` the unit vector from P_i to P_j in the cross-section (no axial component).
#[derive(Clone, Copy, Debug)]
struct Line {
    /// N_i . w_p (> 0: P_j is in front of P_i's tangent plane).
    a: f64,
    /// -N_j . w_p (> 0: P_i is in front of P_j's tangent plane).
    c: f64,
    /// N_i . E.
    ne: f64,
    /// N_j . L.
    nl: f64,
    /// w_p . E.
    pe: f64,
    /// w_p . L.
    pl: f64,
    /// Distance in the cross-section.
    d: f64,
}

/// The integrand of eqs 5.28-5.31 per unit area of C2, integrated along one generator line.
///
/// On the line P_j = P_i + D w_p + y Y, so with y = D tan u the direction from P_i to P_j is
/// w = cos u w_p + sin u Y: every cosine the facets need is linear in (cos u, sin u), e.g.
/// N_i . w = a cos u and w . E = pe cos u + E_y sin u, and the solid angle element is
/// (N_j . -w) dA / R^2 = r2 dbeta c cos u du / D (eq. 5.25). The diffuse-diffuse part has no
/// facet lobe and is integrated in closed form: a c N_j.L / (pi D) times the integral of
/// cos^2 u (radiometric kernel), a^2 c N_j.L / D times that of cos^3 u (thesis kernel); the
/// three with a specular reflection by the nodes given. `cos_int` is that integral of cos^2 u
/// or cos^3 u over the line's range. Returns the colourless parts per unit r2 dbeta.
fn line_integral(
    pair: &Pair,
    s: &Setting,
    ln: &Line,
    facets: (CosineFacet, CosineFacet),
    cos_int: f64,
    nodes: &AxialNodes,
) -> Parts {
    let (ey, ly) = (s.e.y, s.l.y);
    let thesis = pair.kernel == Kernel::Thesis;
    let g = match pair.kernel {
        Kernel::Thesis => ln.c / ln.d,
        Kernel::Radiometric => ln.c / (PI * ln.d),
    };
    let dd = if thesis {
        g * ln.a * ln.a * ln.nl * cos_int
    } else {
        g * ln.a * ln.nl * cos_int
    };
    let (mut ss, mut sd, mut ds) = (0.0, 0.0, 0.0);
    let (f1, f2) = facets;
    if !(f1.is_zero() && f2.is_zero()) {
        // Two nodes at a time in two lanes, the odd one alone: the same terms either way.
        let pairs = nodes.chunks_exact(2);
        let rest = pairs.remainder();
        let zero = F64x2::splat(0.0);
        let (mut ss2, mut sd2, mut ds2) = (zero, zero, zero);
        for p in pairs {
            let lane = |k: fn(&(f64, f64, f64)) -> f64| F64x2::new(k(&p[0]), k(&p[1]));
            let (a, b, c) = node_terms(
                ln,
                facets,
                (ey, ly),
                thesis,
                (lane(|n| n.0), lane(|n| n.1), lane(|n| n.2)),
            );
            ss2 = ss2 + a;
            sd2 = sd2 + b;
            ds2 = ds2 + c;
        }
        let sum = |v: F64x2| v.lanes()[0] + v.lanes()[1];
        (ss, sd, ds) = (sum(ss2), sum(sd2), sum(ds2));
        for &(su, cu, wt) in rest {
            let (a, b, c) = node_terms(ln, facets, (ey, ly), thesis, (su, cu, wt));
            ss += a;
            sd += b;
            ds += c;
        }
    }
    Parts([g * ss, g * sd, g * ds, dd])
}

/// One axial node's contributions `(ss, sd, ds)` to [`line_integral`] (before the line's
/// factor), for one node or two lanes of nodes: `(sin u, cos u, weight)`, `(E_y, L_y)`.
#[inline(always)]
fn node_terms<T: Real>(
    ln: &Line,
    (f1, f2): (CosineFacet, CosineFacet),
    (ey, ly): (f64, f64),
    thesis: bool,
    (su, cu, wt): (T, T, T),
) -> (T, T, T) {
    let s = T::splat;
    let nli = cu * s(ln.a); // N_i . w (> 0)
    let nej = cu * s(ln.c); // N_j . (-w) (> 0)
    let we = cu * s(ln.pe) + su * s(ey); // w . E
    let wl = cu * s(ln.pl) + su * s(ly); // w . L
                                         // At P_i light arrives along w and leaves toward E; at P_j it arrives from L and leaves
                                         // along -w. Both cosines of each are positive on the line (N_i . E and N_j . L are checked
                                         // by the caller).
    let si = f1.specular(nli, s(ln.ne), we);
    let sj = f2.specular(s(ln.nl), nej, s(0.0) - wl);
    let k = if thesis { wt * cu * nli } else { wt * cu };
    (k * si * sj, k * nli * sj, k * si * s(ln.nl))
}

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
    let e = s.e;
    // The panels of C1's visible arc between the kinks of the integrand where P_i sees a lit
    // part of C2 (the support's ends are kinks): only they get nodes, and the maximum reflection
    // point is searched there.
    let lit_at = |t: f64| normal(t).dot(e) > 0.0 && !pair.lit_seen_arc(t, s.lit2).0.is_empty();
    let mut kinks = Vec::with_capacity(16);
    theta_kinks(pair, s.lit2, s.vis1, &mut kinks);
    let mut buf = [0.0f64; 20];
    let n = cut_points(s.vis1.lo, s.vis1.hi, &kinks, &mut buf);
    let mut live = [(0.0f64, 0.0f64); 20];
    let mut n_live = 0;
    for w in buf[..n].windows(2) {
        if w[1] > w[0] && lit_at(0.5 * (w[0] + w[1])) {
            live[n_live] = (w[0], w[1]);
            n_live += 1;
        }
    }
    if n_live == 0 {
        return Secondary::default();
    }
    let support = Arc {
        lo: live[0].0,
        hi: live[n_live - 1].1,
    };
    let pk = match ranges {
        Ranges::Full => peak_in(pair, s, support),
        Ranges::Thesis { .. } => peak(pair, s),
    };
    // Sharper lobes need more nodes across C2 and along the axis: scale the orders by
    // sqrt(n / 15) beyond n = 15 (the lobe width goes as 1 / sqrt(n)).
    let boost = (pair.m1.exponent.max(pair.m2.exponent) / 15.0)
        .sqrt()
        .max(1.0);
    let scaled = |o: usize| (o as f64 * boost).ceil() as usize;
    let (nt, nb, nu) = (
        scaled(orders.theta),
        scaled(orders.beta),
        scaled(orders.axial),
    );
    let (theta_range, beta_window, l0) = match ranges {
        Ranges::Full => (s.vis1, None, f64::INFINITY),
        Ranges::Thesis { c_max, l0 } => {
            let Some((t1, b2)) = pk else {
                return Secondary::default();
            };
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
        return Secondary::default();
    }
    let (ylo, yhi) = (s.axial.0.max(-l0), s.axial.1.min(l0));
    if ylo >= yhi {
        return Secondary::default();
    }
    // The lobe centres along every line, in u: reflection on a cylinder keeps the axial
    // component, so the mirror direction of E at P_i has w_y = -E_y, that of L at P_j w_y = L_y.
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
    // The integral of the diffuse-diffuse part's cos^2 u (radiometric) or cos^3 u (thesis).
    let cos_power = |a: AxialEnd, b: AxialEnd| match pair.kernel {
        Kernel::Radiometric => int_cos2(a, b),
        Kernel::Thesis => int_cos3(a, b),
    };
    let whole = cos_power(AxialEnd::of(f64::NEG_INFINITY), AxialEnd::of(f64::INFINITY));
    let facets = (
        CosineFacet::new(pair.facet, &pair.m1),
        CosineFacet::new(pair.facet, &pair.m2),
    );
    let mut shared = AxialNodes::new();
    if endless {
        axial_nodes(-FRAC_PI_2, FRAC_PI_2, centres, nu, true, &mut shared);
    }
    // The rule of a line of finite extent, rebuilt for every line: one buffer for the call
    // (`inner` runs one point at a time, so the borrow never overlaps).
    let own_rule = std::cell::RefCell::new(AxialNodes::with_capacity(if endless {
        0
    } else {
        4 * nu + 4
    }));
    // J(theta) times (N_i . E) r1: the inner double integral over C2 for one point of C1.
    let inner = |t: f64| -> Parts {
        let mut acc = Parts::default();
        let ni = normal(t);
        let ne = ni.dot(e);
        if ne <= 0.0 {
            return acc;
        }
        let (mut barc, gamma, dist) = pair.lit_seen_arc(t, s.lit2);
        if let Some(bw) = beta_window {
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
        let bcuts = [pk.map_or(f64::NAN, |p| near(p.1))];
        let mut own = own_rule.borrow_mut();
        graded_panels(
            barc.lo,
            barc.hi,
            nearest,
            gap.clamp(1e-9, 4.0),
            &bcuts,
            nb,
            1,
            |b, wb| {
                let nj = normal(b);
                let (dx, dz) = (
                    pair.d + pair.r2 * nj.x - pi_.x,
                    pair.h2 + pair.r2 * nj.z - pi_.z,
                );
                let d = (dx * dx + dz * dz).sqrt();
                if d <= 0.0 {
                    return;
                }
                let wp = Vec3::new(dx / d, 0.0, dz / d);
                let ln = Line {
                    a: ni.dot(wp),
                    c: -nj.dot(wp),
                    ne,
                    nl: nj.dot(s.l),
                    pe: wp.dot(e),
                    pl: wp.dot(s.l),
                    d,
                };
                if ln.a <= 0.0 || ln.c <= 0.0 || ln.nl <= 0.0 {
                    return;
                }
                let (cos_int, nodes) = if endless {
                    (whole, &shared)
                } else {
                    let (a, b) = (AxialEnd::of(ylo / d), AxialEnd::of(yhi / d));
                    axial_nodes(a.u, b.u, centres, nu, false, &mut own);
                    (cos_power(a, b), &*own)
                };
                acc.add_scaled(&line_integral(pair, s, &ln, facets, cos_int, nodes), wb);
            },
        );
        acc.scaled(ne * pair.r1 * pair.r2)
    };
    let mut out = Parts::default();
    if orders.tol > 0.0 {
        // The kinks found over C1's visible arc (cut_points keeps those inside theta_range).
        let mut tcuts = kinks.clone();
        tcuts.extend(pk.map(|p| p.0));
        // Adaptive G7/K15 along C1, split at the maximum reflection point. Where the arc starts
        // near the point of C1 closest to C2 and the cylinders (nearly) touch, a point there sees
        // C2 under almost a hemisphere and the integrand grows like a logarithm: the first panel
        // is integrated in s with theta = lo + (hi - lo) s^2, which removes that.
        let closest = (pair.h2 - pair.h1).atan2(pair.d);
        let near_contact = theta_range.lo < closest + 0.5
            && pair.d - pair.r1 - pair.r2 < 0.5 * pair.r1.min(pair.r2);
        let mut buf = [0.0f64; 20];
        let n = cut_points(theta_range.lo, theta_range.hi, &tcuts, &mut buf);
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
                    let (v, e) = gk15_components(&inner, w[0], w[1]);
                    (v, e, w[0], w[1])
                }
            })
            .collect();
        let scale: f64 = first.iter().map(|(v, ..)| v.sum()).sum::<f64>().abs();
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
        // The live panels (Full ranges: those found above; thesis ranges: their part inside
        // theta_range), split at the maximum reflection point; `nt` nodes shared in proportion
        // to their lengths, each graded toward that point by the in-plane width of the lobes
        // (the mirror direction turns twice as fast as the normal).
        let mut panels_t = [(0.0f64, 0.0f64); 21];
        let mut m_t = 0;
        for &(a, b) in &live[..n_live] {
            let (a, b) = (a.max(theta_range.lo), b.min(theta_range.hi));
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
    }
    out.colour(pair.m1.albedo, pair.m2.albedo)
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
            // The defaults trade accuracy for speed: within 2% of the converged rule (their
            // documented worst case; about 1% here), which agrees with fine sampling to 0.5%.
            assert!(
                (a - reference).abs() < 0.02 * reference,
                "{kernel:?}: default orders {a} vs {reference}"
            );
            assert!(
                (reference - b).abs() < 0.005 * reference,
                "{kernel:?}: analytic {reference} vs sampling {b}"
            );
        }
    }
}
