//! The binary table: a [`Table`] in the binary container (kind `table`, the [`Metadata`] as
//! the JSON header, the values as f32), and the read-only reader of version-1 tables (bincode
//! header). `docs/reference/table-format.md` describes both byte by byte.

use std::path::Path;

use crate::container::{
    file_version, read_container, write_container, ContainerKind, LEGACY_TABLE_VERSION,
};
use crate::error::TableError;
use crate::table::{check_format_version, Metadata, Table};

/// Writes a table in the binary format (a container of kind `table`, see
/// `docs/reference/table-format.md`), atomically.
pub fn write_binary(path: &Path, table: &Table, overwrite: bool) -> Result<(), TableError> {
    table.validate().map_err(|e| e.unwritable(path))?;
    let header = serde_json::to_value(&table.meta).map_err(|e| TableError::Unwritable {
        path: path.to_path_buf(),
        what: "table".into(),
        reason: format!("the metadata cannot be written as JSON ({e})"),
    })?;
    write_container(
        path,
        ContainerKind::Table,
        &header,
        &table.values,
        overwrite,
    )
}

/// Reads a binary table, checking magic bytes, version, kind, sizes, checksum and contents.
/// Reads the current container (version 2) and version-1 tables.
pub fn read_binary(path: &Path) -> Result<Table, TableError> {
    if file_version(path, &[ContainerKind::Table])? == LEGACY_TABLE_VERSION {
        return legacy::read(path);
    }
    let c = read_container(path, &[ContainerKind::Table])?;
    // The version first, so that newer tables say "update the loader".
    check_format_version(path, &c.header)?;
    let meta: Metadata = serde_json::from_value(c.header).map_err(|e| TableError::Corrupted {
        path: path.to_path_buf(),
        reason: format!("the header does not describe a table ({e})"),
    })?;
    Table::new(meta, c.values).map_err(|e| e.in_file(path))
}

/// Version-1 binary tables: the container's layout before kinds, with the [`Metadata`] in
/// bincode. Read-only.
mod legacy {
    use std::io::BufReader;
    use std::path::Path;

    use bincode::Options;

    use crate::bytes::{hex, open_sized, read_f32s, read_hashed, read_up_to};
    use crate::container::{BINARY_MAGIC, LEGACY_TABLE_VERSION};
    use crate::error::TableError;
    use crate::table::{Metadata, Table, FORMAT_VERSION};

    /// Layout: magic (8) + version (4) + header length (8).
    const PREFIX_LEN: u64 = 8 + 4 + 8;
    /// Layout: everything except the header bytes and the values.
    const FIXED_LEN: u64 = PREFIX_LEN + 8 + 4;

    /// bincode settings of the header: fixed-width little-endian integers, strings as a u64
    /// length and UTF-8 bytes (see `docs/reference/table-format.md`).
    fn bincode_options() -> impl Options {
        bincode::DefaultOptions::new()
            .with_fixint_encoding()
            .with_little_endian()
    }

    /// Reads a version-1 binary table, checking magic bytes, version, sizes, checksum and
    /// contents.
    pub(super) fn read(path: &Path) -> Result<Table, TableError> {
        let (file, src) = open_sized(path, "table")?;
        let file_len = src.len;
        let mut r = BufReader::with_capacity(1 << 20, file);
        let mut hasher = crc32fast::Hasher::new();

        let mut magic = [0u8; 8];
        let n = read_up_to(&mut r, &mut magic).map_err(|e| src.io(e))?;
        if magic[..n] != BINARY_MAGIC[..n] {
            return Err(TableError::Foreign {
                path: path.to_path_buf(),
                what: "table".into(),
                reason: format!(
                    "the first bytes are {}, not the magic bytes \"CLTHBAKE\" of a binary table",
                    hex(&magic[..n])
                ),
            });
        }
        if n < magic.len() {
            return Err(src.ends_inside("magic bytes"));
        }
        hasher.update(&magic);

        let mut word = [0u8; 4];
        read_hashed(&mut r, &mut hasher, &mut word, src, "format version")?;
        let version = u32::from_le_bytes(word);
        if version != LEGACY_TABLE_VERSION {
            return Err(TableError::Version {
                path: path.to_path_buf(),
                what: "table",
                found: version,
                reads: LEGACY_TABLE_VERSION,
            });
        }

        let mut long = [0u8; 8];
        read_hashed(&mut r, &mut hasher, &mut long, src, "header length")?;
        let header_len = u64::from_le_bytes(long);
        let room = file_len.saturating_sub(FIXED_LEN);
        if header_len > room {
            return Err(TableError::Truncated {
                path: path.to_path_buf(),
                detail: format!(
                    "the header is {header_len} bytes long, but the file has only {file_len} bytes in all"
                ),
            });
        }
        let mut header = vec![0u8; header_len as usize];
        read_hashed(&mut r, &mut hasher, &mut header, src, "header")?;

        read_hashed(&mut r, &mut hasher, &mut long, src, "value count")?;
        let n_values = u64::from_le_bytes(long);
        let expected_len = n_values
            .checked_mul(4)
            .and_then(|b| b.checked_add(FIXED_LEN + header_len));
        src.expect_len(expected_len, &format!("{n_values} values"))?;

        // The file size bounds n_values, so this allocation is backed by real bytes.
        let values = read_f32s(&mut r, &mut hasher, n_values as usize, src)?;

        src.check_crc(&mut r, hasher.finalize())?;

        let meta: Metadata = bincode_options()
            .with_limit(header_len)
            .reject_trailing_bytes()
            .deserialize::<HeaderV1>(&header)
            .map(HeaderV1::into_metadata)
            .map_err(|e| TableError::Corrupted {
                path: path.to_path_buf(),
                reason: format!(
                    "the metadata header cannot be decoded ({})",
                    header_fault(&header).unwrap_or_else(|| e.to_string())
                ),
            })?;
        if meta.format_version != FORMAT_VERSION {
            return Err(TableError::Version {
                path: path.to_path_buf(),
                what: "table",
                found: meta.format_version,
                reads: FORMAT_VERSION,
            });
        }
        Table::new(meta, values).map_err(|e| e.in_file(path))
    }

