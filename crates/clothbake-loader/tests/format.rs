//! Round trips and failure modes of the table formats.

use std::fs;
use std::path::{Path, PathBuf};

use clothbake_loader::{
    read_binary, read_exr, read_table, write_atomic_as, write_binary, write_exr, Grid, Metadata,
    Precision, Table, TableError, BINARY_MAGIC, EXR_MAGIC, FORMAT_VERSION,
};

/// A grid with a different size on every axis, so that layout mix-ups show.
const GRID: Grid = Grid::new(2, 3, 4, 5);

fn sample_meta(grid: Grid) -> Metadata {
    Metadata::new(
        "clothbake 0.1.0",
        grid,
        "{\"name\": \"twill\", \"note\": \"Baumwolle ü — 🧵\"}",
        r#"{"samples": 16}"#,
        "mirror x, mirror y",
    )
}

/// Values that differ in every cell and channel and span several decades.
fn sample_table(grid: Grid) -> Table {
    let values = (0..grid.len() * 3)
        .map(|i| {
            let x = i as f32;
            (x * 0.37).sin().abs() * 10f32.powi((i % 7) as i32 - 3) + x * 1e-3
        })
        .collect();
    Table::new(sample_meta(grid), values).unwrap()
}

fn dir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// Names of the files in a folder.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// An EXR file's first layer as RGB pixels and text attributes, read with the exr crate alone,
/// as another tool would.
struct ExrRgb {
    /// Width and height in pixels.
    size: (usize, usize),
    /// Row by row.
    pixels: Vec<[f32; 3]>,
    attributes: exr::meta::header::LayerAttributes,
}

impl ExrRgb {
    fn read(path: &Path) -> Self {
        use exr::prelude::*;
        let image = read_first_rgba_layer_from_file(
            path,
            |res, _| (res.width(), vec![[0f32; 3]; res.width() * res.height()]),
            |(w, px), Vec2(x, y), (r, g, b, _a): (f32, f32, f32, f32)| px[y * *w + x] = [r, g, b],
        )
        .unwrap();
        let layer = image.layer_data;
        Self {
            size: (layer.size.0, layer.size.1),
            pixels: layer.channel_data.pixels.1,
            attributes: layer.attributes,
        }
    }

    /// The text attribute `name`; panics if there is none or it is not text.
    fn attr(&self, name: &str) -> String {
        use exr::meta::attribute::{AttributeValue, Text};
        match self.attributes.other.get(&Text::from(name)) {
            Some(AttributeValue::Text(t)) => t.to_string(),
            other => panic!("{name}: {other:?}"),
        }
    }
}

fn message(e: TableError) -> String {
    e.to_string()
}

/// A fresh folder with the sample table written to `t.exr` in it at `precision`.
fn exr_written(precision: Precision) -> (tempfile::TempDir, PathBuf, Table) {
    let d = dir();
    let path = d.path().join("t.exr");
    let table = sample_table(GRID);
    write_exr(&path, &table, precision, false).unwrap();
    (d, path, table)
}

/// Writes `bytes` to `path` and returns the message of reading it as a table, which must fail
/// (printed, so that `--nocapture` shows what a user reads).
fn refusal(path: &Path, bytes: &[u8]) -> String {
    fs::write(path, bytes).unwrap();
    let e = message(read_table(path).unwrap_err());
    eprintln!("{e}");
    e
}

/// Asserts that the message `e` contains every one of `needles`.
fn mentions(e: &str, needles: &[&str]) {
    for n in needles {
        assert!(e.contains(n), "{n:?} missing from: {e}");
    }
}

