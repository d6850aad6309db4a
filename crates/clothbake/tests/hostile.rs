//! A replay of issue 18's family of hostile inputs, wider than its examples: magnitudes, sizes,
//! special files, outputs that are inputs, malformed drafts and tables, options past their
//! ranges. Every case must answer as docs/limits.md promises: exit 2, one line on stderr
//! naming what is wrong, nothing on stdout, nothing written in the folder, no special file
//! replaced, within seconds; and no case's process may grow past 1 GB.

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
    let period = |rows: usize, pairs: usize| {
        let row = format!("[{}]", vec!["1,0"; pairs].join(","));
        format!(
            r#"{{"pattern": [{}], "warp": {{"radius": 1, "spacing": 2.5}},
                "weft": {{"radius": 1, "spacing": 2.5}}}}"#,
            vec![row.as_str(); rows].join(",")
        )
    };
    w("wide.json", period(1, 35_000).as_bytes());
    w("cells.json", period(2000, 1000).as_bytes());
    std::fs::copy(fabric("twill"), d.join("self.json")).unwrap();
    std::fs::create_dir(d.join("folder")).unwrap();
    // A sparse file of 1 GiB: refused from its size.
    std::fs::File::create(d.join("huge.json"))
        .unwrap()
        .set_len(1 << 30)
        .unwrap();
    #[cfg(unix)]
    for name in ["fifo.json", "fifo.exr"] {
        let ok = std::process::Command::new("mkfifo")
            .arg(d.join(name))
            .status()
            .unwrap();
        assert!(ok.success());
    }
}

