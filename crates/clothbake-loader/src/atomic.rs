//! Atomic file writes: a file appears at its path complete or not at all, and the files of
//! one command appear together or not at all.
//!
//! [`write_atomic_as`] writes any file (tables, binary container files, PNG images, plots)
//! through a temporary file in the same folder; its errors name what is written. Between
//! [`Batch::begin`] and [`Batch::commit`] the writes of the calling thread are held as
//! finished temporary files and moved into place together (a render's PNG and EXR). Every
//! temporary file in flight is listed, so that a front end ending the process on a signal can
//! remove them first ([`abandon_temporaries`]); libraries install no signal handler.

use std::cell::RefCell;
use std::fs::{self, File};
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

use crate::error::TableError;

/// Distinguishes temporary files of concurrent writes from one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// The temporary files of this process in flight; held while files are moved into place.
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

fn forget_temporary(list: &mut Vec<PathBuf>, path: &Path) {
    if let Some(k) = list.iter().position(|p| p == path) {
        list.swap_remove(k);
    }
}

/// Batches committed by this process (see [`abandon_temporaries`]).
static COMMITTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Removes every temporary file this process is writing and keeps any other from being made
/// or moved into place: for a front end about to end the process on a signal (a second
/// Ctrl-C). Waits for a [`Batch::commit`] in progress to finish, so that a set of outputs is
/// left whole or absent, and returns whether a batch was committed (its outputs are in place,
/// whole). Call it only just before the process exits: writes of other threads block from
/// then on.
pub fn abandon_temporaries() -> bool {
    let mut list = temporaries();
    for p in list.drain(..) {
        let _ = fs::remove_file(p);
    }
    // Held until the process exits: no write registers or renames a file after this.
    std::mem::forget(list);
    COMMITTED.load(Ordering::SeqCst) > 0
}

/// Removes the temporary file when dropped, unless disarmed.
struct TempGuard {
    path: PathBuf,
    armed: bool,
}

impl TempGuard {
    /// Lists `path` as in flight and guards it (before the file is created, so that a signal
    /// in between finds it listed).
    fn new(path: PathBuf) -> TempGuard {
        temporaries().push(path.clone());
        TempGuard { path, armed: true }
    }
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        let mut list = temporaries();
        if self.armed {
            let _ = fs::remove_file(&self.path);
        }
        forget_temporary(&mut list, &self.path);
    }
}

/// A written, flushed temporary file waiting to be moved to `path`.
struct Staged {
    guard: TempGuard,
    path: PathBuf,
    what: String,
    overwrite: bool,
    owned: bool,
}

thread_local! {
    /// The files of this thread's open [`Batch`], if one is open.
    static BATCH: RefCell<Option<Vec<Staged>>> = const { RefCell::new(None) };
}

/// The outputs of one command, moved into place together: between [`Batch::begin`] and
/// [`Batch::commit`], each [`write_atomic_as`] of this thread writes and flushes its
/// temporary file and leaves it there; `commit` moves them all into place, and dropping the
/// batch uncommitted removes them (nothing written). A signal that ends the process through
/// [`abandon_temporaries`] leaves every output of the batch written or none.
#[must_use = "a batch writes nothing until it is committed"]
pub struct Batch {
    open: bool,
}

impl Batch {
    /// Opens a batch on this thread (one at a time: a second replaces nothing and is refused
    /// by a panic, a bug in the caller).
    pub fn begin() -> Batch {
        BATCH.with(|b| {
            let mut b = b.borrow_mut();
            assert!(
                b.is_none(),
                "a batch of writes is already open on this thread"
            );
            *b = Some(Vec::new());
        });
        Batch { open: true }
    }

    /// Moves every file written since [`Batch::begin`] into place, in the order written. On
    /// an error the files not yet moved are removed (the ones already in place stay: they are
    /// whole).
    pub fn commit(mut self) -> Result<(), TableError> {
        self.open = false;
        let staged = BATCH.with(|b| b.borrow_mut().take()).unwrap_or_default();
        commit(staged, true)
    }
}

