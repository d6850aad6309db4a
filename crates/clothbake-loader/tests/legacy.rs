//! Version-1 binary tables (a bincode header, before the container had kinds) still open. The
//! shipped golden tables baked before version 2 (`tables/golden/*.bin` whose version field is
//! 1: six of them; later ones are version-2 files) are parsed here by the documented version-1
//! layout, without the loader, and must equal what the loader reads and what a fresh version-2
//! write of it reads back.

use std::fs;
use std::path::{Path, PathBuf};

use clothbake_loader::{read_binary, read_table, write_binary, Grid, Metadata, Table};

fn golden() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/golden");
    let mut v: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "bin"))
        .filter(|p| {
            let b = fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            b.len() >= 12 && b[8..12] == 1u32.to_le_bytes()
        })
        .collect();
    v.sort();
    assert!(v.len() >= 6, "the golden tables: {v:?}");
    v
}

/// Reads a version-1 table by `docs/reference/table-format.md`: magic, version 1, header length H, the
/// metadata (fixed-width integers, strings as a u64 length and UTF-8), the value count N, the
/// values, and a CRC-32 of everything before it.
fn parse_v1(b: &[u8]) -> Table {
    struct Cursor<'a>(&'a [u8], usize);
    impl Cursor<'_> {
        fn take(&mut self, n: usize) -> &[u8] {
            self.1 += n;
            &self.0[self.1 - n..self.1]
        }
        fn u32(&mut self) -> u32 {
            u32::from_le_bytes(self.take(4).try_into().unwrap())
        }
        fn u64(&mut self) -> u64 {
            u64::from_le_bytes(self.take(8).try_into().unwrap())
        }
        fn text(&mut self) -> String {
            let n = self.u64() as usize;
            String::from_utf8(self.take(n).to_vec()).unwrap()
        }
    }
    let mut c = Cursor(b, 0);
    assert_eq!(c.take(8), b"CLTHBAKE");
    assert_eq!(c.u32(), 1, "a version-1 file");
    let h = c.u64() as usize;
    let meta = Metadata {
        format_version: c.u32(),
        tool: c.text(),
        grid: Grid::new(c.u32(), c.u32(), c.u32(), c.u32()),
        centring: c.text(),
        quantity: c.text(),
        units: c.text(),
        fabric_json: c.text(),
        options_json: c.text(),
        symmetry: c.text(),
        spatial: None,
        yarns: None,
        openness: None,
    };
    assert_eq!(c.1, 20 + h, "the header is exactly H bytes");
    let n = c.u64() as usize;
    let values = (0..n)
        .map(|_| f32::from_le_bytes(c.take(4).try_into().unwrap()))
        .collect();
    let crc = c.u32();
    assert_eq!(c.1, b.len());
    assert_eq!(crc, crc32fast::hash(&b[..b.len() - 4]));
    Table { meta, values }
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn golden_version_1_tables_open_and_survive_a_version_2_round_trip() {
    let d = tempfile::tempdir().unwrap();
    for path in golden() {
        let bytes = fs::read(&path).unwrap();
        let want = parse_v1(&bytes);
        assert_eq!(want.meta.grid.len() * 3, want.values.len());
        assert!(want.meta.fabric_json.starts_with('{'));

        let got = read_table(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(got.meta, want.meta, "{}", path.display());
        assert_eq!(bits(&got.values), bits(&want.values), "{}", path.display());
        assert_eq!(read_binary(&path).unwrap(), got);

        // Written again: a version-2 container, the same table bit for bit.
        let again = d.path().join(path.file_name().unwrap());
        write_binary(&again, &got, false).unwrap();
        let new = fs::read(&again).unwrap();
        assert_eq!(u32::from_le_bytes(new[8..12].try_into().unwrap()), 2);
        assert_eq!(&new[12..17], b"table");
        let back = read_table(&again).unwrap();
        assert_eq!(back.meta, want.meta);
        assert_eq!(bits(&back.values), bits(&want.values));
    }
}

#[test]
fn damaged_version_1_tables_are_clear_errors() {
    let d = tempfile::tempdir().unwrap();
    let bytes = fs::read(&golden()[0]).unwrap();
    let path = d.path().join("old.bin");
    let h = u64::from_le_bytes(bytes[12..20].try_into().unwrap()) as usize;
    let check = |bad: &[u8], want: &str| {
        fs::write(&path, bad).unwrap();
        let m = read_table(&path).unwrap_err().to_string();
        assert!(m.starts_with(&path.display().to_string()), "{m}");
        assert!(m.contains(want), "{want}: {m}");
    };
    for cut in [
        9,
        13,
        20,
        20 + h / 2,
        20 + h + 3,
        bytes.len() / 2,
        bytes.len() - 1,
    ] {
        check(&bytes[..cut], "truncated");
    }
    for at in [24, 20 + h + 20, bytes.len() - 100] {
        let mut bad = bytes.clone();
        bad[at] ^= 0x10;
        check(&bad, "checksum mismatch");
    }
    // A huge header length or value count: refused from the file size, nothing allocated.
    let mut bad = bytes.clone();
    bad[12..20].copy_from_slice(&u64::MAX.to_le_bytes());
    check(&bad, "truncated");
    let mut bad = bytes.clone();
    bad[20 + h..28 + h].copy_from_slice(&(1u64 << 60).to_le_bytes());
    check(&bad, "truncated");
}

#[test]
fn a_huge_string_length_names_its_field() {
    // The tool name's length (after magic 8, version 4, header length 8, format_version 4)
    // set to 2^60, with the checksum made right again: only the header's decoding can fail.
    let bytes = fs::read(&golden()[0]).unwrap();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("legacy-string");
    fs::create_dir_all(&dir).unwrap();
    let path = dir.join("long.bin");
    let mut bad = bytes.clone();
    bad[24..32].copy_from_slice(&(1u64 << 60).to_le_bytes());
    let n = bad.len();
    let crc = crc32fast::hash(&bad[..n - 4]);
    bad[n - 4..].copy_from_slice(&crc.to_le_bytes());
    fs::write(&path, &bad).unwrap();
    let m = read_table(&path).unwrap_err().to_string();
    assert!(m.starts_with(&path.display().to_string()), "{m}");
    assert!(
        m.contains("field `tool` says it is 1152921504606846976 bytes long"),
        "{m}"
    );
    assert!(!m.contains("io error: )"), "{m}");
}
