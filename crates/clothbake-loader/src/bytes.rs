//! Byte-level helpers of the file codecs: checksummed writing and reading, bounded reads, hex.

use std::io::{self, Read, Write};
use std::path::Path;

use crate::error::TableError;

/// Number of `f32` values converted per chunk when reading or writing files.
pub(crate) const CHUNK_VALUES: usize = 16 * 1024;

/// A writer that computes the CRC-32 of everything written through it.
pub(crate) struct CrcWriter<W> {
    pub(crate) inner: W,
    pub(crate) hasher: crc32fast::Hasher,
}

impl<W: Write> CrcWriter<W> {
    /// A writer into `inner`, hashing from here on.
    pub(crate) fn new(inner: W) -> CrcWriter<W> {
        CrcWriter {
            inner,
            hasher: crc32fast::Hasher::new(),
        }
    }

    /// Writes `values` as f32 little-endian, chunk by chunk.
    pub(crate) fn write_f32s(&mut self, values: &[f32]) -> io::Result<()> {
        let mut bytes = Vec::with_capacity(CHUNK_VALUES.min(values.len()) * 4);
        for chunk in values.chunks(CHUNK_VALUES) {
            bytes.clear();
            bytes.extend(chunk.iter().flat_map(|v| v.to_le_bytes()));
            self.write_all(&bytes)?;
        }
        Ok(())
    }

    /// Writes the CRC-32 of everything written so far, little-endian, unhashed.
    pub(crate) fn finish(self) -> io::Result<()> {
        let crc = self.hasher.finalize();
        let mut inner = self.inner;
        inner.write_all(&crc.to_le_bytes())
    }
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

/// The file being read, for error messages: its path, its length and what it should be
/// (`"table"`, `"shard"`, ...).
#[derive(Clone, Copy)]
pub(crate) struct Source<'a> {
    pub(crate) path: &'a Path,
    pub(crate) len: u64,
    pub(crate) noun: &'a str,
}

impl Source<'_> {
    /// Checks, before anything is allocated, that the file is exactly `expected` bytes long
    /// (`None`: beyond any file): `needs` says what needs them, e.g. "12 values".
    pub(crate) fn expect_len(&self, expected: Option<u64>, needs: &str) -> Result<(), TableError> {
        let (path, len) = (self.path.to_path_buf(), self.len);
        match expected {
            Some(e) if e == len => Ok(()),
            Some(e) if e > len => Err(TableError::Truncated {
                path,
                detail: format!("{needs} need a file of {e} bytes, but it has {len}"),
            }),
            Some(e) => Err(TableError::Corrupted {
                path,
                reason: format!(
                    "{needs} need a file of {e} bytes, but it has {len} (unexpected trailing bytes)"
                ),
            }),
            None => Err(TableError::Truncated {
                path,
                detail: format!("{needs} are far beyond the file's {len} bytes"),
            }),
        }
    }

    /// Reads the stored CRC-32 that ends the file and compares it with `computed`.
    pub(crate) fn check_crc(&self, r: &mut impl Read, computed: u32) -> Result<(), TableError> {
        let mut word = [0u8; 4];
        read_hashed(
            r,
            &mut crc32fast::Hasher::new(),
            &mut word,
            *self,
            "checksum",
        )?;
        let stored = u32::from_le_bytes(word);
        if stored != computed {
            return Err(TableError::Checksum {
                path: self.path.to_path_buf(),
                stored,
                computed,
            });
        }
        Ok(())
    }

    /// An I/O error while reading this file.
    pub(crate) fn io(&self, e: io::Error) -> TableError {
        TableError::io(self.path, format!("read the {}", self.noun), e)
    }

    /// The file ends inside `what`.
    pub(crate) fn ends_inside(&self, what: &str) -> TableError {
        TableError::Truncated {
            path: self.path.to_path_buf(),
            detail: format!(
                "the file ends inside the {what} ({} bytes in all)",
                self.len
            ),
        }
    }
}