#[test]
fn grid_index_and_cell_centres() {
    assert_eq!(GRID.len(), 120);
    assert_eq!(GRID.index(0, 0, 0, 0), 0);
    assert_eq!(GRID.index(0, 0, 0, 1), 1);
    assert_eq!(GRID.index(0, 0, 1, 0), 5);
    assert_eq!(GRID.index(0, 1, 0, 0), 20);
    assert_eq!(GRID.index(1, 0, 0, 0), 60);
    assert_eq!(GRID.index(1, 2, 3, 4), 119);
    assert_eq!(GRID.theta_i_deg(0), 22.5);
    assert_eq!(GRID.theta_i_deg(1), 67.5);
    assert_eq!(GRID.phi_i_deg(0), 60.0);
    assert_eq!(GRID.theta_o_deg(3), 78.75);
    assert_eq!(GRID.phi_o_deg(4), 324.0);
    GRID.validate().unwrap();
    let zero = Grid { n_phi_o: 0, ..GRID };
    assert!(message(zero.validate().unwrap_err()).contains("n_phi_o is 0"));
    let huge = Grid::new(1 << 16, 1 << 16, 2, 1);
    assert!(message(huge.validate().unwrap_err()).contains("more than the limit"));
    let absurd = Grid::new(u32::MAX, u32::MAX, u32::MAX, 9);
    assert!(absurd.validate().is_err());
}

#[test]
fn table_new_checks_length_and_finiteness() {
    let meta = sample_meta(GRID);
    let e = Table::new(meta.clone(), vec![0.0; 359]).unwrap_err();
    assert!(message(e).contains("needs 360 values"), "message");
    let mut values = vec![0.5; 360];
    values[7] = f32::NAN;
    let e = message(Table::new(meta.clone(), values).unwrap_err());
    assert!(e.contains("value 7 of cell 2 (channel G) is NaN"), "{e}");
    let mut bad = meta;
    bad.centring = "node".into();
    assert!(Table::new(bad, vec![0.5; 360]).is_err());
}

#[test]
fn binary_round_trip_is_exact() {
    let d = dir();
    let path = d.path().join("t.bin");
    let table = sample_table(GRID);
    write_binary(&path, &table, false).unwrap();
    let back = read_binary(&path).unwrap();
    assert_eq!(back, table);
    assert_eq!(read_table(&path).unwrap(), table);
    assert_eq!(listing(d.path()), ["t.bin"]);
    // The documented layout, parsed here: the container of kind "table" with the metadata as
    // its JSON header.
    let bytes = fs::read(&path).unwrap();
    assert_eq!(&bytes[..8], b"CLTHBAKE");
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 2);
    assert_eq!(&bytes[12..28], b"table\0\0\0\0\0\0\0\0\0\0\0");
    let header_len = u64::from_le_bytes(bytes[28..36].try_into().unwrap()) as usize;
    let n = u64::from_le_bytes(bytes[36..44].try_into().unwrap()) as usize;
    assert_eq!(n, 360);
    assert_eq!(bytes.len(), 44 + header_len + 4 * n + 4);
    let header: serde_json::Value = serde_json::from_slice(&bytes[44..44 + header_len]).unwrap();
    assert_eq!(header["format_version"], FORMAT_VERSION);
    assert_eq!(header["grid"]["n_phi_i"], 3);
    assert_eq!(header["fabric_json"], table.meta.fabric_json.as_str());
    let meta: Metadata = serde_json::from_value(header).unwrap();
    assert_eq!(meta, table.meta);
    let at = 44 + header_len;
    let values: Vec<f32> = bytes[at..at + 4 * n]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert_eq!(values, table.values);
    let crc = crc32fast::hash(&bytes[..bytes.len() - 4]);
    assert_eq!(bytes[bytes.len() - 4..], crc.to_le_bytes());
}

#[test]
fn exr_f32_round_trip_is_exact() {
    let (d, path, table) = exr_written(Precision::F32);
    assert_eq!(read_exr(&path).unwrap(), table);
    assert_eq!(read_table(&path).unwrap(), table);
    assert_eq!(listing(d.path()), ["t.exr"]);
    assert_eq!(fs::read(&path).unwrap()[..4], EXR_MAGIC);
}

