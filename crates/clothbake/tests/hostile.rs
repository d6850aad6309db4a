//! A replay of issue 18's family of hostile inputs, wider than its examples: magnitudes, sizes,
//! special files, outputs that are inputs, malformed drafts and tables, options past their
//! ranges. Every case must answer as docs/reference/limits.md promises: exit 2, one line on stderr
//! naming what is wrong, nothing on stdout, nothing written in the folder, no special file
//! replaced, within seconds; and no case's process may grow past 1 GB.
#![cfg(unix)]

use std::path::Path;
use std::time::{Duration, Instant};

mod common;

use common::{fabric, fresh_dir, listing, run_in, text};

/// The plain weave as JSON with the given warp and weft radius and spacing (written as JSON
/// numbers, so `1e400` reaches the parser as written).
fn plain(r: &str, s: &str) -> String {
    format!(
        r#"{{"pattern": [[1,0],[0,1]], "warp": {{"radius": {r}, "spacing": {s}}},
            "weft": {{"radius": {r}, "spacing": {s}}}}}"#
    )
}

/// The shipped denim draft with `old` replaced by `new` (which must occur).
fn denim_with(old: &str, new: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/denim.wif");
    let wif = std::fs::read_to_string(path).unwrap();
    assert!(wif.contains(old), "{old}");
    wif.replacen(old, new, 1)
}

/// A fabric of `rows` identical rows of `pairs` "1,0" pairs (`rows` x 2 `pairs` cells).
fn period(rows: usize, pairs: usize) -> String {
    let row = format!("[{}]", vec!["1,0"; pairs].join(","));
    format!(
        r#"{{"pattern": [{}], "warp": {{"radius": 1, "spacing": 2.5}},
            "weft": {{"radius": 1, "spacing": 2.5}}}}"#,
        vec![row.as_str(); rows].join(",")
    )
}

/// Writes the hostile input files into `d`.
fn inputs(d: &Path) {
    let w = |name: &str, bytes: &[u8]| std::fs::write(d.join(name), bytes).unwrap();
    w("r300.json", plain("1e300", "3.1e300").as_bytes());
    w("rm300.json", plain("1e-300", "3.1e-300").as_bytes());
    w("r400.json", plain("1e400", "3").as_bytes());
    w("rnan.json", plain("\"NaN\"", "3").as_bytes());
    w("rneg.json", plain("-1", "3").as_bytes());
    w("overlap.json", plain("1", "1.5").as_bytes());
    w("array.json", b"[1, 2, 3]");
    w("bom.json", b"\xef\xbb\xbf[1]");
    w("utf16.json", b"\xff\xfe{\x00}\x00");
    w("empty.json", b"");
    // Deterministic noise (an LCG): binary data as a draft, a fabric and tables.
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    let noise: Vec<u8> = (0..65_536)
        .map(|_| {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (x >> 56) as u8
        })
        .collect();
    w("noise.wif", &noise);
    w("noise.json", &noise);
    w("noise.bin", &noise);
    w(
        "noise.exr",
        &[&[0x76, 0x2f, 0x31, 0x01][..], &noise].concat(),
    );
    // Binary tables whose first length field claims 2^60 bytes (versions 1 and 2).
    for v in [1u32, 2] {
        let mut b = b"CLTHBAKE".to_vec();
        b.extend(v.to_le_bytes());
        b.extend((1u64 << 60).to_le_bytes());
        b.extend([b'x'; 64]);
        w(&format!("len60-v{v}.bin"), &b);
    }
    w(
        "spacing300.wif",
        denim_with("Spacing=0.03528", "Spacing=3.1e300").as_bytes(),
    );
    w(
        "spacing-300.wif",
        denim_with("Spacing=0.03528", "Spacing=1e-300").as_bytes(),
    );
    w(
        "threads1e9.wif",
        denim_with("Threads=4\nColor=1", "Threads=1000000000\nColor=1").as_bytes(),
    );
    w(
        "threads-huge.wif",
        denim_with(
            "Threads=4\nColor=1",
            "Threads=99999999999999999999999\nColor=1",
        )
        .as_bytes(),
    );
    w(
        "shafts.wif",
        denim_with("Shafts=4", "Shafts=1000000000").as_bytes(),
    );
    w(
        "colour.wif",
        denim_with("1=21,46,110", "1=21,46,1100").as_bytes(),
    );
    // Periods past the limits: one row of 70 000 columns; 2000 rows of 2000.
    w("wide.json", period(1, 35_000).as_bytes());
    w("cells.json", period(2000, 1000).as_bytes());
    std::fs::copy(fabric("twill"), d.join("self.json")).unwrap();
    // Another bake's lock and checkpoint (what `-o` must not take).
    w("x.exr.lock", b"12345\n");
    w("x.exr.checkpoint", b"CLTHBAKE rows of another bake");
    std::fs::create_dir(d.join("folder")).unwrap();
    // A sparse file of 1 GiB: refused from its size.
    std::fs::File::create(d.join("huge.json"))
        .unwrap()
        .set_len(1 << 30)
        .unwrap();
    for name in ["fifo.json", "fifo.exr"] {
        let ok = std::process::Command::new("mkfifo")
            .arg(d.join(name))
            .status()
            .unwrap();
        assert!(ok.success());
    }
}

