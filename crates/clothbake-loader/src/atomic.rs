//! Atomic file writes: a file appears at its path complete or not at all.
//!
//! [`write_atomic_as`] writes any file (tables, binary container files, PNG images, plots)
//! through a temporary file in the same folder; its errors name what is written.

use std::fs::{self, File};
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::TableError;

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

/// Writes a file atomically: `path` ends up either complete or untouched. `what` names what
/// is written in error messages, e.g. `"table"`, `"PNG image"` or `"checkpoint"` (`cannot
/// write the PNG image: ...`).
///
/// Refuses an existing `path` unless `overwrite`, and a folder or special file always
/// ([`check_target`]). Otherwise calls `write` on a temporary file
/// `.<name>.tmp-<pid>-<n>` in the same folder, flushes and fsyncs it, and renames it over
/// `path` (without `overwrite`, it is hard-linked instead, so that a file created meanwhile is
/// never clobbered). The temporary file is removed on any error.
pub fn write_atomic_as(
    path: &Path,
    what: &str,
    overwrite: bool,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), TableError> {
    let action = |verb: &str| format!("{verb} the {what}");
    check_target(path, what, overwrite)?;
    let name = path.file_name().expect("checked by check_target");
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(TableError::Unwritable {
                path: path.to_path_buf(),
                what: what.to_string().into(),
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
    write(&mut writer).map_err(|e| TableError::io(path, action("write"), e))?;
    let file = writer
        .into_inner()
        .map_err(|e| TableError::io(path, action("write"), e.into_error()))?;
    file.sync_all()
        .map_err(|e| TableError::io(path, action("flush") + " to disk", e))?;
    drop(file);

    let rename = |guard: &mut TempGuard| {
        fs::rename(&temp, path)
            .map_err(|e| TableError::io(path, action("move") + " into place", e))?;
        guard.armed = false;
        Ok::<(), TableError>(())
    };
    if overwrite {
        // Checked again just before the rename: a folder or special file that appeared
        // meanwhile is not replaced.
        check_target(path, what, overwrite)?;
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

/// What kind of file system object `t` is, in words, when it is neither a regular file, a
/// folder nor a symbolic link (a device, a FIFO, a socket).
pub(crate) fn special_kind(t: &fs::FileType) -> Option<&'static str> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return Some("a character device");
        }
        if t.is_block_device() {
            return Some("a block device");
        }
        if t.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if t.is_socket() {
            return Some("a socket");
        }
    }
    if t.is_file() || t.is_dir() || t.is_symlink() {
        None
    } else {
        Some("a special file")
    }
}

/// Checks that `path` may be written as a new regular file by [`write_atomic_as`]: it names a
/// file, and what is there now (if anything) is a regular file (or a link to one) that may be
/// replaced (`overwrite`). A folder and a special file (a device such as `/dev/full`, a FIFO,
/// a socket; or a link to one) are refused even with `overwrite`: the atomic write would
/// replace the node itself, never write into it. `what` names the file in errors (`table`,
/// `PNG image`).
pub fn check_target(path: &Path, what: &str, overwrite: bool) -> Result<(), TableError> {
    let unwritable = |reason: String| TableError::Unwritable {
        path: path.to_path_buf(),
        what: what.to_string().into(),
        reason,
    };
    if path.file_name().is_none() {
        return Err(unwritable(
            "the path does not name a file; give a file name".to_string(),
        ));
    }
    let Ok(node) = fs::symlink_metadata(path) else {
        return Ok(()); // Nothing there (or nothing we may see: the write will say).
    };
    // A link counts as what it points to; a dangling link as a file to replace.
    let target = fs::metadata(path).unwrap_or_else(|_| node.clone());
    if target.is_dir() {
        return Err(unwritable(
            "it is a folder, not a file; give the path of a file, e.g. inside that folder"
                .to_string(),
        ));
    }
    if let Some(kind) = special_kind(&node.file_type()).or(special_kind(&target.file_type())) {
        return Err(unwritable(format!(
            "it is {kind}, not a regular file; write to a regular file (clothbake never \
             replaces a device, FIFO or socket)"
        )));
    }
    if !overwrite {
        return Err(TableError::AlreadyExists {
            path: path.to_path_buf(),
        });
    }
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
