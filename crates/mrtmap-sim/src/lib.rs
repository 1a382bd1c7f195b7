//! # mrtmap-sim
//!
//! Synthetic rooms and a handheld scan simulator with exact truth: the embedded default that the
//! scan pipeline is tested and demonstrated on.
//!
//! ```text
//!  room.toml ──► Room ──► scene (exact MRT truth) ─────────────────────────► truth.json
//!                  │
//!                  └──► Walk ──► depth (30 Hz) / thermal (8.7 Hz) / colour + masks / poses (200 Hz)
//!                                   └──► recording folder (docs/recording.md)
//! ```
//!
//! The world frame of a recording is the depth camera's frame at the first pose (as with a SLAM
//! system), so it is neither the room frame nor z-up; `truth.json` gives `world_from_room`.

mod evaluate;
mod evaluate_scene;
mod operator;
mod radiometric;
mod render;
mod room;
mod sensors;
mod simulate;
mod truth;
mod walk;

pub use evaluate::{CloudScore, score_cloud, truth_at};
pub use evaluate_scene::{FeatureScore, PointScore, SceneScore, SurfaceScore, score_scene};
pub use operator::{OPERATOR_C, Operator};
pub use radiometric::{
    CameraErrors, FfcPeriod, RadiometricModel, ReferenceReading, reference_readings,
};
pub use render::{Element, Hit, RoomRenderer, temperature_at};
pub use room::grey::{
    GLASS_EMISSIVITY, GREY_EMISSIVITY, Grey, IRRADIANCE_RAYS, Surfaces, radiant_c,
};
pub use room::is_glass;
pub use room::{
    EmissivitiesFile, FeatureSpec, FurnitureSpec, GRADIENT_STRIP_M, PRESETS, PlacedFeature,
    PointSpec, Room, RoomError, RoomFile, SurfaceRef, TemperaturesFile, WallFile, preset,
};
pub use sensors::{
    DepthNoise, ThermalNoise, camera_rays, instance_label, instance_of, render_depth,
    render_rgb_and_mask, render_thermal,
};
pub use simulate::{
    Drift, ExtrinsicError, NoiseLevel, Progress, SimConfig, SimSummary, TIME_ORIGIN_S,
    room_as_simulated, simulate,
};
pub use truth::{
    SimSun, TRUTH_FORMAT, Truth, TruthGrid, TruthNode, TruthPoint, TruthSun, TruthSunNode,
    compute_truth, sun_truth,
};
pub use walk::{Walk, WalkParams, inset_polygon};

/// Why a simulation failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// A setting out of its range.
    #[error("{what} = {value} is outside {range}")]
    OutOfRange {
        /// The setting.
        what: String,
        /// Its value.
        value: f64,
        /// What is allowed.
        range: &'static str,
    },
    /// The room could not be written as TOML.
    #[error("cannot write room.toml: {0}")]
    Toml(#[from] toml::ser::Error),
    /// The truth could not be written as JSON.
    #[error("cannot write truth.json: {0}")]
    Json(#[from] serde_json::Error),
    /// The room is invalid.
    #[error(transparent)]
    Room(#[from] RoomError),
    /// A scene rule failed.
    #[error(transparent)]
    Scene(#[from] mrtmap_radiation::SceneError),
    /// The truth could not be computed.
    #[error("truth: {0}")]
    Truth(#[from] mrtmap_radiation::MrtError),
    /// The truth grid could not be laid out.
    #[error("truth grid: {0}")]
    Field(#[from] mrtmap_radiation::FieldError),
    /// Writing failed.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A file error.
    #[error(transparent)]
    File(#[from] mrtmap_io::FileError),
}

use std::path::PathBuf;
