//! The radiant scene file (`scene.json`, format `mrtmap-scene/1`) and its validated model.
//!
//! [`SceneFile`] is the file as data (serde, every key of the spec plus the optional ones);
//! [`RadiantScene`] is a scene that passed every rule of the scene format (docs/scene-format.md), with each
//! surface's plane frame computed once. Conversion goes through [`RadiantScene::new`], whose
//! errors name the surface, feature or occluder id and the rule broken.

use std::collections::HashSet;
use std::path::Path;

use mrtmap_geometry::nalgebra::{
    Isometry3, Point2, Point3, Quaternion, Translation3, Unit, UnitQuaternion, Vector3,
};
use mrtmap_geometry::polygon::{self, NotSimple, PlaneFrame};
use mrtmap_geometry::{Tri, box_triangles};
use mrtmap_physics::Temperature;
use serde::{Deserialize, Serialize};

use crate::raster::{Raster, RasterFile};

/// The `format` value of version 1.
pub const SCENE_FORMAT: &str = "mrtmap-scene/1";
/// Largest distance of a vertex from its polygon's best-fit plane (m).
pub const PLANARITY_TOLERANCE_M: f64 = 1e-3;
/// Distance within which a feature counts as lying in its host's plane, and within which points
/// count as on a polygon's boundary (m).
pub const FEATURE_PLANE_TOLERANCE_M: f64 = 1e-3;
/// Valid surface temperatures (°C).
pub const TEMPERATURE_RANGE_C: (f64, f64) = (-60.0, 200.0);

fn one() -> f64 {
    1.0
}

fn is_one(x: &f64) -> bool {
    *x == 1.0
}

/// A rigid transform as written in files: translation (m) and a unit quaternion (x, y, z, w).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FramePose {
    /// Translation (m).
    pub translation: [f64; 3],
    /// Rotation quaternion (x, y, z, w).
    pub rotation_xyzw: [f64; 4],
}

impl FramePose {
    /// From an isometry.
    pub fn from_isometry(p: &Isometry3<f64>) -> Self {
        let t = p.translation.vector;
        let q = p.rotation.coords;
        Self {
            translation: [t.x, t.y, t.z],
            rotation_xyzw: [q.x, q.y, q.z, q.w],
        }
    }

    /// The isometry, when the numbers are finite and the quaternion is unit length (within 1e-6).
    pub fn to_isometry(&self) -> Option<Isometry3<f64>> {
        let [x, y, z, w] = self.rotation_xyzw;
        let q = Quaternion::new(w, x, y, z);
        let finite = self
            .translation
            .iter()
            .chain(&self.rotation_xyzw)
            .all(|v| v.is_finite());
        if !finite || (q.norm() - 1.0).abs() > 1e-6 {
            return None;
        }
        Some(Isometry3::from_parts(
            Translation3::new(
                self.translation[0],
                self.translation[1],
                self.translation[2],
            ),
            UnitQuaternion::from_quaternion(q),
        ))
    }
}

/// `scene.json` as data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneFile {
    /// Must be `mrtmap-scene/1`.
    pub format: String,
    /// Optional up direction (unit vector); without it, the floor's normal into the room.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<[f64; 3]>,
    /// Where the room's frame (the frame of this file) sits in the scan's world frame:
    /// p_in_world = world_from_room · p_in_room. Written by segmentation; absent in hand-written
    /// scenes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world_from_room: Option<FramePose>,
    /// Standard uncertainty of the temperatures' common level (K): what every temperature may be
    /// off by together (a thermal camera's absolute accuracy, or what reference readings left);
    /// it passes one to one into every MRT's standard error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_level_std_k: Option<f64>,
    /// What `temperature_c` is: `radiant` (what a thermal camera set to emissivity 1 reads: the
    /// radiation leaving the surface, emitted and reflected; segmentation writes this) or
    /// `surface` (true surface temperatures, as a contact thermometer reads them). Absent: as the
    /// format's version 1 says, radiant where the emissivity is 1 and, where it is below 1, true
    /// surface temperatures weighted by emissivity (Tr⁴ = Σ εFT⁴ / Σ εF).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperatures: Option<TemperatureKind>,
    /// The room's surfaces.
    pub surfaces: Vec<SurfaceFile>,
    /// Optional occluders (boxes or triangle meshes).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub occluders: Vec<OccluderFile>,
}

