//! Fitting a [`Params`] to a reflectance, and the residual that says how far it is.
//!
//! The error is the L2 distance of f_r cos(theta_i) over pairs of directions, each direction
//! over the hemisphere with the solid-angle measure, summed over RGB:
//! E = sum over RGB of the double integral of (f_fit - f) ^ 2 cos^2(theta_i) dw_i dw_o. The
//! quadrature is the midpoint rule in (cos theta, phi) on both directions ([`Directions`]),
//! so every node carries the same solid angle. The base colour enters linearly and is solved
//! in closed form for each trial of the other parameters (roughness, anisotropy, sheen and its
//! roughness), which Nelder-Mead minimises from two starts, for the rough direction along the
//! weft and along the warp; the better fit wins.
//!
//! The residual reported ([`Residual`]) is the relative L2 error of f_r cos(theta_i),
//! sqrt(E / the same integral of f ^ 2 cos^2(theta_i)), and the relative error of the
//! directional albedo rho(w_o) = integral of f_r cos(theta_i) dw_i (luminance), its mean and
//! its maximum over the view directions, on a finer set of directions than the fit's.

use super::microfacet::Albedos;
use super::{Convention, Params, Rgb, Terms};
use crate::luminance;
use clothbake_core::{Bsdf, Footprint, UnitVec3};
use std::f64::consts::PI;

/// A set of directions over the hemisphere: `n_mu` x `n_phi` midpoint nodes in
/// (cos theta, phi), each standing for the solid angle 2 pi / (n_mu n_phi).
#[derive(Clone, Debug)]
pub struct Directions {
    dirs: Vec<UnitVec3>,
}

impl Directions {
    /// The `n_mu` x `n_phi` nodes.
    pub fn new(n_mu: usize, n_phi: usize) -> Directions {
        let mut dirs = Vec::with_capacity(n_mu * n_phi);
        for i in 0..n_mu {
            let mu = (i as f64 + 0.5) / n_mu as f64;
            for j in 0..n_phi {
                let phi = 2.0 * PI * (j as f64 + 0.5) / n_phi as f64;
                dirs.push(UnitVec3::from_spherical(mu.acos(), phi));
            }
        }
        Directions { dirs }
    }

    /// The nodes used for fitting (6 x 12).
    pub fn fitting() -> Directions {
        Directions::new(6, 12)
    }

    /// The nodes used for the residuals reported (10 x 20).
    pub fn reporting() -> Directions {
        Directions::new(10, 20)
    }

    /// Solid angle per node.
    pub fn weight(&self) -> f64 {
        2.0 * PI / self.dirs.len() as f64
    }

    /// The nodes.
    pub fn dirs(&self) -> &[UnitVec3] {
        &self.dirs
    }
}

/// A reflectance sampled on all pairs of a [`Directions`] set: `f[o * n + i]` for view `o`
/// and light `i`.
#[derive(Clone, Debug)]
pub struct Samples {
    /// The directions (the same set for light and view).
    pub dirs: Directions,
    /// f_r, RGB, view-major.
    pub f: Vec<Rgb>,
}

impl Samples {
    /// The averaged reflectance of `b` on every pair of `dirs` (its batch path).
    pub fn of(b: &dyn Bsdf, dirs: Directions) -> Samples {
        let n = dirs.dirs.len();
        let mut pairs = Vec::with_capacity(n * n);
        for &o in &dirs.dirs {
            for &i in &dirs.dirs {
                pairs.push((i, o));
            }
        }
        let mut f = vec![[0.0; 3]; pairs.len()];
        b.f_batch(&pairs, &mut f);
        Samples { dirs, f }
    }

    /// The reflectance of `b` at one point of the period, `at`, weighted by the share of the
    /// point's projected area that is yarn there ([`Bsdf::local`]): f_r c on every pair, and
    /// c for each view direction.
    pub fn local_at(b: &dyn Bsdf, at: Footprint, dirs: Directions) -> (Samples, Vec<f64>) {
        let n = dirs.dirs.len();
        let mut f = Vec::with_capacity(n * n);
        let mut cover = Vec::with_capacity(n);
        for &o in &dirs.dirs {
            let c = b.coverage_at(at, o);
            cover.push(c);
            for &i in &dirs.dirs {
                f.push(b.f_at(at, i, o).map(|x| x * c));
            }
        }
        (Samples { dirs, f }, cover)
    }

