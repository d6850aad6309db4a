//! Table file formats: the OpenEXR image and the checksummed binary file.
//!
//! The baker writes tables with [`write_exr`] or [`write_binary`]; renderers read either with
//! [`read_table`], which recognises the format by its first bytes. Both formats hold the same
//! [`Table`]: a [`Metadata`] record and the RGB values of every cell of a cell-centred 4-D
//! [`Grid`]. `docs/table-format.md` describes both formats byte by byte for other tools.
//!
//! Writes are atomic ([`write_atomic`]): a table appears at its path complete or not at all.
//! Reads never panic on bad input: truncated, corrupted or foreign files give a [`TableError`]
//! that names the file, the cause and the fix.

use std::fmt;
use std::fs::{self, File};
use std::io::{self, BufReader, BufWriter, Cursor, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use bincode::Options;
use serde::{Deserialize, Serialize};

use crate::stored::{Samples, StoredTable};

/// Version of both table formats. Readers reject any other version.
pub const FORMAT_VERSION: u32 = 1;

/// The 8 magic bytes that open a binary table.
pub const BINARY_MAGIC: [u8; 8] = *b"CLTHBAKE";

/// The 4 magic bytes that open every OpenEXR file.
pub const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// Largest number of cells a grid may have (2^31).
pub const MAX_CELLS: u64 = 1 << 31;

/// EXR header attribute holding the [`Metadata`] as JSON.
pub const ATTR_METADATA: &str = "clothbake.metadata";
/// EXR header attribute holding the format version as decimal text, for humans and other tools.
pub const ATTR_FORMAT_VERSION: &str = "clothbake.format_version";
/// EXR header attribute describing the grid in words.
pub const ATTR_GRID: &str = "clothbake.grid";
/// EXR header attribute holding the units of the values.
pub const ATTR_UNITS: &str = "clothbake.units";
/// EXR header attribute naming the tool that wrote the file.
pub const ATTR_TOOL: &str = "clothbake.tool";
/// EXR header attribute holding a CRC-32, as 8 lowercase hex digits, of the
/// [`ATTR_METADATA`] text followed by every sample as f32 little-endian, pixels in row-major
/// order, R, G, B per pixel. Readers verify it when present, as EXR itself has no checksum.
pub const ATTR_CRC32: &str = "clothbake.crc32";

/// Binary layout: magic (8) + version (4) + header length (8).
const BINARY_PREFIX_LEN: u64 = 8 + 4 + 8;
/// Binary layout: everything except the header bytes and the values.
const BINARY_FIXED_LEN: u64 = BINARY_PREFIX_LEN + 8 + 4;

/// Number of `f32` values converted per chunk when reading or writing tables.
const CHUNK_VALUES: usize = 16 * 1024;

/// The 4-D grid of incident and outgoing directions, cell-centred, in degrees.
///
/// Polar angles cover [0, 90] degrees from +Z, azimuths [0, 360) degrees from +X toward +Y.
/// Cell `k` of a polar axis with `n` cells is centred on `(k + 0.5) * 90 / n` degrees; cell `k`
/// of an azimuth axis on `(k + 0.5) * 360 / n` degrees. Cells are ordered theta_i, phi_i,
/// theta_o, phi_o, the last varying fastest (see [`Grid::index`]).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grid {
    /// Number of cells of the incident polar angle.
    pub n_theta_i: u32,
    /// Number of cells of the incident azimuth.
    pub n_phi_i: u32,
    /// Number of cells of the outgoing polar angle.
    pub n_theta_o: u32,
    /// Number of cells of the outgoing azimuth.
    pub n_phi_o: u32,
}

impl Grid {
    /// Number of cells. Saturates at `usize::MAX` for absurd grids that [`Grid::validate`]
    /// rejects.
    pub fn len(&self) -> usize {
        usize::try_from(self.cells()).unwrap_or(usize::MAX)
    }

    /// True when the grid has no cells (an invalid grid).
    pub fn is_empty(&self) -> bool {
        self.cells() == 0
    }

    /// Number of cells as `u64`, saturating.
    fn cells(&self) -> u64 {
        [self.n_theta_i, self.n_phi_i, self.n_theta_o, self.n_phi_o]
            .iter()
            .fold(1u64, |acc, &n| acc.saturating_mul(u64::from(n)))
    }

    /// Index of a cell: `((ti * n_phi_i + pi) * n_theta_o + to) * n_phi_o + po`.
    pub fn index(&self, ti: u32, pi: u32, to: u32, po: u32) -> usize {
        debug_assert!(ti < self.n_theta_i && pi < self.n_phi_i);
        debug_assert!(to < self.n_theta_o && po < self.n_phi_o);
        let (ti, pi, to, po) = (ti as usize, pi as usize, to as usize, po as usize);
        ((ti * self.n_phi_i as usize + pi) * self.n_theta_o as usize + to) * self.n_phi_o as usize
            + po
    }

    /// Centre of incident polar cell `k`, degrees from +Z.
    pub fn theta_i_deg(&self, k: u32) -> f64 {
        polar_centre_deg(k, self.n_theta_i)
    }

    /// Centre of incident azimuth cell `k`, degrees from +X toward +Y.
    pub fn phi_i_deg(&self, k: u32) -> f64 {
        azimuth_centre_deg(k, self.n_phi_i)
    }

    /// Centre of outgoing polar cell `k`, degrees from +Z.
    pub fn theta_o_deg(&self, k: u32) -> f64 {
        polar_centre_deg(k, self.n_theta_o)
    }

