//! Test oracle: the direct model as evaluated before issue 22's speed work, kept verbatim in its
//! straightforward form (every angle from the standard library's `atan2`/`asin`, every arc end's
//! sine and cosine from `sin`/`cos`, nothing hoisted out of the per-unit loop). The fast path in
//! `analytic/`, `arc.rs` and `shadowing.rs` must agree with it to 1e-6 relative on every
//! shipped fabric (the test at the end).

use super::{frame, meet, overlap, AnalyticModel, Unit, Variant, EPS};
use crate::arc::{Arc, Projected};
use crate::fabric::Material;
use crate::facet::{Facet, FacetModel};
use crate::quad::integrate;
use crate::reflect::Reflection;
use crate::shadowing::Occluder;
use crate::vec3::{UnitVec3, Vec3};
use crate::weave::Group;
use std::f64::consts::{FRAC_PI_2, PI};

fn angle(v: Projected) -> f64 {
    v.z.atan2(v.c)
}

fn norm(v: Projected) -> f64 {
    v.c.hypot(v.z)
}

fn above_floor(r: f64, h: f64) -> Arc {
    let t = (h / r).clamp(-1.0, 1.0).asin();
    Arc { lo: -t, hi: PI + t }
}

fn facing(v: Projected) -> Arc {
    let t = angle(v);
    Arc {
        lo: t - FRAC_PI_2,
        hi: t + FRAC_PI_2,
    }
}

fn projected_width(r: f64, arc: Arc, e: Projected) -> f64 {
    if arc.is_empty() {
        return 0.0;
    }
    let f = |t: f64| e.c * t.sin() - e.z * t.cos();
    r * (f(arc.hi) - f(arc.lo))
}

fn diffuse_integral(arc: Arc, l: Projected, e: Projected) -> f64 {
    if arc.is_empty() {
        return 0.0;
    }
    let cc = |t: f64| 0.5 * t + 0.25 * (2.0 * t).sin();
    let ss = |t: f64| 0.5 * t - 0.25 * (2.0 * t).sin();
    let sc = |t: f64| 0.5 * t.sin().powi(2);
    let d = |f: &dyn Fn(f64) -> f64| f(arc.hi) - f(arc.lo);
    l.c * e.c * d(&cc) + (l.c * e.z + l.z * e.c) * d(&sc) + l.z * e.z * d(&ss)
}

fn huo_specular_integral(arc: Arc, h: Projected, e: Projected, n: f64) -> Option<f64> {
    if n.fract() != 0.0 || !(0.0..=4096.0).contains(&n) {
        return None;
    }
    if arc.is_empty() {
        return Some(0.0);
    }
    let n = n as u32;
    let th = angle(h);
    let delta = th - angle(e);
    let (sd, cd) = delta.sin_cos();
    let prim = |u: f64| {
        let (su, cu) = u.sin_cos();
        cd * cos_power_integral(n + 1, su, cu, u) + sd * cu.powi(n as i32 + 1) / (n as f64 + 1.0)
    };
    let v = prim(arc.hi - th) - prim(arc.lo - th);
    Some(norm(h).powi(n as i32) * norm(e) * v)
}

fn cos_power_integral(m: u32, su: f64, cu: f64, u: f64) -> f64 {
    let even = m.is_multiple_of(2);
    let mut acc = if even { u } else { su };
    let mut k = if even { 2 } else { 3 };
    let mut cp = if even { cu } else { cu * cu };
    let c2 = cu * cu;
    while k <= m {
        acc = cp * su / k as f64 + (k as f64 - 1.0) / k as f64 * acc;
        cp *= c2;
        k += 2;
    }
    acc
}

enum ArcOcclusion {
    None,
    UpTo(f64),
    All,
}

fn occluded_arc(r1: f64, h1: f64, o: &Occluder, psi: f64) -> ArcOcclusion {
    let (sp, cp) = psi.sin_cos();
    let s = o.support(sp, cp) - h1 * cp;
    if s <= -r1 {
        ArcOcclusion::None
    } else if s >= r1 {
        ArcOcclusion::All
    } else {
        ArcOcclusion::UpTo(psi + (s / r1).asin())
    }
}