/// One surface in the file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SurfaceFile {
    /// Unique id.
    pub id: String,
    /// `floor`, `ceiling`, `wall` or `other`.
    pub kind: String,
    /// Free-text semantic label.
    #[serde(default)]
    pub label: String,
    /// Planar simple polygon, ≥ 3 vertices, metres.
    pub polygon: Vec<[f64; 3]>,
    /// Radiant temperature (°C).
    pub temperature_c: f64,
    /// Emissivity (default 1).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub emissivity: f64,
    /// Standard uncertainty of the temperature (K), written by segmentation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_std_k: Option<f64>,
    /// The true surface temperature (°C; what a contact thermometer reads), derived from the
    /// radiant temperature, the emissivity and the irradiance the surface receives from the rest
    /// of the scene; written by segmentation, not read by the MRT.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_temperature_c: Option<f64>,
    /// Its standard uncertainty (K), the emissivity's included.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_temperature_std_k: Option<f64>,
    /// Observed fraction of the surface, 0…1, written by segmentation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub observed_fraction: Option<f64>,
    /// Features on this surface.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub features: Vec<FeatureFile>,
    /// A temperature raster over the surface's background (written by segmentation); without
    /// one the background radiates at `temperature_c` everywhere.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub raster: Option<RasterFile>,
}

/// One feature (window, light, painting…) in the file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeatureFile {
    /// Unique id.
    pub id: String,
    /// Free-text semantic label.
    #[serde(default)]
    pub label: String,
    /// Polygon in the host's plane and inside the host.
    pub polygon: Vec<[f64; 3]>,
    /// Radiant temperature (°C).
    pub temperature_c: f64,
    /// Emissivity (default 1).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub emissivity: f64,
    /// Standard uncertainty of the temperature (K).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_std_k: Option<f64>,
    /// The true surface temperature (°C), as on surfaces.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_temperature_c: Option<f64>,
    /// Its standard uncertainty (K), the emissivity's included.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_temperature_std_k: Option<f64>,
}

/// What a scene's `temperature_c` values are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TemperatureKind {
    /// Radiant (apparent) temperatures: what leaves the surface, emitted and reflected, as a
    /// thermal camera set to emissivity 1 reads it. The MRT uses them as they are.
    Radiant,
    /// True surface temperatures: the MRT weights them by emissivity.
    Surface,
}

/// An axis-aligned box.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoxFile {
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
}

/// One occluder in the file: a `box`, or `vertices` with `triangles`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OccluderFile {
    /// Unique id.
    pub id: String,
    /// Free-text label.
    #[serde(default)]
    pub label: String,
    /// Radiant temperature (°C).
    pub temperature_c: f64,
    /// Emissivity (default 1).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub emissivity: f64,
    /// A box…
    #[serde(default, rename = "box", skip_serializing_if = "Option::is_none")]
    pub box_: Option<BoxFile>,
    /// …or a triangle mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertices: Option<Vec<[f64; 3]>>,
    /// Vertex index triples of the mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub triangles: Option<Vec<[usize; 3]>>,
}

/// What kind of surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurfaceKind {
    /// Floor.
    Floor,
    /// Ceiling.
    Ceiling,
    /// Wall.
    Wall,
    /// Anything else (a column, a soffit…).
    Other,
}

impl SurfaceKind {
    /// The spec's name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Floor => "floor",
            Self::Ceiling => "ceiling",
            Self::Wall => "wall",
            Self::Other => "other",
        }
    }

    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "floor" => Self::Floor,
            "ceiling" => Self::Ceiling,
            "wall" => Self::Wall,
            "other" => Self::Other,
            _ => return None,
        })
    }
}

/// Why a scene is invalid. Each message names the element and the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
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

/// A validated surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Unique id.
    pub id: String,
    /// Kind.
    pub kind: SurfaceKind,
    /// Semantic label.
    pub label: String,
    /// Vertices (m).
    pub polygon: Vec<Point3<f64>>,
    /// Radiant temperature.
    pub temperature: Temperature,
    /// Emissivity.
    pub emissivity: f64,
    /// Temperature uncertainty (K), if known.
    pub temperature_std_k: Option<f64>,
    /// The true surface temperature and its uncertainty (K), when derived.
    pub surface_temperature: Option<(Temperature, f64)>,
    /// Observed fraction, if known.
    pub observed_fraction: Option<f64>,
    /// Features on it.
    pub features: Vec<Feature>,
    /// The polygon's plane frame (normal by the polygon's winding).
    pub frame: PlaneFrame,
    /// The polygon in `frame`'s 2D coordinates.
    pub polygon_2d: Vec<Point2<f64>>,
    /// Its temperature raster, if any.
    pub raster: Option<Raster>,
}

/// A validated feature.
#[derive(Clone, Debug, PartialEq)]
pub struct Feature {
    /// Unique id.
    pub id: String,
    /// Semantic label.
    pub label: String,
    /// Vertices (m).
    pub polygon: Vec<Point3<f64>>,
    /// Radiant temperature.
    pub temperature: Temperature,
    /// Emissivity.
    pub emissivity: f64,
    /// Temperature uncertainty (K), if known.
    pub temperature_std_k: Option<f64>,
    /// The true surface temperature and its uncertainty (K), when derived.
    pub surface_temperature: Option<(Temperature, f64)>,
    /// The polygon in the host's 2D frame.
    pub polygon_2d: Vec<Point2<f64>>,
    /// Axis-aligned bounds of `polygon_2d`: (min, max).
    pub bounds_2d: (Point2<f64>, Point2<f64>),
}

