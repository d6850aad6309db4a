//! Reading a fabric from a file: a fabric file (JSON, [`crate::fabric`]) or a WIF weaving draft
//! ([`crate::wif`]), chosen by the file's extension. Both end in [`Fabric::new`].
//!
//! The file is checked before it is read: a regular file (not a directory, FIFO, device or
//! socket, which could block or never end) of at most [`MAX_FILE_BYTES`], read through a reader
//! that stops there should it grow meanwhile; then text (no control bytes but tab, line feed,
//! form feed and carriage return; a UTF-8 byte-order mark is skipped, a UTF-16 one named).

use crate::fabric::{Fabric, FabricError};
use crate::wif::WifOptions;
use std::io::Read;
use std::path::Path;

/// Largest fabric file or WIF draft read, in bytes (16 MiB: a period of 2^20 cells as JSON
/// takes about 2 MiB).
pub const MAX_FILE_BYTES: u64 = 16 << 20;

impl Fabric {
    /// Reads and validates a fabric file: JSON, or a WIF weaving draft when the name ends in
    /// `.wif` (any case; see [`crate::wif`]) with the default [`WifOptions`].
    pub fn from_path(path: &Path) -> Result<Fabric, FabricError> {
        Fabric::from_path_with(path, &WifOptions::default())
    }

    /// As [`Fabric::from_path`], with the sizes a WIF draft may leave out.
    pub fn from_path_with(path: &Path, wif: &WifOptions) -> Result<Fabric, FabricError> {
        let file = path.display().to_string();
        let wif_draft = is_wif(path);
        let bytes = read_text_file(path, &file, wif_draft)?;
        if wif_draft {
            // Drafts are often Latin-1 or Windows-1252; only their [TEXT] can hold non-ASCII.
            let text = String::from_utf8_lossy(&bytes);
            return Ok(crate::wif::parse(&text, &file, wif)?);
        }
        let text = String::from_utf8(bytes).map_err(|e| FabricError {
            file: file.clone(),
            field: String::new(),
            problem: format!("the fabric file is not UTF-8 text: {e}"),
            fix: "save it as UTF-8 JSON (see docs/reference/fabric-format.md)".into(),
        })?;
        Fabric::from_json_str(&text, &file)
    }
}

/// True when `path` names a WIF draft (extension `.wif`, any case).
pub fn is_wif(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("wif"))
}

/// The bytes of a fabric file or draft, checked as the module says; `file` names it in errors,
/// `wif` says which kind it should be.
fn read_text_file(path: &Path, file: &str, wif: bool) -> Result<Vec<u8>, FabricError> {
    let kind = if wif {
        "a text WIF draft"
    } else {
        "a JSON fabric file"
    };
    let err = |problem: String, fix: &str| FabricError {
        file: file.to_string(),
        field: String::new(),
        problem,
        fix: fix.to_string(),
    };
    let check = |meta: &std::fs::Metadata| {
        if meta.is_dir() {
            return Err(err(
                "is a directory, not a fabric file".into(),
                "give a fabric file (e.g. tables/twill.json) or a WIF draft",
            ));
        }
        if !meta.is_file() {
            return Err(err(
                format!("is {}, not a regular file", special_kind(meta)),
                "give a fabric file or WIF draft saved as a regular file",
            ));
        }
        if meta.len() > MAX_FILE_BYTES {
            return Err(too_large(file, meta.len()));
        }
        Ok(())
    };
    let cannot = |e: std::io::Error| {
        err(
            format!("cannot read the fabric file: {e}"),
            "check the path",
        )
    };
    // Checked before opening, then again on what was opened: the path may be replaced in
    // between, so it is opened without blocking (a FIFO's open would wait for a writer).
    check(&std::fs::metadata(path).map_err(cannot)?)?;
    let f = open_nonblocking(path).map_err(cannot)?;
    check(&f.metadata().map_err(cannot)?)?;
    let mut bytes = Vec::new();
    f.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(file, bytes.len() as u64));
    }
    if bytes.starts_with(&[0xef, 0xbb, 0xbf]) {
        bytes.drain(..3);
    } else if bytes.starts_with(&[0xff, 0xfe]) || bytes.starts_with(&[0xfe, 0xff]) {
        return Err(err(
            "is UTF-16 text (it starts with a UTF-16 byte-order mark)".into(),
            "save it as UTF-8 (or ASCII) text",
        ));
    }
    if let Some(at) = bytes
        .iter()
        .position(|&b| (b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r' | 0x0c)) || b == 0x7f)
    {
        return Err(err(
            format!(
                "is not {kind}: byte {at} is the control character 0x{:02x} (binary data?)",
                bytes[at]
            ),
            if wif {
                "give a WIF draft as text (docs/reference/wif.md)"
            } else {
                "give a JSON fabric file (docs/reference/fabric-format.md)"
            },
        ));
    }
    Ok(bytes)
}

/// Opens `path` for reading; on Unix with `O_NONBLOCK`, so that a FIFO put in place of a
/// checked regular file cannot block the open (the flag changes nothing for regular files).
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    let mut opts = std::fs::OpenOptions::new();
    opts.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        opts.custom_flags(libc::O_NONBLOCK);
    }
    opts.open(path)
}

