//! Hostile outputs and sizes, driving the built binary: special files, folders and inputs given
//! as outputs, two bakes to one output, grids that do not fit in memory, thread counts. Every
//! case: exit 2, one line naming the path (or the option) and the fix, nothing written or
//! replaced.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

mod common;

use common::{bake_in, cmd, fabric, listing, run_in, succeeds, text};

fn fails_with(out: &Output, needles: &[&str]) -> String {
    common::fails_with(out, 2, needles)
}

fn fresh_dir(name: &str) -> PathBuf {
    common::fresh_dir("limits-cli", name)
}

const RES: &str = "2,4,2,4";

/// Bakes `name` (a small binary table of the plain weave) in `d`.
fn small_table(d: &Path, name: &str) {
    let plain = fabric("plain");
    succeeds(&run_in(
        d,
        &["bake", "--weave", &plain, "--res", RES, "-o", name, "-q"],
    ));
}

#[cfg(unix)]
fn file_type(p: &Path) -> std::fs::FileType {
    std::fs::symlink_metadata(p).unwrap().file_type()
}

#[cfg(target_os = "linux")]
#[test]
fn devices_are_never_replaced() {
    use std::os::unix::fs::FileTypeExt;
    let d = fresh_dir("devices");
    let plain = fabric("plain");
    for dev in ["/dev/full", "/dev/null"] {
        let out = bake_in(&d, &plain, RES, &["-o", dev, "--force", "-q"]);
        fails_with(
            &out,
            &[
                dev,
                "cannot write the table",
                "character device",
                "regular file",
            ],
        );
        assert!(file_type(Path::new(dev)).is_char_device(), "{dev} replaced");
    }
    // A link to a device is refused too (rename would replace the link, e.g. /dev/stdout).
    std::os::unix::fs::symlink("/dev/null", d.join("null-link")).unwrap();
    let out = bake_in(&d, &plain, RES, &["-o", "null-link", "--force"]);
    fails_with(&out, &["null-link", "character device"]);
    assert!(file_type(&d.join("null-link")).is_symlink());
    assert_eq!(listing(&d), ["null-link"]);
}

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_even_with_force() {
    use std::os::unix::fs::FileTypeExt;
    let d = fresh_dir("fifo");
    let made = Command::new("mkfifo").arg(d.join("pipe")).status();
    if !matches!(made, Ok(s) if s.success()) {
        eprintln!("no mkfifo: skipped");
        return;
    }
    let plain = fabric("plain");
    let out = bake_in(&d, &plain, RES, &["-o", "pipe", "--force"]);
    fails_with(&out, &["pipe: cannot write the table", "FIFO"]);
    assert!(file_type(&d.join("pipe")).is_fifo());
    // Reading one neither blocks nor reads garbage.
    let out = run_in(&d, &["info", "pipe"]);
    fails_with(&out, &["pipe", "FIFO", "not a regular file"]);
    let out = run_in(&d, &["merge", "-o", "m.bin", "pipe"]);
    fails_with(&out, &["pipe", "FIFO"]);
    assert_eq!(listing(&d), ["pipe"]);
}

#[test]
fn a_folder_is_not_an_existing_file() {
    let d = fresh_dir("folder");
    std::fs::create_dir(d.join("out")).unwrap();
    std::fs::write(d.join("out/keep"), b"x").unwrap();
    let plain = fabric("plain");
    for force in [false, true] {
        let mut args = vec!["bake", "--weave", &plain, "--res", RES, "-o", "out"];
        if force {
            args.push("--force");
        }
        let e = fails_with(
            &run_in(&d, &args),
            &[
                "out: cannot write the table",
                "it is a folder",
                "path of a file",
            ],
        );
        assert!(!e.contains("already exists"), "{e}");
    }
    assert_eq!(listing(&d.join("out")), ["keep"]);
    // The same for the other commands that write.
    small_table(&d, "t.bin");
    let out = run_in(
        &d,
        &["render", "--table", "t.bin", "-o", "out", "--res", "8"],
    );
    fails_with(&out, &["out: cannot write the PNG image", "folder"]);
    let out = run_in(&d, &["export", "--table", "t.bin", "--merl", "out"]);
    fails_with(&out, &["out: cannot write the MERL file", "folder"]);
    assert_eq!(listing(&d), ["out", "t.bin"]);
}

