//! The secondary reflection of a unit (thesis ch. 5, sec. 5.4): between the piece and its
//! parallel neighbours on both sides, analytic or by two-level sampling.

use super::*;

/// The secondary reflection from both sides, summed in the order of sec. 5.4's two
/// neighbours (+c, then -c).
pub(super) fn both_sides(s: &[Secondary; 2]) -> Secondary {
    let mut out = Secondary::default();
    out.add_scaled(&s[0], 1.0);
    out.add_scaled(&s[1], 1.0);
    out
}

impl AnalyticModel {
    /// Secondary reflection reaching the eye from the visible arc of unit `u`, per unit length,
    /// from each parallel neighbour of `nbs` (+c side, -c side; zero where there is none), the
    /// threads of albedo 1 when `white` (the colourless components of
    /// [`ClassTerms`]). The neighbour's lit arc is taken equal to the unit's own (exact for the
    /// parallel-cylinder surface, where all cylinders are alike).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn secondary(
        &self,
        u: &Unit,
        nbs: &[Option<Neighbour>; 2],
        opts: &SecondaryOptions,
        l: Vec3,
        e: Vec3,
        (vis, lit): (Arc, Arc),
        white: bool,
    ) -> [Secondary; 2] {
        let (c, a) = frame(u.seg.group);
        let mut out = [Secondary::default(); 2];
        let colour = |m: Material| {
            if white {
                Material {
                    albedo: [1.0; 3],
                    ..m
                }
            } else {
                m
            }
        };
        for (k, (side, nb)) in [(1.0, &nbs[0]), (-1.0, &nbs[1])].into_iter().enumerate() {
            let Some(nb) = nb else { continue };
            let local = |v: Vec3| Vec3::new(side * v.dot(c), v.dot(a), v.z);
            let mirror = |arc: Arc| {
                if side > 0.0 {
                    arc
                } else {
                    Arc {
                        lo: PI - arc.hi,
                        hi: PI - arc.lo,
                    }
                }
            };
            let pair = Pair {
                r1: u.seg.radius,
                h1: u.seg.height,
                r2: nb.radius,
                h2: nb.height,
                d: nb.d,
                m1: colour(u.seg.material),
                m2: colour(nb.material),
                facet: self.facet,
                kernel: opts.kernel,
            };
            let setting = Setting {
                l: local(l),
                e: local(e),
                vis1: mirror(vis),
                lit2: mirror(lit),
                axial: nb.axial,
            };
            let part = match opts.method {
                SecondaryMethod::Analytic { ranges, orders } => {
                    secondary_analytic(&pair, &setting, ranges, orders)
                }
                SecondaryMethod::Sampling(p) => two_level_sampling(&pair, &setting, p),
            };
            out[k] = part;
        }
        out
    }
}
