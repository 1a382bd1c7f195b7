//! I/O tests: every error names its file and line; round trips are exact.
#![allow(clippy::unwrap_used, clippy::print_stdout)]

mod formats;
mod recording;
mod thermal_files;