#[test]
fn an_input_is_never_an_output() {
    let d = fresh_dir("inputs");
    let json = std::fs::read(fabric("plain")).unwrap();
    std::fs::write(d.join("plain.json"), &json).unwrap();
    // The fabric itself, by its own path and by another spelling of it.
    for o in [
        "plain.json",
        "./plain.json",
        "../limits-cli-inputs/plain.json",
    ] {
        let out = bake_in(
            &d,
            "plain.json",
            RES,
            &["-o", o, "--force", "--format", "exr"],
        );
        fails_with(
            &out,
            &[o, "an input of this command", "another output path"],
        );
    }
    // A hard link and a symbolic link to it.
    std::fs::hard_link(d.join("plain.json"), d.join("hard.exr")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink("plain.json", d.join("soft.exr")).unwrap();
    for o in ["hard.exr", "soft.exr"] {
        if !d.join(o).exists() {
            continue;
        }
        let out = bake_in(&d, "plain.json", RES, &["-o", o, "--force"]);
        fails_with(&out, &[o, "an input of this command (plain.json)"]);
    }
    assert_eq!(std::fs::read(d.join("plain.json")).unwrap(), json);

    // merge -o one of its shards.
    let base = ["bake", "--weave", "plain.json", "--res", RES, "-q"];
    for k in ["0/2", "1/2"] {
        succeeds(&run_in(&d, &[&base[..], &["--shard", k]].concat()));
    }
    let shard = "plain-0-of-2.shard";
    let before = std::fs::read(d.join(shard)).unwrap();
    let out = run_in(
        &d,
        &[
            "merge",
            "-o",
            shard,
            "--format",
            "bin",
            "--force",
            shard,
            "plain-1-of-2.shard",
        ],
    );
    fails_with(&out, &[shard, "an input of this command"]);
    assert_eq!(std::fs::read(d.join(shard)).unwrap(), before);

    // export and render over their table.
    succeeds(&run_in(
        &d,
        &["merge", "-o", "t.bin", shard, "plain-1-of-2.shard", "-q"],
    ));
    let table = std::fs::read(d.join("t.bin")).unwrap();
    let out = run_in(
        &d,
        &["export", "--table", "t.bin", "--merl", "t.bin", "--force"],
    );
    fails_with(&out, &["t.bin: cannot write the MERL file", "an input"]);
    let out = run_in(
        &d,
        &[
            "render", "--table", "t.bin", "-o", "r.png", "--exr", "t.bin", "--force", "--res", "8",
        ],
    );
    fails_with(&out, &["t.bin: cannot write the OpenEXR image", "an input"]);
    assert_eq!(std::fs::read(d.join("t.bin")).unwrap(), table);
    assert!(!d.join("r.png").exists(), "the PNG was written first");
}

#[test]
fn render_checks_both_outputs_before_writing_either() {
    let d = fresh_dir("render");
    small_table(&d, "t.bin");
    let out = run_in(
        &d,
        &[
            "render",
            "--table",
            "t.bin",
            "-o",
            "o.png",
            "--exr",
            "nodir/o.exr",
            "--res",
            "8",
        ],
    );
    fails_with(&out, &["nodir", "does not exist"]);
    // One file given for both.
    let out = run_in(
        &d,
        &[
            "render", "--table", "t.bin", "-o", "o.png", "--exr", "o.png", "--res", "8",
        ],
    );
    fails_with(
        &out,
        &[
            "o.png: cannot write the OpenEXR image",
            "the PNG image is written to the same file",
        ],
    );
    assert_eq!(listing(&d), ["t.bin"]);
}

/// Runs `args` in `d` under `sh` with writes beyond 0 bytes refused (`ulimit -f 0`, SIGXFSZ
/// ignored: writes fail with EFBIG), so that the atomic writer fails after the preflight.
#[cfg(target_os = "linux")]
fn run_without_room(d: &Path, args: &[&str]) -> Output {
    let mut c = Command::new("sh");
    c.arg("-c")
        .arg("trap '' XFSZ; ulimit -f 0 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_clothbake"))
        .args(args)
        .current_dir(d)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c.output().expect("run sh")
}

