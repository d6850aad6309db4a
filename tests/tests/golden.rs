//! Golden tables: every shipped fabric, baked afresh at the golden grid, equals its table in
//! `tables/golden/` to a relative 1e-9, so any change of the model shows up here as a table
//! difference. After an intended change, regenerate them with `cargo xtask golden` and review
//! the difference (`clothbake diff`) before committing (see docs/baking.md).

use clothbake_bake::compare::compare;
use clothbake_bake::golden::{bake_golden, golden_path, shipped_fabrics, GRID, TOLERANCE};
use clothbake_core::Fabric;
use clothbake_loader::read_table;
use std::path::{Path, PathBuf};

fn tables_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables")
}

#[test]
fn every_shipped_fabric_has_a_golden_table_and_no_other() {
    let fabrics: Vec<String> = shipped_fabrics(&tables_dir())
        .unwrap()
        .into_iter()
        .map(|(n, _)| n)
        .collect();
    let mut golden: Vec<String> = std::fs::read_dir(tables_dir().join("golden"))
        .expect("tables/golden/ exists (cargo xtask golden)")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "bin"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    golden.sort();
    assert_eq!(
        fabrics, golden,
        "tables/*.json and tables/golden/*.bin differ: run `cargo xtask golden`"
    );
}

#[test]
fn fresh_bakes_equal_the_golden_tables() {
    let mut failures = Vec::new();
    for (name, path) in shipped_fabrics(&tables_dir()).unwrap() {
        let gpath = golden_path(&tables_dir(), &name);
        let golden = match read_table(&gpath) {
            Ok(t) => t,
            Err(e) => {
                failures.push(format!("{name}: {e}; run `cargo xtask golden`"));
                continue;
            }
        };
        let f = Fabric::from_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let fresh = bake_golden(&f).unwrap();
        assert_eq!(fresh.meta.grid, GRID);
        if golden.meta.fabric_json != fresh.meta.fabric_json {
            failures.push(format!(
                "{name}: the fabric differs from the one the golden table was baked from \
                 (golden {}, now {})",
                golden.meta.fabric_json, fresh.meta.fabric_json
            ));
        }
        if golden.meta.options_json != fresh.meta.options_json {
            failures.push(format!(
                "{name}: the bake options differ (golden {}, now {})",
                golden.meta.options_json, fresh.meta.options_json
            ));
        }
        match compare(&golden, &fresh, TOLERANCE) {
            Err(e) => failures.push(format!("{name}: {e}")),
            Ok(c) if !c.within() => {
                let w = c.worst.expect("a difference has a worst value");
                failures.push(format!(
                    "{name}: {} of {} values differ beyond a relative {:e}; worst at {}, {}: \
                     golden {:e}, fresh {:e} (max rel. diff {:.3e}, mean {:.3e})",
                    c.beyond,
                    c.values,
                    TOLERANCE.rel,
                    w.cell,
                    ["R", "G", "B"][w.channel],
                    w.a,
                    w.b,
                    c.max_rel,
                    c.mean_rel
                ));
            }
            Ok(_) => {}
        }
    }
    assert!(
        failures.is_empty(),
        "golden tables differ (if the model changed on purpose, run `cargo xtask golden` and \
         review the diff):\n{}",
        failures.join("\n")
    );
}
