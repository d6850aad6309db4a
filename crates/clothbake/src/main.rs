//! `clothbake`: the command-line front end of clothbake-core.
//!
//! Every failure is one line `clothbake: <cause>; <fix>` on stderr with exit status 2.

mod cli;
mod error;
mod eval_cmd;
mod report;

use clap::error::ErrorKind;
use clap::Parser;
use cli::{BakeArgs, Cli, Command};
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
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(e)) => {
            eprintln!("clothbake: {e}");
            ExitCode::from(2)
        }
        Err(_) => ExitCode::from(2), // the panic hook has printed the message
    }
}

fn run() -> Result<(), CliError> {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => {
            let _ = e.print();
            return Ok(());
        }
        Err(e) => {
            let sub = if std::env::args()
                .skip(1)
                .find(|a| !a.starts_with('-'))
                .as_deref()
                == Some("eval")
            {
                "clothbake eval"
            } else {
                "clothbake"
            };
            return Err(error::from_clap(&e, sub));
        }
    };
    let out = match cli.command {
        Some(Command::Eval(args)) => eval_cmd::run(&args)?,
        None => return Err(default_mode(&cli.bake)),
    };
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(out.as_bytes())
        .and_then(|()| stdout.flush())
    {
        // The reader went away (e.g. `| head`): nothing left to tell anyone.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => r.map_err(|e| CliError::new(format!("cannot write the output: {e}"), "check stdout")),
    }
}

/// The default mode, `clothbake --weave FILE`, will bake a table; not yet available.
fn default_mode(bake: &BakeArgs) -> CliError {
    match &bake.weave {
        Some(w) => CliError::new(
            format!(
                "baking a BRDF table (`clothbake --weave {}`) is not yet available",
                w.display()
            ),
            format!(
                "evaluate single directions with `clothbake eval --weave {} --wi THETA,PHI --wo THETA,PHI`",
                w.display()
            ),
        ),
        None => CliError::new(
            "no command given",
            "evaluate a fabric with `clothbake eval --weave FILE --wi THETA,PHI --wo THETA,PHI` \
             (see `clothbake --help`)",
        ),
    }
}