#[cfg(target_os = "linux")]
#[test]
fn write_errors_name_what_is_written() {
    let d = fresh_dir("write-errors");
    small_table(&d, "t.bin");
    let out = run_without_room(
        &d,
        &["render", "--table", "t.bin", "-o", "o.png", "--res", "8"],
    );
    let e = fails_with(&out, &["o.png: cannot write the PNG image", "PNG image"]);
    assert!(!e.contains("table"), "{e}");
    let plain = fabric("plain");
    let out = run_without_room(&d, &["--weave", &plain, "--res", RES, "-o", "u.exr"]);
    fails_with(&out, &["u.exr: cannot write the table"]);
    // No temporary file is left behind.
    assert_eq!(listing(&d), ["t.bin"], "{}", text(&out.stderr));
}

/// A bake of twill that takes minutes (two bounces on a fine grid), to be stopped by the test.
fn long_bake(d: &Path, threads: &str) -> std::process::Child {
    let twill = fabric("twill");
    cmd(
        d,
        &[
            "bake",
            "--weave",
            &twill,
            "--res",
            "16,64,16,64",
            "--bounces",
            "2",
            "--threads",
            threads,
            "--checkpoint-every",
            "100000",
            "-o",
            "t.bin",
            "-q",
        ],
    )
    .spawn()
    .expect("start a bake")
}

