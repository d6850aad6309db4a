//! Checkpoints of a running bake: the finished rows, saved atomically every so often.
//!
//! A [`Checkpointer`] collects the rows a sweep finishes ([`Checkpointer::record`], from the
//! worker threads) in the bake's one buffer ([`Assembly`]). When `interval` has passed since
//! the last save, the worker that finished a row writes every finished row, gathered from the
//! buffer one row at a time, to the checkpoint file (a [`crate::shard::Part`] of kind checkpoint, through
//! the loader's atomic write: the file is always a complete earlier checkpoint or a complete
//! new one). [`Checkpointer::save`] writes at once (Ctrl-C, SIGTERM). `--resume` reads it back
//! and bakes only the rows it lacks; as rows are pure functions of the inputs, the table is
//! bit-identical to an uninterrupted bake.

use crate::assembly::Assembly;
use crate::shard::{Kind, ShardId};
use crate::sweep::Row;
use clothbake_loader::{Metadata, TableError};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The default time between checkpoints: 60 s.
pub const DEFAULT_INTERVAL: Duration = Duration::from_secs(60);

/// Where the checkpoint of a bake writing `output` lives: next to it, `<output>.checkpoint`.
pub fn checkpoint_path(output: &Path) -> PathBuf {
    let mut name = output.file_name().unwrap_or_default().to_os_string();
    name.push(".checkpoint");
    output.with_file_name(name)
}

/// Collects finished rows in the bake's [`Assembly`] and saves them periodically.
pub struct Checkpointer {
    path: Option<PathBuf>,
    interval: Duration,
    shard: Option<ShardId>,
    meta: Metadata,
    done: Assembly,
    last: Mutex<Instant>,
    writing: Mutex<()>,
}

impl Checkpointer {
    /// A checkpointer writing to `path` every `interval` the rows done in `assembly` (those
    /// of a resumed checkpoint already in it, none for a fresh bake).
    pub fn new(
        path: PathBuf,
        interval: Duration,
        shard: Option<ShardId>,
        meta: Metadata,
        assembly: Assembly,
    ) -> Checkpointer {
        Checkpointer {
            path: Some(path),
            interval,
            shard,
            meta,
            done: assembly,
            last: Mutex::new(Instant::now()),
            writing: Mutex::new(()),
        }
    }

    /// A checkpointer that only collects the rows (a bake in memory): it writes nothing.
    pub fn in_memory(meta: Metadata, assembly: Assembly) -> Checkpointer {
        Checkpointer {
            path: None,
            interval: Duration::MAX,
            shard: None,
            meta,
            done: assembly,
            last: Mutex::new(Instant::now()),
            writing: Mutex::new(()),
        }
    }

    /// Stores a finished row; writes a checkpoint when one is due (and no other thread is
    /// writing one). Returns the write's error, if any; the bake can go on without it.
    pub fn record(&self, row: usize, values: Row) -> Result<(), TableError> {
        self.done.put(row, &values);
        drop(values);
        let due = {
            let mut last = self.last.lock().expect("no panic while held");
            if last.elapsed() >= self.interval {
                *last = Instant::now();
                true
            } else {
                false
            }
        };
        if !due {
            return Ok(());
        }
        match self.writing.try_lock() {
            Ok(_guard) => self.write().map(|_| ()),
            Err(_) => Ok(()),
        }
    }

    /// Writes a checkpoint now, if any row is finished; returns the number of rows saved (0
    /// when in memory).
    pub fn save(&self) -> Result<usize, TableError> {
        let _guard = self.writing.lock().expect("no panic while held");
        self.write()
    }

    fn write(&self) -> Result<usize, TableError> {
        let Some(path) = &self.path else {
            return Ok(0);
        };
        if self.done.done_rows().is_empty() {
            return Ok(0);
        }
        // The rows done when it starts; rows finished meanwhile wait for the next one.
        self.done
            .write_part(path, Kind::Checkpoint, self.shard, &self.meta, true)
    }

    /// The rows done (the bake's values).
    pub fn into_assembly(self) -> Assembly {
        self.done
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_is_next_to_the_output() {
        assert_eq!(
            checkpoint_path(Path::new("out/twill.exr")),
            Path::new("out/twill.exr.checkpoint")
        );
        assert_eq!(
            checkpoint_path(Path::new("t.bin")),
            Path::new("t.bin.checkpoint")
        );
    }
}
