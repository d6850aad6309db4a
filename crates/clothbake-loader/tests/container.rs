//! The binary container (`docs/reference/table-format.md`): round trips checked against the documented
//! layout, parsed here byte by byte, and every kind of damage giving a clear error without a
//! panic or a large allocation.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::fs;
use std::path::{Path, PathBuf};

use clothbake_loader::{
    read_container, read_table, write_atomic_as, write_container, write_container_chunks,
    Container, ContainerKind, TableError, CONTAINER_VERSION,
};
use serde_json::json;

/// Records the largest single allocation of the current thread, so that a test can show that
/// reading a damaged file allocates nothing near what its header claims.
struct Largest;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(layout.size())));
        System.alloc(layout)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(new_size)));
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static ALLOCATOR: Largest = Largest;

/// The largest allocation `f` makes on this thread, and its result.
fn largest_allocation<T>(f: impl FnOnce() -> T) -> (usize, T) {
    LARGEST.with(|l| l.set(0));
    let out = f();
    (LARGEST.with(|l| l.get()), out)
}

/// Values with signs, zeros, subnormals, infinities and a NaN payload: the container stores
/// bits, whatever they mean.
fn values() -> Vec<f32> {
    let mut v: Vec<f32> = (0..50).map(|i| (i as f32 * 0.731).sin() * 1e3).collect();
    v.extend([
        0.0,
        -0.0,
        f32::MIN_POSITIVE / 8.0,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::from_bits(0x7fc0_1234),
        f32::MAX,
    ]);
    v
}

