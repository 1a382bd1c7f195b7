//! Geometry tests: analytic solid angles, polygon predicates, direction sets, ray casting.
#![allow(clippy::unwrap_used)]

mod camera;
mod polygon;
mod ray;
mod sampling;
mod solid_angle;
