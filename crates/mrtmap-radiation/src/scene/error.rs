//! Why a scene is invalid or could not be loaded: each message names the element (surface,
//! feature, occluder or raster, by id) and the rule it breaks.

use super::file::{FramePose, SCENE_FORMAT};
use super::limits::MAX_COORDINATE_M;

/// Why a scene is invalid. Each message names the element and the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// Surfaces spanning more than any room (a scene in millimetres).
    #[error(
        "the surfaces span {extent_m:.0} m, more than any room ({max_m:.0} m at most): scene.json is in metres{hint}"
    )]
    TooLarge {
        /// The largest extent of the surfaces' bounding box (m).
        extent_m: f64,
        /// The limit (m).
        max_m: f64,
        /// What the unit likely was.
        hint: String,
    },
    /// Not JSON, or JSON not of the scene's shape.
    #[error("not a valid scene file: {message} (line {line}, column {column})")]
    Json {
        /// serde_json's message.
        message: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
    },
    /// A surface's raster breaks a rule.
    #[error("surface '{id}': raster: {detail}")]
    BadRaster {
        /// The surface.
        id: String,
        /// What is wrong.
        detail: String,
    },
    /// Wrong or missing `format`.
    #[error("unsupported format {found:?}: expected \"{SCENE_FORMAT}\"")]
    Format {
        /// What the file says.
        found: String,
    },
    /// No surfaces at all.
    #[error("the scene has no surfaces")]
    NoSurfaces,
    /// An id used twice.
    #[error("duplicate id '{id}'")]
    DuplicateId {
        /// The id.
        id: String,
    },
    /// An id that is empty.
    #[error("{element} has an empty id")]
    EmptyId {
        /// Which element (e.g. "surface 3").
        element: String,
    },
    /// Unknown surface kind.
    #[error("surface '{id}': unknown kind '{kind}' (expected floor, ceiling, wall or other)")]
    UnknownKind {
        /// Surface id.
        id: String,
        /// The kind given.
        kind: String,
    },
    /// A polygon with fewer than three vertices.
    #[error("{element} '{id}': polygon has {count} vertices; at least 3 are needed")]
    TooFewVertices {
        /// "surface" or "feature".
        element: &'static str,
        /// Its id.
        id: String,
        /// Vertex count.
        count: usize,
    },
    /// A common-level uncertainty that is negative, huge or not a number.
    #[error("temperature_level_std_k = {value} is outside 0…100 K")]
    LevelStd {
        /// As written.
        value: f64,
    },
    /// A coordinate or value that is NaN or infinite.
    #[error("{element} '{id}': {what} is not a finite number")]
    NotFinite {
        /// Element kind.
        element: &'static str,
        /// Its id.
        id: String,
        /// Which value.
        what: &'static str,
    },
    /// A polygon that is not planar.
    #[error(
        "{element} '{id}': polygon is not planar (a vertex lies {deviation_mm:.1} mm off the best-fit plane; the limit is 1 mm)"
    )]
    NonPlanar {
        /// Element kind.
        element: &'static str,
        /// Its id.
        id: String,
        /// Largest vertex distance from the plane, mm.
        deviation_mm: f64,
    },
    /// A polygon that is not simple.
    #[error("{element} '{id}': polygon is not simple ({detail})")]
    NotSimple {
        /// Element kind.
        element: &'static str,
        /// Its id.
        id: String,
        /// What is wrong.
        detail: String,
    },
    /// A feature off its host's plane.
    #[error(
        "feature '{id}' does not lie in the plane of its host surface '{host}' ({distance_mm:.1} mm off; the limit is 1 mm)"
    )]
    FeatureOffPlane {
        /// Feature id.
        id: String,
        /// Host id.
        host: String,
        /// Largest distance, mm.
        distance_mm: f64,
    },
    /// A feature not inside its host polygon.
    #[error("feature '{id}' is not inside the polygon of its host surface '{host}'")]
    FeatureOutsideHost {
        /// Feature id.
        id: String,
        /// Host id.
        host: String,
    },
    /// Two features of one surface overlap.
    #[error("features '{a}' and '{b}' of surface '{host}' overlap")]
    FeaturesOverlap {
        /// First feature.
        a: String,
        /// Second feature.
        b: String,
        /// Host surface.
        host: String,
    },
    /// A temperature outside −60…200 °C.
    #[error("{element} '{id}': temperature {value} °C is outside −60…200 °C")]
    Temperature {
        /// Element kind.
        element: &'static str,
        /// Its id.
        id: String,
        /// Value, °C.
        value: f64,
    },
    /// An emissivity outside (0, 1].
    #[error("{element} '{id}': emissivity {value} is outside 0 < ε ≤ 1")]
    Emissivity {
        /// Element kind.
        element: &'static str,
        /// Its id.
        id: String,
        /// Value.
        value: f64,
    },
    /// A bad optional value (uncertainty, observed fraction).
    #[error("{element} '{id}': {what} = {value} is invalid ({rule})")]
    BadValue {
        /// Element kind.
        element: &'static str,
        /// Its id.
        id: String,
        /// Which key.
        what: &'static str,
        /// Value.
        value: f64,
        /// The rule.
        rule: &'static str,
    },
    /// `up` is zero or not finite.
    #[error("`up` must be a non-zero finite vector, got {value:?}")]
    BadUp {
        /// What the file gives.
        value: [f64; 3],
    },
    /// A coordinate too far from the origin to be part of a room.
    #[error(
        "{element} '{id}': a coordinate of {value:e} m is beyond ±{MAX_COORDINATE_M} m: no room is that large (is it in millimetres, or a typo?)"
    )]
    FarCoordinate {
        /// Element kind.
        element: &'static str,
        /// Its id.
        id: String,
        /// The coordinate.
        value: f64,
    },
    /// `up` points out of the room (the other surfaces lie below the floor along it).
    #[error(
        "`up` {value:?} points out of the room: the floor '{floor}' would be above the other surfaces (give the opposite direction, or leave `up` out)"
    )]
    UpOutOfRoom {
        /// What the file gives.
        value: [f64; 3],
        /// The floor's id.
        floor: String,
    },
    /// `world_from_room` is not finite or its quaternion is not unit length.
    #[error(
        "`world_from_room` {value:?} is not a rigid transform (finite translation, unit quaternion x, y, z, w)"
    )]
    BadWorldFromRoom {
        /// What the file gives.
        value: FramePose,
    },
    /// A malformed occluder.
    #[error("occluder '{id}': {detail}")]
    BadOccluder {
        /// Occluder id.
        id: String,
        /// What is wrong.
        detail: String,
    },
}

/// A scene file that could not be loaded: its path and why.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {kind}")]
pub struct SceneLoadError {
    /// The file.
    pub path: String,
    /// Why.
    pub kind: SceneLoadErrorKind,
}

/// Why a scene file could not be loaded.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneLoadErrorKind {
    /// Reading failed (said by the kind of failure, without the OS's error number).
    #[error("cannot read the file: {}", match .0.kind() {
        std::io::ErrorKind::NotFound => "it does not exist (check the path)".to_string(),
        std::io::ErrorKind::InvalidData => "it is not UTF-8 text (is it the right file?)".to_string(),
        k => k.to_string(),
    })]
    Io(#[from] std::io::Error),
    /// The content is invalid.
    #[error("{0}")]
    Invalid(#[from] SceneError),
}
