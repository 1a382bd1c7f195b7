//! Pipeline tests through the library: a small simulated scan run end to end, progress reported
//! through the trait, stages reused while their inputs are unchanged.
#![allow(clippy::unwrap_used)]

mod inputs;
mod run;