/// The cases: a name and the command line, split at spaces, `TWILL` standing for the shipped
/// twill's path (run in the folder of [`inputs`]).
const CASES: &[(&str, &str)] = &[
    ("lengths of 1e300", "eval --weave r300.json"),
    ("lengths of 1e-300", "eval --weave rm300.json"),
    ("a length past f64", "eval --weave r400.json"),
    ("a length as a string", "eval --weave rnan.json"),
    ("a negative radius", "eval --weave rneg.json"),
    ("spacing under two radii", "eval --weave overlap.json"),
    ("JSON array at the top", "eval --weave array.json"),
    ("BOM before an array", "eval --weave bom.json"),
    ("UTF-16 text", "eval --weave utf16.json"),
    ("an empty fabric file", "eval --weave empty.json"),
    ("binary data as a draft", "eval --weave noise.wif"),
    ("binary data as a fabric", "eval --weave noise.json"),
    ("WIF Spacing=3.1e300", "eval --weave spacing300.wif"),
    ("WIF Spacing=1e-300", "eval --weave spacing-300.wif"),
    ("WIF Threads=1e9", "eval --weave threads1e9.wif"),
    ("WIF Threads past u64", "eval --weave threads-huge.wif"),
    ("WIF Shafts=1e9", "eval --weave shafts.wif"),
    ("WIF colour past its range", "eval --weave colour.wif"),
    ("70 000 threads in a group", "eval --weave wide.json"),
    ("a period of 4 M cells", "eval --weave cells.json"),
    ("a 1 GiB fabric file", "eval --weave huge.json"),
    ("a folder as the fabric", "eval --weave folder"),
    ("--weave /dev/zero", "eval --weave /dev/zero"),
    (
        "bake --weave /dev/urandom",
        "bake --weave /dev/urandom -o u.exr",
    ),
    ("--wi 91,0", "eval --weave TWILL --wi 91,0"),
    ("--wi nan,0", "eval --weave TWILL --wi nan,0"),
    ("--at inf,0", "eval --weave TWILL --at inf,0"),
    ("--bounces 65", "eval --weave TWILL --bounces 65"),
    (
        "--res past memory",
        "bake --weave TWILL --res 32768,65536,1,1 -o a.exr",
    ),
    (
        "--res past u32",
        "bake --weave TWILL --res 4294967297,2,2,2 -o b.exr",
    ),
    (
        "--res past 2^31 cells",
        "bake --weave TWILL --res 65536,65536,2,2 -o c.exr",
    ),
    (
        "--res with a 0",
        "bake --weave TWILL --res 0,2,2,2 -o d.exr",
    ),
    (
        "--threads 100000",
        "bake --weave TWILL --threads 100000 -o t.exr",
    ),
    ("-o a folder", "bake --weave TWILL --res 2,4,2,4 -o folder"),
    (
        "-o in no folder",
        "bake --weave TWILL --res 2,4,2,4 -o no/x.exr",
    ),
    (
        "-o the --weave file",
        "bake --weave self.json --res 2,4,2,4 -o self.json --force",
    ),
    (
        "-o a FIFO, --force",
        "bake --weave TWILL --res 2,4,2,4 -o fifo.exr --force",
    ),
    (
        "-o /dev/null, --force",
        "bake --weave TWILL --res 2,4,2,4 -o /dev/null --force",
    ),
    ("--weave a FIFO", "eval --weave fifo.json"),
    (
        "render --exr in no folder",
        "render --weave TWILL -o r.png --exr no/r.exr",
    ),
    (
        "render --res 100000,100000",
        "render --weave TWILL -o r.png --res 100000,100000",
    ),
    (
        "render --aa 1000000",
        "render --weave TWILL -o r.png --aa 1000000",
    ),
    (
        "render --eye nan",
        "render --weave TWILL -o r.png --eye nan,0,1",
    ),
    (
        "render --periods 1e300",
        "render --weave TWILL -o r.png --periods 1e300",
    ),
    (
        "export --rgl-res past memory",
        "export --weave TWILL --rgl e.bsdf --rgl-res 100000,100000,100000",
    ),
    (
        "export --klems-samples past its range",
        "export --weave TWILL --klems k.xml --klems-samples 1000000",
    ),
    (
        "export --klems onto the fabric",
        "export --weave TWILL --klems TWILL",
    ),
    (
        "plot 20 000 curves",
        "plot --weave TWILL -o p.png --theta-i LIST20000",
    ),
    (
        "plot 10 000 panels",
        "plot --weave TWILL -o p.png --phi-i LIST10000",
    ),
    (
        "polar plot 20 000 curves",
        "plot --weave TWILL --kind polar -o p.svg --theta-o LIST20000",
    ),
    ("info of binary data", "info noise.bin"),
    ("info of a bad OpenEXR", "info noise.exr"),
    ("info of a 2^60 length (v1)", "info len60-v1.bin"),
    ("info of a 2^60 length (v2)", "info len60-v2.bin"),
    ("info /dev/zero", "info /dev/zero"),
    ("info of a FIFO", "info fifo.exr"),
    ("diff of binary data", "diff noise.bin noise.exr"),
    ("merge -o one of its inputs", "merge noise.bin -o noise.bin"),
    // Render numbers whose arithmetic would overflow.
    (
        "render --eye 1e154 away",
        "render --weave TWILL -o r.png --eye 1e154,0,1",
    ),
    (
        "render --look-at 1e308",
        "render --weave TWILL -o r.png --look-at 0,1e308,0",
    ),
    (
        "render --light 1e308",
        "render --weave TWILL -o r.png --light 1e308,0,1",
    ),
    (
        "render --irradiance 1e308",
        "render --weave TWILL -o r.png --irradiance 1e308",
    ),
    (
        "render --exposure 1e308",
        "render --weave TWILL -o r.png --exposure 1e308",
    ),
    // Sample counts and seeds past their ranges.
    (
        "--samples 2^64 - 1",
        "eval --weave TWILL --method raytrace --samples 18446744073709551615",
    ),
    (
        "--samples 2^32",
        "eval --weave TWILL --method raytrace --samples 4294967296",
    ),
    (
        "--samples 1e9 with --bounces all",
        "eval --weave TWILL --bounces all --samples 1000000000",
    ),
    (
        "bake --samples 2^32",
        "bake --weave TWILL --method raytrace --samples 4294967296 --res 2,4,2,4 -o s.exr",
    ),
    (
        "--seed past u64",
        "eval --weave TWILL --method raytrace --seed 18446744073709551616",
    ),
    (
        "--res 100000 on every axis",
        "bake --weave TWILL --res 100000,100000,100000,100000 -o w.exr",
    ),
    // Names a bake owns: its lock and checkpoint, and temporary files, even with --force.
    (
        "bake -o a lock, --force",
        "bake --weave TWILL --res 2,4,2,4 -o x.exr.lock --force",
    ),
    (
        "bake -o a checkpoint, --force",
        "bake --weave TWILL --res 2,4,2,4 -o x.exr.checkpoint --force",
    ),
    (
        "render --exr a checkpoint",
        "render --weave TWILL -o r.png --exr y.exr.checkpoint --force",
    ),
    (
        "export -o a temporary name",
        "export --weave TWILL --rgl .e.bsdf.tmp-1-0 --force",
    ),
    ("merge -o a lock", "merge noise.bin -o t.exr.lock --force"),
];