fn occluded_length(top: f64, o: &Occluder, psi: f64) -> f64 {
    let (sp, cp) = psi.sin_cos();
    let num = o.support(sp, cp) - top * cp;
    if num <= 0.0 {
        0.0
    } else if sp <= 0.0 {
        f64::INFINITY
    } else {
        num / sp
    }
}

#[allow(clippy::too_many_arguments)]
fn mean_occluded_length(
    r: f64,
    h: f64,
    o: &Occluder,
    psi: f64,
    arc: Arc,
    e: Projected,
    max_len: f64,
) -> f64 {
    let (sp, cp) = psi.sin_cos();
    if arc.is_empty() || sp <= 0.0 {
        return occluded_length(crate::geometry::equal_area_height(r, h), o, psi).min(max_len);
    }
    let a = (o.support(sp, cp) - h * cp) / sp;
    let b = r * cp / sp;
    let mut cuts = [0.0f64; 8];
    cuts[0] = arc.lo;
    let mut n = 1;
    if b > 0.0 {
        for x in [a / b, (a - max_len) / b] {
            if x.abs() < 1.0 {
                let t = x.asin();
                for c in [t, PI - t, t - 2.0 * PI] {
                    if c > arc.lo && c < arc.hi {
                        cuts[n] = c;
                        n += 1;
                    }
                }
            }
        }
    }
    cuts[n] = arc.hi;
    let cuts = &mut cuts[..=n];
    cuts.sort_unstable_by(f64::total_cmp);
    let pw = |t: f64| e.c * t.sin() - e.z * t.cos();
    let psw = |t: f64| e.c * 0.5 * t.sin().powi(2) + e.z * (0.5 * t - 0.25 * (2.0 * t).sin());
    let (mut num, mut den) = (0.0, 0.0);
    for w in cuts.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        let l_mid = a - b * (0.5 * (t0 + t1)).sin();
        let wsum = pw(t1) - pw(t0);
        den += wsum;
        num += if l_mid <= 0.0 {
            0.0
        } else if l_mid >= max_len {
            max_len * wsum
        } else {
            a * wsum - b * (psw(t1) - psw(t0))
        };
    }
    if den <= 0.0 {
        0.0
    } else {
        (num / den).clamp(0.0, max_len)
    }
}

fn side_arc(u: &Unit, v: Projected) -> Arc {
    let mut arc = facing(v);
    let theta = angle(v);
    let (table, psi, mirrored) = if v.c > EPS {
        (&u.side_plus, theta, false)
    } else if v.c < -EPS {
        (&u.side_minus, PI - theta, true)
    } else {
        return arc;
    };
    let Some(o) = table.active(psi) else {
        return arc;
    };
    match occluded_arc(u.seg.radius, u.seg.height, o, psi) {
        ArcOcclusion::None => {}
        ArcOcclusion::All => arc.hi = arc.lo,
        ArcOcclusion::UpTo(t) if mirrored => arc.hi = arc.hi.min(PI - t),
        ArcOcclusion::UpTo(t) => arc.lo = arc.lo.max(t),
    }
    arc
}

fn end_interval(
    variant: Variant,
    u: &Unit,
    va: f64,
    vz: f64,
    arc: Arc,
    e: Projected,
) -> (f64, f64) {
    let Some((y0, y1)) = u.seg.extent else {
        return (f64::NEG_INFINITY, f64::INFINITY);
    };
    let (table, psi) = if va > EPS {
        (&u.seg.end_plus, vz.atan2(va))
    } else if va < -EPS {
        (&u.seg.end_minus, vz.atan2(-va))
    } else {
        return (y0, y1);
    };
    let seg = &u.seg;
    let hidden = table.active(psi).map_or(0.0, |o| match variant {
        Variant::Thesis => occluded_length(seg.top, o, psi),
        Variant::Refined | Variant::Sliced | Variant::Sliced3d => {
            mean_occluded_length(seg.radius, seg.height, o, psi, arc, e, y1 - y0)
        }
    });
    if va > 0.0 {
        (y0, y1 - hidden)
    } else {
        (y0 + hidden, y1)
    }
}

