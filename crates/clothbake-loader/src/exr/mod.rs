//! The OpenEXR table: one RGB image of half or float samples, the [`Metadata`] in header
//! attributes (`docs/reference/table-format.md`). Written byte-reproducibly ([`write_exr`]), read
//! without trusting the decoder not to panic ([`read_exr`]).

use std::io::{self, Cursor, Write};
use std::path::Path;

use crate::atomic::write_atomic_as;
use crate::bytes::{hex, CHUNK_VALUES};
use crate::error::TableError;
use crate::grid::Grid;
use crate::spatial::value_index;
use crate::stored::{Samples, StoredTable};
use crate::table::{check_format_version, Metadata, Precision, Table};

/// The 4 magic bytes that open every OpenEXR file.
pub const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

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
/// EXR header attribute explaining which pixel holds which cell ([`layout_text`]).
pub const ATTR_LAYOUT: &str = "clothbake.layout";
/// EXR header attribute giving the cell centres and the direction conventions
/// ([`directions_text`]).
pub const ATTR_DIRECTIONS: &str = "clothbake.directions";
/// EXR header attribute saying what the channels hold ([`values_text`]).
pub const ATTR_VALUES: &str = "clothbake.values";
/// EXR header attribute holding a CRC-32, as 8 lowercase hex digits, of the
/// [`ATTR_METADATA`] text followed by every sample as f32 little-endian, pixels in row-major
/// order, R, G, B per pixel. Readers verify it when present, as EXR itself has no checksum.
pub const ATTR_CRC32: &str = "clothbake.crc32";

/// The pixel-to-cell layout in words, with the grid's numbers: for the reader of `exrheader`.
pub fn layout_text(g: &Grid) -> String {
    format!(
        "pixel (x, y) holds cell (ti, pi, to, po) with x = pi * {npo} + po, y = ti * {nto} + to \
         ({w} x {h} pixels): one tile of {npo} x {nto} pixels (phi_o across, theta_o down) per \
         incident direction (ti, pi); cell index ((ti * {npi} + pi) * {nto} + to) * {npo} + po",
        npo = g.n_phi_o,
        nto = g.n_theta_o,
        npi = g.n_phi_i,
        w = g.exr_width(),
        h = g.exr_height(),
    )
}

/// The cell centres and direction conventions in words, with the grid's numbers (each axis's
/// [`crate::Axis::centre_text`]).
pub fn directions_text(g: &Grid) -> String {
    format!(
        "cell centres in degrees: theta_i = {}, phi_i = {}, theta_o = {}, phi_o = {}; theta \
         from the macro normal +Z, phi from +X (the weft) toward +Y (the warp); i toward the \
         light, o toward the eye",
        g.theta_i().centre_text("ti"),
        g.phi_i().centre_text("pi"),
        g.theta_o().centre_text("to"),
        g.phi_o().centre_text("po"),
    )
}

/// What the channels hold, in words.
pub fn values_text(meta: &Metadata) -> String {
    let classes = match &meta.spatial {
        Some(s) if s.secondary => format!(
            "; class<k>.diffuse, class<k>.specular, class<k>.plus_neighbour, class<k>.plus_both, \
             class<k>.minus_neighbour, class<k>.minus_both (k < {}): each class's f_r at unit \
             diffuse albedo, its f_r of no albedo, and the second bounce's terms per unit albedo \
             of the +c and -c neighbours (and of both threads), for the weave period's cells \
             (clothbake.metadata's \"spatial\" gives each cell's class and albedos)",
            s.classes
        ),
        Some(s) => format!(
            "; class<k>.diffuse, class<k>.specular (k < {}): each class's f_r at unit diffuse \
             albedo and its specular f_r, for the weave period's cells (clothbake.metadata's \
             \"spatial\" gives each cell's class and albedo)",
            s.classes
        ),
        None => String::new(),
    };
    format!(
        "R, G, B: {} in {} at each cell centre (the BRDF, f_r = I / (pi cos theta_i)){classes}; the \
         metadata and the bake's fabric and options are in clothbake.metadata",
        meta.quantity, meta.units
    )
}

/// Version-field flags of multi-part and deep EXR files (not written by clothbake).
const EXR_MULTIPART: u32 = 0x1000;
const EXR_DEEP: u32 = 0x800;

/// Sorts the header attributes of a single-part EXR file by name, in place. Returns false (and
/// leaves the bytes alone) for anything else than a well-formed single-part header.
///
/// The `exr` crate keeps an image's custom header attributes in a `HashMap` and writes them in
/// its (randomly seeded) iteration order; [`write_exr`] sorts them by name (as the OpenEXR
/// library writes them) so the same table always gives the same bytes. Reordering attributes
/// keeps the header's length, so the offset table after it stays valid.
fn sort_exr_attributes(bytes: &mut [u8]) -> bool {
    let Some((attrs, header_end)) = header_attributes(bytes) else {
        return false;
    };
    let start = 8;
    let mut sorted: Vec<&AttributeSpan> = attrs.iter().collect();
    sorted.sort_by(|a, b| bytes[a.0..a.1].cmp(&bytes[b.0..b.1]));
    let mut out = Vec::with_capacity(header_end - start);
    for &&(s, _, e) in &sorted {
        out.extend_from_slice(&bytes[s..e]);
    }
    bytes[start..header_end].copy_from_slice(&out);
    true
}

