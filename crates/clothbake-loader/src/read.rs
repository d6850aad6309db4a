//! Reading a table in either format, recognised by its first bytes.

use std::path::Path;

use crate::binary::read_binary;
use crate::bytes::{hex, open_regular, read_up_to};
use crate::container::BINARY_MAGIC;
use crate::error::TableError;
use crate::exr::{read_exr_stored, EXR_MAGIC};
use crate::stored::StoredTable;
use crate::table::Table;

/// Reads a table in either format, recognised by its first bytes.
pub fn read_table(path: &Path) -> Result<Table, TableError> {
    read_table_stored(path).map(StoredTable::into_table)
}

/// Reads a table in either format like [`read_table`], keeping the samples at their stored
/// precision: half for half-float EXR tables, f32 otherwise.
pub fn read_table_stored(path: &Path) -> Result<StoredTable, TableError> {
    let mut file = open_regular(path, "table")?;
    let mut head = [0u8; 8];
    let n =
        read_up_to(&mut file, &mut head).map_err(|e| TableError::io(path, "read the table", e))?;
    drop(file);
    let head = &head[..n];
    if head.is_empty() {
        Err(TableError::Empty {
            path: path.to_path_buf(),
        })
    } else if head.starts_with(&EXR_MAGIC) {
        read_exr_stored(path)
    } else if BINARY_MAGIC.starts_with(head) || head.starts_with(&BINARY_MAGIC[..4]) {
        read_binary(path).map(StoredTable::from)
    } else {
        Err(TableError::Foreign {
            path: path.to_path_buf(),
            what: "table".into(),
            reason: format!(
                "the first bytes are {}; a table starts with \"CLTHBAKE\" (binary) or 76 2f 31 01 (OpenEXR)",
                hex(head)
            ),
        })
    }
}

/// True when the file starts with the OpenEXR magic bytes (an error when it cannot be read).
pub(crate) fn is_exr(path: &Path) -> Result<bool, TableError> {
    let mut file = open_regular(path, "table")?;
    let mut head = [0u8; 4];
    let n =
        read_up_to(&mut file, &mut head).map_err(|e| TableError::io(path, "read the table", e))?;
    Ok(head[..n] == EXR_MAGIC)
}
