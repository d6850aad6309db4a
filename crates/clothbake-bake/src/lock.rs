//! The lock of a bake's output: one bake at a time writes an output and its checkpoint.
//!
//! Two bakes to one output would share `<output>.checkpoint`, overwrite each other's rows and
//! leave a checkpoint behind. [`OutputLock::take`] takes an advisory lock (`flock`, exclusive,
//! without waiting) on `<output>.lock` ([`lock_path`]) and writes the holder's process id into
//! it; a second bake is refused with that id ([`LockError::Held`]). The operating system
//! releases the lock when its holder ends, however it ends (a killed bake leaves the file, but
//! not the lock: the next bake takes it). Dropping the lock removes the file. Where `flock` is
//! not available (not Unix, or a file system without locks) bakes go on unlocked.

use std::fs::File;
use std::path::{Path, PathBuf};

/// Where the lock of a bake writing `output` lives: next to it, `<output>.lock`.
pub fn lock_path(output: &Path) -> PathBuf {
    let mut name = output.file_name().unwrap_or_default().to_os_string();
    name.push(".lock");
    output.with_file_name(name)
}

/// Why the lock was not taken.
#[derive(Debug)]
pub enum LockError {
    /// Another process holds it.
    Held {
        /// The output.
        output: PathBuf,
        /// The lock file.
        lock: PathBuf,
        /// The holder's process id, as it wrote it (`None`: not written yet, or unreadable).
        pid: Option<u32>,
    },
    /// The lock file is not a regular file (a folder, a FIFO, ...).
    NotAFile {
        /// The lock file.
        lock: PathBuf,
    },
    /// The lock file cannot be created or locked here; the bake may go on unlocked.
    Unavailable {
        /// The lock file.
        lock: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

impl std::fmt::Display for LockError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LockError::Held { output, lock, pid } => write!(
                f,
                "{}: another bake ({}) is writing it and holds {}; wait for it to end, or \
                 write to another output path",
                output.display(),
                pid.map_or("another process".to_string(), |p| format!("process {p}")),
                lock.display()
            ),
            LockError::NotAFile { lock } => write!(
                f,
                "{}: the lock file of this output is not a regular file; remove it, or write \
                 to another output path",
                lock.display()
            ),
            LockError::Unavailable { lock, source } => {
                write!(f, "{}: cannot lock: {source}", lock.display())
            }
        }
    }
}

impl std::error::Error for LockError {}

/// A held lock; released (and its file removed) when dropped.
#[derive(Debug)]
pub struct OutputLock {
    path: PathBuf,
    file: Option<File>,
}

impl OutputLock {
    /// Takes the lock of a bake writing `output`, without waiting.
    pub fn take(output: &Path) -> Result<OutputLock, LockError> {
        let path = lock_path(output);
        imp::take(&path).map(|file| OutputLock {
            path,
            file: Some(file),
        })
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        // Removed while still held, so that no other bake can lock the removed file's inode
        // and believe it holds the lock of the new one (`take` checks the inode too).
        let _ = std::fs::remove_file(&self.path);
        drop(self.file.take());
    }
}

#[cfg(unix)]
mod imp {
    use super::LockError;
    use std::fs::{File, OpenOptions};
    use std::io::{Read, Seek, Write};
    use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
    use std::os::unix::io::AsRawFd;
    use std::path::Path;

    pub(super) fn take(path: &Path) -> Result<File, LockError> {
        let unavailable = |source| LockError::Unavailable {
            lock: path.to_path_buf(),
            source,
        };
        // A few tries: the holder may remove the file between our open and our lock.
        for _ in 0..16 {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .mode(0o644)
                // Never block on a FIFO or follow a link to a device.
                .custom_flags(libc::O_NONBLOCK | libc::O_NOFOLLOW | libc::O_CLOEXEC)
                .open(path)
                .map_err(|e| match e.raw_os_error() {
                    Some(libc::ELOOP) | Some(libc::EISDIR) | Some(libc::ENXIO) => {
                        LockError::NotAFile {
                            lock: path.to_path_buf(),
                        }
                    }
                    _ => unavailable(e),
                })?;
            let meta = file.metadata().map_err(unavailable)?;
            if !meta.is_file() {
                return Err(LockError::NotAFile {
                    lock: path.to_path_buf(),
                });
            }
            // SAFETY: flock on a descriptor this function owns; no memory is passed.
            if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
                let e = std::io::Error::last_os_error();
                if e.kind() == std::io::ErrorKind::WouldBlock {
                    let mut text = String::new();
                    let _ = file.read_to_string(&mut text);
                    return Err(LockError::Held {
                        output: output_of(path),
                        lock: path.to_path_buf(),
                        pid: text.trim().parse().ok(),
                    });
                }
                return Err(unavailable(e));
            }
            // Locked; but is it still the file at `path`?
            match std::fs::symlink_metadata(path) {
                Ok(now) if now.dev() == meta.dev() && now.ino() == meta.ino() => {}
                _ => continue,
            }
            // The process id only informs a second bake; the lock holds without it.
            let _ = file
                .set_len(0)
                .and_then(|()| file.rewind())
                .and_then(|()| writeln!(file, "{}", std::process::id()));
            return Ok(file);
        }
        Err(unavailable(std::io::Error::other(
            "the lock file kept changing under this process",
        )))
    }

    /// The output of lock file `path` (`<output>.lock`).
    fn output_of(path: &Path) -> std::path::PathBuf {
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        path.with_file_name(name.strip_suffix(".lock").unwrap_or(&name))
    }
}

#[cfg(not(unix))]
mod imp {
    use super::LockError;
    use std::fs::File;
    use std::path::Path;

    pub(super) fn take(path: &Path) -> Result<File, LockError> {
        Err(LockError::Unavailable {
            lock: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::Unsupported,
                "advisory locks are implemented on Unix only",
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("clothbake-lock-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn path_is_next_to_the_output() {
        assert_eq!(
            lock_path(Path::new("out/twill.exr")),
            Path::new("out/twill.exr.lock")
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_second_lock_is_refused_with_the_holder_and_released_on_drop() {
        let d = dir("twice");
        let out = d.join("t.exr");
        let first = OutputLock::take(&out).unwrap();
        assert_eq!(
            std::fs::read_to_string(first.path()).unwrap().trim(),
            std::process::id().to_string()
        );
        // flock locks belong to open files: a second open in this process conflicts too.
        match OutputLock::take(&out) {
            Err(LockError::Held { pid, output, .. }) => {
                assert_eq!(pid, Some(std::process::id()));
                assert_eq!(output, out);
            }
            other => panic!("{other:?}"),
        }
        drop(first);
        assert!(!lock_path(&out).exists());
        let again = OutputLock::take(&out).unwrap();
        drop(again);
        // A stale file (its holder gone) does not block.
        std::fs::write(lock_path(&out), "999999\n").unwrap();
        let stale = OutputLock::take(&out).unwrap();
        drop(stale);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_lock_file_that_is_not_a_file_is_refused() {
        let d = dir("folder");
        let out = d.join("t.exr");
        std::fs::create_dir(lock_path(&out)).unwrap();
        assert!(matches!(
            OutputLock::take(&out),
            Err(LockError::NotAFile { .. })
        ));
        std::fs::remove_dir_all(&d).unwrap();
    }
}
