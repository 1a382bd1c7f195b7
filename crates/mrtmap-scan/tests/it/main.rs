//! Fusion tests on small simulated scans, against the simulator's exact truth.
#![allow(clippy::unwrap_used)]

mod common;
mod field;
mod fusion;
mod parts;
mod segment;
