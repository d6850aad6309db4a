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
//! ## Layout
//!
//! `mod.rs`: the pair, its setting and the kernel (eqs 5.9-5.15, 5.25); `peak.rs`: the
//! maximum reflection point and the peak line (5.17-5.19); `rules.rs`: ranges, orders, panel
//! rules; `axial.rs`: the integral along one generator line of C2 (5.25, 5.28-5.31);
//! `analytic.rs`: the triple integral (5.28-5.31); `sampling.rs`: the sampling of sec. 5.2.
//!
//! ## Two solutions
//!
//! * [`two_level_sampling`] (sec. 5.2): first level, regular samples on the visible arc of C1
//!   as seen by the viewer (eq. 5.1); second level, patches of angle `d_alpha` and length `d_l`
//!   on the arc of C2 that P_i sees (eqs 5.2-5.8: between the tangent from P_i to C2 and the
//!   tangent plane of C1 at P_i) and that is lit, over |y| <= l0, each patch weighted by its
//!   exact (projected) solid angle as seen from P_i (Siegel & Howell's projection; the planar
//!   quadrilateral through the patch corners) or by eq. 5.16.
//! * [`analytic()`] (sec. 5.3): the maximum reflection point and the peak line (eqs 5.17-5.19)
//!   locate the specular peak; the triple integral of eqs 5.28-5.31 is evaluated by Gauss-Legendre
//!   panels split at the peak, over the whole visible and lit arcs (default) or over the thesis's
//!   ranges (C_max = 0.3 around the peak, |y| <= l0 = 1.5).

mod analytic;
mod axial;
mod peak;
mod rules;
mod sampling;

pub use analytic::analytic;
/// The kernel and the components of I_2 are shared with the ground truth (clothbake-fabric).
pub use clothbake_fabric::reflection::{Kernel, Secondary};
pub use peak::peak;
pub use rules::{Orders, Ranges, ORDERS_FAST};
pub use sampling::{two_level_sampling, Sampling};

use crate::arc::Arc;
use crate::facet::{Facet, FacetModel};
use crate::trig::sin_cos;
use crate::vec3::Vec3;
use crate::yarn::Material;
use peak::{shift_near, wrap};
use std::f64::consts::PI;

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
#[inline]
pub(super) fn normal(t: f64) -> Vec3 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vec3::UnitVec3;

    fn pf_pair(kernel: Kernel, n: f64) -> Pair {
        let m = Material {
            albedo: [0.4; 3],
            specular: 0.7,
            exponent: n,
            translucency: 0.0,
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
                if let ArcOcclusion::UpTo(t, _) = occluded_arc(1.0, 0.0, &nb, th) {
                    a.lo = a.lo.max(t);
                }
            } else if let ArcOcclusion::UpTo(t, _) = occluded_arc(1.0, 0.0, &nb, PI - th) {
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

    /// Issue 53: the orders grow as sqrt(n / 15) and the rule of a line of finite extent was
    /// sized from them, 744 GB at n = 1e20 (an abort); past about 1e37 the size overflowed.
    /// Every exponent the fabric schema takes (finite, >= 0) now gives finite parts with the
    /// rules' bounded sizes, both facets, both kernels, lines of finite extent and endless.
    #[test]
    fn any_exponent_gives_finite_parts_quickly() {
        let start = std::time::Instant::now();
        for n in [1e17, 1e20, 1e23, 1e38, 1e300, f64::MAX] {
            for facet in [FacetModel::Huo, FacetModel::Lewis] {
                for kernel in [Kernel::Thesis, Kernel::Radiometric] {
                    let mut pair = pf_pair(kernel, n);
                    pair.facet = facet;
                    for (wi, wo) in [((30.0, 0.0), (45.0, 180.0)), ((40.0, 180.0), (35.0, 20.0))] {
                        for axial in [(-10.0, 10.0), (f64::NEG_INFINITY, f64::INFINITY)] {
                            let mut s = setting(
                                UnitVec3::from_degrees(wi.0, wi.1),
                                UnitVec3::from_degrees(wo.0, wo.1),
                            );
                            s.axial = axial;
                            let v = analytic(&pair, &s, Ranges::Full, Orders::default());
                            let t = v.total();
                            assert!(
                                t.iter().all(|x| x.is_finite() && *x >= 0.0) && t[0] > 0.0,
                                "n {n:e}, {facet:?}, {kernel:?}, {wi:?} {wo:?}: {t:?}"
                            );
                        }
                    }
                }
            }
        }
        // 96 evaluations; a few milliseconds each in a debug build.
        assert!(start.elapsed().as_secs() < 20, "{:?}", start.elapsed());
    }

    /// The bound on the orders is reached only past n = 1.5e23, so every exponent that ran
    /// before keeps its rule (and its results); the axial rule's room is at most 68 nodes.
    #[test]
    fn the_orders_bound_leaves_smaller_exponents_alone() {
        for n in [10.0, 1e4, 1e16, 1e17, 1e23] {
            let pair = pf_pair(Kernel::Radiometric, n);
            let boost = (n / 15.0f64).sqrt().max(1.0);
            let o = Orders::default();
            let free = |k: usize| (k as f64 * boost).ceil() as usize;
            assert_eq!(
                analytic::scaled_orders(&pair, o),
                (free(o.theta), free(o.beta), free(o.axial)),
                "n {n:e}"
            );
        }
        let pair = pf_pair(Kernel::Radiometric, 1e300);
        let m = analytic::MAX_ORDER;
        assert_eq!(analytic::scaled_orders(&pair, Orders::default()), (m, m, m));
        assert_eq!(axial::axial_capacity(3), 16);
        assert_eq!(axial::axial_capacity(m), 68);
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
