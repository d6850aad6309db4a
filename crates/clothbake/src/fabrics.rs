//! The fabrics shipped in `tables/`, built into the binary so that `--weave twill` and
//! `clothbake fabrics` work wherever the binary is (e.g. after `cargo install`), and the one
//! place where a `--weave` argument becomes a [`Fabric`].
//!
//! A `--weave` argument names a file; when no such file exists and the argument is a bare name
//! (no folder) of a shipped fabric, with or without its extension (`twill`, `twill.json`,
//! `denim`, `denim.wif`), the built-in copy is read instead. A file always wins over a shipped
//! name.

use clothbake_core::source::is_wif;
use clothbake_core::{Fabric, FabricError, WifOptions};
use std::fmt::Write as _;
use std::path::Path;

/// A fabric file of `tables/`, as shipped.
#[derive(Clone, Copy, Debug)]
pub struct Shipped {
    /// The file name in `tables/`, e.g. `twill.json`.
    pub file: &'static str,
    /// Its text.
    pub text: &'static str,
}

macro_rules! shipped {
    ($($file:literal),* $(,)?) => {
        [$(Shipped { file: $file, text: include_str!(concat!("../../../tables/", $file)) }),*]
    };
}

/// Every fabric file of `tables/` (a test checks the folder holds no other).
pub const SHIPPED: [Shipped; 13] = shipped![
    "plain.json",
    "basket.json",
    "twill.json",
    "twill31.json",
    "satin5.json",
    "parallel.json",
    "denim.wif",
    "gingham.wif",
    "twill22.wif",
    "cotton-poplin.json",
    "wool-twill.json",
    "silk-charmeuse.json",
    "polyester-taffeta.json",
];

impl Shipped {
    /// The name without its extension (`twill`).
    pub fn name(&self) -> &'static str {
        self.file
            .rsplit_once('.')
            .map_or(self.file, |(stem, _)| stem)
    }

    /// Reads the fabric, with the sizes a WIF draft may leave out.
    pub fn fabric(&self, wif: &WifOptions) -> Result<Fabric, FabricError> {
        let label = format!("{} (shipped)", self.file);
        if is_wif(Path::new(self.file)) {
            Ok(clothbake_core::wif::parse(self.text, &label, wif)?)
        } else {
            Fabric::from_json_str(self.text, &label)
        }
    }

    /// One line about the fabric: the fabric file's `description` (JSON) or the draft's leading
    /// `;` comment (WIF), up to its first colon or full stop ending a sentence.
    pub fn summary(&self) -> String {
        let text = if is_wif(Path::new(self.file)) {
            self.text
                .lines()
                .take_while(|l| l.starts_with(';'))
                .map(|l| l.trim_start_matches(';').trim())
                .collect::<Vec<_>>()
                .join(" ")
        } else {
            serde_json::from_str::<serde_json::Value>(self.text)
                .ok()
                .and_then(|v| v["description"].as_str().map(str::to_string))
                .unwrap_or_default()
        };
        first_clause(&text)
    }
}

/// `text` up to its first colon, or else its first full stop followed by a space.
fn first_clause(text: &str) -> String {
    let end = text
        .find(':')
        .or_else(|| text.find(". "))
        .unwrap_or(text.len());
    text[..end].trim().trim_end_matches('.').to_string()
}

/// The shipped fabric a bare name (`twill`, `twill.json`) stands for.
pub fn find(name: &str) -> Option<&'static Shipped> {
    SHIPPED.iter().find(|s| s.file == name || s.name() == name)
}

/// The shipped fabric `weave` stands for: none when a file of that name exists or when it
/// names a folder.
pub fn shipped_for(weave: &Path) -> Option<&'static Shipped> {
    if weave.exists() || weave.components().count() != 1 {
        return None;
    }
    find(weave.to_str()?)
}

/// True when `weave` is read as a WIF draft (a `*.wif` file, or a shipped draft's name).
pub fn is_draft(weave: &Path) -> bool {
    match shipped_for(weave) {
        Some(s) => is_wif(Path::new(s.file)),
        None => is_wif(weave),
    }
}

/// Reads the fabric of a `--weave` argument: the file, or else the shipped fabric it names.
pub fn read(weave: &Path, wif: &WifOptions) -> Result<Fabric, FabricError> {
    match shipped_for(weave) {
        Some(s) => s.fabric(wif),
        None => Fabric::from_path_with(weave, wif).map_err(|mut e| {
            if std::fs::symlink_metadata(weave).is_err() {
                e.fix = missing_fix(weave);
            }
            e
        }),
    }
}

