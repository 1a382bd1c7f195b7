//! Physics tests: every published vector of `shared/reference/physics.md`, plus properties.
#![allow(clippy::unwrap_used)]

mod comfort;
mod globe;
mod mrt;
mod person;
mod solar;
mod units;