fn header() -> serde_json::Value {
    json!({
        "shard": {"index": 1, "count": 4},
        "rows": [[3, 5], [9, 10]],
        "note": "Baumwolle ü — 🧵",
        "metadata": {"tool": "clothbake 0.1.0", "grid": [1, 2, 3]}
    })
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A container with its values as bits (NaN is not equal to itself).
fn exact(c: &Container) -> (ContainerKind, &serde_json::Value, Vec<u32>) {
    (c.kind, &c.header, bits(&c.values))
}

/// The file as `docs/reference/table-format.md` describes it, assembled here without the loader.
fn assemble(version: u32, tag: &[u8], header: &[u8], values: &[f32]) -> Vec<u8> {
    let mut b = b"CLTHBAKE".to_vec();
    b.extend(version.to_le_bytes());
    let mut field = [0u8; 16];
    field[..tag.len()].copy_from_slice(tag);
    b.extend(field);
    b.extend((header.len() as u64).to_le_bytes());
    b.extend((values.len() as u64).to_le_bytes());
    b.extend(header);
    for v in values {
        b.extend(v.to_le_bytes());
    }
    let crc = crc32fast::hash(&b);
    b.extend(crc.to_le_bytes());
    b
}

/// The documented fields of a container file, parsed here.
struct Parsed {
    version: u32,
    tag: String,
    header: serde_json::Value,
    values: Vec<f32>,
}

fn parse(b: &[u8]) -> Parsed {
    assert_eq!(&b[..8], b"CLTHBAKE");
    let u64_at = |at: usize| u64::from_le_bytes(b[at..at + 8].try_into().unwrap()) as usize;
    let (h, n) = (u64_at(28), u64_at(36));
    assert_eq!(b.len(), 44 + h + 4 * n + 4, "the documented length");
    let crc = u32::from_le_bytes(b[b.len() - 4..].try_into().unwrap());
    assert_eq!(crc, crc32fast::hash(&b[..b.len() - 4]));
    let tag_field = &b[12..28];
    let end = tag_field.iter().position(|&c| c == 0).unwrap_or(16);
    assert!(tag_field[end..].iter().all(|&c| c == 0), "zero padding");
    Parsed {
        version: u32::from_le_bytes(b[8..12].try_into().unwrap()),
        tag: String::from_utf8(tag_field[..end].to_vec()).unwrap(),
        header: serde_json::from_slice(&b[44..44 + h]).unwrap(),
        values: b[44 + h..44 + h + 4 * n]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect(),
    }
}

fn dir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn write_shard(d: &Path) -> (PathBuf, Vec<u8>) {
    let path = d.join("part.shard");
    write_container(&path, ContainerKind::Shard, &header(), &values(), false).unwrap();
    let bytes = fs::read(&path).unwrap();
    (path, bytes)
}

/// Reads `bytes` as a shard; the error's message, which must name the file.
fn shard_error(path: &Path, bytes: &[u8]) -> String {
    fs::write(path, bytes).unwrap();
    let e = read_container(path, &[ContainerKind::Shard]).expect_err("must be refused");
    let m = e.to_string();
    assert!(m.starts_with(&path.display().to_string()), "{m}");
    m
}

#[test]
fn round_trip_matches_the_documented_layout() {
    let d = dir();
    let (path, bytes) = write_shard(d.path());
    let p = parse(&bytes);
    assert_eq!(p.version, CONTAINER_VERSION);
    assert_eq!(p.version, 2);
    assert_eq!(p.tag, "shard");
    assert_eq!(p.header, header());
    assert_eq!(bits(&p.values), bits(&values()));
    // Keys sorted: the same header always gives the same bytes.
    let h = u64::from_le_bytes(bytes[28..36].try_into().unwrap()) as usize;
    let text = std::str::from_utf8(&bytes[44..44 + h]).unwrap();
    assert!(
        text.starts_with(r#"{"metadata":{"grid":[1,2,3],"tool":"#),
        "{text}"
    );

    let back = read_container(&path, &[ContainerKind::Shard]).unwrap();
    assert_eq!(back.kind, ContainerKind::Shard);
    assert_eq!(back.header, header());
    assert_eq!(bits(&back.values), bits(&values()));
    // Several kinds accepted, or any.
    let either = [ContainerKind::Shard, ContainerKind::Checkpoint];
    assert_eq!(
        exact(&read_container(&path, &either).unwrap()),
        exact(&back)
    );
    assert_eq!(exact(&read_container(&path, &[]).unwrap()), exact(&back));

    // A file assembled by another writer from the documentation reads the same.
    let other = d.path().join("other.shard");
    let json = serde_json::to_vec(&header()).unwrap();
    fs::write(&other, assemble(2, b"shard", &json, &values())).unwrap();
    assert_eq!(
        exact(&read_container(&other, &either).unwrap()),
        exact(&back)
    );

    // Chunks give the same bytes as one slice; no values and an empty header are fine.
    let v = values();
    let chunked = d.path().join("chunked.shard");
    let chunks = [&v[..7], &v[7..7], &v[7..40], &v[40..]];
    write_container_chunks(&chunked, ContainerKind::Shard, &header(), chunks, false).unwrap();
    assert_eq!(fs::read(&chunked).unwrap(), bytes);
    let empty = d.path().join("empty.checkpoint");
    write_container(&empty, ContainerKind::Checkpoint, &json!({}), &[], false).unwrap();
    let c = read_container(&empty, &either).unwrap();
    assert_eq!((c.kind, c.values.len()), (ContainerKind::Checkpoint, 0));
    assert_eq!(fs::read(&empty).unwrap().len(), 44 + 2 + 4);
}

#[test]
fn writing_refuses_existing_files_and_bad_headers() {
    let d = dir();
    let (path, bytes) = write_shard(d.path());
    let e = write_container(&path, ContainerKind::Shard, &header(), &[1.0], false)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("part.shard: the file already exists; ask for it to be overwritten"),
        "{e}"
    );
    assert_eq!(fs::read(&path).unwrap(), bytes);
    write_container(&path, ContainerKind::Shard, &header(), &[1.0], true).unwrap();
    assert_eq!(read_container(&path, &[]).unwrap().values, [1.0]);

    let e = write_container(&path, ContainerKind::Checkpoint, &json!([1]), &[], true)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("cannot write the checkpoint: the header is not a JSON object"),
        "{e}"
    );
    let huge = json!({ "text": "x".repeat(1 << 24) });
    let e = write_container(&path, ContainerKind::Shard, &huge, &[], true)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("cannot write the shard") && e.contains("16 MiB"),
        "{e}"
    );
    assert_eq!(read_container(&path, &[]).unwrap().values, [1.0]);
}

