//! The binary container: one checksummed file layout for binary tables, the baker's shards
//! and its checkpoints (`docs/reference/table-format.md` describes it byte by byte).
//!
//! ```text
//! magic "CLTHBAKE" (8) | version u32 (4) | kind tag, ASCII, zero-padded (16)
//! | header length H u64 (8) | value count N u64 (8) | header: JSON object, UTF-8 (H)
//! | values: f32 (4 N) | CRC-32 of every byte before it u32 (4)        (all little-endian)
//! ```
//!
//! [`write_container`] writes a (kind, header, values) triple atomically;
//! [`read_container`] reads one back, checking, in order, the magic bytes, the version, the
//! kind, the header length (at most [`MAX_HEADER_LEN`]), that the file is exactly as long as
//! `H` and `N` say (before allocating anything), the checksum and the header's JSON. What the
//! header and values mean is up to each kind: a table's header is its [`crate::Metadata`].

use std::borrow::Cow;
use std::fmt;
use std::io::{BufReader, Write};
use std::path::Path;

use crate::atomic::{write_atomic_as, write_owned_as};
use crate::bytes::{hex, open_sized, read_f32s, read_hashed, read_up_to, CrcWriter, Source};
use crate::error::TableError;

/// The 8 magic bytes that open every binary container file.
pub const BINARY_MAGIC: [u8; 8] = *b"CLTHBAKE";

/// Version of the container layout. Readers reject any other version, except that
/// [`crate::read_binary`] still reads version-1 tables (a bincode header).
pub const CONTAINER_VERSION: u32 = 2;

/// Largest header, in bytes (16 MiB): longer headers are refused before anything is
/// allocated.
pub const MAX_HEADER_LEN: u64 = 1 << 24;

/// Bytes of the kind tag.
pub const KIND_LEN: usize = 16;

/// The version of the first binary tables, whose header is bincode (read by
/// [`crate::read_binary`] only).
pub(crate) const LEGACY_TABLE_VERSION: u32 = 1;

/// Offset of the header: magic, version, kind, header length, value count.
const PREFIX_LEN: usize = 8 + 4 + KIND_LEN + 8 + 8;

/// What a container file holds; stored as its tag ([`ContainerKind::tag`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ContainerKind {
    /// A baked table (tag `table`): the header is its [`crate::Metadata`], the values
    /// `3 * cells` f32 (see [`crate::Table`]).
    Table,
    /// A finished shard of a bake (tag `shard`), written by the baker.
    Shard,
    /// The rows an unfinished bake has done so far (tag `checkpoint`), written by the baker.
    Checkpoint,
}

impl ContainerKind {
    /// Every kind.
    pub const ALL: [ContainerKind; 3] = [
        ContainerKind::Table,
        ContainerKind::Shard,
        ContainerKind::Checkpoint,
    ];

    /// The tag stored in the file: `table`, `shard` or `checkpoint`.
    pub fn tag(self) -> &'static str {
        match self {
            ContainerKind::Table => "table",
            ContainerKind::Shard => "shard",
            ContainerKind::Checkpoint => "checkpoint",
        }
    }

    /// The kind of a tag, `None` for a tag this build does not know.
    pub fn from_tag(tag: &str) -> Option<ContainerKind> {
        ContainerKind::ALL.into_iter().find(|k| k.tag() == tag)
    }
}

impl fmt::Display for ContainerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.tag())
    }
}

/// A container file read back: its kind, its header (a JSON object) and its values.
#[derive(Clone, Debug, PartialEq)]
pub struct Container {
    /// What the file holds.
    pub kind: ContainerKind,
    /// The header, a JSON object.
    pub header: serde_json::Value,
    /// The values.
    pub values: Vec<f32>,
}

/// Writes a container file of `kind` with `header` (a JSON object, at most
/// [`MAX_HEADER_LEN`] bytes as JSON) and `values`, atomically (see
/// [`crate::write_atomic_as`]); refuses an existing `path` unless `overwrite`. Errors name
/// the file as the kind (`cannot write the shard: ...`).
pub fn write_container(
    path: &Path,
    kind: ContainerKind,
    header: &serde_json::Value,
    values: &[f32],
    overwrite: bool,
) -> Result<(), TableError> {
    write_container_chunks(path, kind, header, [values], overwrite)
}

