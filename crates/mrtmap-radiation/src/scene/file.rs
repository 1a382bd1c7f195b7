//! The scene file as data: `scene.json` (format `mrtmap-scene/1`) as serde structs, every key of
//! the spec plus the optional ones, with no rule checked (that is [`RadiantScene::new`]'s).
//!
//! [`RadiantScene::new`]: super::RadiantScene::new

use mrtmap_geometry::nalgebra::{
    Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3,
};
use serde::{Deserialize, Serialize};

/// The `format` value of version 1.
pub const SCENE_FORMAT: &str = "mrtmap-scene/1";

/// A quaternion in a file is a rotation when its length is 1 to within this.
const UNIT_QUATERNION_TOLERANCE: f64 = 1e-6;

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
        if !finite || (q.norm() - 1.0).abs() > UNIT_QUATERNION_TOLERANCE {
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

/// A surface's raster in `scene.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RasterFile {
    /// Texel edge (m).
    pub texel_m: f64,
    /// Corner of texel (0, 0), in the surface's plane (m).
    pub origin: [f64; 3],
    /// Unit direction along a row (columns increase along it), in the surface's plane.
    pub u: [f64; 3],
    /// Unit direction from row to row, in the plane, perpendicular to `u`.
    pub v: [f64; 3],
    /// Texels per row.
    pub cols: usize,
    /// Rows.
    pub rows: usize,
    /// Radiant temperature of each texel (°C), row after row (index = row · cols + col); `null`
    /// for a texel off the surface.
    pub temperature_c: Vec<Option<f64>>,
    /// Texels not observed, whose temperature was filled in from the texels seen around them
    /// (indices).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub filled: Vec<usize>,
    /// Patches of texels the scan never saw, each with the temperatures its seen surroundings
    /// allow: they enter every MRT's standard error as its unseen-areas part.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unseen: Vec<UnseenPatch>,
}

/// Texels of a raster the scan never saw: their temperatures in the raster are filled in, and the
/// truth may lie anywhere in `range_c`, the temperatures seen around them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnseenPatch {
    /// The texels (indices, as in `filled`).
    pub texels: Vec<usize>,
    /// The lowest and highest temperature the patch may have (°C).
    pub range_c: [f64; 2],
}

/// A point from a file's coordinates.
pub(super) fn point(v: &[f64; 3]) -> Point3<f64> {
    Point3::new(v[0], v[1], v[2])
}

/// A point's coordinates for a file.
pub(super) fn arr(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// An id stem from a label: lower case, words joined by '-' ("Recessed light" → "recessed-light").
pub fn slug(label: &str) -> String {
    label
        .to_lowercase()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join("-")
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
