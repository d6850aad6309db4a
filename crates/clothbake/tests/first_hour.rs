//! What a new user meets first: the shipped fabrics by name, the top-level help, hints for
//! common slips, shell completions and man pages, and eval's account of its settings.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

mod common;

use common::{fails_with, fresh_dir, listing, succeeds, text};

use common::run_in;

fn clothbake(args: &[&str]) -> Output {
    run_in(Path::new(env!("CARGO_TARGET_TMPDIR")), args)
}

fn tables() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tables")
        .canonicalize()
        .unwrap()
}

/// Every subcommand, as a user would list them from the README and docs.
const COMMANDS: [&str; 11] = [
    "bake",
    "eval",
    "info",
    "diff",
    "export",
    "merge",
    "render",
    "plot",
    "fabrics",
    "completions",
    "man",
];

#[test]
fn fabrics_lists_every_file_of_tables() {
    let out = succeeds(&clothbake(&["fabrics"]));
    let mut seen = 0;
    for entry in std::fs::read_dir(tables()).unwrap() {
        let file = entry.unwrap().file_name().to_string_lossy().into_owned();
        let Some((stem, ext)) = file.rsplit_once('.') else {
            continue;
        };
        if ext != "json" && ext != "wif" {
            continue;
        }
        seen += 1;
        let line = out
            .lines()
            .find(|l| l.split_whitespace().next() == Some(stem))
            .unwrap_or_else(|| panic!("{stem} not listed:\n{out}"));
        assert!(line.contains(&file), "{line}");
        if ext == "json" {
            // The repeat, warps x wefts, from the file's own pattern (rows are wefts).
            let v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(tables().join(&file)).unwrap())
                    .unwrap();
            let rows = v["pattern"].as_array().unwrap();
            let repeat = format!("{} x {}", rows[0].as_array().unwrap().len(), rows.len());
            assert!(line.contains(&repeat), "{repeat} not in {line}");
            let desc = v["description"].as_str().unwrap();
            let summary = desc.split(':').next().unwrap();
            assert!(line.ends_with(summary.trim()), "{line} / {summary}");
        }
    }
    assert_eq!(seen, 13, "{out}");
    // gingham.wif writes two colour repeats of 16 threads; its period is 8 x 8 (its comment).
    let gingham = out.lines().find(|l| l.starts_with("gingham")).unwrap();
    assert!(gingham.contains("8 x 8") && gingham.contains("A red and white gingham"));
    assert!(out.contains("clothbake --weave twill"), "{out}");
}

#[test]
fn shipped_names_work_in_any_folder() {
    let d = fresh_dir("first-hour", "names");
    let by_name = succeeds(&run_in(&d, &["--weave", "twill", "--res", "4,8,4,8"]));
    assert!(by_name.starts_with("wrote twill.exr"), "{by_name}");
    let path = tables().join("twill.json");
    succeeds(&run_in(
        &d,
        &[
            "--weave",
            path.to_str().unwrap(),
            "--res",
            "4,8,4,8",
            "-o",
            "path.exr",
        ],
    ));
    // The built-in copy and the file bake the same table, bit for bit.
    assert_eq!(
        std::fs::read(d.join("twill.exr")).unwrap(),
        std::fs::read(d.join("path.exr")).unwrap()
    );
    // A draft by name, with the draft-only flags; and eval.
    let e = succeeds(&run_in(
        &d,
        &[
            "eval", "--weave", "denim", "--wi", "30,0", "--wo", "45,180", "--radius", "0.2",
        ],
    ));
    assert!(e.starts_with("fabric  denim (denim)"), "{e}");
    // A folder makes it a path: no fallback.
    fails_with(
        &run_in(
            &d,
            &[
                "eval",
                "--weave",
                "nowhere/twill.json",
                "--wi",
                "0,0",
                "--wo",
                "0,0",
            ],
        ),
        2,
        &["nowhere/twill.json", "check the path"],
    );
    // A file of that name comes first.
    std::fs::copy(tables().join("plain.json"), d.join("twill")).unwrap();
    let e = succeeds(&run_in(
        &d,
        &["eval", "--weave", "twill", "--wi", "30,0", "--wo", "45,180"],
    ));
    assert!(e.starts_with("fabric  plain (twill)"), "{e}");
    assert_eq!(listing(&d), ["path.exr", "twill", "twill.exr"]);
}

