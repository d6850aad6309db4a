//! Ctrl-C, SIGTERM and SIGHUP for every command that writes files.
//!
//! A bake stops cooperatively: the first signal raises [`CANCEL`], the bake saves its
//! checkpoint and exits 130 (a signal that comes while the table is written lets the write
//! finish). Every other writing command (merge, export, render, plot) ends at once: the
//! temporary files in flight are removed (waiting for a set of outputs being moved into place
//! to be whole, `clothbake_loader::Batch`) and the process exits 130, so that no `.tmp-PID`
//! file and no half-written or unpaired output is left. A second signal ends a bake the same
//! way. Commands that write nothing keep the default action.

use std::sync::atomic::{AtomicBool, Ordering};

/// Raised by the first signal of a bake.
pub static CANCEL: AtomicBool = AtomicBool::new(false);

/// The exit status of an interrupted command (128 + SIGINT, as shells report it).
pub const INTERRUPTED: u8 = 130;

/// How the first signal is answered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnSignal {
    /// Raise [`CANCEL`]; a second signal ends the process (a bake).
    Cancel,
    /// End the process, removing the temporary files in flight.
    Exit,
}

/// Ends the process after removing every temporary file in flight (nothing half-written is
/// left; a set of outputs being moved into place is finished first).
fn exit_now() -> ! {
    if clothbake_loader::abandon_temporaries() {
        // The signal came as the outputs were moved into place: they are whole.
        eprintln!("clothbake: interrupted; the outputs were written whole before it");
    } else {
        eprintln!("clothbake: interrupted; nothing was written");
    }
    std::process::exit(i32::from(INTERRUPTED));
}

/// Installs the handler of SIGINT, SIGTERM and SIGHUP (once per process). If a handler cannot
/// be installed, the signals keep their default action.
pub fn install(on: OnSignal) {
    let _ = ctrlc::set_handler(move || {
        if on == OnSignal::Exit || CANCEL.swap(true, Ordering::SeqCst) {
            exit_now();
        }
    });
}
