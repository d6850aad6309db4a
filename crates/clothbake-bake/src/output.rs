//! Writing a baked table through the loader's atomic writers (EXR bytes are reproducible:
//! the loader sorts the header attributes), after the one output check of every command that
//! writes ([`preflight`]).

use clothbake_loader::{check_target, write_binary, write_exr, Precision, Table, TableError};
use std::path::{Path, PathBuf};

/// Refuses outputs that would fail, or do harm, only after the work; every command that writes
/// files (bake, merge, export, render, plot, Python's `bake`) calls it before any work, with
/// every file it will write (`(path, what)`, `what` naming the file in errors: `table`,
/// `shard`, `PNG image`) and every file it reads (`inputs`). Refused, in this order:
///
/// * an output that is one of the inputs (the same file by device and inode, or by canonical
///   path: a link or a hard link to an input counts), even with `overwrite`;
/// * two outputs that are the same file;
/// * a folder or a special file (device, FIFO, socket), even with `overwrite`, and an existing
///   file unless `overwrite` ([`check_target`]);
/// * a missing folder, a folder that is not one, or one that may not be written into (probed
///   by creating and removing a hidden file next to the output).
pub fn preflight(
    outputs: &[(&Path, &str)],
    overwrite: bool,
    inputs: &[&Path],
) -> Result<(), TableError> {
    for (k, &(out, what)) in outputs.iter().enumerate() {
        let unwritable = |reason: String| TableError::Unwritable {
            path: out.to_path_buf(),
            what: what.to_string().into(),
            reason,
        };
        if let Some(input) = inputs.iter().find(|i| same_file(out, i)) {
            return Err(unwritable(format!(
                "it is an input of this command{}, which would be replaced; give another output \
                 path",
                if **input == *out {
                    String::new()
                } else {
                    format!(" ({})", input.display())
                }
            )));
        }
        if let Some((_, other)) = outputs[..k].iter().find(|(o, _)| same_file(out, o)) {
            return Err(unwritable(format!(
                "the {other} is written to the same file; give each output its own path"
            )));
        }
        check_target(out, what, overwrite)?;
        check_folder(out, what)?;
    }
    Ok(())
}

/// The folder of `out` exists, is a folder and may be written into.
fn check_folder(out: &Path, what: &str) -> Result<(), TableError> {
    let dir = folder(out);
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(TableError::Unwritable {
                path: out.to_path_buf(),
                what: what.to_string().into(),
                reason: format!(
                    "{} is not a folder; give an output path inside a folder",
                    dir.display()
                ),
            })
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(TableError::NoSuchFolder {
                dir: dir.to_path_buf(),
                path: out.to_path_buf(),
            })
        }
        Err(e) => {
            return Err(TableError::Io {
                path: dir.to_path_buf(),
                action: "open the folder".into(),
                source: e,
            })
        }
    }
    // Probe: can we create a file there? (The output itself goes through a temporary file too.)
    let mut name = std::ffi::OsString::from(".");
    name.push(out.file_name().unwrap_or_default());
    name.push(format!(".probe-{}", std::process::id()));
    let probe = dir.join(name);
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(f) => {
            drop(f);
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(TableError::Io {
            path: out.to_path_buf(),
            action: format!("create the {what}").into(),
            source: e,
        }),
    }
}

/// The folder a file `p` lies in (`.` for a bare name).
fn folder(p: &Path) -> &Path {
    match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Whether `a` and `b` name the same file: the same device and inode where both exist (a link
/// or a hard link counts), else the same canonical folder and file name.
pub fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        return same_inode(a, &x, b, &y);
    }
    match (identity(a), identity(b)) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

#[cfg(unix)]
fn same_inode(_: &Path, x: &std::fs::Metadata, _: &Path, y: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    x.dev() == y.dev() && x.ino() == y.ino()
}

#[cfg(not(unix))]
fn same_inode(a: &Path, _: &std::fs::Metadata, b: &Path, _: &std::fs::Metadata) -> bool {
    matches!(
        (std::fs::canonicalize(a), std::fs::canonicalize(b)),
        (Ok(x), Ok(y)) if x == y
    )
}

/// The canonical folder of `p` joined with its file name (`p` itself need not exist).
fn identity(p: &Path) -> Option<PathBuf> {
    let name = p.file_name()?;
    Some(std::fs::canonicalize(folder(p)).ok()?.join(name))
}

/// The table formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// OpenEXR with half or float samples.
    Exr(Precision),
    /// The checksummed binary file.
    Binary,
}

/// Writes `table` to `path` atomically (refusing an existing file unless `overwrite`).
pub fn write_table(
    path: &Path,
    table: &Table,
    format: Format,
    overwrite: bool,
) -> Result<(), TableError> {
    match format {
        Format::Binary => write_binary(path, table, overwrite),
        Format::Exr(precision) => write_exr(path, table, precision, overwrite),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_loader::{read_table, Grid, Metadata};

    fn table() -> Table {
        let g = Grid::new(2, 3, 2, 4);
        let values = (0..3 * g.len()).map(|k| 0.01 * k as f32).collect();
        Table::new(
            Metadata::new("clothbake test", g, "{}", "{}", "none"),
            values,
        )
        .unwrap()
    }

    #[test]
    fn exr_bytes_are_reproducible_and_readable() {
        let dir = std::env::temp_dir().join(format!("clothbake-output-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let t = table();
        let mut files = Vec::new();
        for k in 0..4 {
            let p = dir.join(format!("t{k}.exr"));
            write_table(&p, &t, Format::Exr(Precision::F32), true).unwrap();
            assert_eq!(read_table(&p).unwrap(), t);
            files.push(std::fs::read(&p).unwrap());
        }
        assert!(files.iter().all(|f| *f == files[0]));
        // No temporary file is left behind.
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["t0.exr", "t1.exr", "t2.exr", "t3.exr"]);
        // Refuses to overwrite.
        let e = write_table(&dir.join("t0.exr"), &t, Format::Exr(Precision::F16), false);
        assert!(matches!(e, Err(TableError::AlreadyExists { .. })));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
