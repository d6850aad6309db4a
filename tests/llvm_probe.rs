// Mitsuba's llvm variants and the LLVM they need: included after the shared probes
// (crates/clothbake-loader/build/probe.rs) by this crate's build script and by its library's
// `probe` module, and used by `cargo xtask test` and `cargo xtask gallery`.
//
// Dr.Jit's llvm backend loads libLLVM at run time; with LLVM 15 (Debian bookworm's default)
// Mitsuba 3.9 aborts ("Cannot select ... fmaximum"), so a libLLVM of version 17 or later is
// looked for and handed to Dr.Jit through DRJIT_LIBLLVM_PATH.

/// The oldest LLVM major version Mitsuba's llvm variants work with.
#[allow(dead_code)]
pub const LLVM_MIN: u32 = 17;

/// A libLLVM of version `LLVM_MIN` or later: DRJIT_LIBLLVM_PATH when it is set, else the
/// newest found in the usual system folders (Debian's `libllvmNN` package installs
/// `/usr/lib/<triplet>/libLLVM-NN.so` or `libLLVM.so.NN...`, LLVM's own packages
/// `/usr/lib/llvm-NN/lib/libLLVM*.so*`).
#[allow(dead_code)]
pub fn libllvm() -> Option<std::path::PathBuf> {
    if let Some(p) = std::env::var_os("DRJIT_LIBLLVM_PATH").filter(|p| !p.is_empty()) {
        return Some(p.into());
    }
    let mut dirs: Vec<std::path::PathBuf> = [
        "/usr/lib/x86_64-linux-gnu",
        "/usr/lib/aarch64-linux-gnu",
        "/usr/lib64",
        "/usr/lib",
        "/usr/local/lib",
    ]
    .iter()
    .map(std::path::PathBuf::from)
    .collect();
    if let Ok(entries) = std::fs::read_dir("/usr/lib") {
        dirs.extend(
            entries
                .flatten()
                .filter(|e| e.file_name().to_string_lossy().starts_with("llvm-"))
                .map(|e| e.path().join("lib")),
        );
    }
    let mut best: Option<(u32, std::path::PathBuf)> = None;
    for dir in dirs {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let Some(major) = llvm_major(&name) else {
                continue;
            };
            if major >= LLVM_MIN && best.as_ref().is_none_or(|(m, _)| major > *m) {
                best = Some((major, e.path()));
            }
        }
    }
    best.map(|(_, p)| p)
}

/// The major version in a libLLVM file name: `libLLVM-19.so`, `libLLVM-19.so.1`,
/// `libLLVM.so.19.1`, `libLLVM.so.19`; None for other names.
#[allow(dead_code)]
fn llvm_major(name: &str) -> Option<u32> {
    let digits = |s: &str| -> Option<u32> {
        let d: String = s.chars().take_while(char::is_ascii_digit).collect();
        d.parse().ok()
    };
    if let Some(rest) = name.strip_prefix("libLLVM-") {
        return rest.contains(".so").then(|| digits(rest)).flatten();
    }
    name.strip_prefix("libLLVM.so.").and_then(digits)
}

/// Mitsuba 3's `llvm_ad_rgb` variant renders (with the libLLVM `libllvm` finds), and numpy.
#[allow(dead_code)]
pub const MITSUBA_LLVM: Dependency = Dependency {
    name: "mitsuba_llvm",
    needs: "the mitsuba and numpy Python packages and a libLLVM of version 17 or later for \
            Mitsuba's llvm_ad_rgb variant",
    install: "python3 -m pip install mitsuba numpy and apt-get install libllvm19 (or set \
              DRJIT_LIBLLVM_PATH to a libLLVM >= 17; `cargo xtask test` installs the Python \
              packages, not libLLVM)",
    uses_path: true,
    check: mitsuba_llvm_ready,
};

#[allow(dead_code)]
fn mitsuba_llvm_ready() -> Result<(), String> {
    let lib = libllvm().ok_or_else(|| {
        format!("no libLLVM of version {LLVM_MIN} or later found and DRJIT_LIBLLVM_PATH unset")
    })?;
    // A tiny render: the old LLVM aborts in code generation, not at import.
    let code = "import mitsuba as mi, numpy; mi.set_variant('llvm_ad_rgb'); \
                s = mi.load_dict({'type': 'scene', 'i': {'type': 'path'}, 'sh': {'type': 'sphere'}, \
                'e': {'type': 'constant'}, 'c': {'type': 'perspective', 'film': \
                {'type': 'hdrfilm', 'width': 4, 'height': 4}, 'to_world': \
                mi.ScalarTransform4f().look_at(origin=[0, -4, 0], target=[0, 0, 0], \
                up=[0, 0, 1])}}); assert numpy.array(mi.render(s, spp=1)).mean() > 0";
    match std::process::Command::new("python3")
        .args(["-c", code])
        .env("DRJIT_LIBLLVM_PATH", &lib)
        .output()
    {
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(format!(
            "Mitsuba's llvm_ad_rgb variant failed with {} ({}): {}",
            lib.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr)
                .trim()
                .lines()
                .last()
                .unwrap_or("")
        )),
        Err(e) => Err(format!("python3 cannot be run: {e}")),
    }
}
