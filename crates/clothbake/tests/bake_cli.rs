//! The bake, info and diff commands, driving the built binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;

use common::{bake_in, fabric, fails_with, listing, succeeds, text};

fn fresh_dir(name: &str) -> PathBuf {
    common::fresh_dir("bake-cli", name)
}

use common::run_in;

const SMALL: &str = "4,8,4,8";

/// `clothbake --weave <the shipped twill> --res SMALL <extra...>` (the default mode) in `dir`.
fn small_twill(dir: &Path, extra: &[&str]) -> Output {
    let twill = fabric("twill");
    run_in(
        dir,
        &[&["--weave", &twill, "--res", SMALL][..], extra].concat(),
    )
}

#[test]
fn default_mode_writes_a_table_that_info_reads() {
    let d = fresh_dir("default");
    let twill = fabric("twill");
    // The binary's folder on PATH: the hints call it by name.
    let exe = Path::new(env!("CARGO_BIN_EXE_clothbake"));
    let mut c = common::cmd(&d, &["--weave", &twill, "--res", SMALL]);
    c.env("PATH", exe.parent().unwrap());
    let out = succeeds(&c.output().unwrap());
    assert_eq!(out.lines().count(), 2, "{out}");
    assert!(out
        .lines()
        .nth(1)
        .unwrap()
        .starts_with("next: `clothbake info twill.exr`"));
    // Not on PATH, run by cargo (CARGO set): the hints say how cargo runs it; run by neither,
    // its path.
    for (cargo, want) in [
        (
            true,
            "next: `cargo run --release -p clothbake -- info t2.exr`".to_string(),
        ),
        (false, format!("next: `{} info t3.exr`", exe.display())),
    ] {
        let out_name = if cargo { "t2.exr" } else { "t3.exr" };
        let mut c = common::cmd(&d, &["--weave", &twill, "--res", SMALL, "-o", out_name]);
        c.env("PATH", "/nonexistent");
        if cargo {
            c.env("CARGO", "cargo");
        } else {
            c.env_remove("CARGO");
        }
        let out = succeeds(&c.output().unwrap());
        assert!(out.lines().nth(1).unwrap().starts_with(&want), "{out}");
    }
    std::fs::remove_file(d.join("t2.exr")).unwrap();
    std::fs::remove_file(d.join("t3.exr")).unwrap();
    for w in [
        "wrote twill.exr",
        "4x8x4x8",
        "512 of 1,024 cells evaluated",
        "rotate 180",
        "cells/s",
    ] {
        assert!(out.contains(w), "{w:?} missing in {out}");
    }
    assert_eq!(listing(&d), ["twill.exr"]);
    let info = succeeds(&run_in(&d, &["info", "twill.exr"]));
    for w in [
        "OpenEXR",
        "clothbake 0.1.0",
        "version 1",
        "fabric     twill",
        "theta_i 4 x phi_i 8 x theta_o 4 x phi_o 8 = 1024 cells",
        "centring cell",
        "f_r in 1/sr",
        "symmetry   rotate 180",
        "\"bounces\":1",
        "min",
        "max",
        "mean",
        "directional albedo",
        "phi_i 22.50 (row 0",
        " 0 -> row 0 (11.25 deg)",
        "30 -> row 1 (33.75 deg)",
        "60 -> row 2 (56.25 deg)",
        "80 -> row 3 (78.75 deg)",
    ] {
        assert!(info.contains(w), "{w:?} missing in\n{info}");
    }
    // The subcommand spelled out, binary format from --format, quiet.
    let out = succeeds(&bake_in(&d, &twill, SMALL, &["--format", "bin", "--quiet"]));
    assert!(out.is_empty(), "{out}");
    assert_eq!(listing(&d), ["twill.bin", "twill.exr"]);
    assert!(succeeds(&run_in(&d, &["info", "twill.bin"])).contains("binary format"));
}