/// The arguments of a case's command line: `TWILL` replaced by `twill`, `LIST<n>` by n angles;
/// `eval` given its directions where the line has none.
fn case_args(line: &str, twill: &str) -> Vec<String> {
    let mut v: Vec<String> = line
        .split(' ')
        .map(|w| match w.strip_prefix("LIST") {
            Some(n) => vec!["10"; n.parse().unwrap()].join(","),
            None if w == "TWILL" => twill.to_string(),
            None => w.to_string(),
        })
        .collect();
    if v[0] == "eval" {
        for (flag, dir) in [("--wi", "30,0"), ("--wo", "45,180")] {
            if !v.iter().any(|a| a == flag) {
                v.extend([flag.to_string(), dir.to_string()]);
            }
        }
    }
    v
}

/// The kind of each special file a case could replace, and the files a case could overwrite
/// (the fabric, another bake's lock and checkpoint).
fn guarded(d: &Path) -> (Vec<String>, Vec<Vec<u8>>) {
    let kinds = [
        Path::new("/dev/null").to_path_buf(),
        Path::new("/dev/zero").to_path_buf(),
        d.join("fifo.exr"),
        d.join("fifo.json"),
    ]
    .into_iter()
    .map(|p| format!("{:?}", std::fs::symlink_metadata(p).map(|m| m.file_type())))
    .collect();
    let files = ["self.json", "x.exr.lock", "x.exr.checkpoint"]
        .iter()
        .map(|f| std::fs::read(d.join(f)).unwrap())
        .collect();
    (kinds, files)
}