/// The fix for a fabric file that does not exist: the shipped fabric of that file name, built
/// in (`tables/basket.json` outside the source: `--weave basket`), or the way to name one.
fn missing_fix(weave: &Path) -> String {
    let name = weave.file_name().and_then(|n| n.to_str()).unwrap_or("");
    match find(name) {
        Some(s) => format!(
            "check the path, or give the shipped fabric of that name, built in: --weave {} \
             (`clothbake fabrics` lists them)",
            s.name()
        ),
        None => "check the path, or give a shipped fabric by name, e.g. --weave twill \
                 (`clothbake fabrics` lists them)"
            .into(),
    }
}

/// `clothbake fabrics`: a table of the shipped fabrics (name, file, repeat in warps x wefts,
/// summary) and how to use them.
pub fn list() -> String {
    let mut rows = vec![(
        "NAME".to_string(),
        "FILE".to_string(),
        "REPEAT".to_string(),
        "DESCRIPTION".to_string(),
    )];
    for s in &SHIPPED {
        let repeat = match s.fabric(&WifOptions::default()) {
            Ok(f) => format!("{} x {}", f.weave().n_warp(), f.weave().n_weft()),
            Err(_) => "?".into(), // a test keeps every shipped fabric valid
        };
        rows.push((s.name().into(), s.file.into(), repeat, s.summary()));
    }
    let w0 = rows.iter().map(|r| r.0.len()).max().unwrap_or(0);
    let w1 = rows.iter().map(|r| r.1.len()).max().unwrap_or(0);
    let w2 = rows.iter().map(|r| r.2.len()).max().unwrap_or(0);
    let mut out = String::new();
    for (a, b, c, d) in rows {
        let _ = writeln!(out, "{a:w0$}  {b:w1$}  {c:w2$}  {d}");
    }
    out.push_str(
        "\nREPEAT: warp x weft threads of one period. Use a name wherever a fabric file goes, \
         e.g. `clothbake --weave twill` (a file of that name in the current folder comes first); \
         the files are in tables/ of the source (docs/reference/fabric-format.md, docs/reference/wif.md).\n",
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tables() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables")
    }

    #[test]
    fn every_fabric_of_tables_is_shipped_and_valid() {
        let mut on_disk: Vec<String> = std::fs::read_dir(tables())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".json") || n.ends_with(".wif"))
            .collect();
        on_disk.sort();
        let mut shipped: Vec<String> = SHIPPED.iter().map(|s| s.file.to_string()).collect();
        shipped.sort();
        assert_eq!(
            on_disk, shipped,
            "add new fabric files of tables/ to SHIPPED"
        );
        for s in &SHIPPED {
            let from_file = Fabric::from_path(&tables().join(s.file)).unwrap();
            let built_in = s.fabric(&WifOptions::default()).unwrap();
            assert_eq!(from_file.to_json(), built_in.to_json(), "{}", s.file);
            assert!(
                !s.summary().is_empty() && s.summary().len() < 80,
                "{}",
                s.file
            );
        }
    }

    #[test]
    fn names_resolve_only_when_no_file_is_there() {
        assert_eq!(find("twill").unwrap().file, "twill.json");
        assert_eq!(find("twill.json").unwrap().file, "twill.json");
        assert_eq!(find("denim").unwrap().file, "denim.wif");
        assert!(find("twill.wif").is_none() && find("velvet").is_none());
        assert_eq!(
            shipped_for(Path::new("gingham")).unwrap().file,
            "gingham.wif"
        );
        assert!(is_draft(Path::new("gingham")) && !is_draft(Path::new("twill")));
        // A path with a folder is a path, even when the file is missing.
        assert!(shipped_for(Path::new("nowhere/twill.json")).is_none());
        assert!(shipped_for(&tables().join("twill.json")).is_none());
    }

    #[test]
    fn summaries_stop_at_the_first_clause() {
        assert_eq!(
            find("twill").unwrap().summary(),
            "2/1 twill of Huo 1993, Fig. 4.7 / sec. 4.3"
        );
        assert_eq!(find("plain").unwrap().summary(), "1/1 plain weave (tabby)");
        assert_eq!(
            find("gingham").unwrap().summary(),
            "A red and white gingham"
        );
        assert_eq!(first_clause("One. Two"), "One");
        assert_eq!(first_clause("no stop"), "no stop");
    }
}
