//! Integration tests of the live page's server.
#![allow(clippy::unwrap_used)]

mod serve;