    /// Centre of outgoing azimuth cell `k`, degrees from +X toward +Y.
    pub fn phi_o_deg(&self, k: u32) -> f64 {
        azimuth_centre_deg(k, self.n_phi_o)
    }

    /// Width of the EXR image: `n_phi_i * n_phi_o`.
    pub fn exr_width(&self) -> u64 {
        u64::from(self.n_phi_i) * u64::from(self.n_phi_o)
    }

    /// Height of the EXR image: `n_theta_i * n_theta_o`.
    pub fn exr_height(&self) -> u64 {
        u64::from(self.n_theta_i) * u64::from(self.n_theta_o)
    }

    /// Checks that every axis has cells and that the grid has at most [`MAX_CELLS`] cells.
    pub fn validate(&self) -> Result<(), TableError> {
        let axes = [
            ("n_theta_i", self.n_theta_i),
            ("n_phi_i", self.n_phi_i),
            ("n_theta_o", self.n_theta_o),
            ("n_phi_o", self.n_phi_o),
        ];
        for (name, n) in axes {
            if n == 0 {
                return Err(TableError::InvalidTable {
                    reason: format!("grid {self}: {name} is 0; every axis needs at least 1 cell"),
                });
            }
        }
        if self.cells() > MAX_CELLS {
            return Err(TableError::InvalidTable {
                reason: format!(
                    "grid {self}: {} cells is more than the limit of {MAX_CELLS} (2^31); use a coarser grid",
                    self.cells()
                ),
            });
        }
        Ok(())
    }
}

impl fmt::Display for Grid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "theta_i {} phi_i {} theta_o {} phi_o {}",
            self.n_theta_i, self.n_phi_i, self.n_theta_o, self.n_phi_o
        )
    }
}

fn polar_centre_deg(k: u32, n: u32) -> f64 {
    (f64::from(k) + 0.5) * 90.0 / f64::from(n)
}

fn azimuth_centre_deg(k: u32, n: u32) -> f64 {
    (f64::from(k) + 0.5) * 360.0 / f64::from(n)
}

/// What a table holds and how it was made. Stored in both formats.
///
/// The field order is part of the binary format (see `docs/table-format.md`): do not reorder.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Metadata {
    /// [`FORMAT_VERSION`] of the file.
    pub format_version: u32,
    /// The tool that wrote the table, e.g. `"clothbake 0.1.0"`.
    pub tool: String,
    /// The grid of directions.
    pub grid: Grid,
    /// Where samples sit in their cells: always `"cell"` (cell centres).
    pub centring: String,
    /// The tabulated quantity: `"f_r"`, the BRDF.
    pub quantity: String,
    /// Units of the values: `"1/sr"`.
    pub units: String,
    /// The full fabric file, as JSON text.
    pub fabric_json: String,
    /// The bake options, as JSON text.
    pub options_json: String,
    /// The symmetry the baker exploited, in words, e.g. `"mirror x, mirror y"` or `"none"`.
    pub symmetry: String,
}

impl Metadata {
    /// Metadata of the current format version for a cell-centred table of `f_r` in `1/sr`.
    pub fn new(
        tool: impl Into<String>,
        grid: Grid,
        fabric_json: impl Into<String>,
        options_json: impl Into<String>,
        symmetry: impl Into<String>,
    ) -> Metadata {
        Metadata {
            format_version: FORMAT_VERSION,
            tool: tool.into(),
            grid,
            centring: "cell".to_string(),
            quantity: "f_r".to_string(),
            units: "1/sr".to_string(),
            fabric_json: fabric_json.into(),
            options_json: options_json.into(),
            symmetry: symmetry.into(),
        }
    }

    /// Checks the format version, the grid and the centring.
    pub fn validate(&self) -> Result<(), TableError> {
        if self.format_version != FORMAT_VERSION {
            return Err(TableError::InvalidTable {
                reason: format!(
                    "metadata says format version {}, but this is version {FORMAT_VERSION}",
                    self.format_version
                ),
            });
        }
        self.grid.validate()?;
        if self.centring != "cell" {
            return Err(TableError::InvalidTable {
                reason: format!(
                    "centring is {:?}, but only \"cell\" (cell-centred samples) is supported",
                    self.centring
                ),
            });
        }
        Ok(())
    }

    /// The metadata as JSON text with every non-ASCII character escaped (`\uXXXX`), so that
    /// it survives any tool that treats EXR text attributes as bytes or as Latin-1.
    pub fn to_ascii_json(&self) -> String {
        let json = serde_json::to_string(self).expect("Metadata serialises to JSON");
        escape_non_ascii(&json)
    }
}

/// Replaces every non-ASCII character of a JSON text by `\uXXXX` escapes (UTF-16 surrogate
/// pairs above U+FFFF). Valid because non-ASCII characters only occur inside JSON strings.
fn escape_non_ascii(json: &str) -> String {
    if json.is_ascii() {
        return json.to_string();
    }
    let mut out = String::with_capacity(json.len() + 16);
    for c in json.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            let mut units = [0u16; 2];
            for unit in c.encode_utf16(&mut units) {
                out.push_str(&format!("\\u{unit:04x}"));
            }
        }
    }
    out
}

