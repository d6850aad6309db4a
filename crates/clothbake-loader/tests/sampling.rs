//! Importance sampling: the pdf integrates to 1, samples follow it (chi-square), the weight is
//! f cos / pdf, and the estimator of the directional albedo is unbiased.

use clothbake_loader::{Brdf, Grid, Metadata, Options, Table};
use std::f64::consts::{FRAC_PI_2, TAU};

const GRID: Grid = Grid::new(8, 16, 6, 12);

/// A glossy lobe around the mirror direction plus a diffuse part, zero beyond 70 degrees
/// of incidence (an empty region the sampler must still cover, as interpolation leaks into it).
fn lobe(wi: [f64; 3], wo: [f64; 3], k: usize) -> f64 {
    if wi[2] < 70f64.to_radians().cos() {
        return 0.0;
    }
    let r = [-wo[0], -wo[1], wo[2]];
    let c = (wi[0] * r[0] + wi[1] * r[1] + wi[2] * r[2]).max(0.0);
    0.05 * (k + 1) as f64 + 3.0 * c.powi(12)
}

fn dir(theta: f64, phi: f64) -> [f64; 3] {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

fn f32s(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

fn brdf() -> Brdf {
    let g = GRID;
    let mut values = vec![0f32; g.len() * 3];
    for ti in 0..g.n_theta_i {
        for pi in 0..g.n_phi_i {
            for to in 0..g.n_theta_o {
                for po in 0..g.n_phi_o {
                    let wi = dir(g.theta_i_deg(ti).to_radians(), g.phi_i_deg(pi).to_radians());
                    let wo = dir(g.theta_o_deg(to).to_radians(), g.phi_o_deg(po).to_radians());
                    for k in 0..3 {
                        values[3 * g.index(ti, pi, to, po) + k] = lobe(wi, wo, k) as f32;
                    }
                }
            }
        }
    }
    let t = Table::new(Metadata::new("test", g, "{}", "{}", "none"), values).unwrap();
    Brdf::from_table(t, Options::default()).unwrap()
}

mod common;
use common::Rng;

/// Outgoing directions to test: near the pole, oblique, grazing, on a cell edge.
fn outgoing() -> Vec<[f32; 3]> {
    [(3.0, 10.0), (40.0, 100.0), (75.0, 250.0), (45.0, 30.0)]
        .iter()
        .map(|&(t, p): &(f64, f64)| f32s(dir(t.to_radians(), p.to_radians())))
        .collect()
}

/// Midpoint rule over the hemisphere in (cos theta, phi), where d omega = d mu d phi: the
/// grid's lines do not coincide with the table's cell edges.
fn hemisphere_integral(n_mu: usize, n_phi: usize, f: impl Fn([f32; 3]) -> [f64; 3]) -> [f64; 3] {
    let (d_mu, d_phi) = (1.0 / n_mu as f64, TAU / n_phi as f64);
    let mut sum = [0.0; 3];
    for i in 0..n_mu {
        let mu = (i as f64 + 0.5) * d_mu;
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) * d_phi;
            let v = f(f32s(dir(mu.acos(), phi)));
            for k in 0..3 {
                sum[k] += v[k];
            }
        }
    }
    sum.map(|s| s * d_mu * d_phi)
}

#[test]
fn the_pdf_integrates_to_one_over_the_hemisphere() {
    let b = brdf();
    for wo in outgoing() {
        let total = hemisphere_integral(800, 1600, |wi| [f64::from(b.pdf(wi, wo)); 3])[0];
        assert!((total - 1.0).abs() < 2e-3, "wo {wo:?}: integral {total}");
    }
}

/// Probability of the bin [mu_a, mu_b] x [phi_a, phi_b] under a density that is constant
/// on the table's cells: the sum over cells of (pdf at the cell's centre) x (the solid angle
/// of the overlap, exact in (mu, phi)).
fn bin_probability(b: &Brdf, wo: [f32; 3], mu: (f64, f64), phi: (f64, f64)) -> f64 {
    let (nt, np) = (GRID.n_theta_i, GRID.n_phi_i);
    let mut p = 0.0;
    for ti in 0..nt {
        let (t_lo, t_hi) = (
            ti as f64 * FRAC_PI_2 / nt as f64,
            (ti + 1) as f64 * FRAC_PI_2 / nt as f64,
        );
        let (m_lo, m_hi) = (t_hi.cos(), t_lo.cos());
        let dm = (mu.1.min(m_hi) - mu.0.max(m_lo)).max(0.0);
        if dm == 0.0 {
            continue;
        }
        for pi in 0..np {
            let (p_lo, p_hi) = (
                pi as f64 * TAU / np as f64,
                (pi + 1) as f64 * TAU / np as f64,
            );
            let dp = (phi.1.min(p_hi) - phi.0.max(p_lo)).max(0.0);
            if dp > 0.0 {
                let centre = f32s(dir(0.5 * (t_lo + t_hi), 0.5 * (p_lo + p_hi)));
                p += f64::from(b.pdf(centre, wo)) * dm * dp;
            }
        }
    }
    p
}

