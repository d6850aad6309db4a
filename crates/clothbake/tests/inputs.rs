//! The binary's input side: weaving drafts as weavers write them (yarns thicker than their
//! spacing, packed), the size flags, and bounded reading of `--weave` (docs/reference/wif.md,
//! docs/reference/limits.md).

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
            "docs/reference/limits.md",
        ],
    );
}

/// `eval --weave PATH` with fixed directions.
fn eval_path(path: &Path) -> Output {
    clothbake(&[
        "eval",
        "--weave",
        path.to_str().unwrap(),
        "--wi",
        "30,0",
        "--wo",
        "30,180",
    ])
}

const PLAIN: &str = r#"{"pattern": [[1,0],[0,1]], "warp": {"radius": 1, "spacing": 2.5},
    "weft": {"radius": 1, "spacing": 2.5}}"#;

/// A WIF header and a 2-end plain weave after `warp`, the body of `[WARP]`.
fn plain_wif(warp: &str) -> String {
    format!("[WIF]\nVersion=1.1\n[WARP]\n{warp}\n[THREADING]\n1=1\n2=2\n[LIFTPLAN]\n1=1\n2=2\n")
}

#[test]
fn special_and_oversized_files_are_refused_before_reading() {
    // Each within seconds (no endless read, no blocking open), one line, exit 2.
    #[cfg(unix)]
    {
        fails_with(
            &eval_path(Path::new("/dev/zero")),
            2,
            &[
                "/dev/zero",
                "is a device, not a regular file",
                "give a fabric file",
            ],
        );
        // A draft name that is a device: refused the same way.
        let link = temp("zero.wif");
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        fails_with(&eval_path(&link), 2, &["inputs-zero.wif", "a device"]);
        // A FIFO nobody writes to: opening it would block.
        let fifo = temp("fifo.json");
        let _ = std::fs::remove_file(&fifo);
        let made = Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("run mkfifo");
        assert!(made.success());
        fails_with(
            &eval_path(&fifo),
            2,
            &["inputs-fifo.json", "a FIFO (named pipe)"],
        );
    }
    // 2 GB (sparse): refused from its size.
    let big = temp("big.json");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(2 << 30)
        .unwrap();
    fails_with(
        &eval_path(&big),
        2,
        &[
            "inputs-big.json",
            "2147483648 bytes, more than the 16 MiB",
            "docs/reference/limits.md",
        ],
    );
    std::fs::remove_file(&big).unwrap();
    fails_with(
        &eval_path(Path::new(env!("CARGO_TARGET_TMPDIR"))),
        2,
        &["is a directory, not a fabric file"],
    );
}

#[test]
fn draft_counts_too_large_say_so() {
    for n in ["1000000000", "99999999999999999999999"] {
        let p = temp(&format!("threads-{}.wif", n.len()));
        std::fs::write(&p, plain_wif(&format!("Threads={n}"))).unwrap();
        fails_with(
            &eval_path(&p),
            2,
            &[
                &format!("inputs-threads-{}.wif", n.len()),
                "[WARP] line 4",
                &format!("Threads={n}: the number of warp ends is too large, at most 65536"),
                "docs/reference/limits.md",
            ],
        );
    }
}

#[test]
fn binary_data_is_not_a_text_draft() {
    // Bytes of a pseudo-random sequence (SplitMix64): not echoed back.
    let mut x: u64 = 1;
    let bytes: Vec<u8> = (0..4096)
        .map(|_| {
            x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            (z ^ (z >> 31)) as u8
        })
        .collect();
    for name in ["noise.wif", "noise.json"] {
        let p = temp(name);
        std::fs::write(&p, &bytes).unwrap();
        let line = fails_with(&eval_path(&p), 2, &[name, "is not a", "control character"]);
        assert!(line.len() < 250, "{line}");
    }
    let line = fails_with(&eval_path(&temp("noise.wif")), 2, &["not a text WIF draft"]);
    assert!(line.contains("docs/reference/wif.md"), "{line}");
}

#[test]
fn a_utf8_byte_order_mark_is_accepted() {
    for (name, text) in [
        ("bom.json", format!("\u{feff}{PLAIN}")),
        ("bom.wif", format!("\u{feff}{}", plain_wif("Threads=2"))),
    ] {
        let p = temp(name);
        std::fs::write(&p, text).unwrap();
        succeeds(&eval_path(&p));
    }
}

#[test]
fn a_json_top_level_that_is_not_an_object_is_named() {
    for (name, text, what) in [
        ("array.json", "[1, 2]", "is a JSON array"),
        ("string.json", "\"twill\"", "is a JSON string"),
        ("empty.json", "  \n", "is empty"),
    ] {
        let p = temp(name);
        std::fs::write(&p, text).unwrap();
        fails_with(
            &eval_path(&p),
            2,
            &[
                name,
                what,
                "expected an object",
                "docs/reference/fabric-format.md",
            ],
        );
    }
}
