//! Integration ranges and quadrature orders of the analytic solution (sec. 5.3; the thesis's
//! ranges follow eq. 5.31), and the composite Gauss-Legendre panel rules it is built from.

use crate::trig::sin_cos;

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
/// `docs/science/interreflection.md`): the analytic side of the comparison with the two-level
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
pub(super) fn share(x: f64) -> usize {
    (x + 1e-9).round() as usize
}

/// The sorted end points of the panels of [a, b] split at `cuts` (at most `out.len() - 2` of
/// them), into `out`; returns how many. Cuts within 1e-9 (b - a) of an end or of each other
/// are dropped, so that rounding does not create slivers (and change the rule) on one side of
/// a mirror symmetry but not on the other.
pub(super) fn cut_points(a: f64, b: f64, cuts: &[f64], out: &mut [f64]) -> usize {
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
pub(super) fn graded_panels(
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
