//! The C API from C: tests/c/lookup.c, compiled with the machine's `cc` against
//! crates/clothbake-capi/include/clothbake.h and the crate's static library, opens a baked twill
//! table and checks lookups, batched lookups, samples and pdfs against the Rust loader, bit for
//! bit, and its error paths (missing file, NULL pointers, unknown flags).

use clothbake_bake::BakeOptions;
use clothbake_tests::fixtures::{grid, root, succeeded, temp_dir, twill_table};
use std::ffi::OsStr;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The static library cargo built for this test (a dev-dependency), next to the test binary.
fn static_lib() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    for dir in [deps, deps.parent().unwrap()] {
        let p = dir.join("libclothbake_capi.a");
        if p.exists() {
            return p;
        }
    }
    panic!("libclothbake_capi.a not found next to {}", exe.display());
}

/// Compiles `sources` with `cc` in the workspace root, with `flags`, against the static library
/// into `exe`; panics with the compiler's messages unless it succeeds.
fn cc_against_capi<S: AsRef<OsStr>>(flags: &[&str], sources: &[S], exe: &Path) {
    let out = Command::new("cc")
        .current_dir(root())
        .args(flags)
        .args(sources)
        .arg(static_lib())
        .args(["-lpthread", "-ldl", "-lm", "-o"])
        .arg(exe)
        .output()
        .expect("the C compiler `cc` runs");
    succeeded("cc", &out);
}

fn f(x: f32) -> String {
    format!("{x:.9e}")
}

fn v3(v: [f32; 3]) -> String {
    v.map(f).join(" ")
}

#[test]
fn the_c_program_agrees_with_the_rust_loader() {
    let dir = temp_dir("capi-test");
    let grid = grid(8, 16);
    // A spatial table: the averaged lookups as any table's, and `clothbake_eval_at`'s weave.
    let opts = BakeOptions {
        grid,
        spatial: true,
        ..BakeOptions::default()
    };
    let (table_path, b) = twill_table(&dir, &opts);

    let mut cases = format!(
        "G {} {} {} {}\n",
        grid.n_theta_i, grid.n_phi_i, grid.n_theta_o, grid.n_phi_o
    );
    let dir_of = |t: f32, p: f32| {
        let (t, p) = (t.to_radians(), p.to_radians());
        [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]
    };
    for k in 0..200 {
        let x = k as f32;
        let wi = dir_of((x * 37.3) % 95.0, (x * 61.7) % 360.0);
        let wo = dir_of((x * 53.1) % 92.0, (x * 97.9) % 360.0);
        writeln!(cases, "E {} {} {}", v3(wi), v3(wo), v3(b.eval(wi, wo))).unwrap();
        let a = [
            (x * 7.1) % 89.0,
            (x * 13.3) % 360.0,
            (x * 5.7) % 89.0,
            x * 3.1,
        ];
        let fd = b.eval_deg(a[0], a[1], a[2], a[3]);
        writeln!(cases, "D {} {}", a.map(f).join(" "), v3(fd)).unwrap();
        let (u1, u2) = ((x * 0.618_034) % 1.0, (x * 0.414_214) % 1.0);
        let s = b.sample(wo, u1, u2);
        writeln!(
            cases,
            "S {} {} {} {} {} {}",
            v3(wo),
            f(u1),
            f(u2),
            v3(s.wi),
            v3(s.weight),
            f(s.pdf)
        )
        .unwrap();
        writeln!(cases, "P {} {} {}", v3(wo), v3(wi), f(b.pdf(wi, wo))).unwrap();
        // Points of the period (any real numbers) through footprints from a point to beyond a
        // period; doubles printed to round-trip.
        let (u, v) = (x as f64 * 0.37 - 20.0, x as f64 * 0.23);
        let width = [0.0, 0.05, 0.3, 0.9, 1.5][k % 5];
        let fa = b.eval_at(wi, wo, u, v, width);
        let ca = b.coverage_at(wo, u, v, width);
        writeln!(
            cases,
            "A {} {} {u:e} {v:e} {width:e} {} {}",
            v3(wi),
            v3(wo),
            v3(fa),
            f(ca)
        )
        .unwrap();
    }
    let cases_path = dir.join("cases.txt");
    std::fs::write(&cases_path, cases).unwrap();

    let exe = dir.join("lookup");
    cc_against_capi(
        &["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-I"],
        &[
            root().join("crates/clothbake-capi/include"),
            root().join("tests/c/lookup.c"),
        ],
        &exe,
    );
    let run = Command::new(&exe)
        .arg(&table_path)
        .arg(&cases_path)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "lookup.c failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.contains(
            "1 grid, 200 eval (and batch), 200 eval_deg, 200 sample, 200 pdf, 200 eval_at cases: 0 failures"
        ),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_documented_example_compiles_as_given_and_runs() {
    // docs/reference/loader.md shows examples/c/sample.c whole.
    let example = std::fs::read_to_string(root().join("examples/c/sample.c")).unwrap();
    let doc = std::fs::read_to_string(root().join("docs/reference/loader.md")).unwrap();
    assert!(
        doc.contains(&format!("```c\n{example}```")),
        "the C block of docs/reference/loader.md is not examples/c/sample.c"
    );
    let dir = temp_dir("capi-example");
    // A small twill table (8 x 16 x 8 x 16, f16 EXR) and the Rust loader on it.
    let opts = BakeOptions {
        grid: grid(8, 16),
        ..BakeOptions::default()
    };
    let (table, b) = twill_table(&dir, &opts);
    let exe = dir.join("sample");
    // The documented command line, with the warnings a careful C programmer turns on.
    cc_against_capi(
        &["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I"],
        &["crates/clothbake-capi/include", "examples/c/sample.c"],
        &exe,
    );
    let run = Command::new(&exe).arg(&table).output().unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    clothbake_tests::fixtures::check_sample_c_output(&stdout, &b);
    // A missing table: the loader's message on stderr, exit 1.
    let run = Command::new(&exe)
        .arg(dir.join("none.exr"))
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&run.stderr).contains("none.exr"));
    let _ = std::fs::remove_dir_all(&dir);
}
