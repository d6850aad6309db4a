//! The one error type of the binary: a single line naming the cause and the fix.
//!
//! `main` prints it as `clothbake: <message>` on stderr and exits with status 2.

use std::fmt;

/// A user-facing failure. The message is always a single line (newlines are folded).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CliError {
    message: String,
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
        CliError { message }
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
    fn new_is_one_line() {
        let e = CliError::new("bad\nthing", "fix it");
        assert_eq!(e.to_string(), "bad thing; fix it");
    }
}
