//! Simulator tests: geometry and radiometry of noise-free frames against the room, the recording
//! read back through the shared layout reader, rooms and truth.
#![allow(clippy::unwrap_used)]

mod common;
mod recording;
mod rooms;
