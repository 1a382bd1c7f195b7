//! The limits scene.json's rules set on its numbers (docs/scene-format.md), shared by the
//! validation of surfaces, features, occluders and rasters, and by the errors that name them.

/// Largest distance of a vertex from its polygon's best-fit plane (m).
pub const PLANARITY_TOLERANCE_M: f64 = 1e-3;
/// Distance within which a feature counts as lying in its host's plane, and within which points
/// count as on a polygon's boundary (m).
pub const FEATURE_PLANE_TOLERANCE_M: f64 = 1e-3;
/// Valid surface temperatures (°C).
pub const TEMPERATURE_RANGE_C: (f64, f64) = (-60.0, 200.0);

/// Coordinates beyond this (m) are refused: no room is that large.
pub const MAX_COORDINATE_M: f64 = 10_000.0;

/// The largest extent of a room's surfaces (m): a hall or a hangar is under this; a scene whose
/// surfaces span more was most likely written in millimetres or centimetres.
pub const MAX_ROOM_EXTENT_M: f64 = 500.0;

/// The largest standard uncertainty of the temperatures' common level a scene may state (K).
pub(super) const MAX_LEVEL_STD_K: f64 = 100.0;
