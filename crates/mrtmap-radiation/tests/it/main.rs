//! Radiation tests: scene validation, exact and Monte Carlo view factors, occlusion, MRT fields.
#![allow(clippy::unwrap_used)]

mod common;
mod engines;
mod field;
mod person;
mod raster;
mod scene;
