//! Helpers shared by the tests that drive the `clothbake` binary.

use std::path::{Path, PathBuf};

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