#[allow(clippy::too_many_arguments)]
fn arc_integral(
    facet: FacetModel,
    m: &Material,
    g: Group,
    arc: Arc,
    wi: UnitVec3,
    wo: UnitVec3,
    lp: Projected,
    ep: Projected,
) -> (f64, f64) {
    let kd = diffuse_integral(arc, lp, ep);
    if m.specular == 0.0 {
        return (kd, 0.0);
    }
    if facet == FacetModel::Huo {
        let h = wi.get() + wo.get();
        let hl = h.length();
        let (c, _) = frame(g);
        let hp = Projected {
            c: h.dot(c) / hl,
            z: h.z / hl,
        };
        if let Some(s) = huo_specular_integral(arc, hp, ep, m.exponent) {
            return (kd, m.specular * s);
        }
    }
    let (c, _) = frame(g);
    let (l, e) = (wi.get(), wo.get());
    let mut f = |t: f64| {
        let n = c * t.cos() + Vec3::new(0.0, 0.0, t.sin());
        facet.intensity(m, n, l, e).specular * n.dot(e).max(0.0)
    };
    let h = l + e;
    let peak = angle(Projected {
        c: h.dot(c),
        z: h.z,
    })
    .clamp(arc.lo, arc.hi);
    let tol = 1e-10 * (arc.hi - arc.lo);
    let s = integrate(&mut f, arc.lo, peak, tol) + integrate(&mut f, peak, arc.hi, tol);
    (kd, s)
}

/// A unit's visible length l_v, projected width and (l_vi, diffuse, specular) integrals.
type Terms = (f64, f64, Option<(f64, f64, f64)>);

/// Unit `u`'s (l_v, width, lit) of eq. 4.11, as `AnalyticModel::unit_terms` computed them.
fn unit_terms(m: &AnalyticModel, u: &Unit, wi: UnitVec3, wo: UnitVec3) -> Option<Terms> {
    let (l, e) = (wi.get(), wo.get());
    let seg = &u.seg;
    let (c, a) = frame(seg.group);
    let ep = Projected {
        c: e.dot(c),
        z: e.z,
    };
    let floor = above_floor(seg.radius, seg.height);
    let arc = side_arc(u, ep).meet(floor);
    let along = end_interval(m.variant, u, e.dot(a), e.z, arc, ep);
    let l_v = overlap(u.range, along);
    if arc.is_empty() || l_v <= 0.0 {
        return None;
    }
    let width = projected_width(seg.radius, arc, ep);
    let lp = Projected {
        c: l.dot(c),
        z: l.z,
    };
    let lit = side_arc(u, lp).meet(floor);
    let vi = arc.meet(lit);
    let lit_len = end_interval(m.variant, u, l.dot(a), l.z, vi, ep);
    let l_vi = overlap(u.range, meet(along, lit_len));
    let lit = (!vi.is_empty() && l_vi > 0.0).then(|| {
        let (kd, ks) = arc_integral(m.facet, &seg.material, seg.group, vi, wi, wo, lp, ep);
        (l_vi, kd, ks)
    });
    Some((l_v, width, lit))
}

/// The direct reflection I_1 (eq. 4.11) as `AnalyticModel::intensity` computed it.
pub(super) fn intensity(m: &AnalyticModel, wi: UnitVec3, wo: UnitVec3) -> Reflection {
    if !(wi.above_horizon() && wo.above_horizon()) {
        return Reflection::default();
    }
    let mut s_total = 0.0;
    let mut i_d = [0.0; 3];
    let mut i_s = 0.0;
    for u in &m.units {
        let Some((l_v, width, lit)) = unit_terms(m, u, wi, wo) else {
            continue;
        };
        let d = u.count as f64;
        s_total += d * l_v * width;
        let Some((l_vi, kd, ks)) = lit else {
            continue;
        };
        let w = d * l_vi * u.seg.radius;
        for (acc, a) in i_d.iter_mut().zip(u.seg.material.albedo) {
            *acc += w * kd * a;
        }
        i_s += w * ks;
    }
    if s_total <= 0.0 {
        return Reflection::default();
    }
    Reflection {
        i_d: i_d.map(|x| x / s_total),
        i_s: [i_s / s_total; 3],
        secondary: None,
    }
}

