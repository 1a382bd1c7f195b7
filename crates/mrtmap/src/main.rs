//! The `mrtmap` command line.

use std::process::ExitCode;

fn main() -> ExitCode {
    mrtmap::on_interrupt_say_what_is_left();
    match mrtmap::run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => mrtmap::report_error(&e),
    }
}
