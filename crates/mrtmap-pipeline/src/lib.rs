//! # mrtmap-pipeline
//!
//! Orchestration: what runs in which order, where its files go, and when a stage's outputs can be
//! reused. A front end (the CLI, the Python binding) resolves its flags into a [`Project`], holds a
//! [`Pipeline`] (the front door: one method per command), and prints what comes back.
//!
//! ```text
//!  source (bag, MCAP, ROS 2 bag, RTAB-Map db) ──convert──► recording folder
//!  recording ──Pipeline::run──► fuse/ ──► segment/ (scene.json) ──► map-H.HHm/ per height
//!            └─ report.html, run.json
//!  demo::demo = simulate (sim) + run + comparison with the exact truth
//!  calibration: image pairs ──► rig.toml + report folder
//! ```
//!
//! The public API is kept small (issue 53: at most 150 items, counted by
//! `crates/mrtmap/tests/it/architecture.rs`); the stages themselves are crate-private.
//!
//! - [`Pipeline`]: `run`, `fuse`, `track`, `segment`, `map`, `mrt`, `coverage`; each result has a
//!   `lines()` giving what the CLI prints, so a binding can show the same.
//! - [`Project`] (project.toml, [`settings`]), resolved once for every front end: the defaults,
//!   then project.toml, then the flags given ([`Overrides`], [`Project::resolve`]; `[mrt]`'s flags
//!   as [`MrtFlags`]).
//! - [`Progress`]: the trait the CLI implements with progress bars ([`Silent`]: none).
//! - [`RunLayout`]: where a run's files go (the demo's folder: [`DemoLayout`]).
//! - Commands that need no project: [`source`] (inspect, convert), [`demo`], [`calibration`],
//!   [`simulation`], [`export`], [`points`] and [`maps`] (scenes, their points and grids),
//!   [`comfort`], [`validation`] (also globe ↔ MRT), [`thermal_image`] (one thermal file);
//!   [`parse`]: the text forms flags share (`20x20`, `X,Y,Z`).
//! - On site, live: [`Pipeline::live`] follows a recording as it is written and sends a
//!   [`LiveState`] to a [`LiveSink`] (the live page's server, `mrtmap-live`);
//!   [`Pipeline::replay`] writes a recording again at its own pace.
//!
//! Everything here returns data, text lines and files; nothing prints.
//!
//! ```no_run
//! use mrtmap_pipeline::{Overrides, Pipeline, Project, Silent};
//! # fn main() -> Result<(), mrtmap_pipeline::Error> {
//! let project = Project::resolve(None, &Overrides::new())?;
//! let done = Pipeline::new(project)
//!     .progress(&Silent)
//!     .run("scan".as_ref(), "out".as_ref())?;
//! println!("{} maps", done.outcome.maps.len());
//! # Ok(())
//! # }
//! ```

mod advice;
mod cache;
pub mod calibration;
pub mod comfort;
mod conversion;
mod coverage;
pub mod demo;
mod error;
pub mod export;
mod front;
mod layout;
mod level;
mod live;
mod lock;
pub mod maps;
pub mod parse;
pub mod points;
mod progress;
mod report;
mod resolve;
mod run;
pub mod settings;
pub mod simulation;
pub mod source;
pub mod thermal_image;
pub mod validation;

pub use error::Error;
pub(crate) use error::Result;
pub use front::{FuseDone, Pipeline, SegmentDone, TrackDone};
pub use layout::{DemoLayout, RunLayout};
pub use live::replay::ReplayDone;
pub use live::{LivePhase, LiveSink, LiveState};
pub use progress::{Progress, Silent};
pub use report::RunDone;
pub use resolve::{FuseFlags, MrtFlags, Overrides, SegmentFlags, TrackFlags};
pub use run::RunOutcome;
pub use settings::Project;
pub use settings::mrt::MrtSection;