#[test]
fn top_level_help_shows_commands_not_bake_options() {
    let help = succeeds(&clothbake(&["-h"]));
    for c in COMMANDS {
        assert!(
            help.lines().any(|l| l.trim_start().starts_with(c)),
            "{c} missing:\n{help}"
        );
    }
    assert!(help.contains("--weave"), "{help}");
    let listed = |help: &str, opt: &str| {
        help.lines()
            .any(|l| l.trim_start().starts_with(&format!("{opt} ")))
    };
    for opt in ["--res", "--bounces", "--threads", "--albedo", "--shard"] {
        assert!(!listed(&help, opt), "{opt} in the top-level help:\n{help}");
    }
    assert!(help.contains("clothbake bake --help"), "{help}");
    let bake = succeeds(&clothbake(&["bake", "--help"]));
    for opt in ["--res", "--bounces", "--threads", "--albedo", "--shard"] {
        assert!(listed(&bake, opt), "{opt} missing in bake --help");
    }
    // The hidden options still work without `bake`, with their errors pointing at bake's help.
    fails_with(
        &clothbake(&["--weave", "twill", "--bouncez", "2"]),
        2,
        &["--bouncez", "--bounces", "clothbake bake --help"],
    );
}

#[test]
fn slips_get_one_line_with_the_way_out() {
    let msg = fails_with(
        &clothbake(&[]),
        2,
        &["no command", "clothbake --weave FILE"],
    );
    for c in COMMANDS {
        assert!(msg.contains(&format!(" {c}")), "{c} missing: {msg}");
    }
    for arg in ["tables/twill.json", "twill", "mine.wif"] {
        fails_with(
            &clothbake(&[arg]),
            2,
            &[
                &format!("`{arg}` is not a command"),
                &format!("clothbake --weave {arg}"),
            ],
        );
    }
    fails_with(
        &clothbake(&["frobnicate"]),
        2,
        &["frobnicate", "clothbake --help"],
    );
}

#[test]
fn bash_completion_parses_and_completes() {
    let script = succeeds(&clothbake(&["completions", "bash"]));
    let dir = fresh_dir("first-hour", "bash");
    let file = dir.join("clothbake.bash");
    std::fs::write(&file, &script).unwrap();
    let check = Command::new("bash").arg("-n").arg(&file).output();
    let Ok(check) = check else {
        eprintln!("no bash: the completion script is not checked");
        return;
    };
    assert!(check.status.success(), "bash -n: {}", text(&check.stderr));
    // Complete `clothbake fab<TAB>` and `clothbake --res<TAB>`-style prefixes through the
    // script's function, as bash's programmable completion calls it.
    let complete = |words: &str, cword: usize| {
        let prog = format!(
            "source {}; COMP_WORDS=({words}); COMP_CWORD={cword}; COMP_LINE='{words}'; \
             COMP_POINT=${{#COMP_LINE}}; _clothbake clothbake \"${{COMP_WORDS[$COMP_CWORD]}}\" \
             \"${{COMP_WORDS[$COMP_CWORD-1]}}\"; printf '%s\\n' \"${{COMPREPLY[@]}}\"",
            file.display()
        );
        let out = Command::new("bash").arg("-c").arg(prog).output().unwrap();
        assert!(out.status.success(), "{}", text(&out.stderr));
        text(&out.stdout)
    };
    assert_eq!(complete("clothbake fab", 1).trim(), "fabrics");
    let opts = complete("clothbake --bou", 1);
    assert_eq!(opts.trim(), "--bounces", "{opts}");
    let opts = complete("clothbake eval --wi", 2);
    assert!(opts.lines().any(|l| l == "--wi"), "{opts}");
    for shell in ["zsh", "fish", "elvish", "powershell"] {
        let s = succeeds(&clothbake(&["completions", shell]));
        assert!(s.contains("clothbake") && s.contains("fabrics"), "{shell}");
    }
    fails_with(&clothbake(&["completions", "tcsh"]), 2, &["tcsh", "bash"]);
}

