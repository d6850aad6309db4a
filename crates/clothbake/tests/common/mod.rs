//! Helpers shared by the tests that drive the `clothbake` binary (each test file uses some).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

/// The absolute path of the shipped fabric `tables/<name>.json`.
pub fn fabric(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tables")
        .join(format!("{name}.json"))
        .canonicalize()
        .unwrap()
        .to_string_lossy()
        .into_owned()
}

/// A fresh, empty folder `<prefix>-<name>` for one test.
pub fn fresh_dir(prefix: &str, name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{prefix}-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Bytes as text (lossy).
pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Asserts exit status 0; returns stdout.
pub fn succeeds(out: &Output) -> String {
    assert_eq!(
        out.status.code(),
        Some(0),
        "stdout: {}\nstderr: {}",
        text(&out.stdout),
        text(&out.stderr)
    );
    text(&out.stdout)
}

/// Exit status `code`, nothing on stdout, one line `clothbake: ...` with every needle; returns
/// that line.
pub fn fails_with(out: &Output, code: i32, needles: &[&str]) -> String {
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "stderr: {err}");
    assert!(out.stdout.is_empty(), "stdout: {}", text(&out.stdout));
    assert!(
        err.ends_with('\n') && err.lines().count() == 1,
        "not one line: {err:?}"
    );
    assert!(err.starts_with("clothbake: "), "{err}");
    for n in needles {
        assert!(err.contains(n), "{err:?} does not contain {n:?}");
    }
    err
}

/// The names of the files in `dir`, sorted.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The `clothbake` binary run in `dir` with `args`, outside any SLURM or Kubernetes array job,
/// its output captured.
pub fn cmd(dir: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_clothbake"));
    c.args(args)
        .current_dir(dir)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

/// Runs [`cmd`] to its end.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    cmd(dir, args).output().expect("run the clothbake binary")
}

/// Sends the signal `sig` (`"INT"`, `"TERM"`, ...) to `child` with `kill`, which must succeed.
pub fn signal(child: &Child, sig: &str) {
    let sent = Command::new("kill")
        .arg(format!("-{sig}"))
        .arg(child.id().to_string())
        .status()
        .expect("run kill");
    assert!(sent.success(), "kill -{sig} {}", child.id());
}

/// The arguments `bake --weave <fabric> --res <res> <extra...>`.
pub fn bake_args<'a>(fabric: &'a str, res: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    [&["bake", "--weave", fabric, "--res", res][..], extra].concat()
}

/// Runs `clothbake bake --weave <fabric> --res <res> <extra...>` in `dir` to its end.
pub fn bake_in(dir: &Path, fabric: &str, res: &str, extra: &[&str]) -> Output {
    run_in(dir, &bake_args(fabric, res, extra))
}
