//! `cargo xtask ir-accuracy`: the accuracy of the secondary reflection's solutions against a
//! converged analytic rule, on the parallel-cylinder surface (thesis sec. 5.4 facets, several
//! exponents) and the twill, into the table of `docs/science/interreflection.md` (between its
//! `ir-accuracy` markers). Times are in the criterion benchmark
//! (`cargo bench -p clothbake-core --bench eval -- secondary`), which runs the same settings.

use clothbake_core::directions::secondary_direction_set;
use clothbake_core::interreflection::{Orders, Ranges, Sampling};
use clothbake_core::{
    AnalyticModel, Fabric, FacetModel, Kernel, SecondaryMethod, SecondaryOptions,
};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// The converged rule the others are measured against (24-point rules, adaptive along C1).
const REFERENCE: Orders = Orders {
    theta: 24,
    tol: 1e-7,
    beta: 24,
    axial: 24,
};

/// A two-level sampling setting and its label: first-level samples, angular and axial step,
/// axial half-length, exact (Siegel & Howell) or eq. 5.16 solid angles.
fn sampling(first: usize, step: f64, l0: f64, exact: bool) -> (String, SecondaryMethod) {
    let label = format!(
        "sampling {first}, {step}, l0 {l0}{}",
        if exact { "" } else { ", eq. 5.16" }
    );
    let method = SecondaryMethod::Sampling(Sampling {
        first_level: first,
        d_alpha: step,
        d_l: step,
        l0,
        exact_solid_angle: exact,
    });
    (label, method)
}

/// The methods of the table: name and method.
fn methods() -> Vec<(String, SecondaryMethod)> {
    let analytic = |o: Orders| SecondaryMethod::Analytic {
        ranges: Ranges::Full,
        orders: o,
    };
    let fast = clothbake_core::interreflection::ORDERS_FAST;
    let (thesis, thesis_method) = sampling(32, 0.2, 1.5, true);
    let mut rows = vec![
        (
            "analytic, default orders".into(),
            analytic(Orders::default()),
        ),
        ("analytic, fast orders".into(), analytic(fast)),
        (format!("{thesis} (thesis)"), thesis_method),
    ];
    rows.extend(
        [
            (32, 0.2, true),
            (32, 0.15, true),
            (24, 0.17, true),
            (28, 0.15, false),
            (64, 0.1, true),
        ]
        .map(|(first, step, exact)| sampling(first, step, 3.0, exact)),
    );
    rows
}

/// Mean and worst relative error of `got` against `reference` (pairs whose reference I_2 is
/// above 1e-9), and the worst error relative to I_1.
fn errors(got: &[(f64, f64)], reference: &[(f64, f64)]) -> (f64, f64, f64) {
    let (mut sum, mut count, mut worst, mut worst_i1) = (0.0, 0, 0.0f64, 0.0f64);
    for ((g, _), (r, i1)) in got.iter().zip(reference) {
        if *r > 1e-9 {
            let e = (g - r).abs() / r;
            sum += e;
            count += 1;
            worst = worst.max(e);
            worst_i1 = worst_i1.max((g - r).abs() / i1.max(1e-12));
        }
    }
    (sum / count.max(1) as f64, worst, worst_i1)
}

/// `(I_2, I_1)` (channel 0) of `method` over the direction set.
fn eval(m: &AnalyticModel, method: SecondaryMethod) -> Vec<(f64, f64)> {
    let opts = SecondaryOptions {
        method,
        kernel: Kernel::Radiometric,
    };
    secondary_direction_set()
        .par_iter()
        .map(|&(wi, wo)| {
            let r = m.intensity_with(wi, wo, Some(&opts));
            (r.secondary.expect("asked for").total()[0], r.direct()[0])
        })
        .collect()
}

fn reference(m: &AnalyticModel) -> Vec<(f64, f64)> {
    eval(
        m,
        SecondaryMethod::Analytic {
            ranges: Ranges::Full,
            orders: REFERENCE,
        },
    )
}

