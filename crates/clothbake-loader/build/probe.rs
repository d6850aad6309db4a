// Optional dependencies of some tests, probed once: shared by the build scripts of
// clothbake-loader (AVX2) and clothbake-tests (Python packages, SLURM) through `include!`, and
// by clothbake-tests' library, whose tests fail with the same message when run without them.
// It lives in the loader so that the loader stays packageable on its own.
//
// A build script calls `emit(&[...])`: for each dependency it declares the cfg
// `missing_<name>` and sets it when the probe fails, so that the tests needing it, marked
// `#[cfg_attr(missing_<name>, ignore = "...")]`, show as `ignored` in cargo test's summary.
// With `CI` set (to anything but empty, 0 or false) no cfg is ever set: those tests run, and
// fail on the missing dependency. `CLOTHBAKE_ASSUME_MISSING=name,name` makes the probes of the
// named dependencies fail (to see the skip, or under CI the failure, without uninstalling).

/// An optional dependency of some tests.
#[allow(dead_code)]
pub struct Dependency {
    /// Short name: the cfg `missing_<name>` and the name in `CLOTHBAKE_ASSUME_MISSING`.
    pub name: &'static str,
    /// What is needed, in words.
    pub needs: &'static str,
    /// How to get it.
    pub install: &'static str,
    /// True when the probe runs programs found through PATH.
    pub uses_path: bool,
    check: fn() -> Result<(), String>,
}

/// python3 with numpy and pytest (the Python package's tests).
#[allow(dead_code)]
pub const PYTHON: Dependency = Dependency {
    name: "python",
    needs: "python3 with numpy and pytest",
    install: "python3 -m pip install numpy pytest, or run `cargo xtask test`",
    uses_path: true,
    check: || python_imports("import numpy, pytest"),
};

/// python3 with numpy (the pbrt file check).
#[allow(dead_code)]
pub const NUMPY: Dependency = Dependency {
    name: "numpy",
    needs: "python3 with numpy",
    install: "python3 -m pip install numpy, or run `cargo xtask test`",
    uses_path: true,
    check: || python_imports("import numpy"),
};

/// Radiance's binaries and BSDF library as the pyradiance package ships them (the daylighting
/// export's round trip).
#[allow(dead_code)]
pub const PYRADIANCE: Dependency = Dependency {
    name: "pyradiance",
    needs: "the pyradiance Python package (Radiance's binaries and BSDF library)",
    install: "python3 -m pip install pyradiance, or run `cargo xtask test`",
    uses_path: true,
    check: || python_imports("import pyradiance.bsdf"),
};

/// Mitsuba 3 with its scalar_rgb variant, and numpy.
#[allow(dead_code)]
pub const MITSUBA: Dependency = Dependency {
    name: "mitsuba",
    needs: "the mitsuba and numpy Python packages",
    install: "python3 -m pip install mitsuba numpy, or run `cargo xtask test`",
    uses_path: true,
    check: || python_imports("import mitsuba, numpy; mitsuba.set_variant('scalar_rgb')"),
};

/// The reference OpenEXR library's Python package, and numpy.
#[allow(dead_code)]
pub const OPENEXR: Dependency = Dependency {
    name: "openexr",
    needs: "the OpenEXR and numpy Python packages",
    install: "python3 -m pip install OpenEXR numpy, or run `cargo xtask test`",
    uses_path: true,
    check: || python_imports("import OpenEXR, numpy"),
};

/// MaterialX and usd-core (the fitted OpenPBR material's checks).
#[allow(dead_code)]
pub const MATERIALX: Dependency = Dependency {
    name: "materialx",
    needs: "the MaterialX and usd-core Python packages",
    install: "python3 -m pip install materialx usd-core, or run `cargo xtask test`",
    uses_path: true,
    check: || python_imports("import MaterialX; from pxr import Usd, UsdShade"),
};

/// Blender as a Python module (`bpy`), for rendering the fitted material with Cycles.
#[allow(dead_code)]
pub const BLENDER: Dependency = Dependency {
    name: "blender",
    needs: "Blender's Python module bpy (with numpy)",
    install: "python3 -m pip install bpy (its wheels need the Python version Blender ships \
              with), or run `cargo xtask test`",
    uses_path: true,
    check: || python_imports("import bpy, numpy"),
};