    /// Every value of view direction `o` divided by `d[o]` (where positive).
    pub fn divide_by_view(&mut self, d: &[f64]) {
        let n = self.dirs.dirs.len();
        for (k, v) in self.f.iter_mut().enumerate() {
            let q = d[k / n];
            if q > 0.0 {
                *v = v.map(|x| x / q);
            }
        }
    }

    /// A fitted material's values on the same pairs.
    pub fn of_params(conv: Convention, p: &Params, t: &Albedos, dirs: Directions) -> Samples {
        let mut f = Vec::with_capacity(dirs.dirs.len().pow(2));
        for &o in &dirs.dirs {
            for &i in &dirs.dirs {
                f.push(conv.f(p, t, i.get(), o.get()));
            }
        }
        Samples { dirs, f }
    }

    /// The mean of several sample sets on the same directions.
    pub fn mean(sets: &[Samples]) -> Samples {
        let mut f = vec![[0.0; 3]; sets[0].f.len()];
        for s in sets {
            for (a, b) in f.iter_mut().zip(&s.f) {
                for c in 0..3 {
                    a[c] += b[c] / sets.len() as f64;
                }
            }
        }
        Samples {
            dirs: sets[0].dirs.clone(),
            f,
        }
    }

    fn cos_i(&self, k: usize) -> f64 {
        let n = self.dirs.dirs.len();
        self.dirs.dirs[k % n].cos_theta()
    }
}

/// How far a fitted material is from the reflectance it was fitted to (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Residual {
    /// Relative L2 error of f_r cos(theta_i), RGB.
    pub l2: f64,
    /// Mean over view directions of the relative error of the directional albedo.
    pub albedo_mean: f64,
    /// Its maximum.
    pub albedo_max: f64,
}

/// The residual of `fit` against `reference` (the same directions).
pub fn residual(fit: &Samples, reference: &Samples) -> Residual {
    let n = reference.dirs.dirs.len();
    let (mut num, mut den) = (0.0, 0.0);
    for (k, (a, b)) in fit.f.iter().zip(&reference.f).enumerate() {
        let c2 = reference.cos_i(k).powi(2);
        for ch in 0..3 {
            num += (a[ch] - b[ch]).powi(2) * c2;
            den += b[ch] * b[ch] * c2;
        }
    }
    let (mut sum, mut max) = (0.0f64, 0.0f64);
    for o in 0..n {
        let (mut ra, mut rb) = (0.0, 0.0);
        for i in 0..n {
            let c = reference.dirs.dirs[i].cos_theta();
            ra += luminance(fit.f[o * n + i]) * c;
            rb += luminance(reference.f[o * n + i]) * c;
        }
        let e = if rb > 0.0 { (ra - rb).abs() / rb } else { 0.0 };
        sum += e;
        max = max.max(e);
    }
    Residual {
        l2: if den > 0.0 { (num / den).sqrt() } else { 0.0 },
        albedo_mean: sum / n as f64,
        albedo_max: max,
    }
}

/// The shape parameters Nelder-Mead searches, mapped from unbounded coordinates (the fifth,
/// the diffuse roughness, only where the convention has one).
fn shape(x: &[f64], tangent_deg: f64) -> Params {
    let sig = |t: f64| 1.0 / (1.0 + (-t).exp());
    Params {
        base: [0.0; 3],
        roughness: 0.2 + 0.8 * sig(x[0]),
        anisotropy: 0.95 * sig(x[1]),
        tangent_deg,
        sheen: sig(x[2]),
        sheen_roughness: 0.1 + 0.9 * sig(x[3]),
        diffuse_roughness: x.get(4).map_or(0.0, |&d| sig(d)),
    }
}

