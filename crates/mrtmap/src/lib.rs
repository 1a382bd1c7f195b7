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

use clap::Parser;

pub use cli::Cli;

/// Parses the command line and runs the subcommand.
pub fn run() -> anyhow::Result<()> {
    let cli = Cli::parse();
    commands::dispatch(cli)
}

/// Prints an error as one line (with its causes) and gives the exit code.
pub fn report_error(e: &anyhow::Error) -> ExitCode {
    eprintln!("error: {e:#}");
    ExitCode::FAILURE
}