/// [`write_container`] with the values given as consecutive chunks (e.g. one per row), so
/// that they need not be copied into one slice first. The chunks are iterated twice: once to
/// count the values, once to write them.
pub fn write_container_chunks<'a, I>(
    path: &Path,
    kind: ContainerKind,
    header: &serde_json::Value,
    chunks: I,
    overwrite: bool,
) -> Result<(), TableError>
where
    I: IntoIterator<Item = &'a [f32]>,
    I::IntoIter: Clone,
{
    let chunks = chunks.into_iter();
    let count: u64 = chunks.clone().map(|c| c.len() as u64).sum();
    write_container_counted(path, kind, header, count, chunks, overwrite)
}

/// [`write_container_chunks`] with the number of values known beforehand: the chunks are
/// iterated once, so each may be made as it is written (gathered from a larger buffer). An
/// error (and no file) when they hold another number of values than `count`.
pub fn write_container_counted<I>(
    path: &Path,
    kind: ContainerKind,
    header: &serde_json::Value,
    count: u64,
    chunks: I,
    overwrite: bool,
) -> Result<(), TableError>
where
    I: IntoIterator,
    I::Item: AsRef<[f32]>,
{
    let unwritable = |reason: String| TableError::Unwritable {
        path: path.to_path_buf(),
        what: kind.tag().into(),
        reason,
    };
    if !header.is_object() {
        return Err(unwritable(
            "the header is not a JSON object (a bug in the caller)".to_string(),
        ));
    }
    let header = serde_json::to_vec(&sorted_keys(header))
        .map_err(|e| unwritable(format!("the header cannot be written as JSON ({e})")))?;
    if header.len() as u64 > MAX_HEADER_LEN {
        return Err(unwritable(format!(
            "the header is {} bytes of JSON, more than the limit of {MAX_HEADER_LEN} (16 MiB)",
            header.len()
        )));
    }
    let mut tag = [0u8; KIND_LEN];
    tag[..kind.tag().len()].copy_from_slice(kind.tag().as_bytes());
    // A checkpoint is the one file written under a name a bake owns (`<output>.checkpoint`).
    let owned = kind == ContainerKind::Checkpoint;
    let write_file =
        |path: &Path,
         what: &str,
         overwrite: bool,
         f: &mut dyn FnMut(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>| {
            if owned {
                write_owned_as(path, what, overwrite, |w| f(w))
            } else {
                write_atomic_as(path, what, overwrite, |w| f(w))
            }
        };
    let mut chunks = Some(chunks);
    write_file(path, kind.tag(), overwrite, &mut |out| {
        let chunks = chunks.take().expect("written once");
        let mut w = CrcWriter::new(out);
        w.write_all(&BINARY_MAGIC)?;
        w.write_all(&CONTAINER_VERSION.to_le_bytes())?;
        w.write_all(&tag)?;
        w.write_all(&(header.len() as u64).to_le_bytes())?;
        w.write_all(&count.to_le_bytes())?;
        w.write_all(&header)?;
        let mut written = 0u64;
        for chunk in chunks {
            let chunk = chunk.as_ref();
            written += chunk.len() as u64;
            if written > count {
                break;
            }
            w.write_f32s(chunk)?;
        }
        if written != count {
            return Err(std::io::Error::other(format!(
                "{written} values were given for a count of {count} (a bug in the caller)"
            )));
        }
        w.finish()
    })
}

/// The JSON value with every object's keys in sorted order, whatever the `serde_json`
/// features of the build (`preserve_order` keeps insertion order), so that the same header
/// always gives the same bytes.
fn sorted_keys(v: &serde_json::Value) -> serde_json::Value {
    match v {
        serde_json::Value::Object(m) => {
            let mut entries: Vec<(&String, &serde_json::Value)> = m.iter().collect();
            entries.sort_by(|a, b| a.0.cmp(b.0));
            serde_json::Value::Object(
                entries
                    .into_iter()
                    .map(|(k, v)| (k.clone(), sorted_keys(v)))
                    .collect(),
            )
        }
        serde_json::Value::Array(a) => {
            serde_json::Value::Array(a.iter().map(sorted_keys).collect())
        }
        other => other.clone(),
    }
}

/// Reads a container file whose kind is one of `accepted` (any kind when empty), checking
/// the magic bytes, the version, the kind, the sizes (before allocating), the checksum and
/// that the header is a JSON object. Never panics on bad input; every error names the file,
/// the cause and the fix.
pub fn read_container(path: &Path, accepted: &[ContainerKind]) -> Result<Container, TableError> {
    let noun = accepted.first().map_or("file", |k| k.tag());
    let (file, src) = open_sized(path, noun)?;
    let mut r = BufReader::with_capacity(1 << 16, file);
    let mut prefix = [0u8; PREFIX_LEN];
    let n = read_up_to(&mut r, &mut prefix).map_err(|e| src.io(e))?;
    let version = check_start(&prefix[..n], src, accepted)?;
    if version == LEGACY_TABLE_VERSION {
        return Err(legacy_table(src, accepted));
    }
    if version != CONTAINER_VERSION {
        return Err(TableError::Version {
            path: path.to_path_buf(),
            what: noun,
            found: version,
            reads: CONTAINER_VERSION,
        });
    }
    if n < 12 + KIND_LEN {
        return Err(src.ends_inside("kind tag"));
    }
    let tag = &prefix[12..12 + KIND_LEN];
    let kind = parse_tag(tag).and_then(ContainerKind::from_tag);
    if let Some(k) = kind {
        if !accepted.is_empty() && !accepted.contains(&k) {
            return Err(wrong_kind(src, k.tag().to_string(), accepted, Some(k)));
        }
    }
    if n < PREFIX_LEN {
        let what = if n < 36 {
            "header length"
        } else {
            "value count"
        };
        return Err(src.ends_inside(what));
    }
    let word = |at: usize| u64::from_le_bytes(prefix[at..at + 8].try_into().expect("8 bytes"));
    let (header_len, count) = (word(28), word(36));
    if header_len > MAX_HEADER_LEN {
        return Err(TableError::Corrupted {
            path: path.to_path_buf(),
            reason: format!(
                "the header length is {header_len} bytes, more than the limit of {MAX_HEADER_LEN} (16 MiB)"
            ),
        });
    }
    // The sizes, before anything is allocated: the file bounds every allocation below.
    let expected = count
        .checked_mul(4)
        .and_then(|b| b.checked_add(PREFIX_LEN as u64 + header_len + 4));
    src.expect_len(
        expected,
        &format!("a {header_len}-byte header and {count} values"),
    )?;

    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&prefix);
    let mut header = vec![0u8; header_len as usize];
    read_hashed(&mut r, &mut hasher, &mut header, src, "header")?;
    let count = usize::try_from(count).map_err(|_| TableError::Corrupted {
        path: path.to_path_buf(),
        reason: format!("{count} values do not fit in this machine's memory"),
    })?;
    let values = read_f32s(&mut r, &mut hasher, count, src)?;
    src.check_crc(&mut r, hasher.finalize())?;

    // The checksum holds: the tag is what the writer wrote.
    let Some(kind) = kind else {
        return Err(match parse_tag(tag) {
            Some(t) => wrong_kind(src, format!("{t:?} file"), accepted, None),
            None => TableError::Corrupted {
                path: path.to_path_buf(),
                reason: format!("the kind tag {} is not lowercase ASCII", hex(tag)),
            },
        });
    };
    let header: serde_json::Value =
        serde_json::from_slice(&header).map_err(|e| TableError::Corrupted {
            path: path.to_path_buf(),
            reason: format!("the header is not valid JSON ({e})"),
        })?;
    if !header.is_object() {
        return Err(TableError::Corrupted {
            path: path.to_path_buf(),
            reason: "the header is not a JSON object".to_string(),
        });
    }
    Ok(Container {
        kind,
        header,
        values,
    })
}