impl Drop for Batch {
    fn drop(&mut self) {
        if self.open {
            // Uncommitted: the guards remove the temporary files.
            drop(BATCH.with(|b| b.borrow_mut().take()));
        }
    }
}

/// Moves staged files into place while holding the list of temporaries (so that
/// [`abandon_temporaries`] waits for the whole set).
fn commit(mut staged: Vec<Staged>, batch: bool) -> Result<(), TableError> {
    let mut result = Ok(());
    {
        let _list = temporaries();
        for s in &mut staged {
            result = place(s);
            if result.is_err() {
                break;
            }
        }
        if batch && result.is_ok() {
            COMMITTED.fetch_add(1, Ordering::SeqCst);
        }
    }
    // The guards (which take the list) are dropped once it is released: they remove the
    // temporary names left (hard-linked into place, or not placed after an error).
    let mut dirs: Vec<PathBuf> = Vec::new();
    for s in staged.drain(..) {
        let dir = folder(&s.path).to_path_buf();
        if !dirs.contains(&dir) {
            dirs.push(dir);
        }
    }
    if result.is_ok() {
        for d in dirs {
            sync_dir(&d);
        }
    }
    result
}

/// The folder a file `p` lies in (`.` for a bare name).
fn folder(p: &Path) -> &Path {
    match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Moves one staged file into place (rename with `overwrite`, else a hard link that fails if
/// the target appeared meanwhile) and disarms its guard.
fn place(s: &mut Staged) -> Result<(), TableError> {
    let (temp, path, what) = (s.guard.path.clone(), s.path.as_path(), s.what.as_str());
    let action = |verb: &str| format!("{verb} the {what}");
    let rename = |guard: &mut TempGuard| {
        fs::rename(&temp, path)
            .map_err(|e| TableError::io(path, action("move") + " into place", e))?;
        guard.armed = false;
        Ok::<(), TableError>(())
    };
    if s.overwrite {
        // Checked again just before the rename: a folder or special file that appeared
        // meanwhile is not replaced.
        check_target_as(path, what, true, s.owned)?;
        rename(&mut s.guard)
    } else {
        // A hard link fails if the target appeared meanwhile; the guard then removes the
        // temporary name, as it does after success.
        match fs::hard_link(&temp, path) {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => Err(TableError::AlreadyExists {
                path: path.to_path_buf(),
            }),
            // File systems without hard links: check, then rename (a small race).
            Err(_) => {
                if fs::symlink_metadata(path).is_ok() {
                    return Err(TableError::AlreadyExists {
                        path: path.to_path_buf(),
                    });
                }
                rename(&mut s.guard)
            }
        }
    }
}

/// Writes a file atomically: `path` ends up either complete or untouched. `what` names what
/// is written in error messages, e.g. `"table"`, `"PNG image"` or `"checkpoint"` (`cannot
/// write the PNG image: ...`).
///
/// Refuses an existing `path` unless `overwrite`, and a folder, a special file or a name a
/// bake owns ([`bake_owned`]) always ([`check_target`]). Otherwise calls `write` on a temporary file
/// `.<name>.tmp-<pid>-<n>` in the same folder, flushes and fsyncs it, and renames it over
/// `path` (without `overwrite`, it is hard-linked instead, so that a file created meanwhile is
/// never clobbered). The temporary file is removed on any error.
pub fn write_atomic_as(
    path: &Path,
    what: &str,
    overwrite: bool,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), TableError> {
    write_atomic_impl(path, what, overwrite, false, write)
}

/// [`write_atomic_as`] for a file a bake owns (its checkpoint, named by [`bake_owned`]).
pub(crate) fn write_owned_as(
    path: &Path,
    what: &str,
    overwrite: bool,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), TableError> {
    write_atomic_impl(path, what, overwrite, true, write)
}

fn write_atomic_impl(
    path: &Path,
    what: &str,
    overwrite: bool,
    owned: bool,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), TableError> {
    let action = |verb: &str| format!("{verb} the {what}");
    check_target_as(path, what, overwrite, owned)?;
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

    let mut guard = TempGuard::new(temp.clone());
    let file = match fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&temp)
    {
        Ok(f) => f,
        Err(e) => {
            guard.armed = false; // not ours to remove
            return Err(TableError::io(&temp, "create the temporary file", e));
        }
    };

    let mut writer = BufWriter::with_capacity(1 << 20, file);
    write(&mut writer).map_err(|e| TableError::io(path, action("write"), e))?;
    let file = writer
        .into_inner()
        .map_err(|e| TableError::io(path, action("write"), e.into_error()))?;
    file.sync_all()
        .map_err(|e| TableError::io(path, action("flush") + " to disk", e))?;
    drop(file);

    let staged = Staged {
        guard,
        path: path.to_path_buf(),
        what: what.to_string(),
        overwrite,
        owned,
    };
    // In an open batch the file waits for the batch's commit.
    let staged = BATCH.with(|b| match b.borrow_mut().as_mut() {
        Some(batch) => {
            batch.push(staged);
            None
        }
        None => Some(staged),
    });
    match staged {
        Some(s) => commit(vec![s], false),
        None => Ok(()),
    }
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
    check_target_as(path, what, overwrite, false)
}

/// What a bake owns under a name like `path`'s, in words: `<output>.lock` and
/// `<output>.checkpoint` (a running bake's lock and the rows it has saved) and the hidden
/// temporary and probe files of a write in progress (`.<name>.tmp-<pid>-<n>`,
/// `.<name>.probe-<pid>`); `None` for any other name. No command writes an output under such
/// a name, even when asked to overwrite: it could take another bake's lock or checkpoint.
pub fn bake_owned(path: &Path) -> Option<&'static str> {
    let name = path.file_name()?.to_string_lossy();
    if name.ends_with(".lock") {
        Some("the lock file of a bake (`<output>.lock`)")
    } else if name.ends_with(".checkpoint") {
        Some("the checkpoint of a bake (`<output>.checkpoint`)")
    } else if name.starts_with('.') && (name.contains(".tmp-") || name.contains(".probe-")) {
        Some("a temporary file of a write in progress")
    } else {
        None
    }
}