/// The cases: a name, then the arguments (run in the folder of [`inputs`]).
fn cases(twill: &str) -> Vec<(&'static str, Vec<String>)> {
    let eval = |weave: &str| {
        let a = ["eval", "--weave", weave, "--wi", "30,0", "--wo", "45,180"];
        a.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let args = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let mut v: Vec<(&str, Vec<String>)> = vec![
        ("lengths of 1e300", eval("r300.json")),
        ("lengths of 1e-300", eval("rm300.json")),
        ("a length past f64", eval("r400.json")),
        ("a length as a string", eval("rnan.json")),
        ("a negative radius", eval("rneg.json")),
        ("spacing under two radii", eval("overlap.json")),
        ("JSON array at the top", eval("array.json")),
        ("BOM before an array", eval("bom.json")),
        ("UTF-16 text", eval("utf16.json")),
        ("an empty fabric file", eval("empty.json")),
        ("binary data as a draft", eval("noise.wif")),
        ("binary data as a fabric", eval("noise.json")),
        ("WIF Spacing=3.1e300", eval("spacing300.wif")),
        ("WIF Spacing=1e-300", eval("spacing-300.wif")),
        ("WIF Threads=1e9", eval("threads1e9.wif")),
        ("WIF Threads past u64", eval("threads-huge.wif")),
        ("WIF Shafts=1e9", eval("shafts.wif")),
        ("WIF colour past its range", eval("colour.wif")),
        ("70 000 threads in a group", eval("wide.json")),
        ("a period of 4 M cells", eval("cells.json")),
        ("a 1 GiB fabric file", eval("huge.json")),
        ("a folder as the fabric", eval("folder")),
        ("--weave /dev/zero", eval("/dev/zero")),
        (
            "bake --weave /dev/urandom",
            args(&["bake", "--weave", "/dev/urandom", "-o", "u.exr"]),
        ),
        (
            "--wi 91,0",
            args(&["eval", "--weave", twill, "--wi", "91,0", "--wo", "4,0"]),
        ),
        (
            "--wi nan,0",
            args(&["eval", "--weave", twill, "--wi", "nan,0", "--wo", "4,0"]),
        ),
        (
            "--at inf,0",
            args(&[
                "eval", "--weave", twill, "--wi", "3,0", "--wo", "4,0", "--at", "inf,0",
            ]),
        ),
        (
            "--bounces 65",
            args(&[
                "eval",
                "--weave",
                twill,
                "--wi",
                "3,0",
                "--wo",
                "4,0",
                "--bounces",
                "65",
            ]),
        ),
        (
            "--res past memory",
            args(&[
                "bake",
                "--weave",
                twill,
                "--res",
                "32768,65536,1,1",
                "-o",
                "a.exr",
            ]),
        ),
        (
            "--res past u32",
            args(&[
                "bake",
                "--weave",
                twill,
                "--res",
                "4294967297,2,2,2",
                "-o",
                "b.exr",
            ]),
        ),
        (
            "--res past 2^31 cells",
            args(&[
                "bake",
                "--weave",
                twill,
                "--res",
                "65536,65536,2,2",
                "-o",
                "c.exr",
            ]),
        ),
        (
            "--res with a 0",
            args(&["bake", "--weave", twill, "--res", "0,2,2,2", "-o", "d.exr"]),
        ),
        (
            "--threads 100000",
            args(&[
                "bake",
                "--weave",
                twill,
                "--threads",
                "100000",
                "-o",
                "t.exr",
            ]),
        ),
        (
            "-o a folder",
            args(&["bake", "--weave", twill, "--res", "2,4,2,4", "-o", "folder"]),
        ),
        (
            "-o in no folder",
            args(&[
                "bake", "--weave", twill, "--res", "2,4,2,4", "-o", "no/x.exr",
            ]),
        ),
        (
            "-o the --weave file, --force",
            args(&[
                "bake",
                "--weave",
                "self.json",
                "--res",
                "2,4,2,4",
                "-o",
                "self.json",
                "--force",
            ]),
        ),
        (
            "render --exr in no folder",
            args(&[
                "render", "--weave", twill, "-o", "r.png", "--exr", "no/r.exr",
            ]),
        ),
        (
            "render --res 100000,100000",
            args(&[
                "render",
                "--weave",
                twill,
                "-o",
                "r.png",
                "--res",
                "100000,100000",
            ]),
        ),
        (
            "render --aa 1000000",
            args(&["render", "--weave", twill, "-o", "r.png", "--aa", "1000000"]),
        ),
        (
            "render --eye nan",
            args(&[
                "render", "--weave", twill, "-o", "r.png", "--eye", "nan,0,1",
            ]),
        ),
        (
            "render --periods 1e300",
            args(&[
                "render",
                "--weave",
                twill,
                "-o",
                "r.png",
                "--periods",
                "1e300",
            ]),
        ),
        (
            "export --rgl-res past memory",
            args(&[
                "export",
                "--weave",
                twill,
                "--rgl",
                "e.bsdf",
                "--rgl-res",
                "100000,100000,100000",
            ]),
        ),
        ("info of binary data", args(&["info", "noise.bin"])),
        ("info of a bad OpenEXR", args(&["info", "noise.exr"])),
        (
            "info of a 2^60 length (v1)",
            args(&["info", "len60-v1.bin"]),
        ),
        (
            "info of a 2^60 length (v2)",
            args(&["info", "len60-v2.bin"]),
        ),
        ("info /dev/zero", args(&["info", "/dev/zero"])),
        (
            "diff of binary data",
            args(&["diff", "noise.bin", "noise.exr"]),
        ),
        (
            "merge -o one of its inputs",
            args(&["merge", "noise.bin", "-o", "noise.bin"]),
        ),
    ];
    let theta_i = vec!["10"; 20_000].join(",");
    let phi_i = vec!["10"; 10_000].join(",");
    let plot = |list: &str, values: &str, kind: &str, out: &str| {
        args(&[
            "plot", "--weave", twill, "--kind", kind, "-o", out, list, values,
        ])
    };
    v.extend([
        (
            "plot with 20 000 incidences",
            plot("--theta-i", &theta_i, "slices", "p.png"),
        ),
        (
            "plot with 10 000 panels",
            plot("--phi-i", &phi_i, "slices", "p.png"),
        ),
        (
            "polar plot with 20 000 curves",
            plot("--theta-o", &theta_i, "polar", "p.svg"),
        ),
    ]);
    #[cfg(unix)]
    v.extend([
        ("--weave a FIFO", eval("fifo.json")),
        ("info of a FIFO", args(&["info", "fifo.exr"])),
        (
            "-o a FIFO, --force",
            args(&[
                "bake", "--weave", twill, "--res", "2,4,2,4", "-o", "fifo.exr", "--force",
            ]),
        ),
        (
            "-o /dev/null, --force",
            args(&[
                "bake",
                "--weave",
                twill,
                "--res",
                "2,4,2,4",
                "-o",
                "/dev/null",
                "--force",
            ]),
        ),
    ]);
    v
}

/// The kind of each special file a case could replace, and the fabric a case could overwrite.
fn guarded(d: &Path) -> (Vec<String>, Vec<u8>) {
    let kinds = [
        Path::new("/dev/null").to_path_buf(),
        Path::new("/dev/zero").to_path_buf(),
        d.join("fifo.exr"),
        d.join("fifo.json"),
    ]
    .into_iter()
    .map(|p| format!("{:?}", std::fs::symlink_metadata(p).map(|m| m.file_type())))
    .collect();
    (kinds, std::fs::read(d.join("self.json")).unwrap())
}

#[test]
fn every_hostile_input_gets_one_line_and_exit_2_with_nothing_written() {
    let d = fresh_dir("hostile", "replay");
    inputs(&d);
    let twill = fabric("twill");
    let mut failures = Vec::new();
    let cases = cases(&twill);
    println!("{} hostile inputs", cases.len());
    for (name, args) in cases {
        let before = (listing(&d), guarded(&d));
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
