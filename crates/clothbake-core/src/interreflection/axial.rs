//! The integral along one generator line of C2 (eqs 5.25, 5.28-5.31): the axial rule in
//! u = atan(y / D), the closed-form diffuse-diffuse part and the colourless parts.

use super::rules::graded_panels;
use super::{Kernel, Pair, Secondary, Setting};
use crate::facet::{CosineFacet, FacetModel};
use crate::lanes::{F64x2, Real};
use crate::quad::Components;
use crate::trig::sin_cos;
use std::f64::consts::PI;

/// The four components of one integrand before their albedos, `[ss, sd, ds, dd]`: sd is to be
/// multiplied by C1's albedo (diffuse at P_i), ds by C2's, dd by both.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Parts(pub(super) [f64; 4]);

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
    pub(super) fn scaled(mut self, w: f64) -> Parts {
        self.0.iter_mut().for_each(|x| *x *= w);
        self
    }
    /// The four components with their albedos.
    pub(super) fn colour(&self, a1: [f64; 3], a2: [f64; 3]) -> Secondary {
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
pub(super) type AxialNodes = Vec<(f64, f64, f64)>;

/// A specular lobe along the axis: centre and width in u.
#[derive(Clone, Copy, Debug)]
pub(super) struct Lobe {
    pub(super) centre: f64,
    pub(super) width: f64,
}

/// Gauss-Legendre panels over [u0, u1] cut at the lobe centres inside it (a panel between two
/// centres is halved). With `graded`, each panel is graded toward its nearest lobe
/// ([`graded_panels`]; each half toward its own end): endless lines, whose range runs to
/// u = +-pi/2 where cos u and the lobes' tails vanish. Lines of finite extent get plain panels:
/// there the grading leaves the far part of an end panel, where the diffuse-specular parts still
/// matter, with too few nodes (on the twill, the worst error of I_2 at the default orders drops
/// from 16% to 4.9%, the mean from 0.64% to 0.60%), and it costs two more trigonometric calls a
/// node.
pub(super) fn axial_nodes(
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

/// Room for the rule [`axial_nodes`] makes for a line of finite extent (plain panels) of
/// `order`: at most four panels (two lobe centres cut the range, a panel between them is
/// halved), each of at most [`crate::quad::GL_MAX`] nodes, whatever the order. The order grows
/// with the exponent (sqrt(n / 15)); sized from it unbounded, this was 4 order + 4 nodes, 744 GB
/// at n = 1e20.
pub(super) fn axial_capacity(order: usize) -> usize {
    4 * order.min(crate::quad::GL_MAX) + 4
}

/// Width in u = atan(y / D) of a specular lobe of exponent `n` along the axis: a cosine-power
/// lobe cos^n x falls as exp(-n x^2 / 2), width 1 / sqrt(n) (Lewis, R.E); Huo's N.H holds the
/// half angle, which doubles it.
pub(super) fn lobe_width(facet: FacetModel, n: f64) -> f64 {
    let w = match facet {
        FacetModel::Huo => 2.0,
        FacetModel::Lewis => 1.0,
    };
    (w / n.max(1e-3).sqrt()).min(4.0)
}

/// The end of a line's range in u = atan(q), q = y / D, with its sine and cosine from q
/// (q / sqrt(1 + q^2) and 1 / sqrt(1 + q^2): no trigonometric call).
#[derive(Clone, Copy, Debug)]
pub(super) struct AxialEnd {
    pub(super) u: f64,
    pub(super) sin: f64,
    pub(super) cos: f64,
}

impl AxialEnd {
    pub(super) fn of(q: f64) -> AxialEnd {
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
pub(super) fn int_cos2(a: AxialEnd, b: AxialEnd) -> f64 {
    let f = |e: AxialEnd| 0.5 * (e.u + e.sin * e.cos);
    f(b) - f(a)
}

/// Integral of cos^3 u over [u0, u1]: sin u - sin^3 u / 3.
pub(super) fn int_cos3(a: AxialEnd, b: AxialEnd) -> f64 {
    let f = |e: AxialEnd| e.sin - e.sin * e.sin * e.sin / 3.0;
    f(b) - f(a)
}

/// What one generator line of C2 (fixed beta) needs for a point P_i of C1, with
/// `w_p` the unit vector from P_i to P_j in the cross-section (no axial component).
#[derive(Clone, Copy, Debug)]
pub(super) struct Line {
    /// N_i . w_p (> 0: P_j is in front of P_i's tangent plane).
    pub(super) a: f64,
    /// -N_j . w_p (> 0: P_i is in front of P_j's tangent plane).
    pub(super) c: f64,
    /// N_i . E.
    pub(super) ne: f64,
    /// N_j . L.
    pub(super) nl: f64,
    /// w_p . E.
    pub(super) pe: f64,
    /// w_p . L.
    pub(super) pl: f64,
    /// Distance in the cross-section.
    pub(super) d: f64,
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
#[inline]
pub(super) fn line_integral(
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
