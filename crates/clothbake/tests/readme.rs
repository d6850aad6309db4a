//! The shell examples of README.md and of every docs/**/*.md run in order in a fresh folder, as a
//! new user would run them from a fresh clone: every line of every ```sh or ```bash block of
//! the file, with the built `clothbake` first on PATH and `tables/` of the repository beside
//! them (read only). One test per file, each in its own folder.
//!
//! Conventions of the documents that this test relies on:
//! * A block right after the line `<!-- readme-test: skip (why) -->` is not run: blocks that
//!   install, build or run the test suite (`cargo install`, `cargo xtask test`, `pip install`)
//!   or need what a test cannot have (a SLURM or Kubernetes cluster, GNU parallel); the reason
//!   is in the marker.
//! * `cargo run --release -p clothbake -- ARGS` runs as `clothbake ARGS` (the binary under test).
//! * Any other `cargo`, `pip` or `python` line in a block that is run fails this test: mark its
//!   block instead.
//! * Every command must exit 0; `clothbake diff` may exit 1 (tables beyond the tolerance).
//!
//! Commands run one by one (`bash -c`), so that a failure names its line; outputs must not
//! collide (an existing output is an error without `--force`, so collisions fail here).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

mod common;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

/// One shell command of the README and the line it starts on.
struct Line {
    number: usize,
    command: String,
}

/// The commands of the README's runnable shell blocks, in order.
fn commands(readme: &str) -> Vec<Line> {
    let mut out = Vec::new();
    let mut in_block = false;
    let mut run_block = false;
    let mut previous = "";
    let mut pending: Option<Line> = None;
    for (i, raw) in readme.lines().enumerate() {
        let line = raw.trim_end();
        if !in_block {
            if let Some(info) = line.strip_prefix("```") {
                in_block = true;
                run_block = matches!(info.trim(), "sh" | "bash")
                    && !previous.trim_start().starts_with("<!-- readme-test: skip");
            }
            if !line.trim().is_empty() {
                previous = raw;
            }
            continue;
        }
        if line.starts_with("```") {
            in_block = false;
            previous = "";
            continue;
        }
        if !run_block {
            continue;
        }
        // A backslash at the end continues the command on the next line.
        let (text, continues) = match line.strip_suffix('\\') {
            Some(t) => (t, true),
            None => (line, false),
        };
        let cmd = match pending.take() {
            Some(mut p) => {
                p.command.push(' ');
                p.command.push_str(text.trim());
                p
            }
            None => Line {
                number: i + 1,
                command: text.trim().to_string(),
            },
        };
        if continues {
            pending = Some(cmd);
        } else if !cmd.command.is_empty() && !cmd.command.starts_with('#') {
            out.push(cmd);
        }
    }
    out
}

/// The command as the test runs it; a setup command (one `doc` must mark) panics.
fn as_run(doc: &str, l: &Line) -> String {
    if let Some(rest) = l
        .command
        .strip_prefix("cargo run --release -p clothbake -- ")
    {
        return format!("clothbake {rest}");
    }
    let first = l.command.split_whitespace().next().unwrap_or_default();
    assert!(
        !matches!(first, "cargo" | "pip" | "pip3" | "python" | "python3"),
        "{doc} line {}: `{}` builds, installs or runs Python; put \
         `<!-- readme-test: skip (why) -->` before its block",
        l.number,
        l.command
    );
    l.command.clone()
}

