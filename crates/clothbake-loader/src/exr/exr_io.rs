use super::*;
use exr::block::lines::LineRefMut;
use exr::image::write::samples::{SamplesWriter, WritableSamples};
use exr::math::RoundingMode;
use exr::meta::attribute::{LevelMode, SampleType};
use exr::meta::header::Header;
use exr::meta::BlockDescription;
use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    ReadChannels, ReadLayers, SmallVec, Text, WritableImage,
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
        what: "table".into(),
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

    let names = table.meta.channel_names();
    if precision == Precision::F16 {
        let max = half::f16::MAX.to_f32();
        if let Some(v) = table.values.iter().find(|v| v.abs() > max) {
            return Err(unwritable(format!(
                "value {v} exceeds the half-float range (65504); write with f32 precision"
            )));
        }
    }
    // The channels read the table's values where they lie, line by line, as the encoder
    // asks for them: no copy of the table.
    let planes: Vec<PlaneView<'_>> = (0..names.len())
        .map(|ch| PlaneView {
            values: &table.values,
            grid,
            ch,
            lanes: table.meta.class_lanes(),
            precision,
        })
        .collect();
    let meta_json = table.meta.to_ascii_json();
    let crc = values_crc_with(
        meta_json.as_bytes(),
        width * height,
        names.len(),
        |ch, i| planes[ch].stored(i),
    );
    let mut channels: SmallVec<[AnyChannel<PlaneView<'_>>; 4]> = SmallVec::new();
    for (name, p) in names.iter().zip(planes) {
        channels.push(AnyChannel::new(name.as_str(), p));
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
    other.insert(Text::from(ATTR_LAYOUT), text(&layout_text(&grid)));
    other.insert(Text::from(ATTR_DIRECTIONS), text(&directions_text(&grid)));
    other.insert(Text::from(ATTR_VALUES), text(&values_text(&table.meta)));
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
    // Block by block into the file (the encoder seeks back for its offset table).
    write_atomic_as(path, "table", overwrite, |out| {
        let mut w = SortedHeader::new(out);
        image
            .write()
            .non_parallel()
            .to_buffered(&mut w)
            .map_err(|e| match e {
                exr::error::Error::Io(io) => io,
                e => io::Error::other(format!("OpenEXR encoder: {e}")),
            })?;
        w.flush()
    })
}

/// One channel of a table's values as the encoder sees it: pixel `i` of the row-major
/// image (see [`write_exr`]) read from the interleaved values, rounded to `precision`.
#[derive(Clone, Copy)]
struct PlaneView<'a> {
    values: &'a [f32],
    grid: Grid,
    ch: usize,
    /// Values per class and grid cell.
    lanes: usize,
    precision: Precision,
}

impl PlaneView<'_> {
    /// The value of pixel `(x, y)`.
    fn at(&self, x: usize, y: usize) -> f32 {
        let g = &self.grid;
        let (npo, nto) = (g.n_phi_o as usize, g.n_theta_o as usize);
        let (ti, to, pi, po) = (y / nto, y % nto, x / npo, x % npo);
        let c = ((ti * g.n_phi_i as usize + pi) * nto + to) * npo + po;
        self.values[value_index(self.ch, c, g.len(), self.lanes)]
    }

    /// The value of pixel `i` as stored (rounded to the precision), widened to f32.
    fn stored(&self, i: usize) -> f32 {
        let w = self.grid.exr_width() as usize;
        let v = self.at(i % w, i / w);
        match self.precision {
            Precision::F32 => v,
            Precision::F16 => half::f16::from_f32(v).to_f32(),
        }
    }
}

impl<'a> WritableSamples<'_> for PlaneView<'a> {
    fn sample_type(&self) -> SampleType {
        match self.precision {
            Precision::F16 => SampleType::F16,
            Precision::F32 => SampleType::F32,
        }
    }

    fn infer_level_modes(&self) -> (LevelMode, RoundingMode) {
        (LevelMode::Singular, RoundingMode::Down)
    }

    type Writer = PlaneView<'a>;

    fn create_samples_writer(&self, _: &Header) -> Self::Writer {
        *self
    }
}