/// A baked table: metadata and RGB values, interleaved, one triple per grid cell.
///
/// The value of cell `c` (see [`Grid::index`]) and channel `k` (0 = R, 1 = G, 2 = B) is
/// `values[3 * c + k]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// What the table holds.
    pub meta: Metadata,
    /// RGB values, interleaved; `values.len() == 3 * meta.grid.len()`.
    pub values: Vec<f32>,
}

impl Table {
    /// A table, after checking the metadata, the number of values and that every value is
    /// finite.
    pub fn new(meta: Metadata, values: Vec<f32>) -> Result<Table, TableError> {
        let table = Table { meta, values };
        table.validate()?;
        Ok(table)
    }

    /// Checks what [`Table::new`] checks; the writers call it, as the fields are public.
    pub fn validate(&self) -> Result<(), TableError> {
        let bad = self.values.iter().position(|v| !v.is_finite());
        check_values(
            &self.meta,
            self.values.len(),
            bad.map(|i| (i, self.values[i])),
        )
    }

    /// The grid of the table.
    pub fn grid(&self) -> &Grid {
        &self.meta.grid
    }

    /// The RGB value of a cell.
    pub fn rgb(&self, ti: u32, pi: u32, to: u32, po: u32) -> [f32; 3] {
        let c = self.meta.grid.index(ti, pi, to, po);
        [
            self.values[3 * c],
            self.values[3 * c + 1],
            self.values[3 * c + 2],
        ]
    }
}

/// Checks a table's metadata, its number of values (`len`) and the first non-finite value, if
/// any (its index and value): the rules of [`Table::new`], for any sample type.
pub(crate) fn check_values(
    meta: &Metadata,
    len: usize,
    non_finite: Option<(usize, f32)>,
) -> Result<(), TableError> {
    meta.validate()?;
    let expected = meta.grid.len() * 3;
    if len != expected {
        return Err(TableError::InvalidTable {
            reason: format!(
                "grid {} has {} cells and needs {expected} values (RGB), but there are {len}",
                meta.grid,
                meta.grid.len(),
            ),
        });
    }
    if let Some((i, v)) = non_finite {
        return Err(TableError::InvalidTable {
            reason: format!(
                "value {} of cell {} (channel {}) is {}; every value must be finite",
                i,
                i / 3,
                ['R', 'G', 'B'][i % 3],
                v
            ),
        });
    }
    Ok(())
}

/// Sample type of the EXR channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Precision {
    /// 16-bit half floats (the default): half the size, about 3 significant digits, at most
    /// 65504.
    #[default]
    F16,
    /// 32-bit floats: exact.
    F32,
}

