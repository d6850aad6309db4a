//! Shards, merge, checkpoint and resume, driving the built binary as separate processes.

use std::path::{Path, PathBuf};
use std::process::{Child, Output};
use std::time::{Duration, Instant};

mod common;

use common::{bake_args, bake_in, cmd, fabric, listing, run_in, succeeds, text};

/// Exit status 2, one line `clothbake: ...` on stderr containing every needle.
fn fails_with(out: &Output, needles: &[&str]) -> String {
    common::fails_with(out, 2, needles)
}

fn fresh_dir(name: &str) -> PathBuf {
    common::fresh_dir("shards", name)
}

/// `clothbake diff A B --tol 0 --abs 0`: exit 0 and no value differs.
fn identical(dir: &Path, a: &str, b: &str) {
    let out = succeeds(&run_in(dir, &["diff", a, b, "--tol", "0", "--abs", "0"]));
    assert!(out.contains("every value is equal"), "{out}");
    assert!(out.contains("same fabric, options and tool"), "{out}");
    assert_eq!(
        std::fs::read(dir.join(a)).unwrap(),
        std::fs::read(dir.join(b)).unwrap(),
        "{a} and {b} differ in their bytes"
    );
}

const RES: &str = "8,16,8,16";

#[test]
fn four_shards_two_at_a_time_merge_to_the_single_bake() {
    let d = fresh_dir("four");
    let twill = fabric("twill");
    let base = bake_args(twill.as_str(), RES, &["--threads", "1"]);
    succeeds(&run_in(&d, &[&base[..], &["-o", "single.exr"]].concat()));
    // Four shards as separate processes, two at a time.
    for pair in [[0, 1], [2, 3]] {
        let kids: Vec<Child> = pair
            .iter()
            .map(|k| {
                let s = format!("{k}/4");
                cmd(&d, &[&base[..], &["--shard", &s]].concat())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for k in kids {
            let out = succeeds(&k.wait_with_output().unwrap());
            assert!(
                out.contains("shard ") && out.contains("of-4.shard"),
                "{out}"
            );
        }
    }
    let shards: Vec<String> = (0..4).map(|k| format!("twill-{k}-of-4.shard")).collect();
    let sh: Vec<&str> = shards.iter().map(String::as_str).collect();
    // In any order.
    let rev: Vec<&str> = sh.iter().rev().copied().collect();
    let out = succeeds(&run_in(
        &d,
        &[&["merge", "-o", "merged.exr"], &rev[..]].concat(),
    ));
    assert!(out.contains("4 shards merged"), "{out}");
    identical(&d, "single.exr", "merged.exr");

    // One shard missing: exit 2, names the shard and its rows; nothing written.
    let before = listing(&d);
    let missing = [sh[0], sh[1], sh[3]];
    let err = fails_with(
        &run_in(&d, &[&["merge", "-o", "bad.exr"], &missing[..]].concat()),
        &["shard 2/4", "missing", "rows 56-87", "--shard 2/4"],
    );
    assert!(err.contains("theta_i cell 3"), "{err}");
    // The same shard twice (an overlap).
    let twice = [sh[0], sh[1], sh[1], sh[2], sh[3]];
    fails_with(
        &run_in(&d, &[&["merge", "-o", "bad.exr"], &twice[..]].concat()),
        &["twill-1-of-4.shard", "twice", "rows 24-55"],
    );
    // A shard of another fabric.
    let plain = fabric("plain");
    succeeds(&bake_in(
        &d,
        &plain,
        RES,
        &["--shard", "2/4", "-o", "plain2.shard"],
    ));
    let before_plain = [&before[..], &["plain2.shard".to_string()]].concat();
    let other = [sh[0], sh[1], "plain2.shard", sh[3]];
    fails_with(
        &run_in(&d, &[&["merge", "-o", "bad.exr"], &other[..]].concat()),
        &["plain2.shard", "another fabric (plain)", "twill"],
    );
    // A shard of other options (another facet model) and of a split into 2.
    succeeds(&run_in(
        &d,
        &[&base[..], &["--shard", "1/2", "-o", "half.shard"]].concat(),
    ));
    fails_with(
        &run_in(&d, &["merge", "-o", "bad.exr", sh[0], "half.shard"]),
        &["half.shard", "shard 1/2", "of 4"],
    );
    // A damaged shard.
    let mut bytes = std::fs::read(d.join(sh[2])).unwrap();
    let n = bytes.len() / 2;
    bytes[n] ^= 1;
    std::fs::write(d.join("damaged.shard"), &bytes).unwrap();
    fails_with(
        &run_in(
            &d,
            &[
                "merge",
                "-o",
                "bad.exr",
                sh[0],
                sh[1],
                "damaged.shard",
                sh[3],
            ],
        ),
        &["damaged.shard", "checksum"],
    );
    let expect = [
        &before_plain[..],
        &["damaged.shard".into(), "half.shard".into()],
    ]
    .concat();
    let mut expect = expect;
    expect.sort();
    assert_eq!(listing(&d), expect, "a failed merge wrote something");
}

#[test]
fn spatial_bakes_are_the_same_for_any_thread_count_and_shard_split() {
    let d = fresh_dir("spatial");
    let twill = fabric("twill");
    let base = ["bake", "--weave", twill.as_str(), "--res", RES, "--spatial"];
    succeeds(&run_in(
        &d,
        &[&base[..], &["--threads", "1", "-o", "one.exr"]].concat(),
    ));
    succeeds(&run_in(
        &d,
        &[&base[..], &["--threads", "2", "-o", "two.exr"]].concat(),
    ));
    identical(&d, "one.exr", "two.exr");
    for k in 0..3 {
        let s = format!("{k}/3");
        succeeds(&run_in(&d, &[&base[..], &["--shard", &s]].concat()));
    }
    let out = succeeds(&run_in(
        &d,
        &[
            "merge",
            "-o",
            "merged.exr",
            "twill-2-of-3.shard",
            "twill-0-of-3.shard",
            "twill-1-of-3.shard",
        ],
    ));
    assert!(out.contains("3 shards merged"), "{out}");
    identical(&d, "one.exr", "merged.exr");
    let info = succeeds(&run_in(&d, &["info", "merged.exr"]));
    assert!(info.contains("spatial    3 classes over 3 x 3"), "{info}");
    // The period's yarns travel through shards and merge: the twill's 6 segments.
    assert!(info.contains("yarns      6 yarn segments"), "{info}");
    // Against the averaged bake, `diff` compares the averaged parts: equal to rounding.
    succeeds(&run_in(
        &d,
        &[
            "bake",
            "--weave",
            twill.as_str(),
            "--res",
            RES,
            "-o",
            "avg.exr",
        ],
    ));
    let out = succeeds(&run_in(
        &d,
        &["diff", "one.exr", "avg.exr", "--tol", "1e-5"],
    ));
    assert!(
        out.contains(&format!("{} values", 3 * 8 * 16 * 8 * 16)),
        "{out}"
    );
    // With the second bounce too: threads and shards give the same bits.
    let two = [&base[..], &["--bounces", "2"]].concat();
    succeeds(&run_in(
        &d,
        &[&two[..], &["--threads", "1", "-o", "b2-one.exr"]].concat(),
    ));
    for k in 0..2 {
        let s = format!("{k}/2");
        succeeds(&run_in(
            &d,
            &[&two[..], &["--threads", "2", "--shard", &s]].concat(),
        ));
    }
    succeeds(&run_in(
        &d,
        &[
            "merge",
            "-o",
            "b2-merged.exr",
            "twill-1-of-2.shard",
            "twill-0-of-2.shard",
        ],
    ));
    identical(&d, "b2-one.exr", "b2-merged.exr");
    let info = succeeds(&run_in(&d, &["info", "b2-merged.exr"]));
    assert!(info.contains("with the second bounce"), "{info}");
    // What a spatial table cannot hold is refused before anything is written.
    fails_with(
        &run_in(
            &d,
            &[&base[..], &["--bounces", "all", "-o", "b2.exr"]].concat(),
        ),
        &["--spatial", "--bounces 1"],
    );
    fails_with(
        &run_in(
            &d,
            &[&base[..], &["--method", "raytrace", "-o", "rt.exr"]].concat(),
        ),
        &["--spatial", "--method analytic"],
    );
    assert!(!d.join("b2.exr").exists() && !d.join("rt.exr").exists());
}

#[test]
fn two_faced_bakes_are_the_same_for_any_thread_count_and_shard_split() {
    let d = fresh_dir("two-faced");
    let plain = fabric("plain");
    // Few rays a node: the rest's noise does not matter here, its bits do.
    let base = [
        "bake",
        "--weave",
        plain.as_str(),
        "--res",
        "4,8,4,8",
        "--faces",
        "two",
        "--facet",
        "lewis",
        "--translucency",
        "0.5",
        "--paths",
        "64",
    ];
    let out = succeeds(&run_in(
        &d,
        &[&base[..], &["--threads", "1", "-o", "one.exr"]].concat(),
    ));
    assert!(out.contains("grid 8x8x8x8"), "{out}");
    assert!(
        out.contains("--faces two"),
        "the next steps draw it backlit: {out}"
    );
    succeeds(&run_in(
        &d,
        &[&base[..], &["--threads", "2", "-o", "two.exr"]].concat(),
    ));
    identical(&d, "one.exr", "two.exr");
    for k in 0..3 {
        let s = format!("{k}/3");
        succeeds(&run_in(&d, &[&base[..], &["--shard", &s]].concat()));
    }
    succeeds(&run_in(
        &d,
        &[
            "merge",
            "-o",
            "merged.exr",
            "plain-1-of-3.shard",
            "plain-2-of-3.shard",
            "plain-0-of-3.shard",
        ],
    ));
    identical(&d, "one.exr", "merged.exr");
    // An export from the table names the command that exports the two-faced cloth (it named
    // the loader's Rust type).
    fails_with(
        &run_in(
            &d,
            &["export", "--table", "merged.exr", "--merl", "x.binary"],
        ),
        &["merged.exr: a two-faced table", "--faces two --klems"],
    );
    // info: the sides, and the light from each split into reflected, transmitted and through;
    // the plain weave's gaps are narrow (threads 3 wide every 3.1): at most (1 - 3/3.1)^2 =
    // 0.001 passes straight.
    let info = succeeds(&run_in(&d, &["info", "merged.exr"]));
    assert!(info.contains("faces      two"), "{info}");
    let front = info
        .lines()
        .find(|l| l.trim_start().starts_with("front  0 ->"))
        .unwrap_or_else(|| panic!("{info}"));
    let v: Vec<f64> = front
        .split_whitespace()
        .rev()
        .take(4)
        .map(|x| x.parse().unwrap())
        .collect();
    let (sum, o, t, r) = (v[0], v[1], v[2], v[3]);
    assert!(r > 0.2 && t > 0.05 && o < 1.1e-3, "{front}");
    assert!((r + t + o - sum).abs() < 2e-4 && sum < 1.0, "{front}");
    // A two-faced table renders lit from behind; a one-faced one is refused with --faces two.
    let out = succeeds(&run_in(
        &d,
        &[
            "render",
            "--table",
            "one.exr",
            "--faces",
            "two",
            "--scene",
            "swatch",
            "--eye",
            "0,-55,-45",
            "--light",
            "0,0.5,0.87",
            "--res",
            "24",
            "-o",
            "back.png",
        ],
    ));
    assert!(out.contains("wrote back.png"), "{out}");
    succeeds(&run_in(
        &d,
        &[
            "bake",
            "--weave",
            plain.as_str(),
            "--res",
            "4,8,4,8",
            "-o",
            "flat.exr",
        ],
    ));
    fails_with(
        &run_in(
            &d,
            &[
                "render", "--table", "flat.exr", "--faces", "two", "-o", "x.png",
            ],
        ),
        &["flat.exr", "one-faced", "--faces two"],
    );
    // diff tells the two kinds apart by their grids.
    fails_with(
        &run_in(&d, &["diff", "one.exr", "flat.exr"]),
        &["different grids", "two faces"],
    );
    // What a two-faced table cannot hold is refused before anything is written.
    for (extra, needle) in [
        (&["--spatial"][..], "--spatial"),
        (&["--bounces", "2"][..], "--bounces"),
        (&["--method", "raytrace"][..], "--method raytrace"),
    ] {
        fails_with(
            &run_in(&d, &[&base[..], extra, &["-o", "bad.exr"]].concat()),
            &["--faces two", needle],
        );
    }
    // --paths without --faces two, and a grid whose four blocks pass 2^31 cells.
    for (extra, needles) in [
        (&["--paths", "8"][..], &["--paths", "--faces two"][..]),
        (
            &["--faces", "two", "--res", "32768,65536,1,1"][..],
            &[
                "--res 32768,65536,1,1 with --faces two",
                "8589934592 cells",
                "2^31",
            ][..],
        ),
    ] {
        let args = [
            &["bake", "--weave", plain.as_str()][..],
            extra,
            &["-o", "bad.exr"],
        ];
        fails_with(&run_in(&d, &args.concat()), needles);
    }
    assert!(!d.join("bad.exr").exists());
}

#[test]
fn shard_auto_reads_slurm_and_kubernetes() {
    let d = fresh_dir("auto");
    let twill = fabric("twill");
    let base = bake_args(twill.as_str(), "2,4,2,4", &["--shard", "auto"]);
    // SLURM --array=1-2: task 2 is shard 1/2.
    let out = cmd(&d, &base)
        .env("SLURM_ARRAY_TASK_ID", "2")
        .env("SLURM_ARRAY_TASK_MIN", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "2")
        .output()
        .unwrap();
    succeeds(&out);
    assert!(text(&out.stderr).contains("shard 1/2 from SLURM_ARRAY_TASK_ID=2"));
    assert!(d.join("twill-1-of-2.shard").exists());
    // Kubernetes: JOB_COMPLETION_INDEX with --shards.
    let out = cmd(&d, &[&base[..], &["--shards", "2"]].concat())
        .env("JOB_COMPLETION_INDEX", "0")
        .output()
        .unwrap();
    succeeds(&out);
    assert!(text(&out.stderr).contains("shard 0/2 from JOB_COMPLETION_INDEX=0 and --shards 2"));
    succeeds(&run_in(
        &d,
        &[
            "merge",
            "-o",
            "m.bin",
            "twill-0-of-2.shard",
            "twill-1-of-2.shard",
        ],
    ));
    succeeds(&run_in(
        &d,
        &["bake", "--weave", &twill, "--res", "2,4,2,4", "-o", "s.bin"],
    ));
    identical(&d, "s.bin", "m.bin");
    // Neither: a clear error.
    fails_with(
        &run_in(&d, &base),
        &["neither SLURM_ARRAY_TASK_ID", "--shard K/N"],
    );
    let out = cmd(&d, &base)
        .env("JOB_COMPLETION_INDEX", "1")
        .output()
        .unwrap();
    fails_with(&out, &["--shards N"]);
    fails_with(
        &run_in(&d, &["bake", "--weave", &twill, "--shard", "4/4"]),
        &["0-based"],
    );
    fails_with(
        &run_in(
            &d,
            &[
                "bake", "--weave", &twill, "--shard", "0/4", "--format", "bin",
            ],
        ),
        &["--format", "merge"],
    );
}

/// Waits for `path` to appear (at most `limit`).
fn wait_for(path: &Path, limit: Duration) -> bool {
    let t = Instant::now();
    while t.elapsed() < limit {
        if path.exists() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    false
}

/// The options of a bake of `fabric` on RES slow enough to interrupt: the ray tracer (per-cell
/// seeds), about 1.5 s of one core.
fn slow_bake(fabric: &str) -> [&str; 8] {
    [
        "--weave",
        fabric,
        "--res",
        RES,
        "--method",
        "raytrace",
        "--samples",
        "600",
    ]
}

/// A bake SIGKILLed mid-way and resumed equals an uninterrupted one, bit for bit.
#[cfg(unix)]
#[test]
fn killed_bake_resumes_to_the_same_table() {
    let d = fresh_dir("resume");
    let twill = fabric("twill");
    let base = slow_bake(&twill);
    let t = ["-o", "t.bin"];
    let mut child = cmd(
        &d,
        &[
            &base[..],
            &t[..],
            &["--threads", "1", "--checkpoint-every", "0"],
        ]
        .concat(),
    )
    .spawn()
    .unwrap();
    let ck = d.join("t.bin.checkpoint");
    assert!(
        wait_for(&ck, Duration::from_secs(60)),
        "no checkpoint appeared"
    );
    std::thread::sleep(Duration::from_millis(100));
    child.kill().unwrap(); // SIGKILL
    let status = child.wait().unwrap();
    assert!(
        status.code().is_none(),
        "the bake ended before the kill: {status:?}"
    );
    assert!(
        !d.join("t.bin").exists(),
        "the bake finished before the kill"
    );
    // Without --resume an existing checkpoint is not overwritten.
    fails_with(
        &run_in(&d, &[&base[..], &t[..]].concat()),
        &["t.bin.checkpoint", "--resume"],
    );
    let out = run_in(
        &d,
        &[&base[..], &t[..], &["--resume", "--threads", "2"]].concat(),
    );
    succeeds(&out);
    let err = text(&out.stderr);
    let done: usize = err
        .split("rows done")
        .next()
        .and_then(|s| s.split(": ").last())
        .and_then(|s| s.split(" of ").next())
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or_else(|| panic!("no resume line: {err}"));
    assert!(done > 0 && done < 128, "{err}");
    assert!(!ck.exists(), "the checkpoint outlived the table");
    // The uninterrupted bake.
    succeeds(&run_in(
        &d,
        &[&base[..], &["-o", "u.bin", "--threads", "2"]].concat(),
    ));
    identical(&d, "u.bin", "t.bin");
}

/// SIGINT (Ctrl-C) saves a checkpoint; the resumed shard equals the shard baked at once.
#[cfg(unix)]
#[test]
fn interrupted_shard_resumes() {
    let d = fresh_dir("sigint");
    let twill = fabric("twill");
    let base = [
        &["bake"][..],
        &slow_bake(&twill),
        &["--shard", "1/2", "--threads", "1"],
    ]
    .concat();
    let every = ["--checkpoint-every", "0"];
    let child = cmd(&d, &[&base[..], &["-o", "a.shard"], &every[..]].concat())
        .spawn()
        .unwrap();
    assert!(wait_for(
        &d.join("a.shard.checkpoint"),
        Duration::from_secs(60)
    ));
    common::signal(&child, "INT");
    let out = child.wait_with_output().unwrap();
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(
        err.contains("a.shard.checkpoint") && err.contains("--resume"),
        "{err}"
    );
    succeeds(&run_in(
        &d,
        &[&base[..], &["-o", "a.shard", "--resume"]].concat(),
    ));
    succeeds(&run_in(&d, &[&base[..], &["-o", "b.shard"]].concat()));
    assert_eq!(
        std::fs::read(d.join("a.shard")).unwrap(),
        std::fs::read(d.join("b.shard")).unwrap()
    );
    assert_eq!(listing(&d), ["a.shard", "b.shard"]);
}
