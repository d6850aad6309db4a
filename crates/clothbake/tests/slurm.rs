//! A real single-node SLURM runs the documented job array of 4 shards and the merge step
//! (tests/slurm.sh, docs/cluster/*.sbatch); the merged table must equal a single bake, bit for
//! bit. Where SLURM and munge are not installed (Debian: `apt-get install slurm-wlm munge`,
//! as `.ci/run` does) or the test does not run as root (the daemons' user), it says so and
//! passes.

use std::path::{Path, PathBuf};
use std::process::Command;

const TOOLS: [&str; 7] = [
    "sbatch",
    "squeue",
    "sinfo",
    "slurmctld",
    "slurmd",
    "munged",
    "mungekey",
];

/// PATH with the system folders where Debian puts the daemons.
fn search_path() -> String {
    let mut p = std::env::var("PATH").unwrap_or_default();
    for d in ["/usr/sbin", "/sbin", "/usr/bin", "/bin"] {
        p.push(':');
        p.push_str(d);
    }
    p
}

fn find(tool: &str, path: &str) -> Option<PathBuf> {
    path.split(':')
        .map(|d| Path::new(d).join(tool))
        .find(|p| p.is_file())
}

#[cfg(unix)]
#[test]
fn slurm_job_array_bakes_and_merges_the_same_table() {
    let path = search_path();
    let missing: Vec<&str> = TOOLS
        .iter()
        .copied()
        .filter(|t| find(t, &path).is_none())
        .collect();
    if !missing.is_empty() {
        eprintln!(
            "SKIPPED slurm_job_array_bakes_and_merges_the_same_table: {} not installed \
             (apt-get install slurm-wlm munge)",
            missing.join(", ")
        );
        return;
    }
    let is_root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    if !is_root {
        eprintln!(
            "SKIPPED slurm_job_array_bakes_and_merges_the_same_table: the single-node SLURM \
             runs its daemons as root, and this test is not root"
        );
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let fabric = root.join("../../tables/twill.json").canonicalize().unwrap();
    let docs = root.join("../../docs/cluster").canonicalize().unwrap();
    let out = Command::new("bash")
        .arg(root.join("tests/slurm.sh"))
        .arg(env!("CARGO_BIN_EXE_clothbake"))
        .arg(&fabric)
        .arg(&docs)
        .env("PATH", &path)
        // The system's temporary directory, not the target's: munged refuses a socket below a
        // folder that others cannot search, as a checkout inside a `mktemp -d` folder (mode
        // 700) is. The script makes its own folder there and removes it on exit.
        .env("TMPDIR", std::env::temp_dir())
        .output()
        .expect("run tests/slurm.sh");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "tests/slurm.sh failed:\n{text}");
    assert!(
        text.contains("(4 shards) and merge job") && text.contains("every value is equal"),
        "{text}"
    );
}