#[test]
fn exr_f16_round_trip_rounds_to_half() {
    let (_d, path, table) = exr_written(Precision::F16);
    let back = read_table(&path).unwrap();
    assert_eq!(back.meta, table.meta);
    for (a, b) in table.values.iter().zip(&back.values) {
        assert_eq!(*b, half::f16::from_f32(*a).to_f32());
    }
}

#[test]
fn exr_layout_is_tiles_of_outgoing_directions() {
    let (_d, path, table) = exr_written(Precision::F32);
    // Read it back with the exr crate alone, as another tool would.
    let image = ExrRgb::read(&path);
    assert_eq!(image.size, (15, 8));
    let (w, px) = (image.size.0, &image.pixels);
    for ti in 0..2 {
        for pi in 0..3 {
            for to in 0..4 {
                for po in 0..5 {
                    let (x, y) = ((pi * 5 + po) as usize, (ti * 4 + to) as usize);
                    assert_eq!(px[y * w + x], table.rgb(ti, pi, to, po));
                }
            }
        }
    }
    let attr = |name: &str| image.attr(name);
    assert_eq!(attr("clothbake.format_version"), "1");
    assert_eq!(
        attr("clothbake.grid"),
        "theta_i 2 phi_i 3 theta_o 4 phi_o 5, cell-centred, degrees"
    );
    assert_eq!(attr("clothbake.units"), "1/sr");
    assert_eq!(attr("clothbake.tool"), "clothbake 0.1.0");
    let json = attr("clothbake.metadata");
    assert!(json.is_ascii());
    let meta: Metadata = serde_json::from_str(&json).unwrap();
    assert_eq!(meta, table.meta);
}