#[test]
fn truncated_files_are_a_clear_error() {
    let d = dir();
    let (path, bytes) = write_shard(d.path());
    for cut in 0..bytes.len() {
        let m = shard_error(&path, &bytes[..cut]);
        let want = if cut == 0 {
            "the file is empty"
        } else {
            "truncated"
        };
        assert!(m.contains(want), "cut {cut}: {m}");
    }
    let m = shard_error(&path, &bytes[..30]);
    assert!(m.contains("ends inside the header length"), "{m}");
    let m = shard_error(&path, &bytes[..bytes.len() - 1]);
    assert!(m.contains("bake it again"), "{m}");
}

#[test]
fn corruption_is_caught_by_the_checksum() {
    let d = dir();
    let (path, bytes) = write_shard(d.path());
    // In the header and in the values: the checksum.
    for at in [50, bytes.len() - 20] {
        let mut bad = bytes.clone();
        bad[at] ^= 0x04;
        let m = shard_error(&path, &bad);
        assert!(
            m.contains("checksum mismatch") && m.contains("bake it again"),
            "{m}"
        );
    }
    // Anywhere: some error, never a panic or a silently different file.
    for at in 0..bytes.len() {
        for flip in [0x01u8, 0x80] {
            let mut bad = bytes.clone();
            bad[at] ^= flip;
            shard_error(&path, &bad);
        }
    }
    // Trailing bytes.
    let mut long = bytes.clone();
    long.extend([0, 0, 0, 0]);
    let m = shard_error(&path, &long);
    assert!(m.contains("trailing bytes"), "{m}");
}

#[test]
fn wrong_kind_names_the_kinds_and_the_fix() {
    let d = dir();
    let (path, _) = write_shard(d.path());
    let e = read_container(&path, &[ContainerKind::Table]).unwrap_err();
    assert!(matches!(e, TableError::WrongKind { .. }), "{e}");
    let m = e.to_string();
    assert!(
        m.contains("part.shard: the file is a shard, not a table") && m.contains("clothbake merge"),
        "{m}"
    );
    // Renderers asking for a table get the same answer.
    let m = read_table(&path).unwrap_err().to_string();
    assert!(m.contains("the file is a shard, not a table"), "{m}");

    let cp = d.path().join("t.bin.checkpoint");
    write_container(&cp, ContainerKind::Checkpoint, &header(), &[], false).unwrap();
    let m = read_table(&cp).unwrap_err().to_string();
    assert!(
        m.contains("checkpoint, not a table") && m.contains("--resume"),
        "{m}"
    );
    let m = read_container(&cp, &[ContainerKind::Shard])
        .unwrap_err()
        .to_string();
    assert!(m.contains("the file is a checkpoint, not a shard"), "{m}");

    // A kind this build does not know (with a valid checksum), and a tag that is no tag.
    let json = serde_json::to_vec(&header()).unwrap();
    let m = shard_error(&path, &assemble(2, b"spatial-table", &json, &[1.0]));
    assert!(
        m.contains("\"spatial-table\" file, not a shard") && m.contains("update the loader"),
        "{m}"
    );
    let m = shard_error(&path, &assemble(2, b"Shard", &json, &[1.0]));
    assert!(m.contains("kind tag 53 68 61 72 64 00"), "{m}");
}

#[test]
fn headers_that_are_not_json_objects() {
    let d = dir();
    let path = d.path().join("h.shard");
    let m = shard_error(&path, &assemble(2, b"shard", b"[1, 2]", &[]));
    assert!(m.contains("the header is not a JSON object"), "{m}");
    let m = shard_error(&path, &assemble(2, b"shard", b"{\"a\": ", &[]));
    assert!(m.contains("the header is not valid JSON"), "{m}");
    let m = shard_error(&path, &assemble(2, b"shard", &[0xff, 0xfe], &[]));
    assert!(m.contains("the header is not valid JSON"), "{m}");
}