/// Whether a convention has a diffuse roughness to fit.
fn has_diffuse_roughness(conv: Convention) -> bool {
    matches!(conv, Convention::OpenPbr | Convention::Cycles)
}

/// The best base colour for the shape `p` and its squared error. Each channel is
/// c a + h(c) m + k ([`Convention::terms`]); with the weighted moments of a, m and k - y the
/// error of a channel is a function of c alone, minimised on [0, 1] by golden section (in
/// closed form when m is zero).
fn solve_base(conv: Convention, p: &Params, t: &Albedos, r: &Samples) -> (Rgb, f64) {
    let dirs = r.dirs.dirs();
    let n = dirs.len();
    // Moments: aa, mm, am, then per channel ad, md, dd with d = k - y.
    let (mut aa, mut mm, mut am) = (0.0, 0.0, 0.0);
    let mut shape = Terms::default();
    let (mut ad, mut md, mut dd) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    for (o, wo) in dirs.iter().enumerate() {
        for (i, wi) in dirs.iter().enumerate() {
            let tm = conv.terms(p, t, wi.get(), wo.get());
            shape = tm;
            let y = r.f[o * n + i];
            let w = wi.cos_theta().powi(2);
            aa += w * tm.a * tm.a;
            mm += w * tm.m * tm.m;
            am += w * tm.a * tm.m;
            for c in 0..3 {
                let d = tm.k - y[c];
                ad[c] += w * tm.a * d;
                md[c] += w * tm.m * d;
                dd[c] += w * d * d;
            }
        }
    }
    let mut base = [0.0; 3];
    let mut err = 0.0;
    for c in 0..3 {
        let j = |b: f64| {
            let h = if mm > 0.0 { shape.h(b) } else { 0.0 };
            b * b * aa + h * h * mm + 2.0 * b * h * am + 2.0 * b * ad[c] + 2.0 * h * md[c] + dd[c]
        };
        let b = if mm == 0.0 {
            if aa > 0.0 {
                (-ad[c] / aa).clamp(0.0, 1.0)
            } else {
                0.0
            }
        } else {
            golden(j, 0.0, 1.0)
        };
        base[c] = b;
        err += j(b).max(0.0);
    }
    (base, err)
}

