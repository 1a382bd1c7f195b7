//! # mrtmap-calib
//!
//! Stage 1 of the scan method: the thermal camera's intrinsics and its pose relative to the
//! colour/depth camera, from pairs of images of a heated checkerboard (aluminium foil and black
//! polyethylene: the thermal contrast is the colour image's inverted).
//!
//! ```text
//!  pairs/ (rgb + thermal images)  --pairs-->  Pair list (matched by name or timestamp)
//!    each image   --detect-->  Detection (labelled inner corners, sub-pixel)
//!    detections   --calibrate_mono-->  MonoResult per camera (Zhang + Brown–Conrady, LM)
//!    both         --calibrate_stereo-->  StereoResult (extrinsic by LM, intrinsics fixed, outlier pairs rejected, bootstrap ±)
//!    result       --rig / report-->  rig.toml [thermal] [rgb], report images, calibration.json
//! ```

pub mod board;
pub mod calibrate;
pub mod detect;
pub mod gray;
pub mod lm;
pub mod pairs;
pub mod quality;
pub mod report;
pub mod rig;
pub mod synth;
pub mod zhang;

use std::path::{Path, PathBuf};

pub use board::{Board, GridSize};
pub use calibrate::{
    DistortionModel, MonoResult, PairInput, PairResult, PairStatus, PrincipalPoint, StereoOptions,
    StereoResult, ViewError, calibrate_mono, calibrate_mono_with, calibrate_stereo,
};
pub use detect::{Corner, DetectOptions, Detection, detect, detect_variants};
pub use gray::Gray;
pub use pairs::{ImagePair, find_pairs, list_images};
pub use quality::plausibility;

/// Why a calibration could not be done.
#[derive(Debug, thiserror::Error)]
pub enum CalibError {
    /// A file problem, naming the file.
    #[error("{}: {msg}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        msg: String,
    },
    /// Too few views of the board for one camera's intrinsics.
    #[error(
        "the board was found in {found} image(s) of {width}×{height}; at least 3 views at different angles are needed"
    )]
    TooFewViews {
        /// Views with the board.
        found: usize,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// One camera of a pair set could not be calibrated.
    #[error("{camera} camera")]
    Camera {
        /// "colour" or "thermal".
        camera: &'static str,
        /// Why.
        #[source]
        source: Box<CalibError>,
    },
    /// No pair shows the whole board in both images.
    #[error(
        "no pair shows all {cols}×{rows} inner corners in both images, which is needed to tie the thermal corners' numbering to the colour image's"
    )]
    NoCompletePair {
        /// Inner corners per row.
        cols: u32,
        /// Inner corners per column.
        rows: u32,
    },
}

impl CalibError {
    /// A file problem.
    pub fn file(path: &Path, msg: impl Into<String>) -> Self {
        Self::File {
            path: path.to_path_buf(),
            msg: msg.into(),
        }
    }
}
