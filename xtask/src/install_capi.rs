//! `cargo xtask install-capi PREFIX`: builds the C API (`clothbake-capi`) in release mode and
//! installs the header, the static and shared libraries and a pkg-config file under PREFIX:
//!
//! ```text
//! PREFIX/include/clothbake.h
//! PREFIX/lib/libclothbake_capi.a      (debug sections and embedded LLVM bitcode stripped)
//! PREFIX/lib/libclothbake_capi.so     (.dylib on macOS)
//! PREFIX/lib/pkgconfig/clothbake.pc
//! ```
//!
//! The static library is stripped with binutils' `strip` when it runs (the Rust standard
//! library inside it carries its debug information and LLVM bitcode); without it the library
//! is installed as built, with a note.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The libraries' file names on this platform: static, shared.
fn library_names() -> (&'static str, &'static str) {
    if cfg!(target_os = "macos") {
        ("libclothbake_capi.a", "libclothbake_capi.dylib")
    } else {
        ("libclothbake_capi.a", "libclothbake_capi.so")
    }
}

/// The system libraries a static link needs besides the archive (Linux; rustc's
/// `--print native-static-libs` lists the same).
const STATIC_DEPS: &str = "-lpthread -ldl -lm";

fn fail(msg: &str) -> ! {
    eprintln!("cargo xtask install-capi: {msg}");
    std::process::exit(2);
}

/// The pkg-config file for an installation under `prefix` (absolute).
pub fn pc_file(prefix: &Path, version: &str) -> String {
    format!(
        "prefix={}\n\
         includedir=${{prefix}}/include\n\
         libdir=${{prefix}}/lib\n\
         \n\
         Name: clothbake\n\
         Description: Look up and importance-sample BRDF tables of woven cloth baked by clothbake\n\
         Version: {version}\n\
         Cflags: -I${{includedir}}\n\
         Libs: -L${{libdir}} -lclothbake_capi\n\
         Libs.private: {STATIC_DEPS}\n",
        prefix.display()
    )
}

fn copy(from: &Path, to: &Path) {
    std::fs::copy(from, to).unwrap_or_else(|e| {
        fail(&format!(
            "cannot copy {} to {}: {e}",
            from.display(),
            to.display()
        ))
    });
}

fn size(p: &Path) -> u64 {
    std::fs::metadata(p).map_or(0, |m| m.len())
}

/// The task: see the module documentation. `args`: the prefix, nothing else.
pub fn run(root: &Path, args: &[String]) {
    let [prefix] = args else {
        fail(
            "give the installation prefix, e.g. `cargo xtask install-capi $HOME/.local` (the \
             header goes to PREFIX/include, the libraries to PREFIX/lib)",
        )
    };
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    println!("==> cargo build --release -p clothbake-capi");
    let status = Command::new(&cargo)
        .current_dir(root)
        .args(["build", "--release", "--quiet", "-p", "clothbake-capi"])
        .status()
        .unwrap_or_else(|e| fail(&format!("cannot run cargo: {e}")));
    if !status.success() {
        fail(&format!(
            "cargo build --release -p clothbake-capi failed ({status})"
        ));
    }
    let release = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"))
        .join("release");

    let prefix = PathBuf::from(prefix);
    let (include, lib) = (prefix.join("include"), prefix.join("lib"));
    let pkgconfig = lib.join("pkgconfig");
    for d in [&include, &pkgconfig] {
        std::fs::create_dir_all(d)
            .unwrap_or_else(|e| fail(&format!("cannot create {}: {e}", d.display())));
    }
    let prefix = prefix
        .canonicalize()
        .unwrap_or_else(|e| fail(&format!("{}: {e}", prefix.display())));

    copy(
        &root.join("crates/clothbake-capi/include/clothbake.h"),
        &include.join("clothbake.h"),
    );
    let (static_name, shared_name) = library_names();
    let archive = lib.join(static_name);
    copy(&release.join(static_name), &archive);
    copy(&release.join(shared_name), &lib.join(shared_name));
    let built = size(&archive);
    let stripped = Command::new("strip")
        .args([
            "--strip-debug",
            "--remove-section=.llvmbc",
            "--remove-section=.llvmcmd",
        ])
        .arg(&archive)
        .output();
    match stripped {
        Ok(out) if out.status.success() => println!(
            "==> stripped {static_name}: {:.1} MB -> {:.1} MB",
            built as f64 / 1e6,
            size(&archive) as f64 / 1e6
        ),
        Ok(out) => println!(
            "==> note: strip failed ({}); {static_name} is installed as built ({:.1} MB)",
            String::from_utf8_lossy(&out.stderr).trim(),
            built as f64 / 1e6
        ),
        Err(e) => println!(
            "==> note: no strip ({e}); {static_name} is installed as built ({:.1} MB)",
            built as f64 / 1e6
        ),
    }
    let pc = pkgconfig.join("clothbake.pc");
    std::fs::write(&pc, pc_file(&prefix, env!("CARGO_PKG_VERSION")))
        .unwrap_or_else(|e| fail(&format!("cannot write {}: {e}", pc.display())));
    for p in [
        include.join("clothbake.h"),
        archive,
        lib.join(shared_name),
        pc.clone(),
    ] {
        println!("installed {}", p.display());
    }
    println!(
        "compile with: PKG_CONFIG_PATH={} cc prog.c $(pkg-config --cflags --libs clothbake)",
        pkgconfig.display()
    );
}