/// Where an EXR header attribute lies: its start, the end of its name, its end.
type AttributeSpan = (usize, usize, usize);

/// The attributes of a single-part EXR header at the start of `bytes` and the offset of the
/// header's terminating zero byte; `None` when `bytes` holds no complete, well-formed
/// single-part header.
fn header_attributes(bytes: &[u8]) -> Option<(Vec<AttributeSpan>, usize)> {
    if bytes.len() < 8 || bytes[..4] != EXR_MAGIC {
        return None;
    }
    let flags = u32::from_le_bytes([bytes[4], bytes[5], bytes[6], bytes[7]]);
    if flags & (EXR_MULTIPART | EXR_DEEP) != 0 {
        return None;
    }
    let mut pos = 8;
    let mut attrs: Vec<AttributeSpan> = Vec::new();
    let cstr_end = |from: usize| {
        bytes
            .get(from..)?
            .iter()
            .position(|&b| b == 0)
            .map(|i| from + i)
    };
    loop {
        let name_end = cstr_end(pos)?;
        if name_end == pos {
            return Some((attrs, pos)); // the empty name that ends the header
        }
        let type_end = cstr_end(name_end + 1)?;
        let size_at = type_end + 1;
        let size = bytes.get(size_at..size_at + 4)?;
        let size = i32::from_le_bytes([size[0], size[1], size[2], size[3]]);
        let end = size_at + 4 + usize::try_from(size).ok()?;
        if end > bytes.len() {
            return None;
        }
        attrs.push((pos, name_end, end));
        pos = end;
    }
}

/// A writer that holds back what is written until it holds a whole EXR header, sorts that
/// header's attributes ([`sort_exr_attributes`]) and from then on passes everything through:
/// the encoder streams its blocks to the file, and the file's bytes are reproducible.
struct SortedHeader<W: Write + io::Seek> {
    inner: W,
    /// The bytes written before the header was complete (`None` once passed on).
    pending: Option<Vec<u8>>,
}

impl<W: Write + io::Seek> SortedHeader<W> {
    fn new(inner: W) -> Self {
        SortedHeader {
            inner,
            pending: Some(Vec::new()),
        }
    }

    /// Passes the held bytes on, sorted when they hold a whole header.
    fn release(&mut self) -> io::Result<()> {
        if let Some(mut held) = self.pending.take() {
            sort_exr_attributes(&mut held);
            self.inner.write_all(&held)?;
        }
        Ok(())
    }
}

impl<W: Write + io::Seek> Write for SortedHeader<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match &mut self.pending {
            None => self.inner.write(buf),
            Some(held) => {
                held.extend_from_slice(buf);
                // The header ends with a zero byte: only then can it be whole.
                if buf.contains(&0) && header_attributes(held).is_some() {
                    self.release()?;
                }
                Ok(buf.len())
            }
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        self.release()?;
        self.inner.flush()
    }
}

impl<W: Write + io::Seek> io::Seek for SortedHeader<W> {
    fn seek(&mut self, pos: io::SeekFrom) -> io::Result<u64> {
        self.release()?;
        self.inner.seek(pos)
    }
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

mod exr_io;

/// Writes a table as an OpenEXR image (see `docs/reference/table-format.md`), atomically.
///
/// One RGB layer of f16 or f32 samples, `n_phi_i * n_phi_o` wide and `n_theta_i * n_theta_o`
/// high: pixel `(pi * n_phi_o + po, ti * n_theta_o + to)` holds cell `(ti, pi, to, po)`. The
/// header carries the [`Metadata`] as JSON in [`ATTR_METADATA`] and, for humans and other tools,
/// [`ATTR_FORMAT_VERSION`], [`ATTR_GRID`], [`ATTR_LAYOUT`], [`ATTR_DIRECTIONS`],
/// [`ATTR_VALUES`], [`ATTR_UNITS`] and [`ATTR_TOOL`] (readers ignore these), and a checksum
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

/// The metadata and the lookup's nodes of an averaged half-float OpenEXR table, read
/// straight from its lines; `None` for another table (read it with [`read_exr_stored`]).
pub(crate) fn read_half_nodes(
    path: &Path,
) -> Result<Option<(Metadata, crate::nodes::Nodes)>, TableError> {
    exr_io::read_with(path, &|c| {
        Ok(exr_io::half_nodes(c)?.map(|n| (c.meta.clone(), n)))
    })
}

/// Reads an OpenEXR table like [`read_exr`], keeping the samples at their stored precision
/// (half samples stay half: half the memory).
pub fn read_exr_stored(path: &Path) -> Result<StoredTable, TableError> {
    exr_io::read(path)
}