/// A validated occluder.
#[derive(Clone, Debug, PartialEq)]
pub struct Occluder {
    /// Unique id.
    pub id: String,
    /// Label.
    pub label: String,
    /// Radiant temperature.
    pub temperature: Temperature,
    /// Emissivity.
    pub emissivity: f64,
    /// Shape.
    pub shape: OccluderShape,
}

/// An occluder's shape.
#[derive(Clone, Debug, PartialEq)]
pub enum OccluderShape {
    /// Axis-aligned box.
    Box {
        /// Lower corner.
        min: Point3<f64>,
        /// Upper corner.
        max: Point3<f64>,
    },
    /// Triangle mesh.
    Mesh {
        /// Vertices.
        vertices: Vec<Point3<f64>>,
        /// Index triples.
        triangles: Vec<[usize; 3]>,
    },
}

impl Occluder {
    /// Its triangles.
    pub fn triangles(&self) -> Vec<Tri> {
        match &self.shape {
            OccluderShape::Box { min, max } => box_triangles(min, max),
            OccluderShape::Mesh {
                vertices,
                triangles,
            } => triangles
                .iter()
                .map(|t| [vertices[t[0]], vertices[t[1]], vertices[t[2]]])
                .collect(),
        }
    }

    /// Whether `p` lies inside or on a face, to a micrometre: a point on a face has no radiant
    /// temperature (half its sphere is the furniture's inside). A box by its bounds; a closed mesh
    /// (every edge shared by two triangles, as segmentation's furniture boxes in the room's
    /// frame are) by the parity of a ray's crossings; an open mesh has no inside (false).
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        const ON: f64 = 1e-6;
        match &self.shape {
            OccluderShape::Box { min, max } => {
                (0..3).all(|i| p[i] >= min[i] - ON && p[i] <= max[i] + ON)
            }
            OccluderShape::Mesh {
                vertices,
                triangles,
            } => {
                if !closed(triangles) {
                    return false;
                }
                let tris: Vec<Tri> = triangles
                    .iter()
                    .map(|t| [vertices[t[0]], vertices[t[1]], vertices[t[2]]])
                    .collect();
                if tris.iter().any(|t| distance_to_triangle(p, t) <= ON) {
                    return true;
                }
                // A direction no face or edge of a room's furniture lies along.
                let d = Vector3::new(0.5773, 0.5781, 0.5766).normalize();
                tris.iter()
                    .filter(|t| {
                        mrtmap_geometry::ray_triangle(p, &d, [&t[0], &t[1], &t[2]]).is_some()
                    })
                    .count()
                    % 2
                    == 1
            }
        }
    }
}

/// Whether every edge of `triangles` is shared by exactly two of them.
fn closed(triangles: &[[usize; 3]]) -> bool {
    let mut edges: std::collections::HashMap<(usize, usize), u32> =
        std::collections::HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    !edges.is_empty() && edges.values().all(|&n| n == 2)
}

