//! # mrtmap-radiation
//!
//! The radiant scene and what it radiates onto a point: read and validate `scene.json`, compute
//! view factors from a point (a small sphere) exactly or by Monte Carlo ray tracing, and the
//! ISO 7726 mean radiant temperature at points and over a grid.
//!
//! ```text
//!  scene.json ──► RadiantScene ──► MrtEngine (exact | Monte Carlo BVH) ──► PointMrt (MRT, F table, σ)
//!                                        │
//!                                        └──► MrtField over a grid at a height ──► maps (mrtmap-report)
//! ```
//!
//! ```
//! use mrtmap_radiation::{example_office, Method, MrtEngine};
//! use mrtmap_geometry::nalgebra::Point3;
//! let scene = example_office();
//! let engine = MrtEngine::new(&scene, Method::Exact).unwrap();
//! let at = engine.at(&Point3::new(2.1, 1.8, 1.1), 0).unwrap();
//! assert!((at.view_factor_sum - 1.0).abs() < 1e-9); // a closed room
//! assert!(at.mrt.celsius() > 19.0 && at.mrt.celsius() < 22.0);
//! ```

mod bounds;
pub mod enclosure;
mod engine;
mod field;
pub mod grey;
mod map_frame;
mod person;
mod scene;
mod sun;
mod vocabulary;

pub use bounds::{Outside, ROOM_TOLERANCE_M, RoomBounds};
pub use engine::{
    ENCLOSURE_TOLERANCE, EXACT_OVERLAP_TOLERANCE, Method, MonteCarlo, MrtEngine, MrtError, Patch,
    PatchKind, PointMrt, UnseenPart, patches,
};
pub use field::{
    Extreme, FieldSummary, GridLayout, GridNode, GridSpec, MrtField, StdErrorParts, UNSEEN_LISTED,
    UnseenImpact,
};
pub use map_frame::{FieldError, MapFrame};
pub use person::{AsymmetryVerdict, Facing, PersonMrt, PlaneRadiant, RadiantAsymmetry};
pub use scene::{
    BoxFile, FEATURE_PLANE_TOLERANCE_M, Feature, FeatureFile, FramePose, MAX_COORDINATE_M,
    MAX_TEXELS, Occluder, OccluderFile, OccluderShape, PLANARITY_TOLERANCE_M, RadiantScene, Raster,
    RasterFile, SCENE_FORMAT, SceneError, SceneFile, SceneLoadError, SceneLoadErrorKind, Surface,
    SurfaceFile, SurfaceKind, TEMPERATURE_RANGE_C, TemperatureKind, Texel, UnseenPatch,
    UnseenShare, slug,
};
pub use sun::{
    BODY_WIDTH_M, BeamAudit, SunDirection, SunExposure, SunTracer, audit_the_beam,
    sun_frame_is_z_up,
};
pub use vocabulary::{ElementKind, GlazingKind, LABEL_ALIASES, UNLABELLED, says_nothing};

use serde::{Deserialize, Serialize};

/// The built-in example scene as JSON text: an enclosed office (4.2 × 3.6 × 2.7 m) modelled on the
/// seed paper's winter experiment: one exterior wall at 18.8 °C with a 1.8 × 1.3 m window at
/// 11.5 °C, four 0.6 × 0.6 m recessed lights at 29 °C in a 21.6 °C ceiling, a painting at 22.3 °C,
/// a door, interior walls near the 21 °C setpoint and a 20.4 °C floor. No occluders.
pub const EXAMPLE_OFFICE_JSON: &str = include_str!("../data/example-office.json");

/// The built-in example scene ([`EXAMPLE_OFFICE_JSON`]).
pub fn example_office() -> RadiantScene {
    match RadiantScene::from_json(EXAMPLE_OFFICE_JSON) {
        Ok(s) => s,
        // The embedded file is checked by the crate's tests; this arm cannot run.
        Err(e) => unreachable!("the embedded example scene is invalid: {e}"),
    }
}

/// One row of a view-factor table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewFactorRecord {
    /// Surface, feature or occluder id.
    pub id: String,
    /// Its label.
    pub label: String,
    /// Surface, feature or occluder.
    pub kind: PatchKind,
    /// Host surface of a feature.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub host: Option<String>,
    /// View factor.
    #[serde(rename = "F")]
    pub view_factor: f64,
    /// Its standard error.
    #[serde(rename = "F_std_error")]
    pub view_factor_std_error: f64,
    /// Temperature (°C).
    pub temperature_c: f64,
    /// Emissivity.
    pub emissivity: f64,
}

/// A point's result as written to JSON.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointRecord {
    /// Optional name of the point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Scene coordinates.
    pub xyz: [f64; 3],
    /// Mean radiant temperature (°C).
    pub mrt_c: f64,
    /// Total standard error (K).
    pub std_error_k: f64,
    /// From Monte Carlo sampling (K).
    pub sampling_std_error_k: f64,
    /// From the surfaces' temperature uncertainties (K).
    pub temperature_std_error_k: f64,
    /// From where the point lies relative to the surfaces (K; 0 when no placement uncertainty
    /// was set).
    #[serde(default)]
    pub placement_std_error_k: f64,
    /// From the areas the scan never saw (K; 0 for a scene without unseen patches).
    #[serde(default)]
    pub unseen_std_error_k: f64,
    /// From the camera's absolute level (K; the scene's `temperature_level_std_k`).
    #[serde(default)]
    pub level_std_error_k: f64,
    /// Σ F.
    pub view_factor_sum: f64,
    /// Rays traced (0 for exact).
    pub rays: usize,
    /// The view-factor table.
    pub view_factors: Vec<ViewFactorRecord>,
}

impl PointRecord {
    /// Its standard error's parts.
    pub fn parts(&self) -> StdErrorParts {
        StdErrorParts {
            sampling_k: self.sampling_std_error_k,
            temperatures_k: self.temperature_std_error_k,
            placement_k: self.placement_std_error_k,
            unseen_k: self.unseen_std_error_k,
            level_k: self.level_std_error_k,
        }
    }

    /// The record of `r`, whose view factors follow `patches`.
    pub fn new(name: Option<String>, r: &PointMrt, patches: &[Patch]) -> Self {
        Self {
            name,
            xyz: [r.point.x, r.point.y, r.point.z],
            mrt_c: r.mrt.celsius(),
            std_error_k: r.std_error_k,
            sampling_std_error_k: r.sampling_std_error_k,
            temperature_std_error_k: r.temperature_std_error_k,
            placement_std_error_k: r.placement_std_error_k,
            unseen_std_error_k: r.unseen_std_error_k,
            level_std_error_k: r.level_std_error_k,
            view_factor_sum: r.view_factor_sum,
            rays: r.rays,
            view_factors: patches
                .iter()
                .zip(r.view_factors.iter().zip(&r.view_factor_std_errors))
                .map(|(p, (&f, &se))| ViewFactorRecord {
                    id: p.id.clone(),
                    label: p.label.clone(),
                    kind: p.kind,
                    host: p.host.clone(),
                    view_factor: f,
                    view_factor_std_error: se,
                    temperature_c: p.temperature.celsius(),
                    emissivity: p.emissivity,
                })
                .collect(),
        }
    }
}