#[test]
fn existing_output_needs_force() {
    let d = fresh_dir("force");
    let twill = fabric("twill");
    let base = ["--weave", twill.as_str(), "--res", SMALL, "-o", "t.bin"];
    succeeds(&run_in(&d, &base));
    let before = std::fs::read(d.join("t.bin")).unwrap();
    let other = [&base[..], &["--exponent", "20"]].concat();
    fails_with(
        &run_in(&d, &other),
        2,
        &["t.bin", "already exists", "--force"],
    );
    assert_eq!(std::fs::read(d.join("t.bin")).unwrap(), before);
    succeeds(&run_in(&d, &[&other[..], &["--force"]].concat()));
    assert_ne!(std::fs::read(d.join("t.bin")).unwrap(), before);
    assert_eq!(listing(&d), ["t.bin"]);
}

#[test]
fn diff_exit_statuses() {
    let d = fresh_dir("diff");
    let twill = fabric("twill");
    succeeds(&small_twill(&d, &["-o", "a.bin"]));
    succeeds(&small_twill(&d, &["-o", "b.bin", "--exponent", "20"]));
    succeeds(&run_in(
        &d,
        &["--weave", &twill, "--res", "8,8,4,8", "-o", "c.bin"],
    ));

    let same = succeeds(&run_in(&d, &["diff", "a.bin", "a.bin"]));
    for w in [
        "max 0.000e0",
        "inf (identical)",
        "within tolerance",
        "same fabric",
    ] {
        assert!(same.contains(w), "{w:?} missing in\n{same}");
    }

    let out = run_in(&d, &["diff", "a.bin", "b.bin"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    for w in [
        "DIFFERENT",
        "worst      theta_i",
        "phi_o",
        "PSNR",
        "dB",
        "fabric differs",
    ] {
        assert!(s.contains(w), "{w:?} missing in\n{s}");
    }
    // A loose enough tolerance accepts it.
    succeeds(&run_in(&d, &["diff", "a.bin", "b.bin", "--tol", "10"]));

    fails_with(
        &run_in(&d, &["diff", "a.bin", "c.bin"]),
        2,
        &["different grids", "n_theta_i 4 vs 8", "--res"],
    );
    fails_with(
        &run_in(&d, &["diff", "a.bin", "missing.bin"]),
        2,
        &["missing.bin", "check the path"],
    );
    std::fs::write(d.join("junk.bin"), b"not a table at all").unwrap();
    fails_with(
        &run_in(&d, &["diff", "junk.bin", "a.bin"]),
        2,
        &["junk.bin", "not a clothbake table"],
    );
    fails_with(&run_in(&d, &["info", "junk.bin"]), 2, &["junk.bin"]);
    fails_with(
        &run_in(&d, &["diff", "a.bin", "a.bin", "--tol", "-1"]),
        2,
        &["--tol", "negative"],
    );
}

/// Two spatial tables whose values agree but whose cells do not: `diff` names what differs and
/// exits 1 (it compared the values alone, and called them identical).
#[test]
fn diff_sees_what_a_table_carries_beside_its_values() {
    let d = fresh_dir("diff-carried");
    succeeds(&run_in(
        &d,
        &[
            "bake",
            "--weave",
            "gingham",
            "--spatial",
            "--res",
            "2,4,2,4",
            "-o",
            "a.bin",
        ],
    ));
    let mut t = clothbake_loader::read_table(&d.join("a.bin")).unwrap();
    t.meta.spatial.as_mut().unwrap().cell_albedo[0] = [0.9, 0.1, 0.1];
    clothbake_loader::write_binary(&d.join("b.bin"), &t, false).unwrap();
    let out = run_in(&d, &["diff", "a.bin", "b.bin"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    for w in [
        "DIFFERENT spatial.cell_albedo: 3 of",
        "inf (identical)",
        "what else the tables carry is not (exit 1)",
    ] {
        assert!(s.contains(w), "{w:?} missing in\n{s}");
    }
    let same = succeeds(&run_in(&d, &["diff", "a.bin", "a.bin"]));
    assert!(
        same.contains("carried    the same openness, cells, classes and yarns"),
        "{same}"
    );
}

#[test]
fn missing_folder_writes_nothing() {
    let d = fresh_dir("missing");
    fails_with(
        &small_twill(&d, &["-o", "nope/t.exr"]),
        2,
        &["nope", "does not exist", "create it"],
    );
    assert!(listing(&d).is_empty());
}

#[cfg(unix)]
#[test]
fn unwritable_folder_writes_nothing() {
    use std::os::unix::fs::PermissionsExt;
    let d = fresh_dir("unwritable");
    let ro = d.join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Privileged users write anyway: nothing to test then.
    let probe = ro.join("probe");
    if std::fs::write(&probe, b"x").is_ok() {
        let _ = std::fs::remove_file(&probe);
        eprintln!("skipped: this user can write into read-only folders");
        return;
    }
    fails_with(
        &small_twill(&d, &["-o", "ro/t.exr"]),
        2,
        &[
            "ro/t.exr",
            "you may not write there",
            "-o PATH",
            "nothing was written",
        ],
    );
    assert!(listing(&ro).is_empty());
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn exr_and_binary_tables_agree() {
    let d = fresh_dir("formats");
    let twill = fabric("twill");
    for out in ["t.bin", "t.exr", "t32.exr"] {
        let mut args = vec!["--weave", twill.as_str(), "--res", SMALL, "-o", out];
        if out == "t32.exr" {
            args.extend(["--precision", "f32"]);
        }
        succeeds(&run_in(&d, &args));
    }
    // Half floats round to 2^-11 relative (2^-25 absolute below 6.1e-5).
    succeeds(&run_in(
        &d,
        &["diff", "t.bin", "t.exr", "--tol", "4.9e-4", "--abs", "3e-8"],
    ));
    // ... which the default tolerance (1e-6) does notice.
    assert_eq!(
        run_in(&d, &["diff", "t.bin", "t.exr"]).status.code(),
        Some(1)
    );
    // f32 samples are exact.
    let s = succeeds(&run_in(
        &d,
        &["diff", "t.bin", "t32.exr", "--tol", "0", "--abs", "0"],
    ));
    assert!(s.contains("inf (identical)"), "{s}");
}

#[test]
fn thread_count_does_not_change_the_file() {
    let d = fresh_dir("threads");
    for ext in ["exr", "bin"] {
        let mut files = Vec::new();
        for threads in ["1", "2"] {
            let out = format!("t{threads}.{ext}");
            succeeds(&small_twill(&d, &["--threads", threads, "-o", &out]));
            files.push(std::fs::read(d.join(&out)).unwrap());
        }
        assert!(files[0] == files[1], "{ext}: the files differ");
    }
}

#[test]
fn bad_options_are_one_line_errors() {
    let d = fresh_dir("bad");
    let twill = fabric("twill");
    let with = |extra: &[&str]| run_in(&d, &[&["--weave", twill.as_str()][..], extra].concat());
    for (extra, needles) in [
        (
            &["--res", "32,64,32"][..],
            &["--res", "found 3", "NTI,NPI,NTO,NPO"][..],
        ),
        (&["--res", "0,64,32,64"], &["NTI is 0"]),
        (&["--res", "a,b,c,d"], &["not a whole number"]),
        (&["--res", "4096,4096,4096,4096"], &["2^31"]),
        (&["--threads", "0"], &["--threads", "at least 1"]),
        (&["--bounces", "0"], &["--bounces", "give 1"]),
        (&["--format", "png"], &["--format", "exr", "bin"]),
        (
            &["--format", "bin", "--precision", "f32"],
            &["--precision", "EXR"],
        ),
        (
            &["-o", "x.bin", "--precision", "f16"],
            &["--precision", "EXR"],
        ),
        (
            &["-o", "x.exr", "--format", "bin"],
            &["--format bin", "x.exr", ".exr"],
        ),
        (
            &["--secondary", "analytic"],
            &["--secondary", "--bounces 2"],
        ),
        (&["--kernel", "thesis"], &["--kernel", "--bounces 2"]),
        (
            &["--bounces", "2", "--method", "raytrace"],
            &["--bounces 2", "analytic"],
        ),
        (&["--samples", "10"], &["--samples", "--method raytrace"]),
        (&["--caps", "shaded"], &["--caps", "--method raytrace"]),
        (
            &["--method", "raytrace", "--variant", "thesis"],
            &["--variant", "analytic"],
        ),
        (&["--albedo", "2"], &["--albedo", "[0, 1]"]),
        (&["--frobnicate"], &["--frobnicate", "--help"]),
    ] {
        fails_with(&with(extra), 2, needles);
    }
    fails_with(
        &run_in(&d, &["bake", "--res", SMALL]),
        2,
        &["--weave", "clothbake bake --help"],
    );
    fails_with(
        &run_in(&d, &["--weave", "no-such.json"]),
        2,
        &["no-such.json", "check the path"],
    );
    assert!(listing(&d).is_empty());
}

#[test]
fn raytraced_and_two_bounce_tables() {
    let d = fresh_dir("methods");
    let twill = fabric("twill");
    let grid = ["--res", "2,4,2,4"];
    let s = succeeds(&run_in(
        &d,
        &[
            &["--weave", twill.as_str(), "-o", "rt.bin"][..],
            &grid,
            &["--method", "raytrace", "--samples", "2000", "--seed", "5"],
        ]
        .concat(),
    ));
    assert!(s.contains("wrote rt.bin"));
    for (out, extra) in [
        ("b2.bin", &["--bounces", "2"][..]),
        (
            "b2s.bin",
            &[
                "--bounces",
                "2",
                "--secondary",
                "raytrace",
                "--kernel",
                "thesis",
            ],
        ),
        ("b1.bin", &[]),
        ("sliced.bin", &["--variant", "sliced"]),
    ] {
        succeeds(&run_in(
            &d,
            &[&["--weave", twill.as_str(), "-o", out][..], &grid, extra].concat(),
        ));
    }
    let info = succeeds(&run_in(&d, &["info", "b2s.bin"]));
    assert!(info.contains("\"bounces\":2"), "{info}");
    assert!(info.contains("\"kernel\":\"thesis\""), "{info}");
    assert!(info.contains("\"method\":\"sampling\""), "{info}");
    let info = succeeds(&run_in(&d, &["info", "rt.bin"]));
    assert!(info.contains("\"method\":\"raytrace\""), "{info}");
    assert!(info.contains("\"samples\":2000"), "{info}");
    // The secondary reflection adds light: two bounces differ from one.
    assert_eq!(
        run_in(&d, &["diff", "b1.bin", "b2.bin"]).status.code(),
        Some(1)
    );
    // The sliced variant is recorded and gives another table.
    let info = succeeds(&run_in(&d, &["info", "sliced.bin"]));
    assert!(info.contains("\"variant\":\"sliced\""), "{info}");
    assert_eq!(
        run_in(&d, &["diff", "b1.bin", "sliced.bin"]).status.code(),
        Some(1)
    );
}

/// Ctrl-C stops the bake: exit 130, one line, no table, no temporary file; the rows finished
/// so far, if any, are saved in the checkpoint (tests/shards.rs resumes one).
#[cfg(unix)]
#[test]
fn interrupt_writes_no_table() {
    let d = fresh_dir("interrupt");
    let twill = fabric("twill");
    // A bake of minutes: two bounces on the default grid.
    let child = Command::new(env!("CARGO_BIN_EXE_clothbake"))
        .args(["--weave", &twill, "--bounces", "2", "-o", "big.bin"])
        .current_dir(&d)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Give it time to install its handler and start baking.
    std::thread::sleep(std::time::Duration::from_millis(1500));
    common::signal(&child, "INT");
    let out = child.wait_with_output().unwrap();
    fails_with(&out, 130, &[]);
    let err = text(&out.stderr);
    if listing(&d).is_empty() {
        assert_eq!(err, "clothbake: interrupted; nothing was written\n");
    } else {
        assert_eq!(listing(&d), ["big.bin.checkpoint"]);
        assert!(
            err.starts_with("clothbake: interrupted; no table was written, ")
                && err.contains(" of 2048 rows are saved in big.bin.checkpoint; run the same command with --resume"),
            "{err}"
        );
    }
}