impl SamplesWriter for PlaneView<'_> {
    fn extract_line(&self, line: LineRefMut<'_>) {
        let (x0, y) = (line.location.position.x(), line.location.position.y());
        match self.precision {
            Precision::F32 => line.write_samples(|i| self.at(x0 + i, y)),
            Precision::F16 => line.write_samples(|i| half::f16::from_f32(self.at(x0 + i, y))),
        }
        .expect("a line's bytes have the line's length");
    }
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

/// Bytes of a file read before its header is looked at: the header (metadata, attributes,
/// offset tables) of any table is far smaller.
const HEAD_MAX: u64 = 64 << 20;

/// Reads the file, but one larger than [`HEAD_MAX`] only after its header says how large
/// its image may be (every channel in f32, twice over for a compression that grows it):
/// a larger file is refused before it is read.
fn read_bounded(path: &Path) -> Result<Vec<u8>, TableError> {
    let read_err = |e| TableError::io(path, "read the table", e);
    let mut file = crate::bytes::open_regular(path, "table")?;
    let len = file.metadata().map_err(read_err)?.len();
    let head = len.min(HEAD_MAX);
    let mut bytes = Vec::with_capacity(head as usize);
    io::Read::read_to_end(&mut io::Read::take(&mut file, head), &mut bytes).map_err(read_err)?;
    if len > head {
        let header = std::panic::catch_unwind(|| {
            exr::meta::MetaData::read_from_buffered(Cursor::new(&bytes), false)
        })
        .map_err(|_| TableError::Corrupted {
            path: path.to_path_buf(),
            reason: "the OpenEXR decoder failed on this file's header".to_string(),
        })?
        .map_err(|e| decode_error(path, "header", e))?;
        let pixels: u64 = header
            .headers
            .iter()
            .map(|h| {
                let n = (h.layer_size.width() as u64).saturating_mul(h.layer_size.height() as u64);
                n.saturating_mul(4 * h.channels.list.len() as u64)
            })
            .fold(0, u64::saturating_add);
        let most = pixels.saturating_mul(2).saturating_add(HEAD_MAX);
        if len > most {
            return Err(TableError::Corrupted {
                path: path.to_path_buf(),
                reason: format!(
                    "the file is {len} bytes, but its header describes at most {most} \
                     (images of {pixels} bytes of samples)"
                ),
            });
        }
        io::Read::read_to_end(&mut file, &mut bytes).map_err(read_err)?;
    }
    Ok(bytes)
}

fn attribute_text(value: &AttributeValue) -> Option<String> {
    match value {
        AttributeValue::Text(t) => Some(String::from_utf8_lossy(t.bytes()).into_owned()),
        _ => None,
    }
}

/// A file whose header passed the checks of [`read_with`]: its bytes, its OpenEXR header
/// and the table's metadata (and its JSON text, which the checksum covers).
pub(super) struct Checked<'a> {
    pub(super) path: &'a Path,
    pub(super) bytes: &'a [u8],
    pub(super) meta_data: &'a exr::meta::MetaData,
    pub(super) meta: &'a Metadata,
    pub(super) meta_json: &'a [u8],
}

impl Checked<'_> {
    fn header(&self) -> &Header {
        &self.meta_data.headers[0]
    }

    /// Half samples in scan-line blocks, every channel at full resolution, the data window
    /// at the origin: what clothbake writes, which [`read_half_lines`] and [`HalfLines`]
    /// decode (anything else goes to the `exr` crate's generic decoder).
    pub(super) fn half_lines(&self) -> bool {
        let header = self.header();
        header.blocks == BlockDescription::ScanLines
            && header.own_attributes.layer_position == exr::math::Vec2(0, 0)
            && !header.deep
            && header
                .channels
                .list
                .iter()
                .all(|c| c.sample_type == SampleType::F16 && c.sampling == exr::math::Vec2(1, 1))
    }

    /// An error unless the checksum attribute, if any, is `computed`.
    pub(super) fn check_crc(&self, computed: u32) -> Result<(), TableError> {
        match stored_crc(self.path, &self.header().own_attributes.other)? {
            Some(stored) if stored != computed => Err(TableError::Checksum {
                path: self.path.to_path_buf(),
                stored,
                computed,
            }),
            _ => Ok(()),
        }
    }
}

/// The error of a damaged file at `path`, with its reason.
fn corrupted_in(path: &Path) -> impl Fn(String) -> TableError + '_ {
    move |reason| TableError::Corrupted {
        path: path.to_path_buf(),
        reason,
    }
}