#[test]
fn versions_magic_and_empty_files() {
    let d = dir();
    let (path, bytes) = write_shard(d.path());
    let mut v = bytes.clone();
    v[8..12].copy_from_slice(&3u32.to_le_bytes());
    let m = shard_error(&path, &v);
    assert!(
        m.contains("shard format version 3, but this build reads versions up to 2")
            && m.contains("update the loader"),
        "{m}"
    );
    v[8..12].copy_from_slice(&0u32.to_le_bytes());
    let m = shard_error(&path, &v);
    assert!(
        m.contains("format version 0") && m.contains("bake the shard again"),
        "{m}"
    );
    let m = shard_error(&path, b"CLTHSHRD\x01\0\0\0");
    assert!(
        m.contains("not a clothbake shard") && m.contains("43 4c 54 48 53"),
        "{m}"
    );
    let m = shard_error(&path, b"");
    assert!(m.contains("the file is empty"), "{m}");
    let missing = d.path().join("missing.shard");
    let m = read_container(&missing, &[ContainerKind::Shard])
        .unwrap_err()
        .to_string();
    assert!(m.contains("missing.shard: cannot open the shard"), "{m}");
}

#[test]
fn oversized_header_length_allocates_nothing_large() {
    let d = dir();
    let (path, bytes) = write_shard(d.path());
    for (h, want) in [
        (u64::MAX, "more than the limit"),
        (1 << 40, "more than the limit"),
        ((1 << 24) + 1, "more than the limit"),
        (1 << 24, "truncated"),
    ] {
        let mut bad = bytes.clone();
        bad[28..36].copy_from_slice(&h.to_le_bytes());
        fs::write(&path, &bad).unwrap();
        let (largest, r) = largest_allocation(|| read_container(&path, &[ContainerKind::Shard]));
        let m = r.unwrap_err().to_string();
        assert!(m.contains(want), "header length {h}: {m}");
        assert!(
            largest < 1 << 20,
            "header length {h}: allocated {largest} bytes"
        );
    }
}

#[test]
fn value_count_beyond_the_file_allocates_nothing_large() {
    let d = dir();
    let (path, bytes) = write_shard(d.path());
    for n in [
        u64::MAX,
        u64::MAX / 4,
        1 << 40,
        1 << 28,
        values().len() as u64 + 1,
    ] {
        let mut bad = bytes.clone();
        bad[36..44].copy_from_slice(&n.to_le_bytes());
        fs::write(&path, &bad).unwrap();
        let (largest, r) = largest_allocation(|| read_container(&path, &[ContainerKind::Shard]));
        let m = r.unwrap_err().to_string();
        assert!(m.contains("truncated"), "count {n}: {m}");
        assert!(largest < 1 << 20, "count {n}: allocated {largest} bytes");
    }
    // The same through the table reader.
    let mut bad = bytes.clone();
    bad[12..17].copy_from_slice(b"table");
    bad[36..44].copy_from_slice(&(1u64 << 40).to_le_bytes());
    fs::write(&path, &bad).unwrap();
    let (largest, r) = largest_allocation(|| read_table(&path));
    assert!(r.unwrap_err().to_string().contains("truncated"));
    assert!(largest < 1 << 20, "allocated {largest} bytes");
}

#[test]
fn atomic_writes_name_what_they_write() {
    let d = dir();
    let path = d.path().join("plot.png");
    let e = write_atomic_as(&path, "PNG image", false, |_| {
        Err(std::io::Error::other("disk on fire"))
    })
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("plot.png: cannot write the PNG image: disk on fire"),
        "{e}"
    );
    let e = write_atomic_as(Path::new("/"), "PNG image", true, |_| Ok(())).unwrap_err();
    assert!(
        e.to_string()
            .contains("cannot write the PNG image: the path does not name a file"),
        "{e}"
    );
    assert!(fs::read_dir(d.path()).unwrap().next().is_none());
}