/// `cargo xtask ir-accuracy --scan`: the mean and worst error of the two-level sampling over a
/// grid of settings (first-level samples, step, both solid angles; l0 3) and of the analytic
/// solution over a grid of orders, on the surface of the criterion comparison (parallel, n 10)
/// and on the twill. A setting's cost grows with its patches, about first-level samples / step^2:
/// the sampling settings of `secondary_vs_sampling` are the cheapest at or under 2% mean error
/// here. Prints only.
pub fn scan(root: &Path) {
    let surfaces = [
        ("parallel, n 10", crate::ch5::pf(10.0, 0.7)),
        (
            "twill",
            Fabric::from_path(&root.join("tables/twill.json")).expect("the shipped twill"),
        ),
    ];
    for (name, fabric) in surfaces {
        let m = AnalyticModel::new(&fabric, FacetModel::Huo);
        let reference = reference(&m);
        println!("\n{name}\n\n| method | first-level samples / step^2 / 1000 | mean error | worst error |");
        println!("|---|---|---|---|");
        let row = |label: String, cost: String, method| {
            let (mean, worst, _) = errors(&eval(&m, method), &reference);
            println!(
                "| {label} | {cost} | {:.2}% | {:.2}% |",
                100.0 * mean,
                100.0 * worst
            );
        };
        for exact in [true, false] {
            for first in [8, 12, 16, 20, 24, 28, 32, 40, 48] {
                for step in [0.12, 0.15, 0.17, 0.2, 0.25, 0.3] {
                    let (label, method) = sampling(first, step, 3.0, exact);
                    let cost = format!("{:.2}", first as f64 / (step * step) / 1000.0);
                    row(label, cost, method);
                }
            }
        }
        for theta in [4, 5, 6, 7, 8, 9, 11, 13] {
            for beta in [2, 3, 4, 5, 6] {
                for axial in [1, 2, 3, 4] {
                    let o = Orders {
                        theta,
                        tol: 0.0,
                        beta,
                        axial,
                    };
                    let method = SecondaryMethod::Analytic {
                        ranges: Ranges::Full,
                        orders: o,
                    };
                    row(
                        format!("analytic {theta}, {beta}, {axial}"),
                        "".into(),
                        method,
                    );
                }
            }
        }
    }
}

pub fn run(root: &Path) {
    let mut surfaces: Vec<(String, Fabric)> = [1.0, 10.0, 50.0]
        .iter()
        .map(|&n| (format!("parallel, n {n}"), crate::ch5::pf(n, 0.7)))
        .collect();
    surfaces.push((
        "twill (tables/twill.json)".into(),
        Fabric::from_path(&root.join("tables/twill.json")).expect("the shipped twill"),
    ));
    let mut table = String::new();
    writeln!(
        table,
        "| surface | method | mean error of I_2 | worst error of I_2 | worst error / I_1 |"
    )
    .unwrap();
    writeln!(table, "|---|---|---|---|---|").unwrap();
    for (name, fabric) in &surfaces {
        let m = AnalyticModel::new(fabric, FacetModel::Huo);
        let reference = reference(&m);
        for (label, method) in methods() {
            let (mean, worst, worst_i1) = errors(&eval(&m, method), &reference);
            let pct = |x: f64| format!("{:.2}%", 100.0 * x);
            writeln!(
                table,
                "| {name} | {label} | {} | {} | {} |",
                pct(mean),
                pct(worst),
                pct(worst_i1)
            )
            .unwrap();
        }
    }
    print!("{table}");
    let path = root.join("docs/science/interreflection.md");
    let doc = std::fs::read_to_string(&path).expect("docs/science/interreflection.md");
    let (begin, end) = ("<!-- ir-accuracy:begin -->", "<!-- ir-accuracy:end -->");
    match (doc.find(begin), doc.find(end)) {
        (Some(a), Some(b)) if a < b => {
            let new = format!("{}{begin}\n{table}{}", &doc[..a], &doc[b..]);
            std::fs::write(&path, new).expect("write docs/science/interreflection.md");
            println!("wrote the table into {}", path.display());
        }
        _ => eprintln!(
            "docs/science/interreflection.md has no ir-accuracy markers; table not written"
        ),
    }
}