/// Opens `path` for reading after checking that it is a regular file (or a link to one): a
/// folder, a device (`/dev/zero` reads without end), a FIFO (opening blocks until a writer
/// comes) or a socket is refused with an error naming what it is. `noun` names the file in
/// errors ("table", "shard", ...).
pub(crate) fn open_regular(path: &Path, noun: &str) -> Result<std::fs::File, TableError> {
    let not = |kind: &str| TableError::Foreign {
        path: path.to_path_buf(),
        what: noun.to_string().into(),
        reason: format!("it is {kind}, not a regular file; give the path of a {noun} file"),
    };
    let meta =
        std::fs::metadata(path).map_err(|e| TableError::io(path, format!("open the {noun}"), e))?;
    if meta.is_dir() {
        return Err(not("a folder"));
    }
    if let Some(kind) = crate::atomic::special_kind(&meta.file_type()) {
        return Err(not(kind));
    }
    // Opened without blocking (the path may have been replaced by a FIFO since it was
    // checked; `O_NONBLOCK` changes nothing for a regular file), then checked again.
    let mut opts = std::fs::OpenOptions::new();
    opts.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        opts.custom_flags(libc::O_NONBLOCK);
    }
    let file = opts
        .open(path)
        .map_err(|e| TableError::io(path, format!("open the {noun}"), e))?;
    let meta = file
        .metadata()
        .map_err(|e| TableError::io(path, format!("open the {noun}"), e))?;
    if let Some(kind) = crate::atomic::special_kind(&meta.file_type()) {
        return Err(not(kind));
    }
    Ok(file)
}

/// Opens `path` for reading ([`open_regular`]) and measures it; an empty file is refused.
/// `noun` names it in errors ("table", "shard", ...).
pub(crate) fn open_sized<'a>(
    path: &'a Path,
    noun: &'a str,
) -> Result<(std::fs::File, Source<'a>), TableError> {
    let file = open_regular(path, noun)?;
    let len = file
        .metadata()
        .map_err(|e| TableError::io(path, format!("read the {noun}"), e))?
        .len();
    if len == 0 {
        return Err(TableError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok((file, Source { path, len, noun }))
}

/// Reads exactly `buf.len()` bytes, hashing them; a short read is reported as truncation
/// inside `what`.
pub(crate) fn read_hashed(
    r: &mut impl Read,
    hasher: &mut crc32fast::Hasher,
    buf: &mut [u8],
    src: Source<'_>,
    what: &str,
) -> Result<(), TableError> {
    r.read_exact(buf).map_err(|e| {
        if e.kind() == io::ErrorKind::UnexpectedEof {
            src.ends_inside(what)
        } else {
            src.io(e)
        }
    })?;
    hasher.update(buf);
    Ok(())
}

/// Reads `n` f32 little-endian values in chunks, hashing their bytes. The caller bounds `n`
/// by the file size, so the allocation is backed by real bytes.
pub(crate) fn read_f32s(
    r: &mut impl Read,
    hasher: &mut crc32fast::Hasher,
    n: usize,
    src: Source<'_>,
) -> Result<Vec<f32>, TableError> {
    let mut values = Vec::with_capacity(n);
    let mut bytes = vec![0u8; CHUNK_VALUES.min(n) * 4];
    let mut left = n;
    while left > 0 {
        let take = left.min(CHUNK_VALUES);
        let buf = &mut bytes[..take * 4];
        read_hashed(r, hasher, buf, src, "values")?;
        values.extend(
            buf.chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        );
        left -= take;
    }
    Ok(values)
}

/// Reads as many bytes as are available, up to `buf.len()`.
pub(crate) fn read_up_to(r: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
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

/// Bytes as lowercase hex pairs separated by spaces, `(none)` for no bytes.
pub(crate) fn hex(bytes: &[u8]) -> String {
    if bytes.is_empty() {
        return "(none)".to_string();
    }
    bytes
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}