/// The minimum of a unimodal `f` on [lo, hi] by golden-section search (to 1e-7).
fn golden(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    while hi - lo > 1e-7 {
        if f1 < f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    0.5 * (lo + hi)
}

/// The parameters of `conv`'s material closest to the reflectance sampled in `r` (module
/// docs). Deterministic.
pub fn fit(conv: Convention, t: &Albedos, r: &Samples) -> Params {
    let mut best: Option<(f64, Params)> = None;
    for tangent in [0.0, 90.0] {
        for start in [[0.0, -1.0, -1.0, 0.0, -1.0], [1.0, 1.0, 0.5, 1.0, 0.0]] {
            let x: Vec<f64> = if has_diffuse_roughness(conv) {
                let cost = |x: &[f64; 5]| solve_base(conv, &shape(x, tangent), t, r).1;
                nelder_mead(cost, start, 0.8, 400).to_vec()
            } else {
                let cost = |x: &[f64; 4]| solve_base(conv, &shape(x, tangent), t, r).1;
                let s4 = [start[0], start[1], start[2], start[3]];
                nelder_mead(cost, s4, 0.8, 160).to_vec()
            };
            let p = shape(&x, tangent);
            let (base, err) = solve_base(conv, &p, t, r);
            if best.as_ref().is_none_or(|(e, _)| err < *e) {
                best = Some((err, Params { base, ..p }));
            }
        }
    }
    best.expect("four starts").1
}

/// Minimises `f` from `x0` with a simplex of side `step`, for at most `evals` evaluations
/// (Nelder & Mead 1965, standard coefficients).
fn nelder_mead<const N: usize>(
    f: impl Fn(&[f64; N]) -> f64,
    x0: [f64; N],
    step: f64,
    evals: usize,
) -> [f64; N] {
    let mut s: Vec<([f64; N], f64)> = Vec::with_capacity(N + 1);
    s.push((x0, f(&x0)));
    for k in 0..N {
        let mut x = x0;
        x[k] += step;
        s.push((x, f(&x)));
    }
    let mut used = N + 1;
    let lerp = |a: &[f64; N], b: &[f64; N], t: f64| {
        let mut r = *a;
        for k in 0..N {
            r[k] = a[k] + t * (b[k] - a[k]);
        }
        r
    };
    while used < evals {
        s.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (s[N].1 - s[0].1).abs() <= 1e-10 * s[0].1.abs().max(1e-300) {
            break;
        }
        let mut c = [0.0; N];
        for (x, _) in &s[..N] {
            for k in 0..N {
                c[k] += x[k] / N as f64;
            }
        }
        let worst = s[N];
        let xr = lerp(&c, &worst.0, -1.0);
        let fr = f(&xr);
        used += 1;
        if fr < s[0].1 {
            let xe = lerp(&c, &worst.0, -2.0);
            let fe = f(&xe);
            used += 1;
            s[N] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < s[N - 1].1 {
            s[N] = (xr, fr);
        } else {
            let xc = lerp(&c, &worst.0, 0.5);
            let fc = f(&xc);
            used += 1;
            if fc < worst.1 {
                s[N] = (xc, fc);
            } else {
                let best = s[0].0;
                for e in s.iter_mut().skip(1) {
                    e.0 = lerp(&best, &e.0, 0.5);
                    e.1 = f(&e.0);
                    used += 1;
                }
            }
        }
    }
    s.sort_by(|a, b| a.1.total_cmp(&b.1));
    s[0].0
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_core::FromFn;

    #[test]
    fn nelder_mead_finds_a_quadratic_minimum() {
        let x = nelder_mead(
            |x: &[f64; 2]| (x[0] - 1.0).powi(2) + 3.0 * (x[1] + 2.0).powi(2),
            [0.0, 0.0],
            0.5,
            400,
        );
        assert!(
            (x[0] - 1.0).abs() < 1e-4 && (x[1] + 2.0).abs() < 1e-4,
            "{x:?}"
        );
    }

    #[test]
    fn a_material_is_recovered_from_its_own_values() {
        // Fitting the OpenPBR material to itself finds parameters that reproduce it: the
        // residual is far under the cloth fits' (which are several percent).
        let t = Albedos::new(super::super::IOR);
        let truth = Params {
            base: [0.6, 0.25, 0.1],
            roughness: 0.55,
            anisotropy: 0.5,
            tangent_deg: 90.0,
            sheen: 0.5,
            sheen_roughness: 0.4,
            diffuse_roughness: 0.3,
        };
        let b =
            FromFn(|i: UnitVec3, o: UnitVec3| Convention::OpenPbr.f(&truth, &t, i.get(), o.get()));
        let r = Samples::of(&b, Directions::fitting());
        let p = fit(Convention::OpenPbr, &t, &r);
        let got = Samples::of_params(Convention::OpenPbr, &p, &t, Directions::reporting());
        let res = residual(&got, &Samples::of(&b, Directions::reporting()));
        assert!(res.l2 < 0.01, "{res:?} {p:?}");
        assert!(res.albedo_max < 0.01, "{res:?}");
        assert_eq!(p.tangent_deg, 90.0);
    }

    #[test]
    fn the_residual_of_a_scaled_reflectance_is_the_scale() {
        let b = FromFn(|i: UnitVec3, _o: UnitVec3| [i.cos_theta(); 3]);
        let c = FromFn(|i: UnitVec3, _o: UnitVec3| [1.1 * i.cos_theta(); 3]);
        let d = Directions::new(4, 8);
        let r = residual(&Samples::of(&c, d.clone()), &Samples::of(&b, d));
        assert!((r.l2 - 0.1).abs() < 1e-12, "{r:?}");
        assert!((r.albedo_mean - 0.1).abs() < 1e-12 && (r.albedo_max - 0.1).abs() < 1e-12);
    }
}