fn too_large(file: &str, len: u64) -> FabricError {
    FabricError {
        file: file.to_string(),
        field: String::new(),
        problem: format!(
            "the file is {len} bytes, more than the {} MiB a fabric file or draft may be",
            MAX_FILE_BYTES >> 20
        ),
        fix: "give one repeat of the weave (docs/reference/limits.md)".into(),
    }
}

/// What a path that is neither a directory nor a regular file is, for messages.
fn special_kind(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    let _ = meta;
    "a special file"
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> std::path::PathBuf {
        let d =
            std::env::temp_dir().join(format!("clothbake-source-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn problem(path: &Path) -> String {
        let e = Fabric::from_path(path).unwrap_err();
        assert_eq!(e.file, path.display().to_string());
        format!("{}; {}", e.problem, e.fix)
    }

    const PLAIN: &str = r#"{"pattern": [[1,0],[0,1]], "warp": {"radius": 1, "spacing": 2.5},
        "weft": {"radius": 1, "spacing": 2.5}}"#;

    #[test]
    fn special_files_large_files_and_binary_data_are_refused_before_parsing() {
        let d = dir("special");
        assert!(problem(&d).contains("is a directory"));
        #[cfg(unix)]
        {
            let e = problem(Path::new("/dev/zero"));
            assert!(e.contains("is a device, not a regular file"), "{e}");
        }
        // A sparse file one byte over the limit: refused from its size, not read.
        let big = d.join("big.json");
        std::fs::File::create(&big)
            .unwrap()
            .set_len(MAX_FILE_BYTES + 1)
            .unwrap();
        let e = problem(&big);
        assert!(e.contains("16777217 bytes, more than the 16 MiB"), "{e}");
        // Binary data: named by its first control byte, not echoed.
        let bin = d.join("noise.wif");
        std::fs::write(&bin, b"[WIF]\n\x00\x9f\xff garbage").unwrap();
        let e = problem(&bin);
        assert!(
            e.contains("is not a text WIF draft: byte 6 is the control character 0x00"),
            "{e}"
        );
        assert!(!e.contains("garbage"), "{e}");
        let utf16 = d.join("u16.json");
        std::fs::write(&utf16, b"\xff\xfe{\x00").unwrap();
        assert!(problem(&utf16).contains("UTF-16"));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_utf8_byte_order_mark_is_skipped() {
        let d = dir("bom");
        let json = d.join("bom.json");
        std::fs::write(&json, format!("\u{feff}{PLAIN}")).unwrap();
        let plain = Fabric::from_json_str(PLAIN, "p").unwrap();
        assert_eq!(Fabric::from_path(&json).unwrap().weave(), plain.weave());
        let wif = d.join("bom.wif");
        std::fs::write(
            &wif,
            "\u{feff}[WIF]\nVersion=1.1\n[THREADING]\n1=1\n2=2\n[LIFTPLAN]\n1=1\n2=2\n",
        )
        .unwrap();
        assert_eq!(Fabric::from_path(&wif).unwrap().weave(), plain.weave());
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// The open after the check cannot block: a FIFO (what a path swapped after its check could
    /// be) opens at once with no writer, and the check on the opened file then refuses it.
    #[cfg(unix)]
    #[test]
    fn a_fifo_in_place_of_the_checked_file_does_not_block_the_open() {
        use std::os::unix::fs::FileTypeExt;
        let fifo = dir("fifo").join("swapped.json");
        let _ = std::fs::remove_file(&fifo);
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: `c` is a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let (tx, rx) = std::sync::mpsc::channel();
        let p = fifo.clone();
        std::thread::spawn(move || {
            let _ = tx.send(open_nonblocking(&p).map(|f| f.metadata().unwrap().file_type()));
        });
        let opened = rx
            .recv_timeout(std::time::Duration::from_secs(10))
            .expect("the open of a FIFO blocked");
        assert!(opened.unwrap().is_fifo());
        assert!(problem(&fifo).contains("is a FIFO (named pipe), not a regular file"));
    }
}