/// The version of a binary container file (its first 12 bytes) that should be of a kind in
/// `accepted`, after checking that it is not empty and starts with [`BINARY_MAGIC`].
pub(crate) fn file_version(path: &Path, accepted: &[ContainerKind]) -> Result<u32, TableError> {
    let noun = accepted.first().map_or("file", |k| k.tag());
    let (mut file, src) = open_sized(path, noun)?;
    let mut start = [0u8; 12];
    let n = read_up_to(&mut file, &mut start).map_err(|e| src.io(e))?;
    check_start(&start[..n], src, accepted)
}

/// Checks the magic bytes at the start of a file (`start`: up to its first 12 bytes) and
/// returns the version.
fn check_start(
    start: &[u8],
    src: Source<'_>,
    accepted: &[ContainerKind],
) -> Result<u32, TableError> {
    let n = start.len().min(8);
    if start[..n] != BINARY_MAGIC[..n] {
        return Err(TableError::Foreign {
            path: src.path.to_path_buf(),
            what: nouns(accepted, src.noun),
            reason: format!(
                "the first bytes are {}, not the magic bytes \"CLTHBAKE\" of a binary file",
                hex(&start[..n])
            ),
        });
    }
    if start.len() < 8 {
        return Err(src.ends_inside("magic bytes"));
    }
    if start.len() < 12 {
        return Err(src.ends_inside("format version"));
    }
    Ok(u32::from_le_bytes(
        start[8..12].try_into().expect("4 bytes"),
    ))
}

