//! The one error type of the binary: a single line naming the cause and the fix.
//!
//! `main` prints it as `clothbake: <message>` on stderr and exits with its status: 2 for every
//! failure, 130 for an interrupted bake.

use std::fmt;

/// A user-facing failure. The message is always a single line (newlines are folded).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CliError {
    message: String,
    code: u8,
}

impl CliError {
    /// `problem; fix` as one line.
    pub fn new(problem: impl AsRef<str>, fix: impl AsRef<str>) -> Self {
        Self::line(format!("{}; {}", problem.as_ref(), fix.as_ref()))
    }

    /// A message that already names its cause and fix (e.g. a `FabricError`).
    pub fn line(message: impl Into<String>) -> Self {
        let message: String = message.into();
        let message = message.split_whitespace().collect::<Vec<_>>().join(" ");
        CliError { message, code: 2 }
    }

    /// The same message with another exit status.
    pub fn with_code(mut self, code: u8) -> Self {
        self.code = code;
        self
    }

    /// The exit status (2 unless set otherwise).
    pub fn code(&self) -> u8 {
        self.code
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for CliError {}

impl From<clothbake_core::FabricError> for CliError {
    fn from(e: clothbake_core::FabricError) -> Self {
        CliError::line(e.to_string())
    }
}

impl From<clothbake_core::VariantError> for CliError {
    fn from(e: clothbake_core::VariantError) -> Self {
        CliError::new(e.to_string(), e.fix())
    }
}

impl From<clothbake_bake::two_faced::TwoFacedError> for CliError {
    fn from(e: clothbake_bake::two_faced::TwoFacedError) -> Self {
        use clothbake_bake::two_faced::TwoFacedError;
        match e {
            TwoFacedError::Back(e) => e.into(),
            TwoFacedError::Variant(e) => e.into(),
        }
    }
}

impl From<clothbake_loader::TableError> for CliError {
    fn from(e: clothbake_loader::TableError) -> Self {
        table_error(&e)
    }
}

/// A table error as one line. The loader's messages name the file, the cause and the fix,
/// except for operating-system errors, which get a fix chosen by their cause here.
pub fn table_error(e: &clothbake_loader::TableError) -> CliError {
    use clothbake_loader::TableError;
    match e {
        TableError::Io {
            path,
            action,
            source,
        } => {
            // Files are opened only to be read (writes create a temporary file); a folder is
            // opened to be written into.
            let reading = action.contains("read")
                || (action.starts_with("open the ") && !action.ends_with("folder"));
            CliError::new(
                format!("{}: cannot {action}: {}", path.display(), os_cause(source)),
                io_fix(source, reading, written(action)),
            )
        }
        TableError::AlreadyExists { path } => CliError::new(
            format!("{}: the file already exists", path.display()),
            "use --force to overwrite it",
        ),
        other => CliError::line(other.to_string()),
    }
}

/// The cause of an I/O error in words (the OS message without its error number).
fn os_cause(e: &std::io::Error) -> String {
    let s = e.to_string();
    match s.find(" (os error") {
        Some(i) => s[..i].to_string(),
        None => s,
    }
}

/// What an action writes, from its words: `write the PNG image` -> `PNG image`, `move the
/// table into place` -> `table`, `create the temporary file` -> `file`.
fn written(action: &str) -> &str {
    let what = action.split_once(" the ").map_or("file", |(_, w)| w);
    let what = what
        .strip_suffix(" to disk")
        .or_else(|| what.strip_suffix(" into place"))
        .unwrap_or(what);
    match what {
        "temporary file" | "" => "file",
        w => w,
    }
}

/// What to do about an I/O error while reading or writing a file (`what`: `table`, `PNG
/// image`, ...).
fn io_fix(e: &std::io::Error, reading: bool, what: &str) -> String {
    use std::io::ErrorKind;
    // ENOSPC, EDQUOT (Linux 122, macOS 69), EROFS: the numbers of Linux and macOS.
    let raw = e.raw_os_error();
    if reading {
        return match e.kind() {
            ErrorKind::NotFound => "check the path".into(),
            ErrorKind::PermissionDenied => "check the file's permissions".into(),
            _ => "check the path and the file".into(),
        };
    }
    let nothing = "nothing was written";
    if raw == Some(28) || (cfg!(target_os = "linux") && raw == Some(122)) {
        format!("the disk is full: free some space or write the {what} elsewhere with -o PATH ({nothing})")
    } else if raw == Some(30) {
        format!("the file system is read-only: write the {what} elsewhere with -o PATH ({nothing})")
    } else if e.kind() == ErrorKind::PermissionDenied {
        format!(
            "you may not write there: write the {what} into a folder you own with -o PATH, or \
             change the folder's permissions ({nothing})"
        )
    } else {
        format!("check the output path and the disk ({nothing})")
    }
}

/// Folds a clap error (help text, usage, tips over several lines) into one line.
///
/// Paragraphs are joined with `; `, the `Usage:` and `For more information` paragraphs are
/// replaced by a pointer to `--help` for `command` (e.g. `clothbake eval`), except after a
/// rejected value, whose message (from the parsers in `cli`) already names the fix.
pub fn from_clap(err: &clap::Error, command: &str) -> CliError {
    let text = err.to_string();
    let mut parts: Vec<String> = Vec::new();
    for para in text.split("\n\n") {
        let para = para.trim();
        if para.is_empty() || para.starts_with("Usage:") || para.starts_with("For more information")
        {
            continue;
        }
        let mut lines = para.lines().map(str::trim).filter(|l| !l.is_empty());
        let Some(first) = lines.next() else { continue };
        let first = first.strip_prefix("error:").unwrap_or(first).trim();
        let rest: Vec<&str> = lines.collect();
        parts.push(if rest.is_empty() {
            first.to_string()
        } else {
            format!("{first} {}", rest.join(", "))
        });
    }
    if parts.is_empty() {
        parts.push("invalid command line".into());
    }
    if err.kind() == clap::error::ErrorKind::ValueValidation {
        // Our value parsers' messages already end with the fix.
        return CliError::line(parts.join("; "));
    }
    CliError::new(
        parts.join("; "),
        format!("run `{command} --help` for the usage"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixes_name_what_is_written() {
        assert_eq!(written("write the PNG image"), "PNG image");
        assert_eq!(written("flush the table to disk"), "table");
        assert_eq!(
            written("move the OpenEXR image into place"),
            "OpenEXR image"
        );
        assert_eq!(written("create the temporary file"), "file");
        let full = std::io::Error::from_raw_os_error(28);
        let fix = io_fix(&full, false, written("write the PNG image"));
        assert!(fix.contains("write the PNG image elsewhere"), "{fix}");
    }

    #[test]
    fn a_file_that_cannot_be_opened_is_a_reading_error() {
        let denied = || std::io::Error::from(std::io::ErrorKind::PermissionDenied);
        let e = table_error(&clothbake_loader::TableError::Io {
            path: "t.exr.checkpoint".into(),
            action: "open the checkpoint".into(),
            source: denied(),
        });
        assert!(
            e.to_string().contains("check the file's permissions"),
            "{e}"
        );
        let e = table_error(&clothbake_loader::TableError::Io {
            path: "out".into(),
            action: "open the folder".into(),
            source: denied(),
        });
        assert!(e.to_string().contains("you may not write there"), "{e}");
    }

    #[test]
    fn new_is_one_line() {
        let e = CliError::new("bad\nthing", "fix it");
        assert_eq!(e.to_string(), "bad thing; fix it");
    }
}
