//! Writing a baked table through the loader's atomic writers (EXR bytes are reproducible:
//! the loader sorts the header attributes).

use clothbake_loader::{write_binary, write_exr, Precision, Table, TableError};
use std::path::Path;

/// Refuses an output that would fail only after the work: an existing file unless
/// `overwrite`, a missing folder, a folder that is not one or that may not be written into
/// (probed by creating and removing a hidden file next to `out`). `what` names the file in
/// errors (`table`, `shard`, `PNG image`).
pub fn preflight(out: &Path, what: &str, overwrite: bool) -> Result<(), TableError> {
    if !overwrite && std::fs::symlink_metadata(out).is_ok() {
        return Err(TableError::AlreadyExists {
            path: out.to_path_buf(),
        });
    }
    let dir = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
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
        let g = Grid {
            n_theta_i: 2,
            n_phi_i: 3,
            n_theta_o: 2,
            n_phi_o: 4,
        };
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
