//! The binary's input side: weaving drafts as weavers write them (yarns thicker than their
//! spacing, packed), the size flags, and bounded reading of `--weave` (docs/wif.md,
//! docs/limits.md).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::{fails_with, fresh_dir, succeeds};

fn clothbake(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_clothbake"))
        .args(args)
        .output()
        .expect("run the clothbake binary")
}

/// The hand-written drafts of `tests/drafts`.
fn test_draft(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/drafts")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn eval_json(weave: &str, rest: &[&str]) -> serde_json::Value {
    let mut args = vec!["eval", "--weave", weave, "--json"];
    args.extend_from_slice(rest);
    serde_json::from_str(&succeeds(&clothbake(&args))).unwrap()
}

#[test]
fn packed_drafts_evaluate_bake_and_say_what_was_done() {
    let dir = fresh_dir("inputs", "packed");
    for (name, notes) in [("herringbone8.wif", 2), ("advancing12.wif", 1)] {
        let weave = test_draft(name);
        // eval: the table names each packed group, --json carries the notes.
        let text = succeeds(&clothbake(&[
            "eval", "--weave", &weave, "--wi", "30,0", "--wo", "45,180",
        ]));
        let lines: Vec<&str> = text.lines().filter(|l| l.starts_with("note ")).collect();
        assert_eq!(lines.len(), notes, "{text}");
        assert!(
            lines[0].contains("warp: ") && lines[0].contains("capped"),
            "{text}"
        );
        let v = eval_json(&weave, &["--wi", "30,0", "--wo", "45,180"]);
        assert_eq!(v["notes"].as_array().unwrap().len(), notes, "{v}");
        assert!(v["I"][0].as_f64().unwrap() > 0.0);
        // bake (a small grid) and info: the table keeps the notes with its fabric.
        let out = dir.join(format!("{name}.bin"));
        let o = out.to_str().unwrap();
        succeeds(&clothbake(&[
            "bake", "--weave", &weave, "-o", o, "--res", "4,8,4,8", "--quiet",
        ]));
        let info = succeeds(&clothbake(&["info", o]));
        let noted: Vec<&str> = info.lines().filter(|l| l.starts_with("note ")).collect();
        assert_eq!(noted.len(), notes, "{info}");
        assert!(noted[0].contains("radius capped") || noted[0].contains("radii capped"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn size_flags_replace_a_drafts_sizes() {
    // herringbone8 gives Thickness and Spacing; --radius 0.05 --spacing 0.2 replace them: the
    // yarns fit, nothing is packed, and the reflection changes. With a radius over half the
    // spacing the flags' sizes are packed like the draft's, and the note says they came from
    // the flags.
    let weave = test_draft("herringbone8.wif");
    let dirs = ["--wi", "40,10", "--wo", "30,200"];
    let drafted = eval_json(&weave, &dirs);
    let mut args = dirs.to_vec();
    args.extend(["--radius", "0.05", "--spacing", "0.2"]);
    let flagged = eval_json(&weave, &args);
    assert!(flagged.get("notes").is_none(), "{flagged}");
    assert_ne!(drafted["I"], flagged["I"]);
    let mut args = dirs.to_vec();
    args.extend(["--radius", "0.15", "--spacing", "0.2"]);
    let packed = eval_json(&weave, &args);
    let notes = packed["notes"].as_array().unwrap();
    assert_eq!(notes.len(), 2, "{packed}");
    assert!(
        notes[0]
            .as_str()
            .unwrap()
            .contains("(mm, from --radius/--spacing); radius capped to 0.1000 mm"),
        "{packed}"
    );
}

/// A path in this test's own temporary folder.
fn temp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("inputs-{name}"))
}

#[test]
fn a_period_beyond_the_limits_is_refused_in_one_line() {
    // 2049 x 512 = 1 049 088 cells, over the 2^20 a period may have.
    let row: Vec<&str> = (0..2049)
        .map(|i| if i % 2 == 0 { "1" } else { "0" })
        .collect();
    let row = format!("[{}]", row.join(","));
    let rows: Vec<&str> = (0..512).map(|_| row.as_str()).collect();
    let p = temp("big-period.json");
    std::fs::write(
        &p,
        format!(
            r#"{{"pattern": [{}], "warp": {{"radius": 1, "spacing": 2}}, "weft": {{"radius": 1, "spacing": 2}}}}"#,
            rows.join(",")
        ),
    )
    .unwrap();
    fails_with(
        &clothbake(&[
            "eval",
            "--weave",
            p.to_str().unwrap(),
            "--wi",
            "30,0",
            "--wo",
            "30,180",
        ]),
        2,
        &[
            "inputs-big-period.json",
            "field `pattern`",
            "2049 x 512 = 1049088 cells, more than the 1048576",
            "docs/limits.md",
        ],
    );
}
