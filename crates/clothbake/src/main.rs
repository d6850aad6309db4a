//! `clothbake`: the command-line front end. `cli` parses (clap), `resolve` turns the parsed
//! flags into what the work needs (the fabric, the model's variant, the checked outputs, the
//! thread pool), and one `*_cmd` module per command does the work; `main` dispatches and
//! prints. Commands never import each other.
//!
//! Every failure is one line `clothbake: <cause>; <fix>` on stderr with exit status 2 (130 for
//! an interrupted command). `clothbake diff` exits 1 when the tables differ beyond its tolerance.

mod bake_cmd;
mod cli;
mod diff_cmd;
mod error;
mod eval_cmd;
mod export_cmd;
mod export_fitted;
mod fabrics;
mod help_cmd;
mod info_cmd;
mod merge_cmd;
mod render_cmd;
mod report;
mod resolve;
mod signals;
mod two_faced_cmd;

use clap::error::{ContextKind, ErrorKind};
use clap::FromArgMatches;
use cli::{Cli, Command};
use error::CliError;
use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        let e = CliError::new(
            format!("internal error{at}: {msg}"),
            "this is a bug in clothbake; please report it with the command line that caused it",
        );
        eprintln!("clothbake: {e}");
    }));
    match std::panic::catch_unwind(run) {
        Ok(Ok(code)) => ExitCode::from(code),
        Ok(Err(e)) => {
            eprintln!("clothbake: {}", printable(&e.to_string()));
            ExitCode::from(e.code())
        }
        Err(_) => ExitCode::from(2), // the panic hook has printed the message
    }
}

/// Runs the command line; returns the exit status of a successful run (0, or 1 for `diff`
/// beyond its tolerance).
fn run() -> Result<u8, CliError> {
    let parsed = cli::command()
        .try_get_matches()
        .and_then(|m| Cli::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => {
            let _ = e.print();
            return Ok(0);
        }
        Err(e) => return Err(parse_error(&e)),
    };
    let (out, code) = match cli.command {
        Some(Command::Eval(args)) if args.faces == cli::Faces::Two => {
            (two_faced_cmd::run(&args)?, 0)
        }
        Some(Command::Eval(args)) => (eval_cmd::run(&args)?, 0),
        Some(Command::Bake(args)) => (bake_cmd::run(&args.weave, &args.opts)?, 0),
        Some(Command::Info(args)) => (info_cmd::run(&args)?, 0),
        Some(Command::Diff(args)) => diff_cmd::run(&args)?,
        Some(Command::Export(args)) => (writes(|| export_cmd::run(&args))?, 0),
        Some(Command::Merge(args)) => (writes(|| merge_cmd::run(&args))?, 0),
        Some(Command::Render(args)) => (writes(|| render_cmd::run_render(&args))?, 0),
        Some(Command::Plot(args)) => (writes(|| render_cmd::run_plot(&args))?, 0),
        Some(Command::Fabrics) => (fabrics::list(), 0),
        Some(Command::Completions(args)) => (help_cmd::completions(args.shell), 0),
        Some(Command::Man(args)) => (help_cmd::man(args.command.as_deref())?, 0),
        None => match &cli.weave {
            Some(w) => (bake_cmd::run(w, &cli.bake)?, 0),
            None => return Err(help_cmd::no_command()),
        },
    };
    let out = printable(&out);
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(out.as_bytes())
        .and_then(|()| stdout.flush())
    {
        // The reader went away (e.g. `| head`): nothing left to tell anyone.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(code),
        r => r
            .map(|()| code)
            .map_err(|e| CliError::new(format!("cannot write the output: {e}"), "check stdout")),
    }
}

/// `text` with every control character but the line feed and the tab escaped (`\u{1b}`): what
/// a table or fabric made before control characters were refused carries (a name, a note)
/// cannot reach the terminal raw.
fn printable(text: &str) -> std::borrow::Cow<'_, str> {
    if !text
        .chars()
        .any(|c| c.is_control() && c != '\n' && c != '\t')
    {
        return text.into();
    }
    text.chars()
        .map(|c| {
            if c.is_control() && c != '\n' && c != '\t' {
                c.escape_unicode().to_string()
            } else {
                c.to_string()
            }
        })
        .collect::<String>()
        .into()
}

/// Runs a command that writes files other than a bake: a signal ends it at once, leaving no
/// temporary file and no partial set of outputs (`signals`); its outputs appear together when
/// it succeeds (`clothbake_loader::Batch`).
fn writes(command: impl FnOnce() -> Result<String, CliError>) -> Result<String, CliError> {
    signals::install(signals::OnSignal::Exit);
    let batch = clothbake_loader::Batch::begin();
    let out = command()?;
    batch.commit().map_err(|e| error::table_error(&e))?;
    Ok(out)
}

/// A command line clap rejected, as one line that points to the help of the command meant: a
/// subcommand's, the bake's (the default mode, `--weave` given) or the top level's. A fabric
/// given where a command goes gets the `--weave` spelling.
fn parse_error(e: &clap::Error) -> CliError {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let names = cli::subcommand_names();
    let first = args.iter().find(|a| !a.starts_with('-'));
    let sub = match first {
        Some(f) if names.contains(f) => format!("clothbake {f}"),
        _ if args
            .iter()
            .any(|a| a == "--weave" || a.starts_with("--weave=")) =>
        {
            "clothbake bake".into()
        }
        _ => "clothbake".into(),
    };
    if e.kind() == ErrorKind::InvalidSubcommand {
        if let Some(hint) = e
            .get(ContextKind::InvalidSubcommand)
            .and_then(|v| help_cmd::fabric_given_as_command(&v.to_string()))
        {
            return hint;
        }
    }
    error::from_clap(e, &sub)
}