/// The distance from `p` to triangle `t`.
fn distance_to_triangle(p: &Point3<f64>, t: &Tri) -> f64 {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let area2 = n.norm();
    if area2 < 1e-18 {
        return f64::INFINITY;
    }
    let n = n / area2;
    let h = (p - t[0]).dot(&n);
    let q = p - n * h;
    // Inside the triangle: the distance to its plane; else to its nearest edge.
    let inside = (0..3).all(|k| {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        (b - a).cross(&(q - a)).dot(&n) >= 0.0
    });
    if inside {
        return h.abs();
    }
    (0..3)
        .map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let ab = b - a;
            let s = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            (p - (a + ab * s)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// A validated radiant scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RadiantScene {
    /// Up as given in the file, if any.
    pub up_given: Option<Unit<Vector3<f64>>>,
    /// p_in_world = world_from_room · p_in_room, when the scene came from a scan.
    pub world_from_room: Option<Isometry3<f64>>,
    /// Standard uncertainty of the temperatures' common level (K; 0 when not stated).
    pub temperature_level_std_k: f64,
    /// What the temperatures are, as the file said (see [`SceneFile::temperatures`]).
    pub temperatures: Option<TemperatureKind>,
    /// Surfaces.
    pub surfaces: Vec<Surface>,
    /// Occluders.
    pub occluders: Vec<Occluder>,
}

fn point(v: &[f64; 3]) -> Point3<f64> {
    Point3::new(v[0], v[1], v[2])
}

fn arr(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

fn check_temperature(element: &'static str, id: &str, c: f64) -> Result<Temperature, SceneError> {
    if !c.is_finite() {
        return Err(SceneError::NotFinite {
            element,
            id: id.into(),
            what: "temperature_c",
        });
    }
    if !(TEMPERATURE_RANGE_C.0..=TEMPERATURE_RANGE_C.1).contains(&c) {
        return Err(SceneError::Temperature {
            element,
            id: id.into(),
            value: c,
        });
    }
    Ok(Temperature::from_celsius(c))
}

fn check_emissivity(element: &'static str, id: &str, e: f64) -> Result<f64, SceneError> {
    if !(e > 0.0 && e <= 1.0) {
        return Err(SceneError::Emissivity {
            element,
            id: id.into(),
            value: e,
        });
    }
    Ok(e)
}

/// An optional true surface temperature with its uncertainty.
fn check_surface_temperature(
    element: &'static str,
    id: &str,
    c: Option<f64>,
    std_k: Option<f64>,
) -> Result<Option<(Temperature, f64)>, SceneError> {
    let Some(c) = c else { return Ok(None) };
    if !(c.is_finite() && (TEMPERATURE_RANGE_C.0..=TEMPERATURE_RANGE_C.1).contains(&c)) {
        return Err(SceneError::BadValue {
            element,
            id: id.into(),
            what: "surface_temperature_c",
            value: c,
            rule: "within −60…200 °C",
        });
    }
    let std_k = check_std(element, id, std_k)?.unwrap_or(0.0);
    Ok(Some((Temperature::from_celsius(c), std_k)))
}

fn check_std(element: &'static str, id: &str, s: Option<f64>) -> Result<Option<f64>, SceneError> {
    match s {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err(SceneError::BadValue {
            element,
            id: id.into(),
            what: "temperature_std_k",
            value: v,
            rule: "a finite value ≥ 0",
        }),
        _ => Ok(s),
    }
}

/// Coordinates beyond this (m) are refused: no room is that large.
pub const MAX_COORDINATE_M: f64 = 10_000.0;

fn check_polygon(
    element: &'static str,
    id: &str,
    poly: &[[f64; 3]],
) -> Result<Vec<Point3<f64>>, SceneError> {
    if poly.len() < 3 {
        return Err(SceneError::TooFewVertices {
            element,
            id: id.into(),
            count: poly.len(),
        });
    }
    if poly.iter().flatten().any(|c| !c.is_finite()) {
        return Err(SceneError::NotFinite {
            element,
            id: id.into(),
            what: "a polygon coordinate",
        });
    }
    if let Some(&value) = poly.iter().flatten().find(|c| c.abs() > MAX_COORDINATE_M) {
        return Err(SceneError::FarCoordinate {
            element,
            id: id.into(),
            value,
        });
    }
    Ok(poly.iter().map(point).collect())
}

fn not_simple(element: &'static str, id: &str, why: NotSimple) -> SceneError {
    let detail = match why {
        NotSimple::TooFewVertices => "fewer than 3 distinct vertices".to_string(),
        NotSimple::ZeroLengthEdge(i) => format!("vertices {} and {} coincide", i, i + 1),
        NotSimple::EdgesIntersect(i, j) => format!("edge {i} intersects edge {j}"),
        NotSimple::ZeroArea => "it encloses no area".to_string(),
    };
    SceneError::NotSimple {
        element,
        id: id.into(),
        detail,
    }
}

fn bounds(poly: &[Point2<f64>]) -> (Point2<f64>, Point2<f64>) {
    let mut lo = Point2::new(f64::INFINITY, f64::INFINITY);
    let mut hi = Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
    for p in poly {
        lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    (lo, hi)
}

/// An id stem from a label: lower case, words joined by '-' ("Recessed light" → "recessed-light").
pub fn slug(label: &str) -> String {
    label
        .to_lowercase()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join("-")
}

/// Ids seen so far: each must be present and unique across surfaces, features and occluders.
#[derive(Default)]
struct Ids(HashSet<String>);

impl Ids {
    fn claim(&mut self, id: &str, element: String) -> Result<(), SceneError> {
        if id.is_empty() {
            return Err(SceneError::EmptyId { element });
        }
        if !self.0.insert(id.to_string()) {
            return Err(SceneError::DuplicateId { id: id.into() });
        }
        Ok(())
    }
}

/// `up`, when given: a finite, non-zero vector.
fn check_up(up: Option<[f64; 3]>) -> Result<Option<Unit<Vector3<f64>>>, SceneError> {
    let Some(u) = up else {
        return Ok(None);
    };
    let v = Vector3::new(u[0], u[1], u[2]);
    if !v.iter().all(|c| c.is_finite()) {
        return Err(SceneError::BadUp { value: u });
    }
    Ok(Some(
        Unit::try_new(v, 1e-9).ok_or(SceneError::BadUp { value: u })?,
    ))
}

/// A feature of the surface `host` (its frame and 2D outline), checked against the features
/// already accepted on it.
fn check_feature(
    f: &FeatureFile,
    host: &str,
    frame: &PlaneFrame,
    host_2d: &[Point2<f64>],
    others: &[Feature],
) -> Result<Feature, SceneError> {
    let fpoly = check_polygon("feature", &f.id, &f.polygon)?;
    let off = fpoly
        .iter()
        .map(|p| frame.signed_distance(p).abs())
        .fold(0.0, f64::max);
    if off > FEATURE_PLANE_TOLERANCE_M {
        return Err(SceneError::FeatureOffPlane {
            id: f.id.clone(),
            host: host.into(),
            distance_mm: off * 1e3,
        });
    }
    let f2: Vec<Point2<f64>> = fpoly.iter().map(|p| frame.to_2d(p)).collect();
    polygon::check_simple(&f2, 1e-6).map_err(|e| not_simple("feature", &f.id, e))?;
    if !polygon::polygon_inside(&f2, host_2d, FEATURE_PLANE_TOLERANCE_M) {
        return Err(SceneError::FeatureOutsideHost {
            id: f.id.clone(),
            host: host.into(),
        });
    }
    if let Some(other) = others
        .iter()
        .find(|o| polygon::polygons_overlap(&o.polygon_2d, &f2, FEATURE_PLANE_TOLERANCE_M))
    {
        return Err(SceneError::FeaturesOverlap {
            a: other.id.clone(),
            b: f.id.clone(),
            host: host.into(),
        });
    }
    Ok(Feature {
        id: f.id.clone(),
        label: f.label.clone(),
        polygon: fpoly,
        temperature: check_temperature("feature", &f.id, f.temperature_c)?,
        emissivity: check_emissivity("feature", &f.id, f.emissivity)?,
        temperature_std_k: check_std("feature", &f.id, f.temperature_std_k)?,
        surface_temperature: check_surface_temperature(
            "feature",
            &f.id,
            f.surface_temperature_c,
            f.surface_temperature_std_k,
        )?,
        bounds_2d: bounds(&f2),
        polygon_2d: f2,
    })
}

/// A surface (the `si`-th) with its features.
fn check_surface(s: &SurfaceFile, si: usize, ids: &mut Ids) -> Result<Surface, SceneError> {
    ids.claim(&s.id, format!("surface {}", si + 1))?;
    let kind = SurfaceKind::parse(&s.kind).ok_or_else(|| SceneError::UnknownKind {
        id: s.id.clone(),
        kind: s.kind.clone(),
    })?;
    let poly = check_polygon("surface", &s.id, &s.polygon)?;
    let dev = polygon::planarity_deviation(&poly);
    if dev > PLANARITY_TOLERANCE_M {
        return Err(SceneError::NonPlanar {
            element: "surface",
            id: s.id.clone(),
            deviation_mm: dev * 1e3,
        });
    }
    let frame = PlaneFrame::of_polygon(&poly)
        .ok_or_else(|| not_simple("surface", &s.id, NotSimple::ZeroArea))?;
    let poly2: Vec<Point2<f64>> = poly.iter().map(|p| frame.to_2d(p)).collect();
    polygon::check_simple(&poly2, 1e-6).map_err(|e| not_simple("surface", &s.id, e))?;
    let temperature = check_temperature("surface", &s.id, s.temperature_c)?;
    let emissivity = check_emissivity("surface", &s.id, s.emissivity)?;
    let temperature_std_k = check_std("surface", &s.id, s.temperature_std_k)?;
    let surface_temperature = check_surface_temperature(
        "surface",
        &s.id,
        s.surface_temperature_c,
        s.surface_temperature_std_k,
    )?;
    if let Some(f) = s.observed_fraction
        && !(0.0..=1.0).contains(&f)
    {
        return Err(SceneError::BadValue {
            element: "surface",
            id: s.id.clone(),
            what: "observed_fraction",
            value: f,
            rule: "between 0 and 1",
        });
    }
    let mut features: Vec<Feature> = Vec::with_capacity(s.features.len());
    for (fi, f) in s.features.iter().enumerate() {
        ids.claim(&f.id, format!("feature {} of surface '{}'", fi + 1, s.id))?;
        features.push(check_feature(f, &s.id, &frame, &poly2, &features)?);
    }
    let raster = s
        .raster
        .as_ref()
        .map(|r| Raster::check(r, &s.id, &poly, &frame.normal))
        .transpose()?;
    Ok(Surface {
        id: s.id.clone(),
        kind,
        label: s.label.clone(),
        polygon: poly,
        temperature,
        emissivity,
        temperature_std_k,
        surface_temperature,
        observed_fraction: s.observed_fraction,
        raster,
        features,
        frame,
        polygon_2d: poly2,
    })
}

/// An occluder's shape: a box with min below max, or a mesh whose triangles name its vertices.
fn check_shape(o: &OccluderFile) -> Result<OccluderShape, SceneError> {
    let bad = |detail: String| SceneError::BadOccluder {
        id: o.id.clone(),
        detail,
    };
    let far = |cs: &mut dyn Iterator<Item = &f64>| -> Result<(), SceneError> {
        for &value in cs {
            if value.abs() > MAX_COORDINATE_M {
                return Err(SceneError::FarCoordinate {
                    element: "occluder",
                    id: o.id.clone(),
                    value,
                });
            }
        }
        Ok(())
    };
    match (&o.box_, &o.vertices, &o.triangles) {
        (Some(b), None, None) => {
            if b.min.iter().chain(b.max.iter()).any(|c| !c.is_finite()) {
                return Err(bad("box corners must be finite".into()));
            }
            far(&mut b.min.iter().chain(b.max.iter()))?;
            if (0..3).any(|i| b.min[i] >= b.max[i]) {
                return Err(bad(format!(
                    "box min {:?} is not below max {:?} on every axis",
                    b.min, b.max
                )));
            }
            Ok(OccluderShape::Box {
                min: point(&b.min),
                max: point(&b.max),
            })
        }
        (None, Some(v), Some(t)) => {
            if v.iter().flatten().any(|c| !c.is_finite()) {
                return Err(bad("mesh vertices must be finite".into()));
            }
            far(&mut v.iter().flatten())?;
            if t.is_empty() {
                return Err(bad("mesh has no triangles".into()));
            }
            if let Some((k, tri)) = t
                .iter()
                .enumerate()
                .find(|(_, tri)| tri.iter().any(|&i| i >= v.len()))
            {
                return Err(bad(format!(
                    "triangle {k} {tri:?} refers to a vertex beyond the {} given",
                    v.len()
                )));
            }
            Ok(OccluderShape::Mesh {
                vertices: v.iter().map(point).collect(),
                triangles: t.clone(),
            })
        }
        _ => Err(bad(
            "give either `box` or both `vertices` and `triangles`".into()
        )),
    }
}

impl SceneFile {
    /// The scene with every coordinate mapped by `to_from_this` (p_new = to_from_this · p) and `up`
    /// turned with it; boxes become meshes when the map turns them. `world_from_room` is left as
    /// it is: set it to what the new frame is.
    pub fn transformed(&self, to_from_this: &Isometry3<f64>) -> SceneFile {
        let map = |p: &[f64; 3]| {
            let q = to_from_this * Point3::from(*p);
            [q.x, q.y, q.z]
        };
        let poly = |v: &[[f64; 3]]| v.iter().map(map).collect::<Vec<_>>();
        let turned = to_from_this.rotation.angle() > 1e-12;
        let mut out = self.clone();
        out.up = self.up.map(|u| {
            let v = to_from_this.rotation * Vector3::from(u);
            [v.x, v.y, v.z]
        });
        let turn = |v: &[f64; 3]| {
            let w = to_from_this.rotation * Vector3::from(*v);
            [w.x, w.y, w.z]
        };
        for s in &mut out.surfaces {
            s.polygon = poly(&s.polygon);
            if let Some(r) = &mut s.raster {
                r.origin = map(&r.origin);
                r.u = turn(&r.u);
                r.v = turn(&r.v);
            }
            for f in &mut s.features {
                f.polygon = poly(&f.polygon);
            }
        }
        for o in &mut out.occluders {
            match o.box_.take() {
                Some(b) if turned => {
                    let corners = mrtmap_geometry::box_corners(&point(&b.min), &point(&b.max));
                    o.vertices = Some(corners.iter().map(|c| map(&arr(c))).collect());
                    o.triangles = Some(mrtmap_geometry::BOX_TRIANGLES.to_vec());
                }
                Some(b) => {
                    o.box_ = Some(BoxFile {
                        min: map(&b.min),
                        max: map(&b.max),
                    });
                }
                None => o.vertices = o.vertices.as_deref().map(poly),
            }
        }
        out
    }
}

/// The element at `path` in scene JSON `text`, for people: "surfaces[3] (id 'wall-east')"; `None`
/// at the top level.
fn element_named(text: &str, path: &serde_path_to_error::Path) -> Option<String> {
    use serde_path_to_error::Segment;
    let segments: Vec<&Segment> = path.iter().collect();
    if segments.is_empty() || path.to_string() == "." {
        return None;
    }
    let root: Option<serde_json::Value> = serde_json::from_str(text).ok();
    let mut at = root.as_ref();
    let mut id = None;
    for seg in &segments {
        at = match seg {
            Segment::Seq { index } => at.and_then(|v| v.get(*index)),
            Segment::Map { key } => at.and_then(|v| v.get(key.as_str())),
            _ => None,
        };
        if let Some(i) = at.and_then(|v| v.get("id")).and_then(|v| v.as_str()) {
            id = Some(i.to_string());
        }
    }
    Some(match id {
        Some(id) => format!("{path} (id '{id}')"),
        None => path.to_string(),
    })
}

impl RadiantScene {
    /// The weight of an element of emissivity `emissivity` in a radiant average: 1 when the
    /// temperatures are radiant (the camera's reading already holds what the surface reflects),
    /// the emissivity when they are true surface temperatures (or the file does not say: the
    /// format's version 1).
    pub fn radiant_weight(&self, emissivity: f64) -> f64 {
        match self.temperatures {
            Some(TemperatureKind::Radiant) => 1.0,
            Some(TemperatureKind::Surface) | None => emissivity,
        }
    }

    /// Validates a scene file against every rule of the spec.
    pub fn new(file: &SceneFile) -> Result<Self, SceneError> {
        if file.format != SCENE_FORMAT {
            return Err(SceneError::Format {
                found: file.format.clone(),
            });
        }
        if file.surfaces.is_empty() {
            return Err(SceneError::NoSurfaces);
        }
        let up_given = check_up(file.up)?;
        let world_from_room = match file.world_from_room {
            None => None,
            Some(p) => Some(
                p.to_isometry()
                    .ok_or(SceneError::BadWorldFromRoom { value: p })?,
            ),
        };
        let mut ids = Ids::default();
        let surfaces = file
            .surfaces
            .iter()
            .enumerate()
            .map(|(si, s)| check_surface(s, si, &mut ids))
            .collect::<Result<Vec<_>, _>>()?;
        let mut occluders = Vec::with_capacity(file.occluders.len());
        for (oi, o) in file.occluders.iter().enumerate() {
            ids.claim(&o.id, format!("occluder {}", oi + 1))?;
            occluders.push(Occluder {
                id: o.id.clone(),
                label: o.label.clone(),
                shape: check_shape(o)?,
                temperature: check_temperature("occluder", &o.id, o.temperature_c)?,
                emissivity: check_emissivity("occluder", &o.id, o.emissivity)?,
            });
        }
        let level = file.temperature_level_std_k.unwrap_or(0.0);
        if !(level.is_finite() && (0.0..=100.0).contains(&level)) {
            return Err(SceneError::LevelStd { value: level });
        }
        let scene = Self {
            up_given,
            world_from_room,
            temperature_level_std_k: level,
            temperatures: file.temperatures,
            surfaces,
            occluders,
        };
        scene.check_up_direction()?;
        Ok(scene)
    }

    /// A given `up` must point from the floor towards the rest of the room.
    fn check_up_direction(&self) -> Result<(), SceneError> {
        let (Some(up), Some(floor)) = (self.up_given, self.floor()) else {
            return Ok(());
        };
        let others: Vec<Point3<f64>> = self
            .surfaces
            .iter()
            .filter(|s| !std::ptr::eq(*s, floor))
            .flat_map(|s| s.polygon.iter().copied())
            .collect();
        if others.is_empty() {
            return Ok(());
        }
        let rise = up.dot(&(polygon::centroid(&others) - polygon::centroid(&floor.polygon)));
        if rise < 0.0 {
            return Err(SceneError::UpOutOfRoom {
                value: [up.x, up.y, up.z],
                floor: floor.id.clone(),
            });
        }
        Ok(())
    }

    /// Parses and validates JSON text.
    pub fn from_json(text: &str) -> Result<Self, SceneError> {
        let mut de = serde_json::Deserializer::from_str(text);
        let file: SceneFile = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let element = element_named(text, e.path());
            let e = e.into_inner();
            let message = e
                .to_string()
                .split(" at line ")
                .next()
                .unwrap_or_default()
                .to_string();
            SceneError::Json {
                message: match element {
                    Some(el) => format!("{el}: {message}"),
                    None => message,
                },
                line: e.line(),
                column: e.column(),
            }
        })?;
        Self::new(&file)
    }

    /// Reads, parses and validates a scene file.
    pub fn load(path: &Path) -> Result<Self, SceneLoadError> {
        let wrap = |kind| SceneLoadError {
            path: path.display().to_string(),
            kind,
        };
        let text = std::fs::read_to_string(path).map_err(|e| wrap(SceneLoadErrorKind::Io(e)))?;
        Self::from_json(&text).map_err(|e| wrap(SceneLoadErrorKind::Invalid(e)))
    }

    /// The scene as file data (round-trips through [`RadiantScene::new`]).
    pub fn to_file(&self) -> SceneFile {
        SceneFile {
            format: SCENE_FORMAT.into(),
            up: self.up_given.map(|u| [u.x, u.y, u.z]),
            world_from_room: self.world_from_room.as_ref().map(FramePose::from_isometry),
            temperature_level_std_k: (self.temperature_level_std_k > 0.0)
                .then_some(self.temperature_level_std_k),
            temperatures: self.temperatures,
            surfaces: self
                .surfaces
                .iter()
                .map(|s| SurfaceFile {
                    id: s.id.clone(),
                    kind: s.kind.as_str().into(),
                    label: s.label.clone(),
                    polygon: s.polygon.iter().map(arr).collect(),
                    temperature_c: s.temperature.celsius(),
                    emissivity: s.emissivity,
                    temperature_std_k: s.temperature_std_k,
                    surface_temperature_c: s.surface_temperature.map(|t| t.0.celsius()),
                    surface_temperature_std_k: s.surface_temperature.map(|t| t.1),
                    observed_fraction: s.observed_fraction,
                    raster: s.raster.as_ref().map(|r| r.file.clone()),
                    features: s
                        .features
                        .iter()
                        .map(|f| FeatureFile {
                            id: f.id.clone(),
                            label: f.label.clone(),
                            polygon: f.polygon.iter().map(arr).collect(),
                            temperature_c: f.temperature.celsius(),
                            emissivity: f.emissivity,
                            temperature_std_k: f.temperature_std_k,
                            surface_temperature_c: f.surface_temperature.map(|t| t.0.celsius()),
                            surface_temperature_std_k: f.surface_temperature.map(|t| t.1),
                        })
                        .collect(),
                })
                .collect(),
            occluders: self
                .occluders
                .iter()
                .map(|o| {
                    let (box_, vertices, triangles) = match &o.shape {
                        OccluderShape::Box { min, max } => (
                            Some(BoxFile {
                                min: arr(min),
                                max: arr(max),
                            }),
                            None,
                            None,
                        ),
                        OccluderShape::Mesh {
                            vertices,
                            triangles,
                        } => (
                            None,
                            Some(vertices.iter().map(arr).collect()),
                            Some(triangles.clone()),
                        ),
                    };
                    OccluderFile {
                        id: o.id.clone(),
                        label: o.label.clone(),
                        temperature_c: o.temperature.celsius(),
                        emissivity: o.emissivity,
                        box_,
                        vertices,
                        triangles,
                    }
                })
                .collect(),
        }
    }

    /// Pretty JSON text of the scene.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.to_file()).unwrap_or_default()
    }

    /// The largest floor surface, if any.
    pub fn floor(&self) -> Option<&Surface> {
        self.surfaces
            .iter()
            .filter(|s| s.kind == SurfaceKind::Floor)
            .max_by(|a, b| polygon::area_3d(&a.polygon).total_cmp(&polygon::area_3d(&b.polygon)))
    }

    /// Up: as given, else the floor's normal pointing into the room (towards the mean of the other
    /// surfaces' vertices). `None` without either.
    pub fn up(&self) -> Option<Unit<Vector3<f64>>> {
        if let Some(u) = self.up_given {
            return Some(u);
        }
        let floor = self.floor()?;
        let others: Vec<Point3<f64>> = self
            .surfaces
            .iter()
            .filter(|s| !std::ptr::eq(*s, floor))
            .flat_map(|s| s.polygon.iter().copied())
            .collect();
        let n = floor.frame.normal;
        if others.is_empty() {
            return Some(n);
        }
        let side = floor.frame.signed_distance(&polygon::centroid(&others));
        Some(if side >= 0.0 { n } else { -n })
    }

    /// Every surface and feature triangle, with its owner.
    pub(crate) fn surface_triangles(&self) -> Vec<(Tri, usize)> {
        let mut out = Vec::new();
        for (si, s) in self.surfaces.iter().enumerate() {
            if let Ok(tris) = polygon::triangulate(&s.polygon_2d) {
                out.extend(
                    tris.iter()
                        .map(|t| ([s.polygon[t[0]], s.polygon[t[1]], s.polygon[t[2]]], si)),
                );
            }
        }
        out
    }
}