/// The coverage C(wo) from the units' visible areas, as `AnalyticModel::coverage` computed it.
fn coverage(m: &AnalyticModel, wo: UnitVec3) -> f64 {
    let s: f64 = m
        .units
        .iter()
        .filter_map(|u| unit_terms(m, u, wo, wo).map(|(l_v, w, _)| u.count as f64 * l_v * w))
        .sum();
    let (px, py) = m.grid.period();
    s / (px * py * wo.cos_theta())
}

mod tests {
    use super::*;
    use crate::fabric::Fabric;
    use crate::rng::Rng;
    use std::path::Path;

    /// Every fabric shipped in tables/ (JSON and WIF).
    fn shipped() -> Vec<(String, Fabric)> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables");
        let mut out: Vec<(String, Fabric)> = std::fs::read_dir(&dir)
            .expect("tables/")
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "json" || x == "wif"))
            .map(|p| {
                let f = Fabric::from_path(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
                (p.display().to_string(), f)
            })
            .collect();
        out.sort_by(|a, b| a.0.cmp(&b.0));
        out
    }

    /// Random pairs uniform in solid angle, plus pairs on the symmetry planes (phi a multiple
    /// of 90 degrees: projections on the EPS branches), at normal incidence and near grazing.
    fn pairs(n: usize, seed: u64) -> Vec<(UnitVec3, UnitVec3)> {
        let mut rng = Rng::new(seed);
        let mut dir = move || {
            let mu = 1e-6 + (1.0 - 1e-6) * rng.next_f64();
            UnitVec3::from_spherical(mu.acos(), std::f64::consts::TAU * rng.next_f64())
        };
        let mut out: Vec<_> = (0..n).map(|_| (dir(), dir())).collect();
        out.extend(crate::directions::edge_pairs());
        out
    }

    fn close(x: f64, y: f64) -> bool {
        (x - y).abs() <= 1e-6 * y.abs() + 1e-12
    }

    #[test]
    fn fast_path_matches_the_straightforward_evaluation() {
        let fabrics = shipped();
        assert!(fabrics.len() >= 9, "{}", fabrics.len());
        let mut compared = 0;
        let mut worst = 0f64;
        let mut rel = |x: f64, y: f64| {
            if y.abs() > 1e-9 {
                worst = worst.max((x / y - 1.0).abs());
            }
        };
        for (k, (name, fabric)) in fabrics.iter().enumerate() {
            for (facet, variant) in [
                (FacetModel::Huo, Variant::Refined),
                (FacetModel::Huo, Variant::Thesis),
                (FacetModel::Lewis, Variant::Refined),
            ] {
                let m = AnalyticModel::with_variant(fabric, facet, variant)
                    .expect("the variant takes the period");
                let n = if facet == FacetModel::Lewis {
                    100
                } else {
                    1000
                };
                for (wi, wo) in pairs(n, k as u64) {
                    let (got, want) = (m.intensity(wi, wo), intensity(&m, wi, wo));
                    for ch in 0..3 {
                        rel(got.i_d[ch], want.i_d[ch]);
                        rel(got.i_s[ch], want.i_s[ch]);
                        assert!(
                            close(got.i_d[ch], want.i_d[ch]) && close(got.i_s[ch], want.i_s[ch]),
                            "{name} {facet:?} {variant:?} {wi:?} {wo:?}: {got:?} vs {want:?}"
                        );
                    }
                    let (c, d) = (m.coverage(wo), coverage(&m, wo));
                    assert!(close(c, d), "{name} coverage {wo:?}: {c} vs {d}");
                    compared += 1;
                }
            }
        }
        assert!(compared > 15_000, "{compared}");
        println!("{compared} pairs, largest relative difference {worst:e} (values over 1e-9)");
    }
}
