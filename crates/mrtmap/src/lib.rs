//! # mrtmap (the command line)
//!
//! Argument structs (whose doc comments are the `--help`), one module per subcommand, settings
//! resolved from flags, printing. Everything below this crate returns data; only this crate prints.
#![allow(clippy::print_stdout, clippy::print_stderr)]

mod cli;
mod commands;
mod output;

use std::process::ExitCode;

use clap::Parser;

pub use cli::Cli;

/// Sets up logging to stderr (`RUST_LOG` overrides the default `warn`); says so on stderr when
/// it cannot.
pub fn logging() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn"));
    let set = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .try_init();
    if let Err(e) = set {
        eprintln!("warning: no log output: {e}");
    }
}

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
