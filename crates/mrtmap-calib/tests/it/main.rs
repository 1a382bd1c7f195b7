//! mrtmap-calib integration tests: synthetic rigs, real thermal boards, pairing.
#![allow(clippy::unwrap_used)]

mod pairs;
mod real;
mod synthetic;
