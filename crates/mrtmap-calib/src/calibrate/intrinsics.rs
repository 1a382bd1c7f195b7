//! A camera's intrinsics as the calibration fits them, by name, and which of them a distortion
//! model frees. The solver holds them flat, nine numbers in OpenCV's order (fx fy cx cy k1 k2
//! p1 p2 k3): [`Intrinsics::params`] and [`Intrinsics::from_params`] convert at that boundary
//! only.

use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use serde::{Deserialize, Serialize};

/// A camera's intrinsics: focal lengths, principal point (px) and Brown–Conrady distortion.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Intrinsics {
    /// Focal length along x (px).
    pub fx: f64,
    /// Focal length along y (px).
    pub fy: f64,
    /// Principal point x (px).
    pub cx: f64,
    /// Principal point y (px).
    pub cy: f64,
    /// Distortion coefficients k1 k2 p1 p2 k3.
    pub distortion: BrownConrady,
}

impl Intrinsics {
    /// Parameters in the flat form the solver holds: fx fy cx cy k1 k2 p1 p2 k3.
    pub const LEN: usize = 9;
    /// Where cx sits in the flat parameters.
    pub const CX: usize = 2;
    /// Where cy sits in the flat parameters.
    pub const CY: usize = 3;

    /// Without distortion.
    pub fn new(fx: f64, fy: f64, cx: f64, cy: f64) -> Self {
        Self {
            fx,
            fy,
            cx,
            cy,
            distortion: BrownConrady::default(),
        }
    }

    /// A camera's intrinsics.
    pub fn of(c: &PinholeCamera) -> Self {
        Self {
            fx: c.fx,
            fy: c.fy,
            cx: c.cx,
            cy: c.cy,
            distortion: c.distortion,
        }
    }

    /// From the first [`Intrinsics::LEN`] flat parameters (fx fy cx cy k1 k2 p1 p2 k3).
    pub fn from_params(g: &[f64]) -> Self {
        Self {
            fx: g[0],
            fy: g[1],
            cx: g[2],
            cy: g[3],
            distortion: BrownConrady::from_array([g[4], g[5], g[6], g[7], g[8]]),
        }
    }

    /// The flat parameters (fx fy cx cy k1 k2 p1 p2 k3).
    pub fn params(&self) -> [f64; Self::LEN] {
        let d = self.distortion.to_array();
        [
            self.fx, self.fy, self.cx, self.cy, d[0], d[1], d[2], d[3], d[4],
        ]
    }

    /// The camera of this image size.
    pub fn camera(&self, width: u32, height: u32) -> PinholeCamera {
        let mut c = PinholeCamera::new(width, height, self.fx, self.fy, self.cx, self.cy);
        c.distortion = self.distortion;
        c
    }
}

/// Camera from the 9 intrinsic parameters (fx fy cx cy k1 k2 p1 p2 k3).
pub fn camera_from(width: u32, height: u32, g: &[f64]) -> PinholeCamera {
    Intrinsics::from_params(g).camera(width, height)
}

/// Which distortion coefficients are estimated (the others stay zero).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum DistortionModel {
    /// No distortion.
    None,
    /// k1, k2.
    Radial,
    /// k1, k2, p1, p2 (OpenCV's model with k3 fixed, its advice for ordinary lenses).
    RadialTangential,
    /// k1, k2, p1, p2, k3 (OpenCV's default).
    Full,
    /// k1, k2, or k1, k2, p1, p2 when that predicts held-out views more than 1 % better: only as
    /// many coefficients as the views constrain.
    #[default]
    Auto,
}

impl DistortionModel {
    /// Which of the flat intrinsic parameters are fitted (fx fy cx cy k1 k2 p1 p2 k3).
    pub(super) fn free(self) -> [bool; Intrinsics::LEN] {
        let (r, t, k3) = match self {
            Self::None => (false, false, false),
            Self::Radial => (true, false, false),
            Self::RadialTangential | Self::Auto => (true, true, false),
            Self::Full => (true, true, true),
        };
        [true, true, true, true, r, r, t, t, k3]
    }
}