/// Runs the shell blocks of `doc` (relative to the repository root) in order in a fresh
/// folder, which it returns; at least `least` commands must be found.
fn run_blocks(doc: &str, least: usize) -> PathBuf {
    let text = std::fs::read_to_string(repo().join(doc)).unwrap();
    let lines = commands(&text);
    assert!(
        lines.len() >= least,
        "{doc}: only {} commands found",
        lines.len()
    );
    let dir = common::fresh_dir("docs", &doc.replace(['/', '.'], "-"));
    std::os::unix::fs::symlink(repo().join("tables"), dir.join("tables")).unwrap();
    let bin = Path::new(env!("CARGO_BIN_EXE_clothbake")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let start = Instant::now();
    for l in &lines {
        let cmd = as_run(doc, l);
        let t = Instant::now();
        let out = Command::new("bash")
            .args(["-c", &cmd])
            .current_dir(&dir)
            .env("PATH", &path)
            .output()
            .expect("bash runs");
        let code = out.status.code();
        let allowed = code == Some(0) || (code == Some(1) && cmd.starts_with("clothbake diff "));
        assert!(
            allowed,
            "{doc} line {}: `{cmd}` exited {:?}\nstdout: {}\nstderr: {}",
            l.number,
            code,
            common::text(&out.stdout),
            common::text(&out.stderr)
        );
        eprintln!(
            "{:6.2} s  {doc} line {}: {cmd}",
            t.elapsed().as_secs_f64(),
            l.number
        );
    }
    eprintln!(
        "{doc}: {} commands in {:.1} s",
        lines.len(),
        start.elapsed().as_secs_f64()
    );
    dir
}

#[test]
fn readme_shell_blocks_run_in_order_in_a_fresh_folder() {
    let dir = run_blocks("README.md", 20);
    // What the README says the first command does.
    assert!(dir.join("twill.exr").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// One test per document: its blocks in order in a fresh folder.
macro_rules! doc_test {
    ($($name:ident: $doc:literal, $least:literal;)*) => {$(
        #[test]
        fn $name() {
            let dir = run_blocks($doc, $least);
            let _ = std::fs::remove_dir_all(&dir);
        }
    )*};
}

doc_test! {
    docs_baking: "docs/guide/baking.md", 5;
    docs_cli: "docs/reference/cli.md", 20;
    docs_cluster: "docs/guide/cluster.md", 4;
    docs_daylighting: "docs/guide/daylighting.md", 2;
    docs_export: "docs/guide/export.md", 6;
    docs_fabric_format: "docs/reference/fabric-format.md", 1;
    docs_render: "docs/guide/render.md", 9;
    docs_transport: "docs/science/transport.md", 1;
    docs_wif: "docs/reference/wif.md", 3;
}

/// The documents whose blocks all need what a test cannot have, each with the reason its
/// markers give; the test below keeps this list and docs/ in step.
const NOTHING_TO_RUN: [&str; 2] = ["docs/reference/loader.md", "docs/guide/python.md"];

#[test]
fn every_document_with_shell_blocks_is_run_or_listed() {
    let tested = [
        "docs/guide/baking.md",
        "docs/reference/cli.md",
        "docs/guide/cluster.md",
        "docs/guide/daylighting.md",
        "docs/guide/export.md",
        "docs/reference/fabric-format.md",
        "docs/guide/render.md",
        "docs/science/transport.md",
        "docs/reference/wif.md",
    ];
    // docs/ and its sections (guide/, reference/, science/, results/, ...), one level down.
    let docs = repo().join("docs");
    let mut pages = Vec::new();
    for e in std::fs::read_dir(&docs).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            pages.extend(std::fs::read_dir(&p).unwrap().map(|e| e.unwrap().path()));
        } else {
            pages.push(p);
        }
    }
    let mut with_blocks = Vec::new();
    for p in pages {
        if p.extension().is_some_and(|x| x == "md") {
            let text = std::fs::read_to_string(&p).unwrap();
            if text.contains("```sh") || text.contains("```bash") {
                let doc = format!("docs/{}", p.strip_prefix(&docs).unwrap().display());
                let runs = !commands(&text).is_empty();
                with_blocks.push((doc, runs));
            }
        }
    }
    with_blocks.sort();
    for (doc, runs) in &with_blocks {
        if *runs {
            assert!(tested.contains(&doc.as_str()), "{doc}: add it to doc_test!");
        } else {
            assert!(
                NOTHING_TO_RUN.contains(&doc.as_str()),
                "{doc}: list it in NOTHING_TO_RUN"
            );
        }
    }
    assert_eq!(
        with_blocks.len(),
        tested.len() + NOTHING_TO_RUN.len(),
        "{with_blocks:?}"
    );
}

#[test]
fn blocks_and_markers_are_read_as_documented() {
    let md = "text\n\n```sh\nclothbake a \\\n  --b c   # note\n# comment\n\nclothbake d\n```\n\
              <!-- readme-test: skip (installs) -->\n```sh\ncargo install x\n```\n\
              ```python\nprint(1)\n```\n```bash\ncargo run --release -p clothbake -- --weave t\n```\n";
    let got: Vec<(usize, String)> = commands(md)
        .into_iter()
        .map(|l| (l.number, as_run("t.md", &l)))
        .collect();
    assert_eq!(
        got,
        [
            (4, "clothbake a --b c   # note".to_string()),
            (8, "clothbake d".to_string()),
            (18, "clothbake --weave t".to_string()),
        ]
    );
    let unmarked = commands("```sh\npip install .\n```\n");
    let e = std::panic::catch_unwind(|| as_run("t.md", &unmarked[0])).unwrap_err();
    let msg = e.downcast_ref::<String>().unwrap();
    assert!(
        msg.contains("line 2") && msg.contains("readme-test: skip"),
        "{msg}"
    );
}
