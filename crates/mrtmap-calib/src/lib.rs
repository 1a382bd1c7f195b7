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
//!    both         --calibrate_stereo-->  StereoResult (joint LM, outlier pairs rejected)
//!    result       --rig / report-->  rig.toml [thermal] [rgb], report images, calibration.json
//! ```

pub mod board;
pub mod calibrate;
pub mod detect;
pub mod gray;
pub mod lm;
pub mod pairs;
pub mod report;
pub mod rig;
pub mod synth;
pub mod zhang;

use std::path::{Path, PathBuf};

pub use board::{Board, GridSize};
pub use calibrate::{
    DistortionModel, MonoResult, PairInput, PairResult, PairStatus, StereoOptions, StereoResult,
    ViewError, calibrate_mono, calibrate_stereo,
};
pub use detect::{Corner, DetectOptions, Detection, detect};
pub use gray::Gray;
pub use pairs::{ImagePair, find_pairs, list_images};

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
    /// Too little usable data, and what is missing.
    #[error("{0}")]
    NotEnough(String),
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
