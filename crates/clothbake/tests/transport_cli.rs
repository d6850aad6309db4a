//! `--bounces N|all` on the command line (docs/science/transport.md): what eval reports, its
//! determinism, its agreement with the thesis's analytic second bounce where that is the whole
//! of I_2, and the refusals.

use serde_json::Value;
use std::process::{Command, Output};

mod common;

fn clothbake(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_clothbake"))
        .args(args)
        .output()
        .expect("run the clothbake binary")
}

fn json(args: &[&str]) -> Value {
    let out = clothbake(args);
    serde_json::from_str(&common::succeeds(&out)).expect("one JSON object")
}

fn rgb(v: &Value) -> [f64; 3] {
    std::array::from_fn(|k| v[k].as_f64().expect("a number"))
}

fn eval_args<'a>(weave: &'a str, rest: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec!["eval", "--weave", weave, "--json"];
    a.extend_from_slice(rest);
    a
}

#[test]
fn eval_bounces_all_reports_every_order_and_the_split_of_i2() {
    let twill = common::fabric("twill");
    let dirs = ["--wi", "30,0", "--wo", "45,180"];
    let direct = json(&eval_args(&twill, &dirs));
    let mut rest = dirs.to_vec();
    rest.extend_from_slice(&["--bounces", "all", "--samples", "20000"]);
    let first = common::succeeds(&clothbake(&eval_args(&twill, &rest)));
    let all: Value = serde_json::from_str(&first).expect("one JSON object");
    // The direct term is the analytic model's, exactly.
    assert_eq!(all["orders"][0], direct["I"]);
    assert_eq!(all["I_d"], direct["I_d"]);
    let orders: Vec<[f64; 3]> = all["orders"].as_array().unwrap().iter().map(rgb).collect();
    assert!(orders.len() >= 3, "{all}");
    let (i, multiple) = (rgb(&all["I"]), rgb(&all["I_multiple"]));
    let (par, perp, i2) = (
        rgb(&all["I_2_parallel"]),
        rgb(&all["I_2_perpendicular"]),
        rgb(&all["I_2"]),
    );
    for c in 0..3 {
        let sum: f64 = orders[1..].iter().map(|o| o[c]).sum();
        assert!((sum - multiple[c]).abs() <= 1e-9 * sum, "{all}");
        assert!((orders[0][c] + multiple[c] - i[c]).abs() <= 1e-12, "{all}");
        assert!((par[c] + perp[c] - i2[c]).abs() <= 1e-9 * i2[c], "{all}");
        assert!(perp[c] > 0.0 && par[c] > perp[c], "{all}");
    }
    // The same command gives the same bits (the seed comes from the directions).
    let again = clothbake(&eval_args(&twill, &rest));
    assert_eq!(common::succeeds(&again), first);
    // --bounces 3 stops at the third order.
    let mut three = dirs.to_vec();
    three.extend_from_slice(&["--bounces", "3", "--samples", "20000"]);
    let v = json(&eval_args(&twill, &three));
    assert_eq!(v["orders"].as_array().unwrap().len(), 3, "{v}");
}

#[test]
fn path_traced_i2_on_the_parallel_surface_matches_the_analytic_second_bounce() {
    // The parallel surface has only neighbouring parallel pairs and no visible weft: its I_2 is
    // the thesis's (radiometric kernel), which the analytic solution computes independently.
    let parallel = common::fabric("parallel");
    for (wi, wo) in [("30,180", "40,0"), ("50,20", "35,250")] {
        let dirs = ["--wi", wi, "--wo", wo];
        let mut two = dirs.to_vec();
        two.extend_from_slice(&["--bounces", "2"]);
        let analytic = rgb(&json(&eval_args(&parallel, &two))["I_2"]);
        let mut all = dirs.to_vec();
        all.extend_from_slice(&["--bounces", "all", "--samples", "400000"]);
        let v = json(&eval_args(&parallel, &all));
        let (traced, se) = (rgb(&v["I_2"]), rgb(&v["orders_std_err"][1]));
        assert_eq!(rgb(&v["I_2_perpendicular"]), [0.0; 3], "{v}");
        let tol = 4.0 * se[0] + 0.01 * analytic[0];
        assert!(
            (traced[0] - analytic[0]).abs() <= tol,
            "{wi} -> {wo}: analytic {} vs path-traced {} +- {}",
            analytic[0],
            traced[0],
            se[0]
        );
    }
}

#[test]
fn full_transport_refusals_name_the_flag_and_the_fix() {
    let twill = common::fabric("twill");
    let dirs = ["--wi", "30,0", "--wo", "45,180"];
    for (extra, needles) in [
        (
            &["--bounces", "all", "--kernel", "thesis"][..],
            &["--kernel", "--bounces 2"][..],
        ),
        (&["--bounces", "5", "--orders", "fast"], &["--orders"]),
        (&["--bounces", "all", "--at", "0.5,0.5"], &["--at"]),
        (&["--bounces", "65"], &["--bounces", "all"]),
    ] {
        let mut a = vec!["eval", "--weave", twill.as_str()];
        a.extend_from_slice(&dirs);
        a.extend_from_slice(extra);
        common::fails_with(&clothbake(&a), 2, needles);
    }
    let d = common::fresh_dir("transport", "refusals");
    let out = common::run_in(
        &d,
        &[
            "render",
            "--weave",
            twill.as_str(),
            "--bounces",
            "all",
            "--component",
            "direct",
            "-o",
            "x.png",
        ],
    );
    common::fails_with(&out, 2, &["--component direct", "--bounces all"]);
    let out = common::run_in(
        &d,
        &[
            "bake",
            "--weave",
            twill.as_str(),
            "--bounces",
            "all",
            "--method",
            "raytrace",
            "-o",
            "x.bin",
        ],
    );
    common::fails_with(&out, 2, &["--bounces"]);
}
