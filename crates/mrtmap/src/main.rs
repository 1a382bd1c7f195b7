//! The `mrtmap` command line.

use std::process::ExitCode;

fn main() -> ExitCode {
    match mrtmap::run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => mrtmap::report_error(&e),
    }
}
