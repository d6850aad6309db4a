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
/// Refuses an existing `path` unless `overwrite`. Otherwise calls `write` on a temporary file
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
    let name = path.file_name().ok_or_else(|| TableError::Unwritable {
        path: path.to_path_buf(),
        what: what.to_string().into(),
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
