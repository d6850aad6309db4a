//! Reading a fabric from a file: a fabric file (JSON, [`crate::fabric`]) or a WIF weaving draft
//! ([`crate::wif`]), chosen by the file's extension. Both end in [`Fabric::new`].

use crate::fabric::{Fabric, FabricError};
use crate::wif::WifOptions;
use std::path::Path;

impl Fabric {
    /// Reads and validates a fabric file: JSON, or a WIF weaving draft when the name ends in
    /// `.wif` (any case; see [`crate::wif`]) with the default [`WifOptions`].
    pub fn from_path(path: &Path) -> Result<Fabric, FabricError> {
        Fabric::from_path_with(path, &WifOptions::default())
    }

    /// As [`Fabric::from_path`], with the sizes a WIF draft may leave out.
    pub fn from_path_with(path: &Path, wif: &WifOptions) -> Result<Fabric, FabricError> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| FabricError {
            file: file.clone(),
            field: String::new(),
            problem: format!("cannot read the fabric file: {e}"),
            fix: "check the path (e.g. tables/twill.json)".into(),
        })?;
        if is_wif(path) {
            // Drafts are often Latin-1 or Windows-1252; only their [TEXT] can hold non-ASCII.
            let text = String::from_utf8_lossy(&bytes);
            return Ok(crate::wif::parse(&text, &file, wif)?);
        }
        let text = String::from_utf8(bytes).map_err(|e| FabricError {
            file: file.clone(),
            field: String::new(),
            problem: format!("the fabric file is not UTF-8 text: {e}"),
            fix: "save it as UTF-8 JSON (see docs/fabric-format.md)".into(),
        })?;
        Fabric::from_json_str(&text, &file)
    }
}

/// True when `path` names a WIF draft (extension `.wif`, any case).
pub fn is_wif(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("wif"))
}