/// Errors of reading, writing and building tables. Every message names the file (where there
/// is one), the cause and, where useful, the fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TableError {
    /// The operating system refused an operation on a file.
    #[error("{}: cannot {action}: {source}", .path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What was being done, e.g. "read the table".
        action: &'static str,
        /// The cause.
        source: io::Error,
    },
    /// The target exists and overwriting was not asked for.
    #[error("{}: the file already exists; use --force to overwrite it", .path.display())]
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
    /// The file is neither a binary table nor an EXR, or an EXR not written by clothbake.
    #[error("{}: not a clothbake table: {reason}", .path.display())]
    Foreign {
        /// The file.
        path: PathBuf,
        /// What gave it away.
        reason: String,
    },
    /// The file has a format version this build does not read.
    #[error(
        "{}: table format version {found}, but this build reads version {FORMAT_VERSION}; {}",
        .path.display(),
        if *.found > FORMAT_VERSION { "update the loader" } else { "bake the table again" }
    )]
    Version {
        /// The file.
        path: PathBuf,
        /// The version in the file.
        found: u32,
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
    #[error("{}: corrupted table: {reason}; bake it again", .path.display())]
    Corrupted {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The table cannot be stored in the requested form.
    #[error("{}: cannot write the table: {reason}", .path.display())]
    Unwritable {
        /// The file.
        path: PathBuf,
        /// Why, and what to do instead.
        reason: String,
    },
    /// A table or grid that breaks the rules (see [`Table::new`]), not tied to a file.
    #[error("invalid table: {reason}")]
    InvalidTable {
        /// What is wrong.
        reason: String,
    },
}

impl TableError {
    fn io(path: &Path, action: &'static str, source: io::Error) -> TableError {
        TableError::Io {
            path: path.to_path_buf(),
            action,
            source,
        }
    }

    /// Attaches `path` to an [`TableError::InvalidTable`] error found while writing.
    fn unwritable(self, path: &Path) -> TableError {
        match self {
            TableError::InvalidTable { reason } => TableError::Unwritable {
                path: path.to_path_buf(),
                reason,
            },
            other => other,
        }
    }

    /// Attaches `path` to an [`TableError::InvalidTable`] error found while reading.
    fn in_file(self, path: &Path) -> TableError {
        match self {
            TableError::InvalidTable { reason } => TableError::Corrupted {
                path: path.to_path_buf(),
                reason,
            },
            other => other,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Atomic writes

/// Distinguishes temporary files of concurrent writes from one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Removes the temporary file when dropped, unless disarmed.
struct TempGuard {
    path: PathBuf,
    armed: bool,
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if self.armed {
            let _ = fs::remove_file(&self.path);
        }
    }
}

/// Writes a file atomically: `path` ends up either complete or untouched.
///
/// Refuses an existing `path` unless `overwrite`. Otherwise calls `write` on a temporary file
/// `.<name>.tmp-<pid>-<n>` in the same folder, flushes and fsyncs it, and renames it over
/// `path` (without `overwrite`, it is hard-linked instead, so that a file created meanwhile is
/// never clobbered). The temporary file is removed on any error.
pub fn write_atomic(
    path: &Path,
    overwrite: bool,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), TableError> {
    let name = path.file_name().ok_or_else(|| TableError::Unwritable {
        path: path.to_path_buf(),
        reason: "the path does not name a file".to_string(),
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !overwrite && fs::symlink_metadata(path).is_ok() {
        return Err(TableError::AlreadyExists {
            path: path.to_path_buf(),
        });
    }
    match fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(TableError::Unwritable {
                path: path.to_path_buf(),
                reason: format!("{} is not a folder", dir.display()),
            })
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(TableError::NoSuchFolder {
                dir: dir.to_path_buf(),
                path: path.to_path_buf(),
            })
        }
        Err(e) => return Err(TableError::io(dir, "open the folder", e)),
    }

    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(
        ".tmp-{}-{}",
        std::process::id(),
        TEMP_COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let temp = dir.join(temp_name);

    let file = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&temp)
        .map_err(|e| TableError::io(&temp, "create the temporary file", e))?;
    let mut guard = TempGuard {
        path: temp.clone(),
        armed: true,
    };

    let mut writer = BufWriter::with_capacity(1 << 20, file);
    write(&mut writer).map_err(|e| TableError::io(path, "write the table", e))?;
    let file = writer
        .into_inner()
        .map_err(|e| TableError::io(path, "write the table", e.into_error()))?;
    file.sync_all()
        .map_err(|e| TableError::io(path, "flush the table to disk", e))?;
    drop(file);

    let rename = |guard: &mut TempGuard| {
        fs::rename(&temp, path)
            .map_err(|e| TableError::io(path, "move the table into place", e))?;
        guard.armed = false;
        Ok::<(), TableError>(())
    };
    if overwrite {
        rename(&mut guard)?;
    } else {
        // A hard link fails if the target appeared meanwhile; the guard then removes the
        // temporary name, as it does after success.
        match fs::hard_link(&temp, path) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {
                return Err(TableError::AlreadyExists {
                    path: path.to_path_buf(),
                });
            }
            // File systems without hard links: check, then rename (a small race).
            Err(_) => {
                if fs::symlink_metadata(path).is_ok() {
                    return Err(TableError::AlreadyExists {
                        path: path.to_path_buf(),
                    });
                }
                rename(&mut guard)?;
            }
        }
    }
    drop(guard);
    sync_dir(dir);
    Ok(())
}

/// Makes the rename durable where the platform allows; failures are harmless and ignored.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

// ---------------------------------------------------------------------------------------------
// Binary format

/// bincode settings of the binary header: fixed-width little-endian integers, strings as a
/// u64 length and UTF-8 bytes (see `docs/table-format.md`).
fn bincode_options() -> impl bincode::Options {
    bincode::DefaultOptions::new()
        .with_fixint_encoding()
        .with_little_endian()
}

/// A writer that computes the CRC-32 of everything written through it.
struct CrcWriter<W> {
    inner: W,
    hasher: crc32fast::Hasher,
}

impl<W: Write> Write for CrcWriter<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hasher.update(&buf[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// Writes a table in the binary format (see `docs/table-format.md`), atomically.
pub fn write_binary(path: &Path, table: &Table, overwrite: bool) -> Result<(), TableError> {
    table.validate().map_err(|e| e.unwritable(path))?;
    let header = bincode_options()
        .serialize(&table.meta)
        .map_err(|e| TableError::Unwritable {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
    write_atomic(path, overwrite, |out| {
        let mut w = CrcWriter {
            inner: out,
            hasher: crc32fast::Hasher::new(),
        };
        w.write_all(&BINARY_MAGIC)?;
        w.write_all(&FORMAT_VERSION.to_le_bytes())?;
        w.write_all(&(header.len() as u64).to_le_bytes())?;
        w.write_all(&header)?;
        w.write_all(&(table.values.len() as u64).to_le_bytes())?;
        let mut bytes = Vec::with_capacity(CHUNK_VALUES * 4);
        for chunk in table.values.chunks(CHUNK_VALUES) {
            bytes.clear();
            bytes.extend(chunk.iter().flat_map(|v| v.to_le_bytes()));
            w.write_all(&bytes)?;
        }
        let crc = w.hasher.clone().finalize();
        w.inner.write_all(&crc.to_le_bytes())
    })
}

/// Reads exactly `buf.len()` bytes, hashing them; a short read is reported as truncation.
fn read_hashed(
    r: &mut impl Read,
    hasher: &mut crc32fast::Hasher,
    buf: &mut [u8],
    (path, file_len): (&Path, u64),
    what: &str,
) -> Result<(), TableError> {
    r.read_exact(buf).map_err(|e| {
        if e.kind() == io::ErrorKind::UnexpectedEof {
            TableError::Truncated {
                path: path.to_path_buf(),
                detail: format!("the file ends inside the {what} ({file_len} bytes in all)"),
            }
        } else {
            TableError::io(path, "read the table", e)
        }
    })?;
    hasher.update(buf);
    Ok(())
}

/// Reads a binary table, checking magic bytes, version, sizes, checksum and contents.
pub fn read_binary(path: &Path) -> Result<Table, TableError> {
    let file = File::open(path).map_err(|e| TableError::io(path, "open the table", e))?;
    let file_len = file
        .metadata()
        .map_err(|e| TableError::io(path, "read the table", e))?
        .len();
    if file_len == 0 {
        return Err(TableError::Empty {
            path: path.to_path_buf(),
        });
    }
    let mut r = BufReader::with_capacity(1 << 20, file);
    let mut hasher = crc32fast::Hasher::new();

    let mut magic = [0u8; 8];
    let n =
        read_up_to(&mut r, &mut magic).map_err(|e| TableError::io(path, "read the table", e))?;
    if magic[..n] != BINARY_MAGIC[..n] {
        return Err(TableError::Foreign {
            path: path.to_path_buf(),
            reason: format!(
                "the first bytes are {}, not the magic bytes \"CLTHBAKE\" of a binary table",
                hex(&magic[..n])
            ),
        });
    }
    if n < magic.len() {
        return Err(TableError::Truncated {
            path: path.to_path_buf(),
            detail: format!("the file ends inside the magic bytes ({file_len} bytes in all)"),
        });
    }
    hasher.update(&magic);

    let mut word = [0u8; 4];
    read_hashed(
        &mut r,
        &mut hasher,
        &mut word,
        (path, file_len),
        "format version",
    )?;
    let version = u32::from_le_bytes(word);
    if version != FORMAT_VERSION {
        return Err(TableError::Version {
            path: path.to_path_buf(),
            found: version,
        });
    }

    let mut long = [0u8; 8];
    read_hashed(
        &mut r,
        &mut hasher,
        &mut long,
        (path, file_len),
        "header length",
    )?;
    let header_len = u64::from_le_bytes(long);
    let room = file_len.saturating_sub(BINARY_FIXED_LEN);
    if header_len > room {
        return Err(TableError::Truncated {
            path: path.to_path_buf(),
            detail: format!(
                "the header is {header_len} bytes long, but the file has only {file_len} bytes in all"
            ),
        });
    }
    let mut header = vec![0u8; header_len as usize];
    read_hashed(&mut r, &mut hasher, &mut header, (path, file_len), "header")?;

    read_hashed(
        &mut r,
        &mut hasher,
        &mut long,
        (path, file_len),
        "value count",
    )?;
    let n_values = u64::from_le_bytes(long);
    let expected_len = n_values
        .checked_mul(4)
        .and_then(|b| b.checked_add(BINARY_FIXED_LEN + header_len));
    match expected_len {
        Some(expected) if expected == file_len => {}
        Some(expected) if expected > file_len => {
            return Err(TableError::Truncated {
                path: path.to_path_buf(),
                detail: format!(
                    "{n_values} values need a file of {expected} bytes, but it has {file_len}"
                ),
            })
        }
        Some(expected) => {
            return Err(TableError::Corrupted {
                path: path.to_path_buf(),
                reason: format!(
                    "{n_values} values need a file of {expected} bytes, but it has {file_len} (unexpected trailing bytes)"
                ),
            })
        }
        None => {
            return Err(TableError::Corrupted {
                path: path.to_path_buf(),
                reason: format!("impossible value count {n_values}"),
            })
        }
    }

    // The file size bounds n_values, so this allocation is backed by real bytes.
    let n_values = n_values as usize;
    let mut values = Vec::with_capacity(n_values);
    let mut bytes = vec![0u8; CHUNK_VALUES * 4];
    let mut left = n_values;
    while left > 0 {
        let take = left.min(CHUNK_VALUES);
        let buf = &mut bytes[..take * 4];
        read_hashed(&mut r, &mut hasher, buf, (path, file_len), "values")?;
        values.extend(
            buf.chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        );
        left -= take;
    }

    let computed = hasher.finalize();
    let mut unused = crc32fast::Hasher::new();
    read_hashed(&mut r, &mut unused, &mut word, (path, file_len), "checksum")?;
    let stored = u32::from_le_bytes(word);
    if stored != computed {
        return Err(TableError::Checksum {
            path: path.to_path_buf(),
            stored,
            computed,
        });
    }

    let meta: Metadata = bincode_options()
        .with_limit(header_len)
        .reject_trailing_bytes()
        .deserialize(&header)
        .map_err(|e| TableError::Corrupted {
            path: path.to_path_buf(),
            reason: format!("the metadata header cannot be decoded ({e})"),
        })?;
    if meta.format_version != FORMAT_VERSION {
        return Err(TableError::Version {
            path: path.to_path_buf(),
            found: meta.format_version,
        });
    }
    Table::new(meta, values).map_err(|e| e.in_file(path))
}

/// Reads as many bytes as are available, up to `buf.len()`.
fn read_up_to(r: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

fn hex(bytes: &[u8]) -> String {
    if bytes.is_empty() {
        return "(none)".to_string();
    }
    bytes
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

// ---------------------------------------------------------------------------------------------
// EXR format

/// The `exr` crate keeps an image's custom header attributes in a `HashMap` and writes them in
/// its (randomly seeded) iteration order; [`write_exr`] sorts them by name (as the OpenEXR
/// library writes them) so the same table always gives the same bytes. Reordering attributes
/// keeps the header's length, so the offset table after it stays valid.
/// Version-field flags of multi-part and deep EXR files (not written by clothbake).
const EXR_MULTIPART: u32 = 0x1000;
const EXR_DEEP: u32 = 0x800;

/// Sorts the header attributes of a single-part EXR file by name, in place. Returns false (and
/// leaves the bytes alone) for anything else than a well-formed single-part header.
fn sort_exr_attributes(bytes: &mut [u8]) -> bool {
    if bytes.len() < 8 || bytes[..4] != EXR_MAGIC {
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

#[cfg(test)]
mod sort_tests {
    use super::sort_exr_attributes;

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

mod exr_io {
    use super::*;
    use exr::prelude::{
        AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer,
        LayerAttributes, ReadChannels, ReadLayers, SmallVec, Text, WritableImage,
    };

    fn text(s: &str) -> AttributeValue {
        // Our texts are ASCII (see `Metadata::to_ascii_json`); other bytes are kept as they are.
        AttributeValue::Text(Text::from_slice_unchecked(s.as_bytes()))
    }

    pub(super) fn write(
        path: &Path,
        table: &Table,
        precision: Precision,
        overwrite: bool,
    ) -> Result<(), TableError> {
        let unwritable = |reason: String| TableError::Unwritable {
            path: path.to_path_buf(),
            reason,
        };
        table.validate().map_err(|e| e.unwritable(path))?;
        let grid = table.meta.grid;
        let (width, height) = (grid.exr_width(), grid.exr_height());
        if width > i32::MAX as u64 || height > i32::MAX as u64 {
            return Err(unwritable(format!(
                "the {width} x {height} image is too large for OpenEXR; use the binary format"
            )));
        }
        let (width, height) = (width as usize, height as usize);

        // Channel k, row-major over the 2-D layout.
        let plane = |k: usize| -> Vec<f32> {
            let mut out = Vec::with_capacity(width * height);
            for ti in 0..grid.n_theta_i {
                for to in 0..grid.n_theta_o {
                    for pi in 0..grid.n_phi_i {
                        for po in 0..grid.n_phi_o {
                            out.push(table.values[3 * grid.index(ti, pi, to, po) + k]);
                        }
                    }
                }
            }
            out
        };
        let planes = [plane(0), plane(1), plane(2)];
        if precision == Precision::F16 {
            let max = half::f16::MAX.to_f32();
            if let Some(v) = table.values.iter().find(|v| v.abs() > max) {
                return Err(unwritable(format!(
                    "value {v} exceeds the half-float range (65504); write with f32 precision"
                )));
            }
        }
        let stored = |p: &[f32]| -> Vec<f32> {
            match precision {
                Precision::F32 => p.to_vec(),
                Precision::F16 => p.iter().map(|&v| half::f16::from_f32(v).to_f32()).collect(),
            }
        };
        let meta_json = table.meta.to_ascii_json();
        let kept = [stored(&planes[0]), stored(&planes[1]), stored(&planes[2])];
        let crc = planes_crc(
            meta_json.as_bytes(),
            &[
                Plane::F32(&kept[0]),
                Plane::F32(&kept[1]),
                Plane::F32(&kept[2]),
            ],
        );
        let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
        for (name, p) in ["R", "G", "B"].into_iter().zip(planes) {
            let samples = match precision {
                Precision::F32 => FlatSamples::F32(p),
                Precision::F16 => {
                    FlatSamples::F16(p.into_iter().map(half::f16::from_f32).collect())
                }
            };
            channels.push(AnyChannel::new(name, samples));
        }

        let mut attributes = LayerAttributes {
            software_name: Some(Text::from_slice_unchecked(table.meta.tool.as_bytes())),
            ..LayerAttributes::default()
        };
        let other = &mut attributes.other;
        other.insert(Text::from(ATTR_METADATA), text(&meta_json));
        other.insert(
            Text::from(ATTR_FORMAT_VERSION),
            text(&table.meta.format_version.to_string()),
        );
        other.insert(
            Text::from(ATTR_GRID),
            text(&format!("{grid}, cell-centred, degrees")),
        );
        other.insert(Text::from(ATTR_UNITS), text(&table.meta.units));
        other.insert(Text::from(ATTR_TOOL), text(&table.meta.tool));
        other.insert(Text::from(ATTR_CRC32), text(&format!("{crc:08x}")));

        let layer = Layer::new(
            (width, height),
            attributes,
            Encoding::SMALL_LOSSLESS,
            AnyChannels::sort(channels),
        );
        let image = Image::from_layer(layer);
        let mut bytes = Vec::new();
        image
            .write()
            .non_parallel()
            .to_buffered(Cursor::new(&mut bytes))
            .map_err(|e| unwritable(format!("OpenEXR encoder: {e}")))?;
        sort_exr_attributes(&mut bytes);
        write_atomic(path, overwrite, |out| out.write_all(&bytes))
    }

    /// Maps an exr error; a file that ends early is reported as truncated.
    fn decode_error(path: &Path, what: &str, e: exr::error::Error) -> TableError {
        let truncated = match &e {
            exr::error::Error::Io(io) => io.kind() == io::ErrorKind::UnexpectedEof,
            // exr reports an unexpected end of file as "reference to missing bytes".
            exr::error::Error::Invalid(m) => m.contains("missing bytes"),
            _ => false,
        };
        if truncated {
            TableError::Truncated {
                path: path.to_path_buf(),
                detail: format!("the OpenEXR {what} ends early ({e})"),
            }
        } else {
            TableError::Corrupted {
                path: path.to_path_buf(),
                reason: format!("the OpenEXR {what} cannot be decoded ({e})"),
            }
        }
    }

    fn attribute_text(value: &AttributeValue) -> Option<String> {
        match value {
            AttributeValue::Text(t) => Some(String::from_utf8_lossy(t.bytes()).into_owned()),
            _ => None,
        }
    }

    pub(super) fn read(path: &Path) -> Result<StoredTable, TableError> {
        let bytes = fs::read(path).map_err(|e| TableError::io(path, "read the table", e))?;
        if bytes.is_empty() {
            return Err(TableError::Empty {
                path: path.to_path_buf(),
            });
        }
        if !bytes.starts_with(&EXR_MAGIC) {
            return Err(TableError::Foreign {
                path: path.to_path_buf(),
                reason: format!(
                    "the first bytes are {}, not the OpenEXR magic bytes 76 2f 31 01",
                    hex(&bytes[..bytes.len().min(4)])
                ),
            });
        }
        let corrupted = |reason: String| TableError::Corrupted {
            path: path.to_path_buf(),
            reason,
        };
        let foreign = |reason: String| TableError::Foreign {
            path: path.to_path_buf(),
            reason,
        };

        // The exr decoder is not trusted to never panic on damaged files.
        let guarded = |f: &dyn Fn() -> Result<StoredTable, TableError>| {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|_| {
                Err(corrupted(
                    "the OpenEXR decoder failed on this file".to_string(),
                ))
            })
        };

        guarded(&|| {
            // Header first: check the attributes and dimensions before decoding any pixels.
            let meta_data = exr::meta::MetaData::read_from_buffered(Cursor::new(&bytes), false)
                .map_err(|e| decode_error(path, "header", e))?;
            if meta_data.headers.len() != 1 {
                return Err(foreign(format!(
                    "the EXR has {} parts, but a table has exactly one",
                    meta_data.headers.len()
                )));
            }
            let header = &meta_data.headers[0];
            let attrs = &header.own_attributes.other;
            let meta_json_bytes = match attrs.get(&Text::from(ATTR_METADATA)) {
                Some(AttributeValue::Text(t)) => t.bytes().to_vec(),
                _ => {
                    return Err(foreign(format!(
                        "the EXR has no text attribute {ATTR_METADATA:?}; it was not written by clothbake"
                    )))
                }
            };
            let meta_json = String::from_utf8_lossy(&meta_json_bytes);
            if let Some(v) = attrs
                .get(&Text::from(ATTR_FORMAT_VERSION))
                .and_then(attribute_text)
            {
                match v.trim().parse::<u32>() {
                    Ok(found) if found != FORMAT_VERSION => {
                        return Err(TableError::Version {
                            path: path.to_path_buf(),
                            found,
                        })
                    }
                    Ok(_) => {}
                    Err(_) => {
                        return Err(corrupted(format!(
                            "{ATTR_FORMAT_VERSION} is {v:?}, not a number"
                        )))
                    }
                }
            }
            // Look at the version before the rest, so that newer files say "update the loader".
            let json: serde_json::Value = serde_json::from_str(&meta_json)
                .map_err(|e| corrupted(format!("{ATTR_METADATA} is not valid JSON ({e})")))?;
            if let Some(found) = json.get("format_version").and_then(|v| v.as_u64()) {
                if found != u64::from(FORMAT_VERSION) {
                    return Err(TableError::Version {
                        path: path.to_path_buf(),
                        found: u32::try_from(found).unwrap_or(u32::MAX),
                    });
                }
            }
            let meta: Metadata = serde_json::from_value(json).map_err(|e| {
                corrupted(format!("{ATTR_METADATA} does not describe a table ({e})"))
            })?;
            meta.validate().map_err(|e| e.in_file(path))?;
            let grid = meta.grid;
            let size = header.layer_size;
            if size.width() as u64 != grid.exr_width() || size.height() as u64 != grid.exr_height()
            {
                return Err(corrupted(format!(
                    "the image is {} x {}, but grid {grid} needs {} x {} (n_phi_i * n_phi_o by n_theta_i * n_theta_o)",
                    size.width(),
                    size.height(),
                    grid.exr_width(),
                    grid.exr_height()
                )));
            }
            let names: Vec<String> = header
                .channels
                .list
                .iter()
                .map(|c| String::from_utf8_lossy(c.name.bytes()).into_owned())
                .collect();
            if names != ["B", "G", "R"] {
                return Err(foreign(format!(
                    "the EXR has channels {names:?}, but a table has exactly R, G and B"
                )));
            }

            let image = exr::prelude::read()
                .no_deep_data()
                .largest_resolution_level()
                .all_channels()
                .all_layers()
                .all_attributes()
                .non_parallel()
                .from_buffered(Cursor::new(&bytes))
                .map_err(|e| decode_error(path, "pixel data", e))?;
            let layer = image
                .layer_data
                .first()
                .ok_or_else(|| corrupted("the EXR has no layer".to_string()))?;
            let (width, height) = (grid.exr_width() as usize, grid.exr_height() as usize);
            let mut planes: [Option<Plane>; 3] = Default::default();
            for channel in &layer.channel_data.list {
                let k = match channel.name.bytes() {
                    b"R" => 0,
                    b"G" => 1,
                    b"B" => 2,
                    _ => continue,
                };
                let plane = match &channel.sample_data {
                    FlatSamples::F16(v) => Plane::F16(v),
                    FlatSamples::F32(v) => Plane::F32(v),
                    FlatSamples::U32(_) => {
                        return Err(foreign(
                            "channel samples are u32; a table has f16 or f32 samples".to_string(),
                        ))
                    }
                };
                if plane.len() != width * height {
                    return Err(corrupted(format!(
                        "channel has {} samples, expected {}",
                        plane.len(),
                        width * height
                    )));
                }
                planes[k] = Some(plane);
            }
            let [Some(r), Some(g), Some(b)] = planes else {
                return Err(foreign(
                    "the EXR lacks one of the channels R, G and B".to_string(),
                ));
            };
            let planes = [r, g, b];
            if let Some(stored) = attrs.get(&Text::from(ATTR_CRC32)).and_then(attribute_text) {
                let computed = planes_crc(&meta_json_bytes, &planes);
                if u32::from_str_radix(stored.trim(), 16).ok() != Some(computed) {
                    return Err(TableError::Checksum {
                        path: path.to_path_buf(),
                        stored: u32::from_str_radix(stored.trim(), 16).unwrap_or(0),
                        computed,
                    });
                }
            }
            // Pixel of each cell, in cell order (see `docs/table-format.md`).
            let pixels = || {
                (0..grid.n_theta_i).flat_map(move |ti| {
                    (0..grid.n_phi_i).flat_map(move |pi| {
                        (0..grid.n_theta_o).flat_map(move |to| {
                            (0..grid.n_phi_o).map(move |po| {
                                let y = (ti * grid.n_theta_o + to) as usize;
                                y * width + (pi * grid.n_phi_o + po) as usize
                            })
                        })
                    })
                })
            };
            let samples = match &planes {
                [Plane::F16(r), Plane::F16(g), Plane::F16(b)] => {
                    Samples::F16(pixels().flat_map(|x| [r[x], g[x], b[x]]).collect())
                }
                _ => Samples::F32(
                    pixels()
                        .flat_map(|x| [planes[0].get(x), planes[1].get(x), planes[2].get(x)])
                        .collect(),
                ),
            };
            StoredTable::new(meta.clone(), samples).map_err(|e| e.in_file(path))
        })
    }

    /// One channel's samples as decoded, borrowed from the image.
    enum Plane<'a> {
        F16(&'a [half::f16]),
        F32(&'a [f32]),
    }

    impl Plane<'_> {
        fn len(&self) -> usize {
            match self {
                Plane::F16(v) => v.len(),
                Plane::F32(v) => v.len(),
            }
        }

        fn get(&self, i: usize) -> f32 {
            match self {
                Plane::F16(v) => v[i].to_f32(),
                Plane::F32(v) => v[i],
            }
        }
    }

    /// The [`ATTR_CRC32`] checksum of a metadata text and three row-major planes, widened to
    /// f32 chunk by chunk (no full f32 copy).
    fn planes_crc(meta_json: &[u8], planes: &[Plane; 3]) -> u32 {
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(meta_json);
        let mut bytes = Vec::with_capacity(CHUNK_VALUES * 12);
        let n = planes[0].len();
        for start in (0..n).step_by(CHUNK_VALUES) {
            bytes.clear();
            for i in start..n.min(start + CHUNK_VALUES) {
                for p in planes {
                    bytes.extend_from_slice(&p.get(i).to_le_bytes());
                }
            }
            hasher.update(&bytes);
        }
        hasher.finalize()
    }
}

/// Writes a table as an OpenEXR image (see `docs/table-format.md`), atomically.
///
/// One RGB layer of f16 or f32 samples, `n_phi_i * n_phi_o` wide and `n_theta_i * n_theta_o`
/// high: pixel `(pi * n_phi_o + po, ti * n_theta_o + to)` holds cell `(ti, pi, to, po)`. The
/// header carries the [`Metadata`] as JSON in [`ATTR_METADATA`] and, for humans and other tools,
/// [`ATTR_FORMAT_VERSION`], [`ATTR_GRID`], [`ATTR_UNITS`] and [`ATTR_TOOL`], and a checksum
/// in [`ATTR_CRC32`]. With [`Precision::F16`], values beyond the half-float range (65504) are
/// an error.
pub fn write_exr(
    path: &Path,
    table: &Table,
    precision: Precision,
    overwrite: bool,
) -> Result<(), TableError> {
    exr_io::write(path, table, precision, overwrite)
}

/// Reads a table from an OpenEXR image written by [`write_exr`] (f16 or f32 samples), checking
/// the metadata, the image size against the grid, the channels and, when present, the
/// [`ATTR_CRC32`] checksum.
pub fn read_exr(path: &Path) -> Result<Table, TableError> {
    exr_io::read(path).map(StoredTable::into_table)
}

/// Reads an OpenEXR table like [`read_exr`], keeping the samples at their stored precision
/// (half samples stay half: half the memory).
pub fn read_exr_stored(path: &Path) -> Result<StoredTable, TableError> {
    exr_io::read(path)
}

/// Reads a table in either format, recognised by its first bytes.
pub fn read_table(path: &Path) -> Result<Table, TableError> {
    read_table_stored(path).map(StoredTable::into_table)
}

/// Reads a table in either format like [`read_table`], keeping the samples at their stored
/// precision: half for half-float EXR tables, f32 otherwise.
pub fn read_table_stored(path: &Path) -> Result<StoredTable, TableError> {
    let mut file = File::open(path).map_err(|e| TableError::io(path, "open the table", e))?;
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
            reason: format!(
                "the first bytes are {}; a table starts with \"CLTHBAKE\" (binary) or 76 2f 31 01 (OpenEXR)",
                hex(head)
            ),
        })
    }
}