/// The error of a file at `path` that is not a clothbake table, with its reason.
fn foreign_in(path: &Path) -> impl Fn(String) -> TableError + '_ {
    move |reason| TableError::Foreign {
        path: path.to_path_buf(),
        what: "table".into(),
        reason,
    }
}

pub(super) fn read(path: &Path) -> Result<StoredTable, TableError> {
    read_with(path, &decode_stored)
}

/// Reads the file and checks its header (one part, the metadata, the image size against
/// the grid, the channels), then gives it to `then`; the OpenEXR decoder's panics on
/// damaged files become errors.
pub(super) fn read_with<T>(
    path: &Path,
    then: &dyn Fn(&Checked<'_>) -> Result<T, TableError>,
) -> Result<T, TableError> {
    let bytes = read_bounded(path)?;
    if bytes.is_empty() {
        return Err(TableError::Empty {
            path: path.to_path_buf(),
        });
    }
    if !bytes.starts_with(&EXR_MAGIC) {
        return Err(TableError::Foreign {
            path: path.to_path_buf(),
            what: "table".into(),
            reason: format!(
                "the first bytes are {}, not the OpenEXR magic bytes 76 2f 31 01",
                hex(&bytes[..bytes.len().min(4)])
            ),
        });
    }
    let (corrupted, foreign) = (corrupted_in(path), foreign_in(path));

    // The exr decoder is not trusted to never panic on damaged files.
    let guarded = |f: &dyn Fn() -> Result<T, TableError>| {
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
                Ok(found) if !crate::table::reads_version(u64::from(found)) => {
                    return Err(TableError::Version {
                        path: path.to_path_buf(),
                        what: "table",
                        found,
                        reads: crate::table::TWO_FACED_VERSION,
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
        check_format_version(path, &json)?;
        let meta: Metadata = serde_json::from_value(json)
            .map_err(|e| corrupted(format!("{ATTR_METADATA} does not describe a table ({e})")))?;
        meta.validate().map_err(|e| e.in_file(path))?;
        let grid = meta.grid;
        let size = header.layer_size;
        if size.width() as u64 != grid.exr_width() || size.height() as u64 != grid.exr_height() {
            return Err(corrupted(format!(
                "the image is {} x {}, but grid {grid} needs {} x {} (n_phi_i * n_phi_o by n_theta_i * n_theta_o)",
                size.width(),
                size.height(),
                grid.exr_width(),
                grid.exr_height()
            )));
        }
        let expected = meta.channel_names();
        let mut names: Vec<String> = header
            .channels
            .list
            .iter()
            .map(|c| String::from_utf8_lossy(c.name.bytes()).into_owned())
            .collect();
        names.sort();
        let mut sorted = expected.clone();
        sorted.sort();
        if names != sorted {
            return Err(foreign(if meta.spatial.is_some() {
                format!(
                    "the EXR has channels {names:?}, but this spatial table has exactly {}",
                    expected.join(", ")
                )
            } else {
                format!("the EXR has channels {names:?}, but a table has exactly R, G and B")
            }));
        }

        then(&Checked {
            path,
            bytes: &bytes,
            meta_data: &meta_data,
            meta: &meta,
            meta_json: &meta_json_bytes,
        })
    })
}

/// The samples of a checked file, at their stored precision.
fn decode_stored(c: &Checked<'_>) -> Result<StoredTable, TableError> {
    let (path, bytes, meta) = (c.path, c.bytes, c.meta);
    let grid = meta.grid;
    let expected = meta.channel_names();
    let (corrupted, foreign) = (corrupted_in(path), foreign_in(path));
    {
        // Half samples in scan-line blocks (what clothbake writes): decoded block by block
        // straight into the table's order, the checksum taken as the lines pass.
        if c.half_lines() {
            let (samples, computed) = read_half_lines(c)?;
            c.check_crc(computed)?;
            return StoredTable::new(meta.clone(), Samples::F16(samples))
                .map_err(|e| e.in_file(path));
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
        let mut planes: Vec<Option<Plane<'_>>> = (0..expected.len()).map(|_| None).collect();
        for channel in &layer.channel_data.list {
            let name = String::from_utf8_lossy(channel.name.bytes());
            let Some(k) = expected.iter().position(|e| *e == name) else {
                continue;
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
        let Some(planes) = planes.into_iter().collect::<Option<Vec<Plane<'_>>>>() else {
            return Err(foreign(format!(
                "the EXR lacks one of the channels {}",
                expected.join(", ")
            )));
        };
        c.check_crc(planes_crc(c.meta_json, &planes))?;
        // The averaged RGB, interleaved, then each class's values (diffuse, specular, ...)
        // cell by cell (see `docs/reference/table-format.md`).
        let lanes = meta.class_lanes();
        let halves: Option<Vec<&[half::f16]>> = planes
            .iter()
            .map(|p| match p {
                Plane::F16(v) => Some(*v),
                Plane::F32(_) => None,
            })
            .collect();
        let samples = match halves {
            Some(h) => Samples::F16(gather(&grid, &h, lanes, |x| x)),
            None => {
                let wide: Vec<Vec<f32>> = planes
                    .iter()
                    .map(|p| (0..p.len()).map(|i| p.get(i)).collect())
                    .collect();
                let wide: Vec<&[f32]> = wide.iter().map(Vec::as_slice).collect();
                Samples::F32(gather(&grid, &wide, lanes, |x| x))
            }
        };
        StoredTable::new(meta.clone(), samples).map_err(|e| e.in_file(path))
    }
}

/// The [`ATTR_CRC32`] attribute's checksum, `None` without one; an attribute that is not 8
/// hexadecimal digits is a damaged file, not a checksum of 0.
fn stored_crc(
    path: &Path,
    attrs: &std::collections::HashMap<Text, AttributeValue>,
) -> Result<Option<u32>, TableError> {
    let Some(attr) = attrs.get(&Text::from(ATTR_CRC32)) else {
        return Ok(None);
    };
    let text = attribute_text(attr);
    let stored = text
        .as_deref()
        .map(str::trim)
        .filter(|t| t.len() == 8 && t.bytes().all(|b| b.is_ascii_hexdigit()))
        .and_then(|t| u32::from_str_radix(t, 16).ok());
    match stored {
        Some(v) => Ok(Some(v)),
        None => {
            let shown = match &text {
                Some(t) => format!(
                    "`{}`",
                    t.chars().take(40).collect::<String>().escape_debug()
                ),
                None => "not text".to_string(),
            };
            Err(TableError::Corrupted {
                path: path.to_path_buf(),
                reason: format!(
                    "its {ATTR_CRC32} attribute is {shown}, not a checksum of 8 \
                     hexadecimal digits"
                ),
            })
        }
    }
}

/// The samples of a table whose channels are all half floats in scan-line blocks
/// ([`Checked::half_lines`]), in the table's order (as `gather` orders them), and the
/// [`ATTR_CRC32`] checksum of the metadata and the samples as they pass, line by line
/// ([`HalfLines`]).
fn read_half_lines(c: &Checked<'_>) -> Result<(Vec<half::f16>, u32), TableError> {
    let blocks = HalfBlocks::new(c)?;
    let grid = c.meta.grid;
    let channels = c.meta.channel_names().len();
    let n = grid.len();
    let (nto, npi, npo) = (
        grid.n_theta_o as usize,
        grid.n_phi_i as usize,
        grid.n_phi_o as usize,
    );
    let lanes = c.meta.class_lanes().max(1);
    let total = channels * n;
    let mut samples: Vec<half::f16> = Vec::with_capacity(total);
    crate::nodes::huge_pages(&samples);
    let out = &mut samples.spare_capacity_mut()[..total];
    let mut lines = blocks.lines(0);
    let mut row = vec![0u16; blocks.width * channels];
    for y in 0..blocks.height {
        lines.next_line(&mut row)?;
        let (ti, to) = (y / nto, y % nto);
        for k in 0..channels {
            // Where pixel x = pi npo + po of channel k lands: lane k of cell (ti, pi, to,
            // po) for R, G, B; lane j of class group g after them.
            let (first, stride) = if k < 3 {
                (k, 3)
            } else {
                let (g, j) = ((k - 3) / lanes, (k - 3) % lanes);
                (3 * n + lanes * g * n + j, lanes)
            };
            // The row's pixels of one phi_i column are npo cells in a row.
            for (pi, run) in row.chunks_exact(channels * npo).enumerate() {
                let at = first + stride * (((ti * npi + pi) * nto + to) * npo);
                let dst = &mut out[at..at + stride * (npo - 1) + 1];
                for (d, px) in dst
                    .iter_mut()
                    .step_by(stride)
                    .zip(run.chunks_exact(channels))
                {
                    d.write(half::f16::from_bits(px[k]));
                }
            }
        }
    }
    // SAFETY: every line 0..height was read ([`HalfLines::next_line`] fails otherwise), and
    // a line writes lane k of each of its cells for every channel k: all `total` samples
    // are initialised.
    unsafe { samples.set_len(total) };
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(c.meta_json);
    hasher.combine(&lines.hasher);
    Ok((samples, hasher.finalize()))
}

/// The blocks of a checked half-float scan-line file ([`Checked::half_lines`]), sorted
/// and checked to hold every line once: block `k` starts at line `k * per_block`.
pub(super) struct HalfBlocks<'a> {
    checked: &'a Checked<'a>,
    chunks: Vec<exr::block::chunk::Chunk>,
    per_block: usize,
    /// The table's channel of each of the file's channels.
    slot: Vec<usize>,
    width: usize,
    height: usize,
}

impl<'a> HalfBlocks<'a> {
    pub(super) fn new(c: &'a Checked<'a>) -> Result<HalfBlocks<'a>, TableError> {
        use exr::block::chunk::CompressedBlock;
        let corrupted = |reason: String| TableError::Corrupted {
            path: c.path.to_path_buf(),
            reason,
        };
        let header = c.header();
        let names = c.meta.channel_names();
        let slot: Vec<usize> = header
            .channels
            .list
            .iter()
            .map(|ch| {
                names
                    .iter()
                    .position(|n| n.as_bytes() == ch.name.bytes())
                    .ok_or_else(|| corrupted("a channel of the EXR is not the table's".into()))
            })
            .collect::<Result<_, _>>()?;
        let reader = exr::block::read(Cursor::new(c.bytes), false)
            .map_err(|e| decode_error(c.path, "header", e))?;
        let mut chunks: Vec<(i64, exr::block::chunk::Chunk)> = reader
            .all_chunks(false)
            .map_err(|e| decode_error(c.path, "pixel data", e))?
            .map(|ch| {
                let ch = ch.map_err(|e| decode_error(c.path, "pixel data", e))?;
                match &ch.compressed_block {
                    CompressedBlock::ScanLine(b) => Ok((i64::from(b.y_coordinate), ch)),
                    _ => Err(corrupted(
                        "the EXR's blocks are not scan lines, as its header says".into(),
                    )),
                }
            })
            .collect::<Result<_, _>>()?;
        chunks.sort_by_key(|ch| ch.0);
        let per_block = header.compression.scan_lines_per_block();
        let (width, height) = (
            c.meta.grid.exr_width() as usize,
            c.meta.grid.exr_height() as usize,
        );
        let whole = chunks.len() == height.div_ceil(per_block)
            && chunks
                .iter()
                .enumerate()
                .all(|(k, ch)| ch.0 == (k * per_block) as i64);
        if !whole {
            return Err(corrupted(format!(
                "the OpenEXR pixel data does not cover each of its {height} lines once \
                 ({} blocks of {per_block} lines)",
                chunks.len()
            )));
        }
        Ok(HalfBlocks {
            checked: c,
            chunks: chunks.into_iter().map(|ch| ch.1).collect(),
            per_block,
            slot,
            width,
            height,
        })
    }

    /// The lines from `first` on, in order.
    pub(super) fn lines(&self, first: usize) -> HalfLines<'_> {
        HalfLines {
            blocks: self,
            block: None,
            next: first,
            hasher: crc32fast::Hasher::new(),
            bytes: Vec::new(),
        }
    }
}

/// Lines of a [`HalfBlocks`], decoded a block at a time as they are asked for, in order,
/// and the checksum of the lines passed (without the metadata before them).
pub(super) struct HalfLines<'a> {
    blocks: &'a HalfBlocks<'a>,
    block: Option<(usize, exr::block::UncompressedBlock)>,
    next: usize,
    /// The [`ATTR_CRC32`] checksum of the lines passed, samples widened to f32.
    pub(super) hasher: crc32fast::Hasher,
    /// A line's samples widened, as the checksum reads them.
    bytes: Vec<u8>,
}

impl HalfLines<'_> {
    /// The next line's half-float bits, pixel by pixel, each pixel's channels in the
    /// table's order (R, G, B, ...), into `out` (`width * channels`); adds them to the
    /// checksum.
    pub(super) fn next_line(&mut self, out: &mut [u16]) -> Result<(), TableError> {
        let b = self.blocks;
        let c = b.checked;
        let y = self.next;
        let k = y / b.per_block;
        if y >= b.height {
            return Err(TableError::Corrupted {
                path: c.path.to_path_buf(),
                reason: format!("the OpenEXR pixel data ends at line {}", b.height),
            });
        }
        if self.block.as_ref().is_none_or(|(at, _)| *at != k) {
            let block = exr::block::UncompressedBlock::decompress_chunk(
                b.chunks[k].clone(),
                c.meta_data,
                false,
            )
            .map_err(|e| decode_error(c.path, "pixel data", e))?;
            self.block = Some((k, block));
        }
        let Some((_, block)) = &self.block else {
            unreachable!("decoded above")
        };
        let channels = b.slot.len();
        let line_bytes = 2 * b.width;
        let (at, size) = (block.index.pixel_position, block.index.pixel_size);
        if at != exr::math::Vec2(0, k * b.per_block)
            || size.0 != b.width
            || block.data.len() != size.1 * channels * line_bytes
            || y - at.1 >= size.1
        {
            return Err(TableError::Corrupted {
                path: c.path.to_path_buf(),
                reason: format!(
                    "the OpenEXR block of line {y} holds lines {} to {} of {} pixels",
                    at.1,
                    at.1 + size.1,
                    size.0
                ),
            });
        }
        let row = &block.data[(y - at.1) * channels * line_bytes..][..channels * line_bytes];
        for (line, &slot) in row.chunks_exact(line_bytes).zip(&b.slot) {
            assert!(slot < channels, "a slot is a channel of the table");
            for (px, h) in out.chunks_exact_mut(channels).zip(line.chunks_exact(2)) {
                px[slot] = u16::from_le_bytes([h[0], h[1]]);
            }
        }
        self.bytes.resize(4 * out.len(), 0);
        for (d, &h) in self.bytes.chunks_exact_mut(4).zip(out.iter()) {
            d.copy_from_slice(&crate::stored::f16_to_f32(h).to_bits().to_le_bytes());
        }
        self.hasher.update(&self.bytes);
        self.next += 1;
        Ok(())
    }
}

