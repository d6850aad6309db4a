//! The maximum reflection point on C1 and the peak line on C2 (eqs 5.17-5.19), and the
//! angle helpers of the arcs.

use super::{normal, Pair, Setting};
use crate::arc::Arc;
use crate::trig::{round_nearest, sin_cos};
use std::f64::consts::{FRAC_PI_2, PI};

/// `a` (from atan2) into (-pi/2, 3pi/2].
pub(super) fn wrap(a: f64) -> f64 {
    if a <= -FRAC_PI_2 {
        a + 2.0 * PI
    } else {
        a
    }
}

/// The 2-pi shift of `a` whose middle is closest to `near`.
pub(super) fn shift_near(a: Arc, near: f64) -> Arc {
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
pub(super) fn peak_in(pair: &Pair, s: &Setting, range: Arc) -> Option<(f64, f64)> {
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
