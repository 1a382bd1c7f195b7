//! `[[references]]`: contact-thermometer readings of surface points (also references.csv's
//! rows).

use serde::{Deserialize, Serialize};

use crate::settings::PointFrame;

/// A contact (or spot) thermometer's reading of a surface point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// Label.
    pub label: String,
    /// The point (m).
    pub xyz: [f64; 3],
    /// The reading (°C).
    pub temperature_c: f64,
    /// Its standard uncertainty (K).
    #[serde(default = "default_std")]
    pub std_k: f64,
    /// The frame of `xyz`: room (project.toml's default) or scan (references.csv's).
    #[serde(default)]
    pub frame: PointFrame,
    /// The emissivity of the surface read; unset: the emissivity of the scene's surface or
    /// feature under the point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emissivity: Option<f64>,
}

pub(crate) fn default_std() -> f64 {
    0.2
}
