//! Radiation tests: scene validation, exact and Monte Carlo view factors, occlusion, MRT fields;
//! the top-level modules (this crate's and mrtmap-scan's) form no cycle.
#![allow(clippy::unwrap_used)]

mod common;
mod engines;
mod field;
mod modules;
mod person;
mod raster;
mod scene;
