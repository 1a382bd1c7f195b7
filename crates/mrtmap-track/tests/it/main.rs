//! Integration tests of the tracker.

#![allow(clippy::unwrap_used)]

mod track;