/// The chi-square quantile for `k` degrees of freedom at the standard normal quantile `z`
/// (Wilson-Hilferty).
fn chi2_quantile(k: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

#[test]
fn samples_follow_the_pdf_chi_square() {
    let b = brdf();
    let (n_mu, n_phi, n) = (7usize, 13usize, 200_000usize);
    let bins = n_mu * n_phi;
    let mut rng = Rng(42);
    for wo in outgoing() {
        let mut counts = vec![0f64; bins];
        for _ in 0..n {
            let s = b.sample(wo, rng.next() as f32, rng.next() as f32);
            assert!(s.pdf > 0.0);
            let mu = f64::from(s.wi[2]).clamp(0.0, 1.0 - 1e-12);
            let phi = f64::from(s.wi[1]).atan2(f64::from(s.wi[0])).rem_euclid(TAU);
            let i = ((mu * n_mu as f64) as usize).min(n_mu - 1);
            let j = ((phi / TAU * n_phi as f64) as usize).min(n_phi - 1);
            counts[i * n_phi + j] += 1.0;
        }
        let mut chi2 = 0.0;
        let mut chi2_uniform = 0.0;
        let mut total_p = 0.0;
        for i in 0..n_mu {
            for j in 0..n_phi {
                let mu = (i as f64 / n_mu as f64, (i + 1) as f64 / n_mu as f64);
                let phi = (
                    j as f64 * TAU / n_phi as f64,
                    (j + 1) as f64 * TAU / n_phi as f64,
                );
                let p = bin_probability(&b, wo, mu, phi);
                total_p += p;
                let expected = p * n as f64;
                let c = counts[i * n_phi + j];
                chi2 += (c - expected).powi(2) / expected;
                let uniform = n as f64 / bins as f64; // uniform in solid angle
                chi2_uniform += (c - uniform).powi(2) / uniform;
            }
        }
        assert!(
            (total_p - 1.0).abs() < 1e-5,
            "bin probabilities sum to {total_p}"
        );
        let limit = chi2_quantile((bins - 1) as f64, 4.75); // p ~ 1e-6
        assert!(chi2 < limit, "wo {wo:?}: chi2 {chi2:.1} >= {limit:.1}");
        // The test has power: the same samples are far from a uniform density.
        assert!(
            chi2_uniform > 10.0 * limit,
            "uniform chi2 {chi2_uniform:.1}"
        );
    }
}

#[test]
fn the_weight_is_f_cos_over_pdf_and_the_pdf_is_pdf_of_wi() {
    let b = brdf();
    let mut rng = Rng(5);
    for wo in outgoing() {
        for _ in 0..2000 {
            let s = b.sample(wo, rng.next() as f32, rng.next() as f32);
            assert_eq!(s.pdf, b.pdf(s.wi, wo));
            let f = b.eval(s.wi, wo);
            for (w, f) in s.weight.iter().zip(f) {
                let want = f * s.wi[2] / s.pdf;
                assert!((w - want).abs() <= 1e-6 * want.abs().max(1e-6));
            }
            let len = s.wi.iter().map(|x| x * x).sum::<f32>().sqrt();
            assert!((len - 1.0).abs() < 1e-5 && s.wi[2] >= 0.0);
        }
    }
}

#[test]
fn the_albedo_estimate_is_unbiased() {
    // Directional albedo: the integral of f cos theta_i d omega_i, by quadrature of the
    // lookup itself and by importance sampling.
    let b = brdf();
    let mut rng = Rng(9);
    for wo in outgoing() {
        let quad =
            hemisphere_integral(600, 1200, |wi| b.eval(wi, wo).map(|f| f64::from(f * wi[2])));
        let n = 100_000;
        let (mut sum, mut sq) = ([0f64; 3], [0f64; 3]);
        for _ in 0..n {
            let s = b.sample(wo, rng.next() as f32, rng.next() as f32);
            for k in 0..3 {
                sum[k] += f64::from(s.weight[k]);
                sq[k] += f64::from(s.weight[k]).powi(2);
            }
        }
        for k in 0..3 {
            let mean = sum[k] / n as f64;
            let se = ((sq[k] / n as f64 - mean * mean) / n as f64).sqrt();
            let tol = 5.0 * se + 2e-3 * quad[k];
            assert!(
                (mean - quad[k]).abs() < tol,
                "wo {wo:?} channel {k}: sampled {mean} +- {se}, quadrature {}",
                quad[k]
            );
        }
    }
}

#[test]
fn no_sample_below_the_horizon_or_without_cdfs() {
    let b = brdf();
    let s = b.sample([0.0, 0.6, -0.8], 0.3, 0.3);
    assert_eq!((s.pdf, s.weight), (0.0, [0.0; 3]));
    assert_eq!(b.pdf([0.0, 0.6, -0.8], [0.0, 0.0, 1.0]), 0.0);
    let t = Table::new(
        Metadata::new("t", GRID, "{}", "{}", "none"),
        vec![0.5; GRID.len() * 3],
    )
    .unwrap();
    let off = Brdf::from_table(
        t,
        Options {
            sampling: false,
            ..Options::default()
        },
    )
    .unwrap();
    assert_eq!(off.sample([0.0, 0.0, 1.0], 0.5, 0.5).pdf, 0.0);
    // u = 1 and NaN are clamped, not a panic.
    let s = b.sample([0.0, 0.0, 1.0], 1.0, f32::NAN);
    assert!(s.pdf > 0.0 && s.weight.iter().all(|w| w.is_finite()));
}