/// Waits until `<dir>/t.bin.lock` names process `pid` (the bake holds its lock), up to 2
/// minutes; false if the bake ended first.
fn wait_for_lock(d: &Path, child: &mut std::process::Child) -> bool {
    let start = std::time::Instant::now();
    let pid = child.id().to_string();
    while start.elapsed() < std::time::Duration::from_secs(120) {
        if std::fs::read_to_string(d.join("t.bin.lock")).is_ok_and(|s| s.trim() == pid) {
            return true;
        }
        if child.try_wait().unwrap().is_some() {
            return false;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    false
}

#[cfg(unix)]
#[test]
fn a_second_bake_to_one_output_is_refused_and_a_killed_one_does_not_block() {
    let d = fresh_dir("lock");
    let mut first = long_bake(&d, "1");
    assert!(wait_for_lock(&d, &mut first), "the first bake took no lock");
    let plain = fabric("plain");
    for force in [false, true] {
        let mut args = vec!["bake", "--weave", &plain, "--res", RES, "-o", "t.bin"];
        if force {
            args.push("--force");
        }
        let out = run_in(&d, &args);
        let pid = format!("process {}", first.id());
        fails_with(
            &out,
            &[
                "t.bin: another bake",
                &pid,
                "t.bin.lock",
                "another output path",
            ],
        );
    }
    // The loser wrote nothing: no checkpoint, no table.
    assert_eq!(listing(&d), ["t.bin.lock"]);
    // Killed (SIGKILL: no handler runs), it leaves its lock file, but not its lock.
    first.kill().unwrap();
    first.wait().unwrap();
    assert_eq!(listing(&d), ["t.bin.lock"]);
    succeeds(&run_in(
        &d,
        &["bake", "--weave", &plain, "--res", RES, "-o", "t.bin", "-q"],
    ));
    assert_eq!(listing(&d), ["t.bin"]);
}

#[cfg(unix)]
#[test]
fn sigterm_stops_a_bake_on_many_threads_promptly() {
    let d = fresh_dir("sigterm");
    let mut bake = long_bake(&d, "1024");
    assert!(wait_for_lock(&d, &mut bake), "the bake took no lock");
    std::thread::sleep(std::time::Duration::from_millis(300));
    let sent = std::time::Instant::now();
    common::signal(&bake, "TERM");
    let out = bake.wait_with_output().unwrap();
    // Generous: a loaded machine; before the cap, 100 000 threads ignored it for minutes.
    let took = sent.elapsed();
    assert!(took < std::time::Duration::from_secs(30), "{took:?}");
    assert_eq!(out.status.code(), Some(130), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("interrupted"),
        "{}",
        text(&out.stderr)
    );
    // The lock is gone with the bake; what was done is in the checkpoint, if anything.
    assert!(!d.join("t.bin.lock").exists());
    assert!(!d.join("t.bin").exists());
}

#[test]
fn sizes_beyond_the_limits_are_one_line_errors() {
    let d = fresh_dir("sizes");
    let plain = fabric("plain");
    let bake = |extra: &[&str]| {
        let mut args = vec!["bake", "--weave", plain.as_str(), "-o", "t.exr"];
        args.extend_from_slice(extra);
        run_in(&d, &args)
    };
    fails_with(
        &bake(&["--res", "4294967297,1,1,1"]),
        &[
            "NTI 4294967297 is too large (at most 2147483648",
            "32,64,32,64",
        ],
    );
    fails_with(
        &bake(&["--res", "2,99999999999999999999999,2,4"]),
        &["NPI 99999999999999999999999 is too large"],
    );
    fails_with(
        &bake(&["--res", "2,x,2,4"]),
        &["NPI `x` is not a whole number"],
    );
    fails_with(
        &bake(&["--threads", "100000"]),
        &["--threads 100000 is too large (at most 1024)", "cores"],
    );
    fails_with(
        &bake(&["--threads", "99999999999999999999999"]),
        &["too large (at most 1024)"],
    );
    assert_eq!(listing(&d), Vec::<String>::new());
}

/// `MemAvailable` of this machine in bytes (Linux).
#[cfg(target_os = "linux")]
fn mem_available() -> u64 {
    let info = std::fs::read_to_string("/proc/meminfo").unwrap();
    let line = info
        .lines()
        .find(|l| l.starts_with("MemAvailable:"))
        .unwrap();
    let kb: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kb * 1024
}

#[cfg(target_os = "linux")]
#[test]
fn a_grid_that_does_not_fit_in_memory_is_refused_up_front() {
    // 2^31 cells, inside the grid limit: the values alone are 25.8 GB, twice that at the end.
    let have = mem_available();
    if have > 50_000_000_000 {
        eprintln!("{have} bytes available: the grid would fit; skipped");
        return;
    }
    let d = fresh_dir("memory");
    let plain = fabric("plain");
    for extra in [&[][..], &["--format", "bin"][..], &["--shard", "1/2"][..]] {
        let mut args = vec![
            "bake",
            "--weave",
            plain.as_str(),
            "--res",
            "32768,65536,1,1",
        ];
        args.extend_from_slice(extra);
        let e = fails_with(
            &run_in(&d, &args),
            &[
                "grid 32768,65536,1,1 (2147483648 cells",
                "of memory to bake, but",
                "GB is available",
                "smaller --res",
                "--shard K/N",
            ],
        );
        // The estimate is at least the values.
        let need: f64 = e
            .split("needs about ")
            .nth(1)
            .and_then(|r| r.split(" GB").next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("{e}"));
        assert!(need >= 25.7, "{e}");
    }
    assert_eq!(listing(&d), Vec::<String>::new());
    // merge: from the shards' sizes, before reading any (a sparse file of twice the memory).
    let f = std::fs::File::create(d.join("big.shard")).unwrap();
    if f.set_len(2 * have).is_ok() {
        let out = run_in(&d, &["merge", "-o", "t.bin", "big.shard"]);
        fails_with(
            &out,
            &["merging these 1 shards", "of memory, but", "is available"],
        );
        assert_eq!(listing(&d), ["big.shard"]);
    }
}

/// Issue 53, problem 4: a large specular exponent with `--bounces 2` aborted ("memory
/// allocation of 743612802624 bytes failed", exit 134) from about 1e17 up, from the option and
/// from a fabric file. Every exponent the fabric schema takes now runs, in bounded memory: eval
/// (both facets), a bake (which leaves no lock) and a fabric file at 1e300.
#[test]
fn a_large_exponent_with_two_bounces_runs() {
    let d = fresh_dir("exponent");
    let i2 = |out: &Output| -> f64 {
        let s = succeeds(out);
        // The row `I_2  R G B` (not the header line `I_2 by ...`).
        s.lines()
            .filter(|l| l.starts_with("I_2 "))
            .find_map(|l| l.split_whitespace().nth(1)?.parse().ok())
            .unwrap_or_else(|| panic!("{s}"))
    };
    // The eval, on `weave` with `extra` flags.
    let eval = |weave: &str, extra: &[&str]| {
        let args = [
            "eval",
            "--weave",
            weave,
            "--bounces",
            "2",
            "--wi",
            "30,0",
            "--wo",
            "45,180",
        ];
        run_in(&d, &[&args[..], extra].concat())
    };
    for facet in ["huo", "lewis"] {
        let out = eval("basket", &["--exponent", "1e20", "--facet", facet]);
        let v = i2(&out);
        assert!(v.is_finite() && v > 0.0, "{facet}: I_2 {v}");
    }
    let json = std::fs::read_to_string(fabric("basket")).unwrap();
    let big = json.replace("\"exponent\": 10", "\"exponent\": 1e300");
    assert_ne!(big, json);
    std::fs::write(d.join("big.json"), big).unwrap();
    let out = eval("big.json", &[]);
    assert!(i2(&out).is_finite());
    succeeds(&bake_in(
        &d,
        "basket",
        RES,
        &["--exponent", "1e20", "--bounces", "2", "-o", "t.bin", "-q"],
    ));
    assert_eq!(listing(&d), ["big.json", "t.bin"]);
}

/// Issue 53, problem 1: a fitted export's texture maps (`<stem>.base.png`, `.scalars.png`,
/// `.tangent.png` beside the MaterialX and USD files) are outputs like the others, checked as
/// one set before the fit: a map that names the file of another output is refused with and
/// without --force, naming both, and nothing is written or replaced. A MaterialX and a USD file
/// of one stem in one folder share their maps, however the folder is spelled.
#[test]
fn a_texture_map_that_names_another_output_is_refused_before_the_fit() {
    let d = fresh_dir("maps");
    let cases: [(&[&str], &[&str]); 4] = [
        (
            &["--gltf", "x.base.png", "--mtlx", "x.mtlx"],
            &[
                "x.base.png: cannot write the texture map of x.mtlx",
                "the glTF file is written to the same file",
            ],
        ),
        (
            &["--blender", "x.tangent.png", "--usd", "x.usda"],
            &[
                "x.tangent.png: cannot write the texture map of x.usda",
                "the Blender module is written to the same file",
            ],
        ),
        (
            &[
                "--rgl",
                "./x.scalars.png",
                "--mtlx",
                "x.mtlx",
                "--usd",
                "x.usda",
            ],
            &[
                "x.scalars.png: cannot write the texture map of x.mtlx and x.usda",
                "the RGL file is written to the same file",
            ],
        ),
        (
            &["--usd", "a.usda", "--mtlx", "a.base.png"],
            &[
                "a.base.png: cannot write the texture map of a.usda",
                "the MaterialX file is written to the same file",
            ],
        ),
    ];
    for (outputs, needles) in cases {
        for force in [false, true] {
            let mut args = vec!["export", "--weave", "plain"];
            args.extend_from_slice(outputs);
            if force {
                args.push("--force");
            }
            let start = std::time::Instant::now();
            let e = fails_with(&run_in(&d, &args), needles);
            assert!(e.contains("give each output its own path"), "{e}");
            assert!(
                start.elapsed().as_secs() < 3,
                "{args:?}: refused after the fit"
            );
            assert_eq!(listing(&d), Vec::<String>::new(), "{args:?}");
        }
    }
    // An existing file at the map's path is left alone, even with --force.
    std::fs::write(d.join("x.base.png"), b"mine").unwrap();
    let out = run_in(
        &d,
        &[
            "export",
            "--weave",
            "plain",
            "--gltf",
            "x.base.png",
            "--mtlx",
            "x.mtlx",
            "--force",
        ],
    );
    fails_with(
        &out,
        &["x.base.png: cannot write the texture map of x.mtlx"],
    );
    assert_eq!(std::fs::read(d.join("x.base.png")).unwrap(), b"mine");
    std::fs::remove_file(d.join("x.base.png")).unwrap();
    // One stem in one folder, spelled two ways: one set of maps, written once.
    succeeds(&run_in(
        &d,
        &[
            "export", "--weave", "plain", "--mtlx", "x.mtlx", "--usd", "./x.usda", "-q",
        ],
    ));
    assert_eq!(
        listing(&d),
        [
            "x.base.png",
            "x.mtlx",
            "x.scalars.png",
            "x.tangent.png",
            "x.usda"
        ]
    );
}
