//! I/O tests: every error names its file and line; round trips are exact.
#![allow(clippy::unwrap_used)]

mod formats;
mod recording;