#[test]
fn every_hostile_input_gets_one_line_and_exit_2_with_nothing_written() {
    let d = fresh_dir("hostile", "replay");
    inputs(&d);
    let twill = fabric("twill");
    let mut failures = Vec::new();
    println!("{} hostile inputs", CASES.len());
    for &(name, line) in CASES {
        let before = (listing(&d), guarded(&d));
        let args = case_args(line, &twill);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let t0 = Instant::now();
        let out = run_in(&d, &args);
        let took = t0.elapsed();
        let err = text(&out.stderr);
        let after = (listing(&d), guarded(&d));
        let one_line = err.starts_with("clothbake: ") && err.lines().count() == 1;
        if out.status.code() != Some(2)
            || !one_line
            || !out.stdout.is_empty()
            || before != after
            || took > Duration::from_secs(20)
        {
            failures.push(format!(
                "{name}: status {:?}, {took:?}, stderr {err:?}, stdout {:?}, written: {}",
                out.status.code(),
                text(&out.stdout),
                before != after
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    #[cfg(target_os = "linux")]
    {
        // The largest resident set of any child so far (kilobytes on Linux).
        // SAFETY: getrusage writes into the zeroed struct it is given.
        let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
        assert_eq!(
            unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut ru) },
            0
        );
        assert!(
            ru.ru_maxrss < 1 << 20,
            "a case grew to {} MB",
            ru.ru_maxrss >> 10
        );
    }
}

/// Messages of numbers out of range: the one line names the number, the range and the fix. The
/// expected numbers are written out here (1e20 cells for 100000^4, not a wrapped count).
#[test]
fn numbers_out_of_range_name_their_range() {
    let d = fresh_dir("hostile", "ranges");
    let twill = fabric("twill");
    let cases: &[(&str, &[&str])] = &[
        (
            "bake --weave TWILL --res 100000,100000,100000,100000 -o w.exr",
            &["100000000000000000000 cells", "2^31"],
        ),
        (
            "eval --weave TWILL --method raytrace --seed 18446744073709551616",
            &[
                "--seed 18446744073709551616",
                "at most 18446744073709551615",
                "--seed 1",
            ],
        ),
        (
            "eval --weave TWILL --method raytrace --samples 18446744073709551615",
            &["at most 16777216", "--samples 100000"],
        ),
        (
            "render --weave TWILL -o r.png --irradiance 1e308",
            &["irradiance", "1000000", "e.g. 3.14159"],
        ),
        (
            "render --weave TWILL -o r.png --eye 1e154,0,1",
            &["[-1000000, 1000000]", "--eye"],
        ),
    ];
    for (line, needles) in cases {
        let args = case_args(line, &twill);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        common::fails_with(&run_in(&d, &args), 2, needles);
    }
}

/// A command that writes, for the signal replay: its arguments (`TWILL` for the twill's path),
/// its outputs, and the output whose temporary file, once seen, the signal is sent at (the last
/// one written, so that the others are already written and waiting).
struct Writer {
    name: &'static str,
    line: &'static str,
    outputs: &'static [&'static str],
    at: &'static str,
}

const WRITERS: &[Writer] = &[
    Writer {
        name: "render with --exr",
        line: "render --weave TWILL -o r.png --exr r.exr --res 700 --aa 1",
        outputs: &["r.png", "r.exr"],
        at: "r.exr",
    },
    Writer {
        name: "export of four files",
        line: "export --weave TWILL --rgl e.bsdf --rgl-spectral s.bsdf --merl m.binary \
               --rgl-res 8,12,32 --phi-samples 1 --klems k.xml --klems-samples 1",
        outputs: &["e.bsdf", "s.bsdf", "m.binary", "k.xml"],
        at: "m.binary",
    },
    Writer {
        name: "export of fitted materials (six files: three targets and the maps)",
        line: "export --weave plain --gltf f.glb --mtlx f.mtlx --blender f.py",
        outputs: &[
            "f.glb",
            "f.mtlx",
            "f.py",
            "f.base.png",
            "f.scalars.png",
            "f.tangent.png",
        ],
        at: "f.glb",
    },
    Writer {
        name: "merge",
        line: "merge -o t.exr --precision f32 a.shard b.shard",
        outputs: &["t.exr"],
        at: "t.exr",
    },
    Writer {
        name: "bake",
        line: "bake --weave TWILL --res 16,32,32,64 -o b.exr --precision f32",
        outputs: &["b.exr"],
        at: "b.exr",
    },
];

/// Whether `name` is a temporary, probe, lock or checkpoint file (what an interrupted write
/// could leave).
fn leftover(name: &str) -> bool {
    name.contains(".tmp-")
        || name.contains(".probe-")
        || name.ends_with(".lock")
        || name.ends_with(".checkpoint")
}

/// SIGINT, SIGTERM and SIGHUP sent while each writing command writes its last output (its
/// temporary file seen in the folder): the command either ends with exit 130, one line, and
/// none of its outputs, or (a bake, which finishes the write it began) with exit 0 and every
/// output whole; no temporary, lock or checkpoint file is left. "Whole" is the bytes of the
/// same command run to its end without a signal (the outputs are reproducible).
#[cfg(target_os = "linux")]
#[test]
fn a_signal_during_the_write_leaves_every_output_whole_or_none() {
    let base = fresh_dir("hostile", "signals");
    let twill = fabric("twill");
    // The shards that merge reads.
    for (k, name) in ["a.shard", "b.shard"].iter().enumerate() {
        let shard = format!("{k}/2");
        let out = run_in(
            &base,
            &[
                "bake",
                "-q",
                "--weave",
                &twill,
                "--res",
                "16,32,32,64",
                "--shard",
                &shard,
                "-o",
                name,
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    }
    let setup = |d: &Path| {
        for s in ["a.shard", "b.shard"] {
            std::fs::copy(base.join(s), d.join(s)).unwrap();
        }
    };
    let mut failures = Vec::new();
    for w in WRITERS {
        let args = case_args(w.line, &twill);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        // The reference: the same command run to its end.
        let reference = fresh_dir("hostile", &format!("signals-ref-{}", w.at));
        setup(&reference);
        let out = run_in(&reference, &args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}: {}",
            w.name,
            text(&out.stderr)
        );
        let whole: Vec<Vec<u8>> = w
            .outputs
            .iter()
            .map(|o| std::fs::read(reference.join(o)).unwrap())
            .collect();
        for (sig, sig_name) in [
            (libc::SIGINT, "SIGINT"),
            (libc::SIGTERM, "SIGTERM"),
            (libc::SIGHUP, "SIGHUP"),
        ] {
            let case = format!("{} ({sig_name})", w.name);
            let prefix = format!(".{}.tmp-", w.at);
            // The write can be missed (the command may finish between two looks): try again.
            let mut caught = None;
            for attempt in 0..5 {
                let d = fresh_dir("hostile", &format!("signals-{}-{sig}-{attempt}", w.at));
                setup(&d);
                let mut child = common::cmd(&d, &args).spawn().unwrap();
                let mut seen = false;
                while child.try_wait().unwrap().is_none() {
                    if listing(&d).iter().any(|n| n.starts_with(&prefix)) {
                        // SAFETY: kill sends a signal to our own child process.
                        assert_eq!(unsafe { libc::kill(child.id() as i32, sig) }, 0);
                        seen = true;
                        break;
                    }
                }
                let out = child.wait_with_output().unwrap();
                if seen {
                    caught = Some((d, out));
                    break;
                }
            }
            let Some((d, out)) = caught else {
                failures.push(format!("{case}: the write was never caught in 5 runs"));
                continue;
            };
            let names = listing(&d);
            let left: Vec<&String> = names.iter().filter(|n| leftover(n)).collect();
            let present: Vec<bool> = w.outputs.iter().map(|o| d.join(o).exists()).collect();
            let err = text(&out.stderr);
            let verdict = match out.status.code() {
                Some(130) if present.iter().all(|p| !p) => (err.lines().count() == 1
                    && err.starts_with("clothbake: interrupted"))
                .then_some(())
                .ok_or("exit 130 without one line `clothbake: interrupted...`"),
                // The signal came as the set was moved into place: all whole, and said so.
                Some(130) if err.contains("written whole") => w
                    .outputs
                    .iter()
                    .zip(&whole)
                    .all(|(o, b)| std::fs::read(d.join(o)).ok().as_ref() == Some(b))
                    .then_some(())
                    .ok_or("exit 130 saying the outputs are whole, and they are not"),
                Some(130) => Err("exit 130 with some outputs written"),
                Some(0) => w
                    .outputs
                    .iter()
                    .zip(&whole)
                    .all(|(o, b)| std::fs::read(d.join(o)).ok().as_ref() == Some(b))
                    .then_some(())
                    .ok_or("exit 0 with an output missing or not whole"),
                _ => Err("neither exit 130 nor 0"),
            };
            if let Err(why) = verdict {
                failures.push(format!(
                    "{case}: {why}: status {:?}, outputs present {present:?}, stderr {err:?}",
                    out.status
                ));
            }
            if !left.is_empty() {
                failures.push(format!("{case}: left {left:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Runs `args` in `dir` and returns its exit status and its largest resident set in bytes
/// (`wait4`'s rusage of that child alone).
#[cfg(target_os = "linux")]
fn peak_rss(dir: &Path, args: &[&str]) -> (i32, u64) {
    // Reaped by wait4 below, not by Child::wait.
    #[allow(clippy::zombie_processes)]
    let child = common::cmd(dir, args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut status = 0;
    // SAFETY: wait4 writes the status and the zeroed rusage of our own child.
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut ru) };
    assert_eq!(pid, child.id() as i32);
    (libc::WEXITSTATUS(status), ru.ru_maxrss as u64 * 1024)
}

/// An export stays within the memory bound docs/reference/limits-output.md states, written out here:
/// 64 MiB for the program, 16 bytes a texel of the slices held (and 64 a slice), 192 bytes a
/// texel of each worker's slice, 1 MiB + 64 KiB of buffers; MERL 80 bytes a cell of its
/// 90 x 90 x 180 and 144 bytes a rotation per worker. The spectral file alone (26 f32 a texel)
/// is more than the bound's slices: it must be streamed, not held.
#[cfg(target_os = "linux")]
#[test]
fn an_export_keeps_its_memory_bound() {
    let d = fresh_dir("hostile", "export-memory");
    let twill = fabric("twill");
    let (nt, np, n, threads) = (16u64, 16u64, 128u64, 2u64);
    let res = format!("{nt},{np},{n}");
    let texels = n * n;
    let slices = nt * np;
    let rgl = slices * (16 * texels + 64) + threads * 192 * texels + (1 << 20) + (1 << 16);
    let merl = 80 * 90 * 90 * 180 + 12 + threads * 144 * 4;
    let bound = (64 << 20) + rgl + merl;
    let (code, rss) = peak_rss(
        &d,
        &[
            "export",
            "--weave",
            &twill,
            "--rgl",
            "e.bsdf",
            "--rgl-spectral",
            "s.bsdf",
            "--merl",
            "m.binary",
            "--rgl-res",
            &res,
            "--threads",
            "2",
        ],
    );
    assert_eq!(code, 0);
    let spectral = std::fs::metadata(d.join("s.bsdf")).unwrap().len();
    assert!(spectral > slices * 16 * texels * 6, "{spectral}");
    println!(
        "export --rgl-res {res} with MERL: peak {:.1} MB, bound {:.1} MB, spectral file {:.1} MB",
        rss as f64 / 1e6,
        bound as f64 / 1e6,
        spectral as f64 / 1e6
    );
    assert!(rss <= bound, "peak {rss} bytes above the bound {bound}");
}

/// A container file (binary table, shard, checkpoint) with its kind set to `kind`, its header
/// JSON changed by `edit` and its values by `values`, its lengths and CRC made right again
/// (layout: docs/reference/table-format.md).
fn rewrite_container(
    bytes: &[u8],
    kind: &str,
    edit: impl FnOnce(&mut serde_json::Value),
    values: impl FnOnce(&mut [u8]),
) -> Vec<u8> {
    let header_len = u64::from_le_bytes(bytes[28..36].try_into().unwrap()) as usize;
    let mut header: serde_json::Value =
        serde_json::from_slice(&bytes[44..44 + header_len]).unwrap();
    edit(&mut header);
    let header = serde_json::to_vec(&header).unwrap();
    let mut out = bytes[..12].to_vec();
    let mut tag = [0u8; 16];
    tag[..kind.len()].copy_from_slice(kind.as_bytes());
    out.extend(tag);
    out.extend((header.len() as u64).to_le_bytes());
    out.extend(&bytes[36..44]);
    out.extend(&header);
    let mut vals = bytes[44 + header_len..bytes.len() - 4].to_vec();
    values(&mut vals);
    out.extend(vals);
    let crc = crc32fast::hash(&out);
    out.extend(crc.to_le_bytes());
    out
}

/// The messages the issue found misleading now name the right cause: a negative value in a
/// checkpoint is the checkpoint's fault (not the model's), a damaged CRC attribute is not
/// "stored 0x00000000", control characters in a JSON fabric's name are refused, and a fabric
/// whose header would overflow is refused before the bake.
#[test]
fn misleading_messages_name_the_right_cause() {
    let d = fresh_dir("hostile", "messages");
    let twill = fabric("twill");
    let ok = |args: &[&str]| {
        let out = run_in(&d, args);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    };
    // A checkpoint of shard 0/1 holding -1 in its first value.
    ok(&[
        "bake", "-q", "--weave", &twill, "--res", "2,4,2,4", "--shard", "0/1", "-o", "s.shard",
    ]);
    let shard = std::fs::read(d.join("s.shard")).unwrap();
    let bad = rewrite_container(
        &shard,
        "checkpoint",
        |_| {},
        |v| v[..4].copy_from_slice(&(-1.0f32).to_le_bytes()),
    );
    std::fs::write(d.join("t.shard.checkpoint"), bad).unwrap();
    let out = run_in(
        &d,
        &[
            "bake", "--weave", &twill, "--res", "2,4,2,4", "--shard", "0/1", "-o", "t.shard",
            "--resume",
        ],
    );
    let line = common::fails_with(&out, 2, &["t.shard.checkpoint", "-1", "delete"]);
    assert!(!line.contains("fabric's sizes"), "{line}");
    assert!(!d.join("t.shard").exists());
    // An OpenEXR table whose CRC attribute is not hexadecimal.
    ok(&[
        "bake", "-q", "--weave", &twill, "--res", "2,4,2,4", "-o", "c.exr",
    ]);
    let mut exr = std::fs::read(d.join("c.exr")).unwrap();
    let name = b"clothbake.crc32\0string\0";
    let at = exr.windows(name.len()).position(|w| w == name).unwrap() + name.len() + 4;
    exr[at..at + 8].copy_from_slice(b"zzzzzzzz");
    std::fs::write(d.join("c.exr"), exr).unwrap();
    let line = common::fails_with(
        &run_in(&d, &["info", "c.exr"]),
        2,
        &[
            "c.exr",
            "clothbake.crc32",
            "zzzzzzzz",
            "8 hexadecimal digits",
        ],
    );
    assert!(!line.contains("0x00000000"), "{line}");
    // A JSON fabric named with an escape sequence.
    let twill_json = std::fs::read_to_string(&twill).unwrap();
    let named = twill_json.replacen("\"twill\"", "\"tw\\u001b[31mill\"", 1);
    assert_ne!(named, twill_json);
    std::fs::write(d.join("esc.json"), named).unwrap();
    let line = common::fails_with(
        &run_in(
            &d,
            &[
                "eval", "--weave", "esc.json", "--wi", "30,0", "--wo", "45,180",
            ],
        ),
        2,
        &["esc.json", "name", "U+001B"],
    );
    assert!(!line.contains('\u{1b}'));
    // A table made before: its fabric's name carries the escape; info shows it escaped.
    ok(&[
        "bake", "-q", "--weave", &twill, "--res", "2,4,2,4", "-o", "n.bin",
    ]);
    let table = std::fs::read(d.join("n.bin")).unwrap();
    let renamed = rewrite_container(
        &table,
        "table",
        |h| {
            let f = h["fabric_json"].as_str().unwrap().replacen(
                "\"name\":\"twill\"",
                "\"name\":\"tw\\u001b[31mill\",\"notes\":[\"a\\u001b[2Jb\"]",
                1,
            );
            h["fabric_json"] = f.into();
        },
        |_| {},
    );
    std::fs::write(d.join("n.bin"), renamed).unwrap();
    let out = run_in(&d, &["info", "n.bin"]);
    let shown = common::succeeds(&out);
    assert!(!shown.contains('\u{1b}'), "{shown:?}");
    assert!(shown.contains("tw\\u{1b}[31mill"), "{shown}");
    assert!(shown.contains("a\\u{1b}[2Jb"), "{shown}");
    // A fabric of 15 MB whose notes (quotes, 2 bytes in the file) take 4 bytes each in a
    // header: refused before the bake (a bake of this grid takes seconds), nothing written.
    let quotes = "\\\"".repeat(7_500_000);
    let big = twill_json.replacen('{', &format!("{{\"notes\": [\"{quotes}\"],"), 1);
    assert!(big.len() > 15_000_000 && big.len() < 16 << 20);
    std::fs::write(d.join("notes.json"), big).unwrap();
    let before = listing(&d);
    let t0 = Instant::now();
    common::fails_with(
        &run_in(
            &d,
            &[
                "bake",
                "--weave",
                "notes.json",
                "--res",
                "32,64,32,64",
                "-o",
                "big.exr",
            ],
        ),
        2,
        &["notes.json", "header", "notes", "nothing was baked"],
    );
    assert!(t0.elapsed() < Duration::from_secs(10), "{:?}", t0.elapsed());
    assert_eq!(listing(&d), before);
}

/// A WIF draft with CR-only line endings (old Macintosh files) reads as the same draft with LF
/// endings: the same answer.
#[test]
fn a_draft_with_cr_line_endings_reads_like_lf() {
    let d = fresh_dir("hostile", "cr-draft");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/denim.wif");
    let lf = std::fs::read_to_string(path).unwrap().replace("\r\n", "\n");
    std::fs::write(d.join("lf.wif"), &lf).unwrap();
    std::fs::write(d.join("cr.wif"), lf.replace('\n', "\r")).unwrap();
    let eval = |f: &str| {
        common::succeeds(&run_in(
            &d,
            &[
                "eval", "--weave", f, "--wi", "30,0", "--wo", "45,180", "--json",
            ],
        ))
    };
    let (a, b) = (eval("lf.wif"), eval("cr.wif"));
    assert_eq!(a.replace("lf.wif", "cr.wif"), b);
}

/// A period larger than `--variant sliced3d` takes (docs/reference/limits.md: 16 384 cells) is refused by
/// every command that builds the model, with one line naming the file, the variant, the size
/// and the fix, before any work on it; the same period is evaluated with the other variants.
#[test]
fn a_period_too_large_for_sliced3d_is_refused_before_work() {
    let d = fresh_dir("hostile", "sliced3d");
    // 130 x 129 = 16 770 cells.
    std::fs::write(d.join("big.json"), period(129, 65)).unwrap();
    let cases: [&[&str]; 4] = [
        &[
            "eval",
            "--weave",
            "big.json",
            "--variant",
            "sliced3d",
            "--wi",
            "30,0",
            "--wo",
            "45,180",
        ],
        &[
            "bake",
            "--weave",
            "big.json",
            "--variant",
            "sliced3d",
            "--res",
            "2,4,2,4",
            "-o",
            "b.exr",
        ],
        &[
            "render",
            "--weave",
            "big.json",
            "--variant",
            "sliced3d",
            "-o",
            "r.png",
        ],
        &[
            "export",
            "--weave",
            "big.json",
            "--variant",
            "sliced3d",
            "--merl",
            "m.binary",
        ],
    ];
    for args in cases {
        let out = run_in(&d, args);
        common::fails_with(
            &out,
            2,
            &[
                "big.json",
                "sliced3d",
                "16384 cells",
                "130 x 129",
                "sliced or refined",
            ],
        );
    }
    for f in ["b.exr", "r.png", "m.binary"] {
        assert!(!d.join(f).exists(), "{f} written");
    }
    let out = run_in(
        &d,
        &[
            "eval",
            "--weave",
            "big.json",
            "--variant",
            "sliced",
            "--wi",
            "30,0",
            "--wo",
            "45,180",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
}