/// The lookup's node table of an averaged half-float table straight from the file's
/// lines ([`HalfBlocks`]): no samples in the table's order, no second pass for the
/// checksum. `None` for any other table (spatial, float samples, tiles), which the caller
/// reads as stored. The nodes are those of `padding::pad` of the stored samples, lane for
/// lane; the values are checked as they pass (the first unphysical one in the table's
/// order is reported as [`StoredTable::new`] reports it).
pub(super) fn half_nodes(c: &Checked<'_>) -> Result<Option<crate::nodes::Nodes>, TableError> {
    use crate::nodes::{Nodes, PlaneFill, Tiles, Values};
    use half::f16;
    if !c.half_lines() || c.meta.spatial.is_some() || c.meta.grid.faces == crate::Faces::Two {
        return Ok(None);
    }
    let g = c.meta.grid;
    let blocks = HalfBlocks::new(c)?;
    let (nto, npi, npo) = (g.n_theta_o as usize, g.n_phi_i as usize, g.n_phi_o as usize);
    let width = npi * npo;

    /// The filler of the theta_i rows from `first` on: the incident ring's `n_theta_o`
    /// lines, decoded once, give its planes; the first ring also the pole rows.
    struct Fill<'a> {
        lines: HalfLines<'a>,
        ring: Vec<u16>,
        held: Option<usize>,
        /// The first unphysical sample seen: index in the table's order and value.
        bad: Option<(usize, f32)>,
        /// The incident pole's rows (`n_theta_o` rows of `n_phi_o` nodes) and the pole
        /// of both, once the first ring is read.
        pole_i: Vec<[f16; 4]>,
        pole_io: [f16; 4],
        g: Grid,
    }
    impl Fill<'_> {
        fn widened(&self, pi: usize, to: usize, po: usize, k: usize) -> f64 {
            let npo = self.g.n_phi_o as usize;
            let width = self.g.n_phi_i as usize * npo;
            f64::from(crate::stored::f16_to_f32(
                self.ring[(to * width + pi * npo + po) * 3 + k],
            ))
        }

        /// Reads incident ring `ti` unless held, checking its values.
        fn ring(&mut self, ti: usize) -> Result<(), TableError> {
            if self.held == Some(ti) {
                return Ok(());
            }
            let (nto, npi, npo) = (
                self.g.n_theta_o as usize,
                self.g.n_phi_i as usize,
                self.g.n_phi_o as usize,
            );
            let width = npi * npo;
            for to in 0..nto {
                let line = &mut self.ring[to * width * 3..(to + 1) * width * 3];
                self.lines.next_line(line)?;
                // The whole line tested (no early exit, so that it vectorises).
                let physical = |ok, &h| ok & crate::stored::half_is_physical(h);
                if line.iter().fold(true, physical) {
                    continue;
                }
                for (i, &h) in line.iter().enumerate() {
                    if !crate::stored::half_is_physical(h) {
                        let (x, k) = (i / 3, i % 3);
                        let (pi, po) = (x / npo, x % npo);
                        let cell = ((ti * npi + pi) * nto + to) * npo + po;
                        let at = 3 * cell + k;
                        if self.bad.is_none_or(|(b, _)| at < b) {
                            self.bad = Some((at, f16::from_bits(h).to_f32()));
                        }
                    }
                }
            }
            self.held = Some(ti);
            Ok(())
        }

        /// The mean of lane `k` over `cells`, in f64 in their order, as an f32 rounded
        /// to half (as `padding::poles` and the lane conversion make it).
        fn mean(&self, cells: impl Iterator<Item = (usize, usize, usize)>) -> [f16; 4] {
            let (mut sum, mut n) = ([0f64; 4], 0f64);
            for (pi, to, po) in cells {
                for (k, s) in sum.iter_mut().enumerate().take(3) {
                    *s += self.widened(pi, to, po, k);
                }
                n += 1.0;
            }
            sum.map(|s| f16::from_f32((s / n) as f32))
        }
    }
    impl PlaneFill<f16> for Fill<'_> {
        type Error = TableError;
        fn fill(&mut self, ri: u32, pi: u32, plane: &mut [[f16; 4]]) -> Result<(), TableError> {
            let (nto, npi, npo) = (
                self.g.n_theta_o as usize,
                self.g.n_phi_i as usize,
                self.g.n_phi_o as usize,
            );
            let width = npi * npo;
            let (ri, pi) = (ri as usize, pi as usize);
            self.ring(ri.saturating_sub(1))?;
            let (pole, rows) = plane.split_at_mut(npo);
            if ri == 0 {
                if self.pole_i.is_empty() {
                    self.pole_i = (0..nto)
                        .flat_map(|to| (0..npo).map(move |po| (to, po)))
                        .map(|(to, po)| self.mean((0..npi).map(|p| (p, to, po))))
                        .collect();
                    self.pole_io =
                        self.mean((0..npi).flat_map(|p| (0..npo).map(move |po| (p, 0, po))));
                }
                pole.fill(self.pole_io);
                rows.copy_from_slice(&self.pole_i);
            } else {
                pole.fill(self.mean((0..npo).map(|po| (pi, 0, po))));
                for (to, row) in rows.chunks_exact_mut(npo).enumerate() {
                    let line = &self.ring[(to * width + pi * npo) * 3..][..npo * 3];
                    for (x, v) in row.iter_mut().zip(line.chunks_exact(3)) {
                        *x = [
                            f16::from_bits(v[0]),
                            f16::from_bits(v[1]),
                            f16::from_bits(v[2]),
                            f16::ZERO,
                        ];
                    }
                }
            }
            Ok(())
        }
    }

    let make = |first: u32| Fill {
        lines: blocks.lines(first.saturating_sub(1) as usize * nto),
        ring: vec![0; nto * width * 3],
        held: None,
        bad: None,
        pole_i: Vec::new(),
        pole_io: [f16::ZERO; 4],
        g,
    };
    let (tiles, fills) = Tiles::from_planes(&g, &make)?;
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(c.meta_json);
    for f in &fills {
        hasher.combine(&f.lines.hasher);
    }
    c.check_crc(hasher.finalize())?;
    let bad = fills.iter().filter_map(|f| f.bad).min_by_key(|b| b.0);
    crate::table::check_values(c.meta, 3 * g.len(), bad).map_err(|e| e.in_file(c.path))?;
    Ok(Some(Nodes::with_values(&g, Values::F16(tiles))))
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