fn check_target_as(
    path: &Path,
    what: &str,
    overwrite: bool,
    owned: bool,
) -> Result<(), TableError> {
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
    if let Some(kind) = bake_owned(path).filter(|_| !owned) {
        return Err(unwritable(format!(
            "the name is {kind}, which no command writes as an output, even with \
             overwriting; give another output path"
        )));
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_batch_writes_its_files_together_or_not_at_all() {
        let dir = std::env::temp_dir().join(format!("clothbake-batch-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.png"), dir.join("b.exr"));
        let write = |p: &Path, bytes: &'static [u8]| {
            write_atomic_as(p, "file", false, |w| w.write_all(bytes)).unwrap()
        };
        // Dropped uncommitted: nothing is left, not even the temporary files.
        let batch = Batch::begin();
        write(&a, b"a");
        write(&b, b"b");
        assert_eq!(names(&dir).len(), 2, "two temporary files wait");
        assert!(!a.exists() && !b.exists());
        drop(batch);
        assert!(names(&dir).is_empty(), "{:?}", names(&dir));
        // Committed: both files, nothing else.
        let batch = Batch::begin();
        write(&a, b"a");
        write(&b, b"b");
        batch.commit().unwrap();
        assert_eq!(names(&dir), ["a.png", "b.exr"]);
        assert_eq!(fs::read(&b).unwrap(), b"b");
        // Outside a batch a write is in place at once.
        write(&dir.join("c"), b"c");
        assert_eq!(fs::read(dir.join("c")).unwrap(), b"c");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn names_a_bake_owns_are_refused_even_with_overwrite() {
        for name in [
            "t.exr.lock",
            "t.exr.checkpoint",
            ".t.exr.tmp-12-0",
            ".t.exr.probe-12",
        ] {
            let e = check_target(Path::new(name), "table", true).unwrap_err();
            assert!(e.to_string().contains("no command writes"), "{e}");
        }
        assert!(bake_owned(Path::new("lock.exr")).is_none());
        assert!(bake_owned(Path::new("t.checkpoint.exr")).is_none());
    }
}
