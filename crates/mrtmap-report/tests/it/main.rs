//! Report tests: globe validation, the 3D view.
#![allow(clippy::unwrap_used)]

mod validate;
mod view3d;
