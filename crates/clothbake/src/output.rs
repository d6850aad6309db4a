//! Writing a baked table: through the loader's atomic writers, with reproducible EXR bytes.
//!
//! The `exr` crate keeps an image's custom header attributes in a `HashMap` and writes them in
//! its (randomly seeded) iteration order, so two writes of the same table give EXR files with
//! the same attributes in different orders. [`write_table`] sorts them by name (as the OpenEXR
//! library itself writes them): a table is then byte-identical however and whenever it is
//! baked. Reordering attributes keeps the header's length, so the offset table after it stays
//! valid.

use clothbake_loader::{write_atomic, write_binary, write_exr, Precision, Table, TableError};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The table formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// OpenEXR with half or float samples.
    Exr(Precision),
    /// The checksummed binary file.
    Binary,
}

/// Version-field flags of multi-part and deep EXR files (not written by clothbake).
const EXR_MULTIPART: u32 = 0x1000;
const EXR_DEEP: u32 = 0x800;

/// Sorts the header attributes of a single-part EXR file by name, in place. Returns false (and
/// leaves the bytes alone) for anything else than a well-formed single-part header.
pub fn sort_exr_attributes(bytes: &mut [u8]) -> bool {
    if bytes.len() < 8 || bytes[..4] != clothbake_loader::format::EXR_MAGIC {
        return false;
    }
    let flags = u32::from_le_bytes([bytes[4], bytes[5], bytes[6], bytes[7]]);
    if flags & (EXR_MULTIPART | EXR_DEEP) != 0 {
        return false;
    }
    let start = 8;
    let mut pos = start;
    let mut attrs: Vec<(usize, usize, usize)> = Vec::new(); // (start, name end, end)
    let cstr_end = |from: usize| bytes[from..].iter().position(|&b| b == 0).map(|i| from + i);
    loop {
        let Some(name_end) = cstr_end(pos) else {
            return false;
        };
        if name_end == pos {
            break; // the empty name that ends the header
        }
        let Some(type_end) = cstr_end(name_end + 1) else {
            return false;
        };
        let size_at = type_end + 1;
        if size_at + 4 > bytes.len() {
            return false;
        }
        let size = i32::from_le_bytes([
            bytes[size_at],
            bytes[size_at + 1],
            bytes[size_at + 2],
            bytes[size_at + 3],
        ]);
        let Ok(size) = usize::try_from(size) else {
            return false;
        };
        let end = size_at + 4 + size;
        if end > bytes.len() {
            return false;
        }
        attrs.push((pos, name_end, end));
        pos = end;
    }
    let header_end = pos;
    let mut sorted: Vec<&(usize, usize, usize)> = attrs.iter().collect();
    sorted.sort_by(|a, b| bytes[a.0..a.1].cmp(&bytes[b.0..b.1]));
    let mut out = Vec::with_capacity(header_end - start);
    for &&(s, _, e) in &sorted {
        out.extend_from_slice(&bytes[s..e]);
    }
    bytes[start..header_end].copy_from_slice(&out);
    true
}

/// Removes a staging file when dropped.
struct Staging(PathBuf);

impl Drop for Staging {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Writes `table` to `path` atomically (refusing an existing file unless `overwrite`). EXR
/// tables are encoded by the loader into a staging file beside `path`, their header attributes
/// sorted, and the bytes written atomically to `path`; the staging file is removed in any case.
pub fn write_table(
    path: &Path,
    table: &Table,
    format: Format,
    overwrite: bool,
) -> Result<(), TableError> {
    match format {
        Format::Binary => write_binary(path, table, overwrite),
        Format::Exr(precision) => {
            if !overwrite && std::fs::symlink_metadata(path).is_ok() {
                return Err(TableError::AlreadyExists {
                    path: path.to_path_buf(),
                });
            }
            let name = path.file_name().ok_or_else(|| TableError::Unwritable {
                path: path.to_path_buf(),
                reason: "the path does not name a file".to_string(),
            })?;
            let mut stage_name = std::ffi::OsString::from(".");
            stage_name.push(name);
            stage_name.push(format!(".stage-{}", std::process::id()));
            let stage = path.with_file_name(stage_name);
            let guard = Staging(stage.clone());
            // Errors name the table the user asked for, not the staging file.
            write_exr(&stage, table, precision, true).map_err(|e| rename_path(e, path))?;
            let mut bytes = std::fs::read(&stage).map_err(|source| TableError::Io {
                path: stage.clone(),
                action: "read the table back",
                source,
            })?;
            drop(guard);
            sort_exr_attributes(&mut bytes);
            write_atomic(path, overwrite, |w| w.write_all(&bytes))
        }
    }
}

/// The same error about `path` instead of the staging or temporary file it names.
fn rename_path(e: TableError, path: &Path) -> TableError {
    match e {
        TableError::Io { action, source, .. } => TableError::Io {
            path: path.to_path_buf(),
            action,
            source,
        },
        TableError::Unwritable { reason, .. } => TableError::Unwritable {
            path: path.to_path_buf(),
            reason,
        },
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_loader::{read_table, Grid, Metadata};

    fn table() -> Table {
        let g = Grid {
            n_theta_i: 2,
            n_phi_i: 3,
            n_theta_o: 2,
            n_phi_o: 4,
        };
        let values = (0..3 * g.len()).map(|k| 0.01 * k as f32).collect();
        Table::new(
            Metadata::new("clothbake test", g, "{}", "{}", "none"),
            values,
        )
        .unwrap()
    }

    #[test]
    fn exr_bytes_are_reproducible_and_readable() {
        let dir = std::env::temp_dir().join(format!("clothbake-output-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let t = table();
        let mut files = Vec::new();
        for k in 0..4 {
            let p = dir.join(format!("t{k}.exr"));
            write_table(&p, &t, Format::Exr(Precision::F32), true).unwrap();
            assert_eq!(read_table(&p).unwrap(), t);
            files.push(std::fs::read(&p).unwrap());
        }
        assert!(files.iter().all(|f| *f == files[0]));
        // No staging or temporary file is left behind.
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["t0.exr", "t1.exr", "t2.exr", "t3.exr"]);
        // Refuses to overwrite.
        let e = write_table(&dir.join("t0.exr"), &t, Format::Exr(Precision::F16), false);
        assert!(matches!(e, Err(TableError::AlreadyExists { .. })));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn malformed_headers_are_left_alone() {
        let mut junk = b"not an exr".to_vec();
        assert!(!sort_exr_attributes(&mut junk));
        let mut cut = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, b'a', 0, b'b'];
        let copy = cut.clone();
        assert!(!sort_exr_attributes(&mut cut));
        assert_eq!(cut, copy);
    }
}