/// Node.js, Chromium and the npm packages of tests/renderers (three.js, playwright-core,
/// gltf-validator), for rendering the fitted glTF material in a browser.
#[allow(dead_code)]
pub const WEB: Dependency = Dependency {
    name: "web",
    needs: "node, Chromium (/usr/bin/chromium or $CHROMIUM) and tests/renderers/node_modules",
    install: "apt-get install chromium nodejs npm, then npm ci in tests/renderers (or run \
              `cargo xtask test`, which runs npm ci)",
    uses_path: true,
    check: web_ready,
};

/// The folder tests/renderers of this workspace, found upward from CARGO_MANIFEST_DIR (set by
/// cargo for build scripts and tests; the one this file was compiled in otherwise).
#[allow(dead_code)]
pub fn renderers_dir() -> Option<std::path::PathBuf> {
    let start = std::env::var_os("CARGO_MANIFEST_DIR")
        .or_else(|| option_env!("CARGO_MANIFEST_DIR").map(Into::into))?;
    std::path::PathBuf::from(start)
        .ancestors()
        .map(|d| d.join("tests/renderers"))
        .find(|d| d.join("package.json").is_file())
}

#[allow(dead_code)]
fn web_ready() -> Result<(), String> {
    let node = std::process::Command::new("node").arg("--version").output();
    if !node.is_ok_and(|o| o.status.success()) {
        return Err("node cannot be run".into());
    }
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    if !std::path::Path::new(&chromium).is_file() {
        return Err(format!("no Chromium at {chromium}"));
    }
    let dir = renderers_dir().ok_or("no tests/renderers/package.json above CARGO_MANIFEST_DIR")?;
    for m in ["three", "playwright-core", "gltf-validator"] {
        if !dir
            .join("node_modules")
            .join(m)
            .join("package.json")
            .is_file()
        {
            return Err(format!("tests/renderers/node_modules/{m} is missing"));
        }
    }
    Ok(())
}

/// A single-node SLURM (and munge) that this user, root, may start.
#[allow(dead_code)]
pub const SLURM: Dependency = Dependency {
    name: "slurm",
    needs: "SLURM and munge, run as root (the test starts their daemons)",
    install: "apt-get install slurm-wlm munge as root (as .ci/run does), and run the tests as root",
    uses_path: true,
    check: slurm_ready,
};

/// pkg-config (the test of `cargo xtask install-capi`, which compiles the C example with it).
#[allow(dead_code)]
pub const PKG_CONFIG: Dependency = Dependency {
    name: "pkgconfig",
    needs: "pkg-config",
    install: "apt-get install pkg-config (or your system's package of it)",
    uses_path: true,
    check: || match std::process::Command::new("pkg-config").arg("--version").output() {
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(format!("pkg-config --version failed ({})", out.status)),
        Err(e) => Err(format!("pkg-config cannot be run: {e}")),
    },
};

/// A processor with AVX2, FMA and F16C (the loader's AVX2 kernel).
#[allow(dead_code)]
pub const AVX2: Dependency = Dependency {
    name: "avx2",
    needs: "an x86-64 processor with AVX2, FMA and F16C (the loader's AVX2 kernel)",
    install: "nothing to install: run the tests on such a processor",
    uses_path: false,
    check: avx2_ready,
};

/// The programs the SLURM test runs.
#[allow(dead_code)]
pub const SLURM_TOOLS: [&str; 7] = [
    "sbatch",
    "squeue",
    "sinfo",
    "slurmctld",
    "slurmd",
    "munged",
    "mungekey",
];