/// The tag in a kind field: lowercase ASCII letters, digits and `-`, zero-padded; `None` when
/// the field holds anything else.
fn parse_tag(field: &[u8]) -> Option<&str> {
    let end = field.iter().position(|&b| b == 0).unwrap_or(field.len());
    let (tag, pad) = field.split_at(end);
    let ok = !tag.is_empty()
        && tag
            .iter()
            .all(|&b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
        && pad.iter().all(|&b| b == 0);
    ok.then(|| std::str::from_utf8(tag).expect("ASCII"))
}

/// The accepted kinds in words: `table`, `shard or checkpoint`; `noun` when any kind goes.
fn nouns(accepted: &[ContainerKind], noun: &str) -> Cow<'static, str> {
    match accepted {
        [] => Cow::Owned(format!("binary {noun}")),
        [k] => Cow::Borrowed(k.tag()),
        _ => Cow::Owned(
            accepted
                .iter()
                .map(|k| k.tag())
                .collect::<Vec<_>>()
                .join(" or "),
        ),
    }
}

/// A file of another kind than `accepted`: `found` in words, `kind` when this build knows it.
fn wrong_kind(
    src: Source<'_>,
    found: String,
    accepted: &[ContainerKind],
    kind: Option<ContainerKind>,
) -> TableError {
    let wants_table = accepted.contains(&ContainerKind::Table);
    let fix = match kind {
        None => "this build does not know that kind of file; update the loader",
        Some(ContainerKind::Shard) if wants_table => {
            "merge the shards into a table with `clothbake merge`"
        }
        Some(ContainerKind::Checkpoint) if wants_table => {
            "it is an unfinished bake: finish it with `clothbake bake --resume`, which writes the table"
        }
        Some(ContainerKind::Table) => {
            "give the shard or checkpoint files that `clothbake bake` wrote, not a table"
        }
        Some(_) => "give a file of the kind asked for",
    };
    TableError::WrongKind {
        path: src.path.to_path_buf(),
        found,
        expected: nouns(accepted, src.noun),
        fix,
    }
}

/// The error for a version-1 file (always a table, with a bincode header) given to
/// [`read_container`].
fn legacy_table(src: Source<'_>, accepted: &[ContainerKind]) -> TableError {
    if accepted.is_empty() || accepted.contains(&ContainerKind::Table) {
        TableError::WrongKind {
            path: src.path.to_path_buf(),
            found: "version-1 binary table (bincode header)".to_string(),
            expected: format!("version-{CONTAINER_VERSION} container file").into(),
            fix:
                "open it with clothbake_loader::read_table or read_binary, which read both versions",
        }
    } else {
        wrong_kind(
            src,
            "table".to_string(),
            accepted,
            Some(ContainerKind::Table),
        )
    }
}