/// The number after `key` in `text` (e.g. `x = pi * ` -> 5).
fn number_after(text: &str, key: &str) -> u32 {
    let at = text
        .find(key)
        .unwrap_or_else(|| panic!("no {key:?} in {text:?}"))
        + key.len();
    let digits: String = text[at..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits
        .parse()
        .unwrap_or_else(|_| panic!("no number after {key:?} in {text:?}"))
}

#[test]
fn exr_header_explains_the_table() {
    // The layout and direction attributes, read with the exr crate and followed to the letter,
    // lead from every pixel to the cell the loader finds at those directions.
    let d = dir();
    let path = d.path().join("t.exr");
    // Every value distinct, at least 1/360 from any other, and no steep slopes: a pixel
    // mistaken for another cell shows, the lookup's rounding of angles does not.
    let n = GRID.len() * 3;
    let values = (0..n).map(|i| 1.0 + i as f32 / n as f32).collect();
    let table = Table::new(sample_meta(GRID), values).unwrap();
    write_exr(&path, &table, Precision::F32, false).unwrap();
    let image = ExrRgb::read(&path);
    let attr = |name: &str| image.attr(name);
    let layout = attr("clothbake.layout");
    let (x_stride, y_stride) = (
        number_after(&layout, "x = pi * "),
        number_after(&layout, "y = ti * "),
    );
    assert!(layout.contains("15 x 8 pixels"), "{layout}");
    let dirs = attr("clothbake.directions");
    let count = |axis: &str, idx: &str, span: u32| {
        number_after(&dirs, &format!("{axis} = ({idx} + 0.5) * {span} / "))
    };
    let (nti, npi, nto, npo) = (
        count("theta_i", "ti", 90),
        count("phi_i", "pi", 360),
        count("theta_o", "to", 90),
        count("phi_o", "po", 360),
    );
    for needle in [
        "theta from the macro normal +Z",
        "phi from +X (the weft) toward +Y (the warp)",
        "i toward the light, o toward the eye",
    ] {
        assert!(dirs.contains(needle), "{dirs}");
    }
    let values = attr("clothbake.values");
    assert!(values.starts_with("R, G, B: f_r in 1/sr"), "{values}");

    let brdf = clothbake_loader::Brdf::from_table(table.clone(), Default::default()).unwrap();
    let unit = |theta: f64, phi: f64| {
        let (t, p) = (theta.to_radians(), phi.to_radians());
        [
            (t.sin() * p.cos()) as f32,
            (t.sin() * p.sin()) as f32,
            t.cos() as f32,
        ]
    };
    let (w, px) = (image.size.0, &image.pixels);
    let mut checked = 0;
    for ti in 0..nti {
        for pi in 0..npi {
            for to in 0..nto {
                for po in 0..npo {
                    let (x, y) = ((pi * x_stride + po) as usize, (ti * y_stride + to) as usize);
                    let wi = unit(
                        (f64::from(ti) + 0.5) * 90.0 / f64::from(nti),
                        (f64::from(pi) + 0.5) * 360.0 / f64::from(npi),
                    );
                    let wo = unit(
                        (f64::from(to) + 0.5) * 90.0 / f64::from(nto),
                        (f64::from(po) + 0.5) * 360.0 / f64::from(npo),
                    );
                    let (pixel, looked_up) = (px[y * w + x], brdf.eval(wi, wo));
                    for k in 0..3 {
                        let (a, b) = (pixel[k], looked_up[k]);
                        assert!(
                            (a - b).abs() <= 5e-4,
                            "cell ({ti},{pi},{to},{po}) channel {k}: pixel {a}, lookup {b}"
                        );
                    }
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, GRID.len());
}

#[test]
fn f16_refuses_values_beyond_half_range() {
    let d = dir();
    let path = d.path().join("big.exr");
    let mut table = sample_table(GRID);
    table.values[5] = 1e6;
    let e = message(write_exr(&path, &table, Precision::F16, false).unwrap_err());
    mentions(&e, &["half-float range", "f32"]);
    assert!(listing(d.path()).is_empty());
    write_exr(&path, &table, Precision::F32, false).unwrap();
    assert_eq!(read_table(&path).unwrap(), table);
}

fn write_bin(d: &Path) -> (PathBuf, Vec<u8>) {
    let path = d.join("t.bin");
    write_binary(&path, &sample_table(GRID), false).unwrap();
    let bytes = fs::read(&path).unwrap();
    (path, bytes)
}

#[test]
fn truncated_binary_is_a_clear_error() {
    let d = dir();
    let (path, bytes) = write_bin(d.path());
    for cut in [1, 5, 8, 10, 19, 30, 200, bytes.len() - 100, bytes.len() - 1] {
        let e = refusal(&path, &bytes[..cut]);
        assert!(e.starts_with(&path.display().to_string()), "{e}");
        assert!(e.contains("truncated"), "cut {cut}: {e}");
    }
}

#[test]
fn flipped_byte_anywhere_is_caught() {
    let d = dir();
    let (path, bytes) = write_bin(d.path());
    for i in 0..bytes.len() {
        let mut bad = bytes.clone();
        bad[i] ^= 0x20;
        fs::write(&path, &bad).unwrap();
        let e = read_binary(&path).expect_err("corruption must not go unnoticed");
        let _ = message(e);
    }
    // In the values: a checksum error with the fix.
    let mut bad = bytes.clone();
    let i = bytes.len() - 40;
    bad[i] ^= 0x01;
    let e = refusal(&path, &bad);
    mentions(
        &e,
        &["t.bin: checksum mismatch", "corrupted; bake it again"],
    );
}

#[test]
fn wrong_magic_and_foreign_files() {
    let d = dir();
    let (path, mut bytes) = write_bin(d.path());
    bytes[7] = b'X';
    let e = refusal(&path, &bytes);
    mentions(&e, &["not a clothbake table", "CLTHBAKE"]);
    let e = message(read_binary(&path).unwrap_err());
    assert!(e.contains("not a clothbake table"), "{e}");

    let text = d.path().join("notes.txt");
    let e = refusal(&text, b"hello world");
    mentions(&e, &["notes.txt: not a clothbake table", "68 65 6c 6c"]);
    assert!(read_exr(&text).is_err());
    assert!(read_binary(&text).is_err());
}

#[test]
fn wrong_version_names_the_fix() {
    let d = dir();
    let (path, mut bytes) = write_bin(d.path());
    bytes[8..12].copy_from_slice(&3u32.to_le_bytes());
    let e = refusal(&path, &bytes);
    mentions(&e, &["format version 3", "update the loader"]);
    bytes[8..12].copy_from_slice(&0u32.to_le_bytes());
    let e = refusal(&path, &bytes);
    mentions(&e, &["format version 0", "bake the table again"]);
    // A newer table description in a well-formed container (checksum recomputed).
    bytes[8..12].copy_from_slice(&2u32.to_le_bytes());
    let from = b"\"format_version\":1";
    let at = bytes.windows(from.len()).position(|w| w == from).unwrap();
    bytes[at + from.len() - 1] = b'7';
    let n = bytes.len();
    let crc = crc32fast::hash(&bytes[..n - 4]);
    bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
    let e = refusal(&path, &bytes);
    mentions(
        &e,
        &[
            "table format version 7, but this build reads versions up to 2",
            "update the loader",
        ],
    );
}

#[test]
fn exr_with_wrong_version_or_without_metadata() {
    let (d, path, table) = exr_written(Precision::F32);
    let good = fs::read(&path).unwrap();
    // As a future baker would write it: the same layout with another version number.
    let replace = |bytes: &[u8], from: &[u8], to: &[u8]| {
        let at = bytes.windows(from.len()).position(|w| w == from).unwrap();
        let mut out = bytes.to_vec();
        out[at..at + from.len()].copy_from_slice(to);
        out
    };
    let json7 = replace(&good, b"\"format_version\":1", b"\"format_version\":7");
    let e = refusal(&path, &json7);
    mentions(&e, &["format version 7", "update the loader"]);
    // The text attribute: name, type "string", size 1 (i32 LE), the text "1".
    let attr = b"clothbake.format_version\0string\0\x01\0\0\0";
    let mut from = attr.to_vec();
    from.push(b'1');
    let mut to = attr.to_vec();
    to.push(b'0');
    let e = refusal(&path, &replace(&good, &from, &to));
    mentions(&e, &["format version 0", "bake the table again"]);
    // Writers refuse a table that breaks the rules.
    let mut bad = table.clone();
    bad.meta.format_version = 7;
    let e = message(write_exr(&path, &bad, Precision::F32, true).unwrap_err());
    mentions(&e, &["cannot write the table", "format version 7"]);
    bad = table.clone();
    bad.values.pop();
    let e = message(write_binary(&path, &bad, true).unwrap_err());
    assert!(e.contains("needs 360 values"), "{e}");

    // A plain EXR from another tool.
    let plain = d.path().join("plain.exr");
    exr::prelude::write_rgb_file(&plain, 4, 2, |_x, _y| (0.5f32, 0.5f32, 0.5f32)).unwrap();
    let e = message(read_table(&plain).unwrap_err());
    mentions(
        &e,
        &["plain.exr: not a clothbake table", "clothbake.metadata"],
    );
}

#[test]
fn truncated_exr_is_an_error() {
    let d = dir();
    let path = d.path().join("t.exr");
    write_exr(&path, &sample_table(GRID), Precision::F16, false).unwrap();
    let bytes = fs::read(&path).unwrap();
    for cut in [3, 4, 20, bytes.len() / 2, bytes.len() - 1] {
        let e = refusal(&path, &bytes[..cut]);
        assert!(e.starts_with(&path.display().to_string()), "cut {cut}: {e}");
    }
}

#[test]
fn empty_and_missing_files() {
    let d = dir();
    let path = d.path().join("empty.bin");
    fs::write(&path, b"").unwrap();
    for e in [read_table(&path), read_binary(&path), read_exr(&path)] {
        let e = message(e.unwrap_err());
        assert!(e.contains("empty.bin: the file is empty"), "{e}");
    }
    let missing = d.path().join("missing.bin");
    let e = message(read_table(&missing).unwrap_err());
    assert!(e.contains("missing.bin: cannot open the table"), "{e}");
}

#[test]
fn existing_file_is_not_overwritten_without_force() {
    let d = dir();
    let path = d.path().join("t.bin");
    fs::write(&path, b"precious").unwrap();
    let table = sample_table(GRID);
    let e = message(write_binary(&path, &table, false).unwrap_err());
    assert!(
        e.contains(
            "t.bin: the file already exists; ask for it to be overwritten (overwrite = true)"
        ),
        "{e}"
    );
    let e = message(write_exr(&path, &table, Precision::F16, false).unwrap_err());
    assert!(
        e.contains("(overwrite = true)") && !e.contains("--force"),
        "{e}"
    );
    assert_eq!(fs::read(&path).unwrap(), b"precious");
    assert_eq!(listing(d.path()), ["t.bin"]);

    write_binary(&path, &table, true).unwrap();
    assert_eq!(read_table(&path).unwrap(), table);
    write_exr(&path, &table, Precision::F32, true).unwrap();
    assert_eq!(read_table(&path).unwrap(), table);
    assert_eq!(listing(d.path()), ["t.bin"]);
}

#[test]
fn failed_writes_leave_nothing_behind() {
    let d = dir();
    let table = sample_table(GRID);
    let path = d.path().join("no_such_folder").join("t.bin");
    let e = message(write_binary(&path, &table, false).unwrap_err());
    mentions(&e, &["no_such_folder: cannot write", "does not exist"]);
    let e = message(write_exr(&path, &table, Precision::F16, true).unwrap_err());
    assert!(e.contains("no_such_folder"), "{e}");
    assert!(listing(d.path()).is_empty());

    // A writer that fails half way: neither target nor temporary file remains.
    let path = d.path().join("t.bin");
    let e = write_atomic_as(&path, "table", false, |w| {
        use std::io::Write;
        w.write_all(&[0u8; 100_000])?;
        Err(std::io::Error::other("disk on fire"))
    })
    .unwrap_err();
    assert!(message(e).contains("t.bin: cannot write the table: disk on fire"));
    assert!(listing(d.path()).is_empty());

    // The same over an existing file: the old contents survive.
    fs::write(&path, b"old").unwrap();
    assert!(write_atomic_as(&path, "table", true, |_| Err(std::io::Error::other("no"))).is_err());
    assert_eq!(fs::read(&path).unwrap(), b"old");
    assert_eq!(listing(d.path()), ["t.bin"]);
}

#[test]
fn relative_path_in_current_folder() {
    // A bare file name writes into the current folder; only exercise the error path here
    // (tests must not litter the working directory).
    let e = write_atomic_as(Path::new(""), "table", true, |_| Ok(())).unwrap_err();
    assert!(message(e).contains("does not name a file"));
    assert_eq!(BINARY_MAGIC, *b"CLTHBAKE");
}

#[test]
fn damaged_exr_is_caught_or_harmless() {
    let (_d, path, _) = exr_written(Precision::F16);
    let good = read_table(&path).unwrap();
    let bytes = fs::read(&path).unwrap();
    let mut harmless = 0;
    for i in 0..bytes.len() {
        for flip in [0x01u8, 0x80, 0xff] {
            let mut bad = bytes.clone();
            bad[i] ^= flip;
            fs::write(&path, &bad).unwrap();
            // Never a panic, never a silently different table (clothbake.crc32 covers the
            // metadata and every sample); flips in other attributes may be harmless.
            if let Ok(t) = read_table(&path) {
                assert_eq!(t, good, "flip {flip:#x} at byte {i} of {}", bytes.len());
                harmless += 1;
            }
        }
    }
    eprintln!(
        "{harmless} of {} damaged EXR files read unchanged",
        bytes.len() * 3
    );
}
