//! Secondary reflection (thesis ch. 5) on the parallel-cylinder surface: the analytical
//! solution against the two-level ray-traced sampling and the path tracer, convergence, symmetry.

use clothbake_core::interreflection::{Orders, Ranges, Sampling};
use clothbake_core::{
    AnalyticModel, Fabric, FacetModel, Kernel, SecondaryMethod, SecondaryOptions, UnitVec3,
};
use clothbake_truth::pathtracer::PathOptions;
use clothbake_truth::RayTracer;

/// The thesis's surface (d = 2, r = 1, h = 0) with its sec. 5.4 facets (rho_d 0.4, rho_s 0.7).
fn pf(n: f64) -> Fabric {
    let json = format!(
        r#"{{"pattern": [[1]], "warp": {{"radius": 1, "spacing": 2,
            "material": {{"albedo": 0.4, "specular": 0.7, "exponent": {n}}}}},
            "weft": {{"radius": 1, "spacing": 2}}}}"#
    );
    Fabric::from_json_str(&json, "pf").unwrap()
}

fn pairs() -> Vec<(UnitVec3, UnitVec3)> {
    // (theta_i, phi_i, theta_o, phi_o) in degrees.
    [
        [30.0, 180.0, 40.0, 0.0],
        [15.0, 90.0, 45.0, 30.0],
        [60.0, 200.0, 20.0, 340.0],
        [45.0, 0.0, 45.0, 0.0],
        [5.0, 0.0, 5.0, 180.0],
        [70.0, 150.0, 50.0, 60.0],
    ]
    .iter()
    .map(|&[ti, pi, to, po]| {
        (
            UnitVec3::from_degrees(ti, pi),
            UnitVec3::from_degrees(to, po),
        )
    })
    .collect()
}

fn i2(
    m: &AnalyticModel,
    wi: UnitVec3,
    wo: UnitVec3,
    method: SecondaryMethod,
    kernel: Kernel,
) -> f64 {
    let opts = SecondaryOptions { method, kernel };
    m.intensity_with(wi, wo, Some(&opts))
        .secondary
        .unwrap()
        .total()[0]
}

/// The analytic solution at its default orders (`Orders::default()`).
fn analytic() -> SecondaryMethod {
    SecondaryMethod::Analytic {
        ranges: Ranges::Full,
        orders: Orders::default(),
    }
}

#[test]
fn analytic_within_5_percent_of_two_level_sampling() {
    // The sampling over a long axial range (the analytic one integrates all of y), with steps
    // fine enough for the exponent's lobes (the thesis's 0.2 suits n ~ 1).
    for (n, step) in [(1.0, 0.1), (10.0, 0.05), (40.0, 0.025)] {
        let sampling = SecondaryMethod::Sampling(Sampling {
            first_level: (3.2 / step) as usize,
            d_alpha: step,
            d_l: 2.0 * step,
            l0: 12.0,
            exact_solid_angle: true,
        });
        let m = AnalyticModel::new(&pf(n), FacetModel::Huo);
        for kernel in [Kernel::Thesis, Kernel::Radiometric] {
            // Pair 4 (light and eye 5 degrees off the normal) sees deep into the grooves, where a
            // point sees its touching neighbour under almost a hemisphere: the midpoint rule of
            // the sampling converges slowly there (it needs steps below 0.025); that pair is held
            // against the path tracer instead (`near_normal_directions_match_the_path_tracer`).
            for (k, (wi, wo)) in pairs().into_iter().enumerate() {
                if k == 4 {
                    continue;
                }
                let (a, b) = (
                    i2(&m, wi, wo, analytic(), kernel),
                    i2(&m, wi, wo, sampling, kernel),
                );
                assert!(b > 0.0);
                assert!(
                    (a - b).abs() < 0.05 * b,
                    "n {n} {kernel:?} {wi:?} {wo:?}: analytic {a} vs sampling {b}"
                );
            }
        }
    }
}

/// The path tracer's second order I_2 (red channel) with its standard error: 100 000 paths of
/// at most two bounces weighted by `kernel`.
fn path_i2(rt: &RayTracer, wi: UnitVec3, wo: UnitVec3, seed: u64, kernel: Kernel) -> (f64, f64) {
    let p = rt.render_paths(
        wi,
        wo,
        100_000,
        seed,
        PathOptions {
            max_bounces: 2,
            kernel,
            roulette_from: 9,
            first_order: 1,
        },
    );
    (p.orders[1][0], p.std_err[1][0])
}

#[test]
fn two_level_sampling_matches_the_path_tracer_second_bounce() {
    let f = pf(10.0);
    let m = AnalyticModel::new(&f, FacetModel::Huo);
    let rt = RayTracer::new(&f, FacetModel::Huo);
    let sampling = SecondaryMethod::Sampling(Sampling {
        first_level: 48,
        d_alpha: 0.05,
        d_l: 0.1,
        l0: 25.0,
        exact_solid_angle: true,
    });
    for kernel in [Kernel::Thesis, Kernel::Radiometric] {
        for (k, (wi, wo)) in pairs().into_iter().enumerate().take(4) {
            let a = i2(&m, wi, wo, sampling, kernel);
            let (b, e) = path_i2(&rt, wi, wo, 17 + k as u64, kernel);
            // Within the path tracer's noise (4 sigma) plus the sampling's own discretisation (1%).
            assert!(
                (a - b).abs() < 4.0 * e + 0.01 * a,
                "{kernel:?} {k}: sampling {a} vs path {b} ± {e}"
            );
        }
    }
}

