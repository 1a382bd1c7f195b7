//! # mrtmap (the command line)
//!
//! Argument structs (whose doc comments are the `--help`), one module per subcommand, settings
//! resolved from flags, printing. Everything below this crate returns data; only this crate prints.
#![allow(clippy::print_stdout, clippy::print_stderr)]

#[macro_use]
mod output;
mod cli;
mod commands;

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::Parser;

pub use cli::Cli;

/// Parses the command line and runs the subcommand.
pub fn run() -> anyhow::Result<()> {
    let cli = Cli::parse();
    commands::dispatch(cli)
}

/// Runs the command line `args` (the program's name first), as the `mrtmap` binary does, and
/// gives the exit code: what the Python wheel's `mrtmap` command calls.
pub fn main_with(args: Vec<std::ffi::OsString>) -> ExitCode {
    on_interrupt_say_what_is_left();
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    match commands::dispatch(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => report_error(&e),
    }
}

/// Prints an error as one line (with its causes) and gives the exit code.
pub fn report_error(e: &anyhow::Error) -> ExitCode {
    eprintln!("error: {e:#}");
    ExitCode::FAILURE
}

/// Set by a command that stops gracefully on a first Ctrl-C (`live`: the full run is still made).
pub(crate) static STOP_GRACEFULLY: AtomicBool = AtomicBool::new(false);

/// Set by the first Ctrl-C when [`STOP_GRACEFULLY`] is.
pub(crate) static STOP: AtomicBool = AtomicBool::new(false);

/// Ctrl-C: says what is left (outputs are written whole or not at all, and finished stages are
/// reused), then exits as a shell expects of an interrupted program (130). Under `live` the first
/// Ctrl-C asks it to stop following and make the full run; a second one exits at once.
pub fn on_interrupt_say_what_is_left() {
    let _ = ctrlc::set_handler(|| {
        if STOP_GRACEFULLY.load(Ordering::SeqCst) && !STOP.swap(true, Ordering::SeqCst) {
            eprintln!(
                "\nstopping: following ends and the full run is made; press Ctrl-C again to stop at once (every file already written stays complete)"
            );
            return;
        }
        eprintln!(
            "\ninterrupted: every file already written is complete (outputs are written whole or not at all); run the same command again and the stages that finished are reused"
        );
        std::process::exit(130);
    });
}
