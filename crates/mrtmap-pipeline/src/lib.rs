//! # mrtmap-pipeline
//!
//! Orchestration: what runs in which order, where its files go, and when a stage's outputs can be
//! reused. The CLI parses flags into these types, calls one function, and prints what comes back.
//!
//! ```text
//!  source (bag, MCAP, ROS 2 bag, RTAB-Map db) ──source::prepare──► recording folder
//!  recording ──run::run──► fuse/ ──► segment/ (scene.json) ──► map-H.HHm/ per height
//!            └─ report::report_data ──► report.html, run.json
//!  demo::demo = simulate (sim) + run + comparison with the exact truth
//!  calibration: image pairs ──► rig.toml + report folder
//! ```
//!
//! - [`settings`]: [`Project`] (project.toml) and the typed choices
//!   shared by flags and files ([`MethodChoice`], [`DirectionChoice`]).
//! - [`resolve`]: settings resolved once for every front end: the defaults, then project.toml,
//!   then the flags given ([`Overrides`], [`Project::resolve`]; `[mrt]`'s flags as [`MrtFlags`]).
//! - [`cache`]: a stage's [`Fingerprint`] and [`run_or_reuse`]; the run's stages, source
//!   conversion and the demo's simulation all use it.
//! - [`progress`]: the [`Progress`] trait the CLI implements with progress bars.
//! - [`layout`]: where a run's files go, [`RunLayout`] (and each stage's folder, the demo's
//!   [`DemoLayout`]); no other module spells a file name of the run folder.
//! - [`source`], [`run`], [`maps`], [`report`], [`demo`], [`calibration`]: one job each.
//! - [`points`]: MRT at points of a scene (a sphere's, a person's, the plane radiant
//!   temperatures) from one call, [`points::mrt_at_points`].
//! - [`coverage`], [`comfort`], [`validation`] (also globe ↔ MRT), [`thermal_image`] (one thermal
//!   file), [`simulation`]: one job each; [`parse`]: the text forms flags share (`20x20`,
//!   `X,Y,Z`, `on|off`); [`files`]: mrtmap-io's types a front end handles itself.
//!
//! Everything here returns data, text lines and files; nothing prints. A result a person reads
//! has a `lines()` (or `*_lines`) giving what the CLI prints, so a binding can show the same.
//!
//! ```no_run
//! use mrtmap_pipeline::{Project, Silent, run::run};
//! # fn main() -> Result<(), mrtmap_pipeline::Error> {
//! let outcome = run(
//!     std::path::Path::new("scan"),
//!     std::path::Path::new("out"),
//!     &Project::default(),
//!     false,
//!     &Silent,
//! )?;
//! println!("{} maps", outcome.maps.len());
//! # Ok(())
//! # }
//! ```

mod advice;
pub mod cache;
pub mod calibration;
pub mod comfort;
mod conversion;
pub mod coverage;
pub mod demo;
mod error;
pub mod export;
pub mod front;
pub mod layout;
pub mod level;
pub mod live;
pub mod lock;
pub mod maps;
pub mod parse;
pub mod points;
pub mod progress;
pub mod report;
pub mod resolve;
pub mod run;
pub mod settings;
pub mod simulation;
pub mod source;
pub mod thermal_image;
pub mod validation;

/// The file formats a front end reads or writes itself (mrtmap-io's): a recording, its rig,
/// atomic writes, and I/O errors in words.
pub mod files {
    pub use mrtmap_io::{FileError, InterpolationLimits, Recording, Rig, io_words, write_atomic};
}

pub use advice::Advice;
pub use cache::{Fingerprint, Stage, StageOutcome, run_or_reuse};
pub use error::{Error, Result};
pub use front::{FuseDone, Pipeline, TrackDone};
pub use layout::{DemoLayout, RunLayout};
pub use progress::{Progress, Silent};
pub use resolve::{MrtFlags, Overrides};
pub use settings::{DirectionChoice, MethodChoice, MrtSection, Project};
