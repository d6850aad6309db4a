//! A real single-node SLURM runs the documented job array of 4 shards and the merge step
//! (tests/slurm.sh, docs/cluster/*.sbatch); the merged table must equal a single bake, bit for
//! bit. Ignored, with the reason, where SLURM and munge are not installed (Debian: `apt-get
//! install slurm-wlm munge`, as `.ci/run` does) or the tests do not run as root (the daemons'
//! user); under `CI` it runs and fails then. The `clothbake` binary is built in release mode
//! by a nested cargo, as the Python test does.

use clothbake_tests::fixtures::release_build;
use clothbake_tests::probe::{search_path, SLURM};
use std::path::Path;
use std::process::Command;

#[test]
#[cfg_attr(
    missing_slurm,
    ignore = "needs SLURM and munge, run as root: apt-get install slurm-wlm munge (as .ci/run does), and run the tests as root"
)]
fn slurm_job_array_bakes_and_merges_the_same_table() {
    SLURM.require();
    let path = search_path();
    let bin = release_build(&["clothbake"]).join("clothbake");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let fabric = root.join("../tables/twill.json").canonicalize().unwrap();
    let docs = root.join("../docs/cluster").canonicalize().unwrap();
    let out = Command::new("bash")
        .arg(root.join("slurm.sh"))
        .arg(&bin)
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