#[cfg(test)]
mod containment_tests {
    use super::*;
    use mrtmap_geometry::nalgebra::{Isometry3, Translation3, UnitQuaternion};

    /// A desk 1.26 × 0.95 × 0.75 m turned 0.02° (as segmentation writes furniture: a mesh in the
    /// room's frame): a point inside it, and one on its top, are inside; one above it, one
    /// beside it, are not; the same triangles with one missing (an open mesh) have no inside.
    #[test]
    fn a_closed_mesh_contains_the_points_inside_it() {
        let turn = Isometry3::from_parts(
            Translation3::new(0.434, 2.546, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.02f64.to_radians()),
        );
        let corners =
            mrtmap_geometry::box_corners(&Point3::origin(), &Point3::new(1.26, 0.95, 0.75));
        let vertices: Vec<Point3<f64>> = corners.iter().map(|c| turn * c).collect();
        let triangles: Vec<[usize; 3]> = mrtmap_geometry::BOX_TRIANGLES.to_vec();
        let desk = |triangles: Vec<[usize; 3]>| Occluder {
            id: "desk-1".into(),
            label: "desk".into(),
            temperature: Temperature::from_celsius(21.2),
            emissivity: 0.95,
            shape: OccluderShape::Mesh {
                vertices: vertices.clone(),
                triangles,
            },
        };
        let closed = desk(triangles.clone());
        assert!(closed.contains(&Point3::new(1.0, 3.0, 0.4)));
        assert!(closed.contains(&(turn * Point3::new(0.5, 0.5, 0.75))));
        assert!(!closed.contains(&Point3::new(1.0, 3.0, 0.8)));
        assert!(!closed.contains(&Point3::new(2.0, 3.0, 0.4)));
        assert!(!closed.contains(&Point3::new(1.0, 1.0, 0.4)));
        let open = desk(triangles[1..].to_vec());
        assert!(!open.contains(&Point3::new(1.0, 3.0, 0.4)));
    }
}