/// True when `CI` is set to anything but empty, "0" or "false".
#[allow(dead_code)]
pub fn in_ci() -> bool {
    std::env::var("CI")
        .is_ok_and(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
}

/// PATH with the system folders where Debian puts SLURM's and munge's daemons.
#[allow(dead_code)]
pub fn search_path() -> String {
    let mut p = std::env::var("PATH").unwrap_or_default();
    for d in ["/usr/sbin", "/sbin", "/usr/bin", "/bin"] {
        p.push(':');
        p.push_str(d);
    }
    p
}

#[allow(dead_code)]
fn find_tool(tool: &str, path: &str) -> Option<std::path::PathBuf> {
    path.split(':')
        .map(|d| std::path::Path::new(d).join(tool))
        .find(|p| p.is_file())
}

#[allow(dead_code)]
fn python_imports(code: &str) -> Result<(), String> {
    match std::process::Command::new("python3").args(["-c", code]).output() {
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(String::from_utf8_lossy(&out.stderr)
            .trim()
            .lines()
            .last()
            .map(str::to_string)
            .unwrap_or_else(|| format!("python3 -c \"{code}\" failed ({})", out.status))),
        Err(e) => Err(format!("python3 cannot be run: {e}")),
    }
}

#[allow(dead_code)]
fn slurm_ready() -> Result<(), String> {
    let path = search_path();
    let missing: Vec<&str> = SLURM_TOOLS
        .iter()
        .copied()
        .filter(|t| find_tool(t, &path).is_none())
        .collect();
    if !missing.is_empty() {
        return Err(format!("{} not installed", missing.join(", ")));
    }
    let root = std::process::Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    if root {
        Ok(())
    } else {
        Err("not running as root".into())
    }
}

#[allow(dead_code)]
fn avx2_ready() -> Result<(), String> {
    // In a build script the target may differ from the processor the script runs on.
    if let Ok(arch) = std::env::var("CARGO_CFG_TARGET_ARCH") {
        if arch != "x86_64" || std::env::var("HOST").ok() != std::env::var("TARGET").ok() {
            return Err(format!("the target ({arch}) is not this x86-64 machine"));
        }
    }
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("f16c")
        {
            Ok(())
        } else {
            Err("this processor lacks AVX2, FMA or F16C".into())
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    Err("this processor is not x86-64".into())
}

impl Dependency {
    /// Ok when the dependency is there; the reason otherwise. `CLOTHBAKE_ASSUME_MISSING`
    /// naming it makes it missing.
    #[allow(dead_code)]
    pub fn probe(&self) -> Result<(), String> {
        let assumed = std::env::var("CLOTHBAKE_ASSUME_MISSING")
            .is_ok_and(|v| v.split(',').any(|n| n.trim() == self.name));
        if assumed {
            return Err(format!(
                "assumed missing (CLOTHBAKE_ASSUME_MISSING names {})",
                self.name
            ));
        }
        (self.check)()
    }

    /// Panics, saying what is missing and how to install it, unless the dependency is there.
    #[allow(dead_code)]
    #[track_caller]
    pub fn require(&self) {
        if let Err(why) = self.probe() {
            panic!(
                "this test needs {} ({why}); {}{}",
                self.needs,
                self.install,
                if in_ci() {
                    " (CI is set, so a missing dependency fails instead of skipping)"
                } else {
                    ""
                }
            );
        }
    }
}

/// For build scripts: declares `missing_<name>` for each dependency and, unless under CI, sets
/// it for those whose probe fails; asks cargo to rerun when CI, the override or (for probes
/// that search PATH) PATH or VIRTUAL_ENV change. The build script names its own files with
/// `cargo::rerun-if-changed`.
#[allow(dead_code)]
pub fn emit(deps: &[Dependency]) {
    for var in ["CI", "CLOTHBAKE_ASSUME_MISSING"] {
        println!("cargo::rerun-if-env-changed={var}");
    }
    if deps.iter().any(|d| d.uses_path) {
        for var in ["PATH", "VIRTUAL_ENV"] {
            println!("cargo::rerun-if-env-changed={var}");
        }
    }
    let ci = in_ci();
    for d in deps {
        println!("cargo::rustc-check-cfg=cfg(missing_{})", d.name);
        if ci {
            continue;
        }
        if let Err(why) = d.probe() {
            println!("cargo::rustc-cfg=missing_{}", d.name);
            println!(
                "cargo::warning=tests needing {} are ignored: {why}; {}",
                d.needs, d.install
            );
        }
    }
}