#[test]
fn man_pages_are_roff_that_groff_reads() {
    let top = succeeds(&clothbake(&["man"]));
    assert!(
        top.starts_with(".ie") || top.starts_with(".TH"),
        "{}",
        &top[..80]
    );
    assert!(top.contains(".TH clothbake 1"), "{top}");
    for c in COMMANDS {
        assert!(top.contains(&format!("clothbake\\-{c}")), "{c} missing");
    }
    let bake = succeeds(&clothbake(&["man", "bake"]));
    assert!(bake.contains(".TH clothbake-bake 1") && bake.contains("\\-\\-res"));
    fails_with(
        &clothbake(&["man", "frobnicate"]),
        2,
        &["frobnicate", "bake, eval"],
    );
    // groff renders both without a warning, when it is installed.
    for page in [&top, &bake] {
        let groff = Command::new("groff")
            .args(["-man", "-Tutf8", "-ww", "-z"])
            .stdin(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn();
        let Ok(mut groff) = groff else {
            eprintln!("no groff: the man pages are not rendered");
            return;
        };
        use std::io::Write;
        groff
            .stdin
            .take()
            .unwrap()
            .write_all(page.as_bytes())
            .unwrap();
        let out = groff.wait_with_output().unwrap();
        assert!(
            out.status.success() && out.stderr.is_empty(),
            "{}",
            text(&out.stderr)
        );
    }
}

#[test]
fn eval_names_its_settings() {
    let eval = |extra: &[&str]| {
        let mut args = vec![
            "eval", "--weave", "parallel", "--wi", "30,180", "--wo", "40,0",
        ];
        args.extend_from_slice(extra);
        succeeds(&clothbake(&args))
    };
    let line = |out: &str, head: &str| {
        out.lines()
            .find(|l| l.starts_with(head))
            .unwrap_or_else(|| panic!("no {head} line in\n{out}"))
            .to_string()
    };
    let out = eval(&[]);
    assert_eq!(
        line(&out, "method"),
        "method  analytic, huo facets, variant refined, 1 bounce"
    );
    assert!(!out.contains("I_2 "), "{out}");
    let out = eval(&["--bounces", "2", "--orders", "fast", "--variant", "thesis"]);
    assert_eq!(
        line(&out, "method"),
        "method  analytic, huo facets, variant thesis, 2 bounces"
    );
    assert_eq!(
        line(&out, "I_2 by  "),
        "I_2 by  analytic solution (sec. 5.3), orders 7,3,3 (theta,beta,axial), full ranges, \
         radiometric kernel"
    );
    let out = eval(&["--bounces", "2", "--orders", "9,4,2", "--kernel", "thesis"]);
    assert!(line(&out, "I_2 by  ").contains("orders 9,4,2 (theta,beta,axial)"));
    assert!(line(&out, "I_2 by  ").ends_with("thesis kernel"));
    let out = eval(&[
        "--bounces",
        "2",
        "--secondary",
        "raytrace",
        "--sampling",
        "8,0.3,1,area",
        "--facet",
        "lewis",
    ]);
    assert!(line(&out, "method").contains("lewis facets"));
    assert_eq!(
        line(&out, "I_2 by  "),
        "I_2 by  two-level sampling (sec. 5.2), 8 first-level samples, steps 0.3 rad and 0.3, \
         l0 1, area solid angles, radiometric kernel"
    );
    let out = eval(&[
        "--method",
        "raytrace",
        "--samples",
        "2000",
        "--bounces",
        "2",
    ]);
    assert_eq!(
        line(&out, "method"),
        "method  raytrace, huo facets, caps excluded, 2 bounces"
    );
    assert_eq!(
        line(&out, "I_2 by  "),
        "I_2 by  path tracer, radiometric kernel"
    );
}

/// Outside the clone, `--weave tables/basket.json` names no file: the hint gives the shipped
/// fabric of that name, and the command it gives works there; a name shipped under no file
/// gets the way to name one, and `clothbake fabrics` (which the hints point to) lists `twill`.
#[test]
fn a_missing_fabric_file_points_to_what_exists() {
    let d = fresh_dir("first-hour", "outside");
    let line = fails_with(
        &run_in(&d, &["--weave", "tables/basket.json", "--res", "2,4,2,4"]),
        2,
        &["tables/basket.json", "--weave basket"],
    );
    assert!(!line.contains("tables/twill.json"), "{line}");
    succeeds(&run_in(
        &d,
        &["--weave", "basket", "--res", "2,4,2,4", "-q"],
    ));
    assert!(d.join("basket.exr").exists());
    fails_with(
        &run_in(
            &d,
            &[
                "eval",
                "--weave",
                "tables/nope.json",
                "--wi",
                "30,0",
                "--wo",
                "45,180",
            ],
        ),
        2,
        &["tables/nope.json", "--weave twill", "clothbake fabrics"],
    );
    assert!(succeeds(&run_in(&d, &["fabrics"]))
        .lines()
        .any(|l| l.starts_with("twill ")));
}