    /// The metadata of a version-1 header: [`Metadata`]'s fields of that version, in order.
    #[derive(serde::Deserialize)]
    struct HeaderV1 {
        format_version: u32,
        tool: String,
        grid: [u32; 4],
        centring: String,
        quantity: String,
        units: String,
        fabric_json: String,
        options_json: String,
        symmetry: String,
    }

    impl HeaderV1 {
        fn into_metadata(self) -> Metadata {
            Metadata {
                format_version: self.format_version,
                tool: self.tool,
                // Version-1 grids are one-faced: four counts.
                grid: crate::grid::Grid::new(
                    self.grid[0],
                    self.grid[1],
                    self.grid[2],
                    self.grid[3],
                ),
                centring: self.centring,
                quantity: self.quantity,
                units: self.units,
                fabric_json: self.fabric_json,
                options_json: self.options_json,
                symmetry: self.symmetry,
                spatial: None,
                yarns: None,
                openness: None,
            }
        }
    }

    /// The fields of a version-1 header, in order: `(name, false)` for a u32, `(name, true)`
    /// for a string (a u64 length and UTF-8 bytes); the grid is four u32.
    const FIELDS: [(&str, bool); 12] = [
        ("format_version", false),
        ("tool", true),
        ("grid.n_theta_i", false),
        ("grid.n_phi_i", false),
        ("grid.n_theta_o", false),
        ("grid.n_phi_o", false),
        ("centring", true),
        ("quantity", true),
        ("units", true),
        ("fabric_json", true),
        ("options_json", true),
        ("symmetry", true),
    ];

    /// The first field of a version-1 header that cannot be read, in words (bincode's own
    /// message for a string longer than the header is an empty I/O error): `None` when every
    /// field reads.
    pub(super) fn header_fault(header: &[u8]) -> Option<String> {
        let mut at = 0usize;
        for (name, string) in FIELDS {
            let left = header.len() - at;
            let width = if string { 8 } else { 4 };
            if left < width {
                return Some(format!(
                    "the header ends inside field `{name}` ({left} of its {width} bytes are there)"
                ));
            }
            let word = &header[at..at + width];
            at += width;
            if !string {
                continue;
            }
            let len = u64::from_le_bytes(word.try_into().expect("8 bytes"));
            let left = (header.len() - at) as u64;
            if len > left {
                return Some(format!(
                    "field `{name}` says it is {len} bytes long, but only {left} bytes of the \
                     header are left"
                ));
            }
            let bytes = &header[at..at + len as usize];
            if let Err(e) = std::str::from_utf8(bytes) {
                return Some(format!("field `{name}` is not UTF-8 text ({e})"));
            }
            at += len as usize;
        }
        (at < header.len()).then(|| {
            format!(
                "{} bytes follow the last field `symmetry`",
                header.len() - at
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::legacy::header_fault;

    fn string(s: &str) -> Vec<u8> {
        let mut v = (s.len() as u64).to_le_bytes().to_vec();
        v.extend_from_slice(s.as_bytes());
        v
    }

    fn header(tool_len: Option<u64>) -> Vec<u8> {
        let mut h = 1u32.to_le_bytes().to_vec();
        match tool_len {
            Some(n) => h.extend_from_slice(&n.to_le_bytes()),
            None => h.extend(string("clothbake 0.1.0")),
        }
        for n in [2u32, 3, 2, 4] {
            h.extend_from_slice(&n.to_le_bytes());
        }
        for s in ["cell", "f_r", "1/sr", "{}", "{}", "none"] {
            h.extend(string(s));
        }
        h
    }

    #[test]
    fn a_good_header_has_no_fault() {
        assert_eq!(header_fault(&header(None)), None);
    }

    #[test]
    fn faults_name_the_field() {
        let e = header_fault(&header(Some(1 << 60))).unwrap();
        assert!(
            e.contains("field `tool` says it is 1152921504606846976 bytes long"),
            "{e}"
        );
        let h = header(None);
        let e = header_fault(&h[..h.len() - 2]).unwrap();
        assert!(
            e.contains("field `symmetry` says it is 4 bytes long"),
            "{e}"
        );
        let e = header_fault(&h[..6]).unwrap();
        assert!(e.contains("ends inside field `tool`"), "{e}");
        let mut more = h.clone();
        more.push(0);
        assert!(header_fault(&more).unwrap().contains("1 bytes follow"));
    }
}
