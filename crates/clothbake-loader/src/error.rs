//! [`TableError`]: what can go wrong reading, writing or building a table or another file of
//! the binary container. Every message names the file (where there is one), the cause and,
//! where useful, the fix.

use std::borrow::Cow;
use std::io;
use std::path::{Path, PathBuf};

/// Errors of reading, writing and building tables, and of the other files of the binary
/// container (shards, checkpoints). Every message names the file (where there is one), the
/// cause and, where useful, the fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TableError {
    /// The operating system refused an operation on a file.
    #[error("{}: cannot {action}: {source}", .path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What was being done, e.g. "read the table" or "write the PNG image".
        action: Cow<'static, str>,
        /// The cause.
        source: io::Error,
    },
    /// The target exists and overwriting was not asked for. (The front ends name their own
    /// switch: `--force` on the command line, `overwrite=True` in Python.)
    #[error("{}: the file already exists; ask for it to be overwritten (overwrite = true) to replace it", .path.display())]
    AlreadyExists {
        /// The existing file.
        path: PathBuf,
    },
    /// The folder to write into does not exist.
    #[error("{}: cannot write {}: the folder does not exist; create it first", .dir.display(), .path.display())]
    NoSuchFolder {
        /// The missing folder.
        dir: PathBuf,
        /// The file that was to be written.
        path: PathBuf,
    },
    /// The file is empty.
    #[error("{}: the file is empty; bake it again", .path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The file is not a clothbake file of the kind wanted: neither a binary file nor an EXR,
    /// or an EXR not written by clothbake.
    #[error("{}: not a clothbake {what}: {reason}", .path.display())]
    Foreign {
        /// The file.
        path: PathBuf,
        /// What it should have been, e.g. "table".
        what: Cow<'static, str>,
        /// What gave it away.
        reason: String,
    },
    /// The file has a format version this build does not read.
    #[error(
        "{}: {what} format version {found}, but this build reads versions up to {reads}; {}",
        .path.display(),
        if *.found > *.reads { "update the loader".to_string() } else { format!("bake the {what} again") }
    )]
    Version {
        /// The file.
        path: PathBuf,
        /// What the file should be, e.g. "table".
        what: &'static str,
        /// The version in the file.
        found: u32,
        /// The newest version this build reads (and writes).
        reads: u32,
    },
    /// A binary container file of another kind than the one wanted (a shard given as a
    /// table, say).
    #[error("{}: the file is a {found}, not a {expected}; {fix}", .path.display())]
    WrongKind {
        /// The file.
        path: PathBuf,
        /// The kind the file holds, in words.
        found: String,
        /// The kind or kinds wanted, in words.
        expected: Cow<'static, str>,
        /// What to do.
        fix: &'static str,
    },
    /// The file is shorter than its header says.
    #[error("{}: truncated: {detail}; the file is incomplete, bake it again", .path.display())]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Sizes expected and found.
        detail: String,
    },
    /// The stored checksum does not match the contents.
    #[error(
        "{}: checksum mismatch (stored {stored:#010x}, computed {computed:#010x}): the file is corrupted; bake it again",
        .path.display()
    )]
    Checksum {
        /// The file.
        path: PathBuf,
        /// CRC-32 stored in the file.
        stored: u32,
        /// CRC-32 of the contents.
        computed: u32,
    },
    /// The file is damaged or inconsistent in some other way.
    #[error("{}: corrupted file: {reason}; bake it again", .path.display())]
    Corrupted {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The file cannot be written in the requested form.
    #[error("{}: cannot write the {what}: {reason}", .path.display())]
    Unwritable {
        /// The file.
        path: PathBuf,
        /// What was to be written, e.g. "table" or "PNG image".
        what: Cow<'static, str>,
        /// Why, and what to do instead.
        reason: String,
    },
    /// A table or grid that breaks the rules (see [`crate::Table::new`]), not tied to a file.
    #[error("invalid table: {reason}")]
    InvalidTable {
        /// What is wrong.
        reason: String,
    },
}

impl TableError {
    /// An [`TableError::Io`] error.
    pub(crate) fn io(
        path: &Path,
        action: impl Into<Cow<'static, str>>,
        source: io::Error,
    ) -> TableError {
        TableError::Io {
            path: path.to_path_buf(),
            action: action.into(),
            source,
        }
    }

    /// Attaches `path` to an [`TableError::InvalidTable`] error found while writing a table.
    pub(crate) fn unwritable(self, path: &Path) -> TableError {
        match self {
            TableError::InvalidTable { reason } => TableError::Unwritable {
                path: path.to_path_buf(),
                what: "table".into(),
                reason,
            },
            other => other,
        }
    }

    /// Whether this is a one-faced lookup's refusal of a two-faced table ([`crate::Brdf::open`]:
    /// open it with [`crate::TwoFacedBrdf`] instead).
    pub fn is_two_faced_table(&self) -> bool {
        matches!(self, TableError::WrongKind { found, .. } if found.starts_with(crate::TWO_FACED))
    }

    /// Attaches `path` to an [`TableError::InvalidTable`] error found while reading.
    pub(crate) fn in_file(self, path: &Path) -> TableError {
        match self {
            TableError::InvalidTable { reason } => TableError::Corrupted {
                path: path.to_path_buf(),
                reason,
            },
            other => other,
        }
    }
}