#[test]
fn near_normal_directions_match_the_path_tracer() {
    let f = pf(1.0);
    let m = AnalyticModel::new(&f, FacetModel::Huo);
    let rt = RayTracer::new(&f, FacetModel::Huo);
    let (wi, wo) = pairs()[4];
    for kernel in [Kernel::Thesis, Kernel::Radiometric] {
        let a = i2(&m, wi, wo, analytic(), kernel);
        let (b, e) = path_i2(&rt, wi, wo, 29, kernel);
        assert!(
            (a - b).abs() < 4.0 * e + 0.01 * a,
            "{kernel:?}: analytic {a} vs path {b} ± {e}"
        );
    }
}

#[test]
fn sampling_converges_under_refinement() {
    let m = AnalyticModel::new(&pf(10.0), FacetModel::Huo);
    let (wi, wo) = pairs()[0];
    let reference = i2(
        &m,
        wi,
        wo,
        SecondaryMethod::Analytic {
            ranges: Ranges::Full,
            orders: Orders {
                theta: 24,
                tol: 0.0,
                beta: 24,
                axial: 24,
            },
        },
        Kernel::Radiometric,
    );
    let mut last = f64::INFINITY;
    for step in [0.4, 0.2, 0.1, 0.05] {
        let s = Sampling {
            first_level: (6.4 / step) as usize,
            d_alpha: step,
            d_l: step,
            l0: 25.0,
            exact_solid_angle: true,
        };
        let err = (i2(
            &m,
            wi,
            wo,
            SecondaryMethod::Sampling(s),
            Kernel::Radiometric,
        ) - reference)
            .abs()
            / reference;
        assert!(
            err < last,
            "step {step}: error {err} did not shrink from {last}"
        );
        last = err;
    }
    assert!(last < 0.005, "{last}");
}

#[test]
fn mirror_symmetric_surface_gives_mirror_symmetric_i2() {
    let m = AnalyticModel::new(&pf(10.0), FacetModel::Huo);
    for kernel in [Kernel::Thesis, Kernel::Radiometric] {
        for (wi, wo) in pairs() {
            let a = i2(&m, wi, wo, analytic(), kernel);
            for (b_wi, b_wo) in [
                (wi.mirror_x(), wo.mirror_x()),
                (wi.mirror_y(), wo.mirror_y()),
            ] {
                let b = i2(&m, b_wi, b_wo, analytic(), kernel);
                assert!(
                    (a - b).abs() <= 1e-9 * a.max(1e-12),
                    "{a} vs {b} for {:?} {:?} -> {:?} {:?}",
                    wi.to_spherical(),
                    wo.to_spherical(),
                    b_wi.to_spherical(),
                    b_wo.to_spherical()
                );
            }
        }
    }
}

#[test]
fn thesis_kernel_is_larger_by_pi_times_the_cosine() {
    // Pointwise the thesis kernel is pi (N_i . w) times the radiometric one, and N_i . w <= 1:
    // so I_2(thesis) <= pi I_2(radiometric), and typically well above I_2(radiometric).
    let m = AnalyticModel::new(&pf(10.0), FacetModel::Huo);
    for (wi, wo) in pairs() {
        let (t, r) = (
            i2(&m, wi, wo, analytic(), Kernel::Thesis),
            i2(&m, wi, wo, analytic(), Kernel::Radiometric),
        );
        assert!(
            t <= std::f64::consts::PI * r * 1.0001 && t > r,
            "{t} vs {r}"
        );
    }
}

#[test]
fn thesis_ranges_integrate_a_part_of_the_full_ranges() {
    // The C_max window around the double-specular peak is a subset of the full domain and the
    // integrand is non-negative: every component is smaller, I_ss keeps most of its value.
    let m = AnalyticModel::new(&pf(10.0), FacetModel::Huo);
    let thesis = SecondaryMethod::Analytic {
        ranges: Ranges::Thesis {
            c_max: 0.3,
            l0: 1.5,
        },
        orders: Orders::default(),
    };
    let opts = |method| SecondaryOptions {
        method,
        kernel: Kernel::Thesis,
    };
    let (wi, wo) = pairs()[0];
    let t = m
        .intensity_with(wi, wo, Some(&opts(thesis)))
        .secondary
        .unwrap();
    let f = m
        .intensity_with(wi, wo, Some(&opts(analytic())))
        .secondary
        .unwrap();
    for (a, b) in [(t.ss, f.ss), (t.sd, f.sd), (t.ds, f.ds), (t.dd, f.dd)] {
        assert!(a[0] >= 0.0 && a[0] <= b[0] * 1.001, "{a:?} vs {b:?}");
    }
    assert!(t.ss[0] > 0.3 * f.ss[0], "{} vs {}", t.ss[0], f.ss[0]);
}
