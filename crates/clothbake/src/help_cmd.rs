//! Help beyond clap's own: `clothbake completions SHELL`, `clothbake man [COMMAND]`, and the
//! one-line answers to `clothbake` alone and to a fabric file given where a command goes.

use crate::cli::{self, Cli};
use crate::error::CliError;
use clap::CommandFactory;
use std::path::Path;

/// The completion script for `shell`, completing every option (the default mode's bake options
/// included).
pub fn completions(shell: clap_complete::Shell) -> String {
    let mut cmd = Cli::command();
    let mut buf = Vec::new();
    clap_complete::generate(shell, &mut cmd, "clothbake", &mut buf);
    String::from_utf8_lossy(&buf).into_owned()
}

/// The man page (roff) of `clothbake`, or of one subcommand (`clothbake-bake(1)`).
pub fn man(subcommand: Option<&str>) -> Result<String, CliError> {
    let top = cli::command();
    let page = match subcommand {
        None => top,
        Some(name) => top
            .find_subcommand(name)
            .cloned()
            .ok_or_else(|| {
                CliError::new(
                    format!("`{name}` is not a clothbake command"),
                    format!("give one of {}", cli::subcommand_names().join(", ")),
                )
            })?
            .display_name(format!("clothbake-{name}"))
            .bin_name(format!("clothbake {name}")),
    };
    let mut buf = Vec::new();
    clap_mangen::Man::new(page)
        .source(format!("clothbake {}", env!("CARGO_PKG_VERSION")))
        .render(&mut buf)
        .map_err(|e| CliError::new(format!("cannot write the man page: {e}"), "check stdout"))?;
    Ok(String::from_utf8_lossy(&buf).into_owned())
}

/// `clothbake` alone: how to bake, and every command.
pub fn no_command() -> CliError {
    CliError::new(
        "no command given",
        format!(
            "bake a table with `clothbake --weave FILE` (a fabric file, or a shipped fabric's \
             name: `clothbake --weave twill`), or give a command: {} (`clothbake help COMMAND` \
             explains one)",
            cli::subcommand_names().join(", ")
        ),
    )
}

/// The answer to `clothbake ARG` where ARG is not a command but looks like a fabric (a `.json`
/// or `.wif` name, an existing file or a shipped fabric's name): bake it with `--weave`.
pub fn fabric_given_as_command(arg: &str) -> Option<CliError> {
    let p = Path::new(arg);
    let looks_like_fabric = p.is_file()
        || crate::fabrics::find(arg).is_some()
        || p.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json") || e.eq_ignore_ascii_case("wif"));
    looks_like_fabric.then(|| {
        CliError::new(
            format!("`{arg}` is not a command"),
            format!(
                "to bake this fabric give it with --weave: `clothbake --weave {arg}`; the \
                 commands are {}",
                cli::subcommand_names().join(", ")
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    // That `no_command` names every subcommand on one line is checked through the binary,
    // against the user's list of commands, in tests/first_hour.rs
    // (`slips_get_one_line_with_the_way_out`).

    #[test]
    fn fabric_names_get_a_weave_hint() {
        for arg in ["tables/twill.json", "my.wif", "twill", "denim"] {
            let e = fabric_given_as_command(arg).unwrap().to_string();
            assert!(e.contains(&format!("clothbake --weave {arg}")), "{e}");
        }
        assert!(fabric_given_as_command("frobnicate").is_none());
    }

    #[test]
    fn unknown_man_page() {
        let e = man(Some("frobnicate")).unwrap_err().to_string();
        assert!(e.contains("frobnicate") && e.contains("bake, eval"), "{e}");
    }
}