/// The values of row-major `planes` (in [`Metadata::channel_names`] order) in the
/// table's order: each cell's R, G, B in cell order, then each class's `lanes` channels
/// cell by cell; `lane` converts a sample.
fn gather<T: Copy, V>(grid: &Grid, planes: &[&[T]], lanes: usize, lane: impl Fn(T) -> V) -> Vec<V> {
    let (nti, npi, nto, npo) = (
        grid.n_theta_i as usize,
        grid.n_phi_i as usize,
        grid.n_theta_o as usize,
        grid.n_phi_o as usize,
    );
    let width = npi * npo;
    let mut out = Vec::with_capacity(planes.len() * grid.len());
    // Each group of channels interleaved, cell by cell: the pixels of cell (ti, pi, to,
    // po) for po = 0..npo are one run of a pixel row.
    let groups = std::iter::once(0..3.min(planes.len())).chain(
        (3..planes.len())
            .step_by(lanes.max(1))
            .map(|ch| ch..(ch + lanes).min(planes.len())),
    );
    for group in groups {
        let chans = &planes[group];
        for ti in 0..nti {
            for pi in 0..npi {
                for to in 0..nto {
                    let start = (ti * nto + to) * width + pi * npo;
                    for x in start..start + npo {
                        for p in chans {
                            out.push(lane(p[x]));
                        }
                    }
                }
            }
        }
    }
    out
}

