//! `clothbake export --gltf --mtlx --usd --blender`: every shipped fabric exports to all four
//! targets, the residuals it prints are the table of docs/guide/export.md (written by `cargo xtask
//! fitted` from the same library calls: the table must be current), and bad requests are
//! refused before any work.

mod common;

use common::{fails_with, fresh_dir, listing, run_in, succeeds};
use std::path::{Path, PathBuf};

fn tables() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tables")
        .canonicalize()
        .unwrap()
}

/// The shipped fabrics: every `.json` and `.wif` directly in tables/.
fn shipped() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(tables())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.is_file()
                && matches!(
                    p.extension().and_then(|e| e.to_str()),
                    Some("json") | Some("wif")
                )
        })
        .collect();
    v.sort();
    v
}

/// The three numbers of "albedo error A% mean, B% max; L2 of f_r cos C%" in `line`, as the
/// docs table writes them ("A% / B% / C%").
fn residual_cell(line: &str) -> String {
    let after = |key: &str| {
        let i = line
            .find(key)
            .unwrap_or_else(|| panic!("{key:?} in {line:?}"))
            + key.len();
        line[i..].split('%').next().unwrap().trim().to_string()
    };
    let mean = after("albedo error ");
    let max = after("mean, ");
    let l2 = after("L2 of f_r cos ");
    format!("{mean}% / {max}% / {l2}%")
}

#[test]
fn every_shipped_fabric_exports_to_all_four_targets_with_the_documented_residuals() {
    let docs = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/guide/export.md"),
    )
    .unwrap();
    let fabrics = shipped();
    assert!(fabrics.len() >= 13, "{fabrics:?}");
    for path in fabrics {
        let file = path.file_name().unwrap().to_string_lossy().into_owned();
        let dir = fresh_dir("fitted", &file);
        let out = run_in(
            &dir,
            &[
                "export",
                "--weave",
                path.to_str().unwrap(),
                "--gltf",
                "c.glb",
                "--mtlx",
                "c.mtlx",
                "--usd",
                "c.usda",
                "--blender",
                "c.py",
            ],
        );
        let text = succeeds(&out);
        let files = listing(&dir);
        for f in ["c.glb", "c.mtlx", "c.usda", "c.py"] {
            assert!(files.contains(&f.to_string()), "{file}: {files:?}");
        }
        let glb = std::fs::read(dir.join("c.glb")).unwrap();
        assert_eq!(&glb[..4], b"glTF", "{file}");
        let textured = !text.contains("one set of parameters");
        assert_eq!(
            files.contains(&"c.base.png".to_string()),
            textured,
            "{file}: {files:?}"
        );
        // The table row: | file | cells | glTF | OpenPBR | Blender |.
        let row = docs
            .lines()
            .find(|l| l.starts_with(&format!("| {file} |")))
            .unwrap_or_else(|| {
                panic!("docs/guide/export.md has no row for {file}: run cargo xtask fitted")
            });
        let cols: Vec<&str> = row.split('|').map(str::trim).collect();
        let line = |what: &str| {
            text.lines()
                .find(|l| l.contains(what))
                .unwrap_or_else(|| panic!("{file}: no {what} line in {text}"))
                .to_string()
        };
        assert_eq!(residual_cell(&line("c.glb")), cols[3], "{file} glTF: {row}");
        assert_eq!(
            residual_cell(&line("c.mtlx")),
            cols[4],
            "{file} OpenPBR: {row}"
        );
        assert_eq!(
            residual_cell(&line("c.py")),
            cols[5],
            "{file} Blender: {row}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn fitted_exports_refuse_bad_requests_before_work() {
    let dir = fresh_dir("fitted", "refusals");
    let twill = tables().join("twill.json");
    let w = twill.to_str().unwrap();
    let err = fails_with(
        &run_in(
            &dir,
            &[
                "export",
                "--weave",
                w,
                "--gltf",
                "a.glb",
                "--periods-per-uv",
                "0",
            ],
        ),
        2,
        &["--periods-per-uv", "1/1024 to 1024"],
    );
    assert!(err.contains("e.g. 8"), "{err}");
    // Two outputs on one file.
    fails_with(
        &run_in(
            &dir,
            &["export", "--weave", w, "--gltf", "a.x", "--mtlx", "a.x"],
        ),
        2,
        &["same file"],
    );
    // An existing map beside the MaterialX file is an output: refused without --force, and
    // nothing is written.
    std::fs::write(dir.join("m.base.png"), b"keep").unwrap();
    fails_with(
        &run_in(&dir, &["export", "--weave", w, "--mtlx", "m.mtlx"]),
        2,
        &["m.base.png", "--force"],
    );
    assert_eq!(listing(&dir), vec!["m.base.png".to_string()]);
    assert_eq!(std::fs::read(dir.join("m.base.png")).unwrap(), b"keep");
    // A stem that cannot name the maps inside a USD or MaterialX file (an asset path ends at
    // `@`; a quote ends an XML attribute), refused before any work, nothing written.
    for name in ["a@b.usda", "q\"x.mtlx"] {
        let flag = if name.ends_with(".usda") {
            "--usd"
        } else {
            "--mtlx"
        };
        fails_with(
            &run_in(&dir, &["export", "--weave", w, flag, name]),
            2,
            &["file name holds", "texture maps"],
        );
    }
    assert_eq!(listing(&dir), vec!["m.base.png".to_string()]);
}

#[test]
fn a_period_of_more_than_1024_cells_gets_one_material() {
    // A 33 x 33 plain weave has 1089 crossing cells: fitted as one material (the bound on the
    // per-cell fits' time and memory), said on stdout, no maps written.
    let dir = fresh_dir("fitted", "many-cells");
    let n = 33;
    let pattern: Vec<Vec<u8>> = (0..n)
        .map(|j| (0..n).map(|i| ((i + j) % 2) as u8).collect())
        .collect();
    let group = serde_json::json!({
        "height": vec![0.0; n], "radius": vec![1.5; n], "spacing": vec![3.1; n],
        "material": {"albedo": [0.5, 0.4, 0.3], "exponent": 10.0, "specular": 0.3}});
    let fabric =
        serde_json::json!({"name": "big", "pattern": pattern, "warp": group, "weft": group});
    std::fs::write(dir.join("big.json"), fabric.to_string()).unwrap();
    let out = run_in(
        &dir,
        &[
            "export", "--weave", "big.json", "--gltf", "b.glb", "--mtlx", "b.mtlx",
        ],
    );
    let text = succeeds(&out);
    assert!(text.contains("1089 crossing cells"), "{text}");
    assert!(text.contains("one set of parameters"), "{text}");
    assert!(!listing(&dir).contains(&"b.base.png".to_string()));
}
