//! # mrtmap-report
//!
//! What people look at: the MRT heatmap with labelled contours (PNG and SVG from one drawing
//! routine), the grid as CSV, and the map summary.
//!
//! ```text
//!  MrtField + RadiantScene + marks ──► render_png / render_svg ──► mrt_map.png / mrt_map.svg
//!  MrtField                        ──► grid_csv                ──► mrt_grid.csv
//! ```
//!
//! Nothing here writes files or prints: functions return bytes and text for the caller to write.

mod html;
mod map;
pub mod mesh;
pub mod numbers;
mod tables;
mod validate;
pub mod view3d;

pub use html::{ComparisonRow, KeyValues, ReportData, ReportMap, esc, render_html, view3d_page};
pub use map::{MapInput, MapMark, MapQuantity, contour_step, render_png, render_svg};
pub use tables::{MapAxes, MapSummary, coverage_svg, grid_csv, parts_line, unseen_line};
pub use validate::{
    GLOBE_COLUMNS, GlobeRow, IN_SUN_NOTE, ISO_DESIRED_K, ISO_REQUIRED_K, ValidationRow,
    parse_globe_csv, validate, validation_csv,
};

/// Errors of report rendering.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// Drawing or encoding failed (plotters' and image's errors, in words).
    #[error("drawing the map failed: {0}")]
    Draw(String),
    /// A line of a globe readings file is wrong.
    #[error("{file}:{line}: {problem}")]
    Globe {
        /// The file, as named to the parser.
        file: String,
        /// 1-based line (0 when unknown).
        line: u64,
        /// What is wrong.
        problem: String,
    },
    /// A globe readings file holds no readings.
    #[error("{file}: no readings")]
    NoReadings {
        /// The file.
        file: String,
    },
    /// A CSV table could not be written.
    #[error("cannot write CSV: {0}")]
    Csv(String),
}
