//! CLI round trips: run the built binary and check what it prints and writes.
#![allow(clippy::unwrap_used)]

mod calibrate;
mod cli;
mod pipeline;
