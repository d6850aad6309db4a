//! `cargo xtask ir-accuracy`: the accuracy of the secondary reflection's solutions against a
//! converged analytic rule, on the parallel-cylinder surface (thesis sec. 5.4 facets, several
//! exponents) and the twill, into the table of `docs/interreflection.md` (between its
//! `ir-accuracy` markers). Times are in the criterion benchmark
//! (`cargo bench -p clothbake-core --bench eval -- secondary`), which runs the same settings.

use clothbake_core::interreflection::{Orders, Ranges, Sampling};
use clothbake_core::validate::secondary_direction_set;
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

/// The methods of the table: name and method.
fn methods() -> Vec<(String, SecondaryMethod)> {
    let analytic = |o: Orders| SecondaryMethod::Analytic {
        ranges: Ranges::Full,
        orders: o,
    };
    let sampling = |first: usize, step: f64, l0: f64| {
        SecondaryMethod::Sampling(Sampling {
            first_level: first,
            d_alpha: step,
            d_l: step,
            l0,
            exact_solid_angle: true,
        })
    };
    let fast = clothbake_core::interreflection::ORDERS_FAST;
    vec![
        (
            "analytic, default orders".into(),
            analytic(Orders::default()),
        ),
        ("analytic, fast orders".into(), analytic(fast)),
        (
            "sampling 32, 0.2, l0 1.5 (thesis)".into(),
            sampling(32, 0.2, 1.5),
        ),
        ("sampling 32, 0.2, l0 3".into(), sampling(32, 0.2, 3.0)),
        ("sampling 32, 0.15, l0 3".into(), sampling(32, 0.15, 3.0)),
        ("sampling 64, 0.1, l0 3".into(), sampling(64, 0.1, 3.0)),
    ]
}

/// The parallel-cylinder surface with the sec. 5.4 facets (rho_d 0.4, rho_s 0.7, exponent n).
fn parallel(n: f64) -> Fabric {
    let json = format!(
        r#"{{"pattern": [[1]], "warp": {{"radius": 1, "spacing": 2,
            "material": {{"albedo": 0.4, "specular": 0.7, "exponent": {n}}}}},
            "weft": {{"radius": 1, "spacing": 2}}}}"#
    );
    Fabric::from_json_str(&json, "parallel").expect("a valid fabric")
}

pub fn run(root: &Path) {
    let dirs = secondary_direction_set();
    let mut surfaces: Vec<(String, Fabric)> = [1.0, 10.0, 50.0]
        .iter()
        .map(|&n| (format!("parallel, n {n}"), parallel(n)))
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
        let opts = |method| SecondaryOptions {
            method,
            kernel: Kernel::Radiometric,
        };
        let eval = |method: SecondaryMethod| -> Vec<(f64, f64)> {
            dirs.par_iter()
                .map(|&(wi, wo)| {
                    let r = m.eval_with(wi, wo, Some(&opts(method)));
                    (r.secondary.expect("asked for").total()[0], r.direct()[0])
                })
                .collect()
        };
        let reference = eval(SecondaryMethod::Analytic {
            ranges: Ranges::Full,
            orders: REFERENCE,
        });
        for (label, method) in methods() {
            let got = eval(method);
            let (mut sum, mut count, mut worst, mut worst_i1) = (0.0, 0, 0.0f64, 0.0f64);
            for ((g, _), (r, i1)) in got.iter().zip(&reference) {
                if *r > 1e-9 {
                    let e = (g - r).abs() / r;
                    sum += e;
                    count += 1;
                    worst = worst.max(e);
                    worst_i1 = worst_i1.max((g - r).abs() / i1.max(1e-12));
                }
            }
            let pct = |x: f64| format!("{:.2}%", 100.0 * x);
            writeln!(
                table,
                "| {name} | {label} | {} | {} | {} |",
                pct(sum / count.max(1) as f64),
                pct(worst),
                pct(worst_i1)
            )
            .unwrap();
        }
    }
    print!("{table}");
    let path = root.join("docs/interreflection.md");
    let doc = std::fs::read_to_string(&path).expect("docs/interreflection.md");
    let (begin, end) = ("<!-- ir-accuracy:begin -->", "<!-- ir-accuracy:end -->");
    match (doc.find(begin), doc.find(end)) {
        (Some(a), Some(b)) if a < b => {
            let new = format!("{}{begin}\n{table}{}", &doc[..a], &doc[b..]);
            std::fs::write(&path, new).expect("write docs/interreflection.md");
            println!("wrote the table into {}", path.display());
        }
        _ => eprintln!("docs/interreflection.md has no ir-accuracy markers; table not written"),
    }
}