/// The [`ATTR_CRC32`] checksum of a metadata text and `pixels` pixels of `channels`
/// row-major planes (in [`Metadata::channel_names`] order), pixel by pixel, sample `(ch, i)` widened
/// to f32 by `sample`, chunk by chunk (no full copy): the writer's.
fn values_crc_with(
    meta_json: &[u8],
    pixels: usize,
    channels: usize,
    sample: impl Fn(usize, usize) -> f32,
) -> u32 {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(meta_json);
    let mut bytes = Vec::with_capacity(CHUNK_VALUES * 4 * channels);
    for start in (0..pixels).step_by(CHUNK_VALUES) {
        bytes.clear();
        for i in start..pixels.min(start + CHUNK_VALUES) {
            for ch in 0..channels {
                bytes.extend_from_slice(&sample(ch, i).to_le_bytes());
            }
        }
        hasher.update(&bytes);
    }
    hasher.finalize()
}

/// The [`ATTR_CRC32`] checksum as [`values_crc_with`] computes it, of the decoded planes:
/// each plane's samples widened a run at a time.
fn planes_crc(meta_json: &[u8], planes: &[Plane<'_>]) -> u32 {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(meta_json);
    let pixels = planes.first().map_or(0, Plane::len);
    let mut words: Vec<u32> = Vec::with_capacity(CHUNK_VALUES * planes.len());
    let mut bytes: Vec<u8> = Vec::with_capacity(4 * CHUNK_VALUES * planes.len());
    for start in (0..pixels).step_by(CHUNK_VALUES) {
        let end = pixels.min(start + CHUNK_VALUES);
        words.clear();
        words.resize((end - start) * planes.len(), 0);
        for (ch, p) in planes.iter().enumerate() {
            let out = words.iter_mut().skip(ch).step_by(planes.len());
            match p {
                Plane::F16(v) => {
                    for (w, h) in out.zip(&v[start..end]) {
                        *w = crate::stored::f16_to_f32(h.to_bits()).to_bits();
                    }
                }
                Plane::F32(v) => {
                    for (w, x) in out.zip(&v[start..end]) {
                        *w = x.to_bits();
                    }
                }
            }
        }
        bytes.clear();
        bytes.extend(words.iter().flat_map(|w| w.to_le_bytes()));
        hasher.update(&bytes);
    }
    hasher.finalize()
}
