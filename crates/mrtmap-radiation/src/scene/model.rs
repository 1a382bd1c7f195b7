//! The validated scene in memory: [`RadiantScene`], its surfaces (each with its plane frame
//! computed once), features and occluders, and what is asked of them (the floor, up, the
//! triangles, an occluder's inside, the radiant weight), and the scene back as file data.

use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Unit, Vector3};
use mrtmap_geometry::polygon::{self, PlaneFrame};
use mrtmap_geometry::{Tri, box_triangles};
use mrtmap_physics::Temperature;
use serde::{Deserialize, Serialize};

use super::file::{
    BoxFile, FeatureFile, FramePose, OccluderFile, SCENE_FORMAT, SceneFile, SurfaceFile,
    TemperatureKind, arr,
};
use super::raster::Raster;

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

    /// The kind named `s` in a file, if it is one.
    pub(super) fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "floor" => Self::Floor,
            "ceiling" => Self::Ceiling,
            "wall" => Self::Wall,
            "other" => Self::Other,
            _ => return None,
        })
    }
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

impl RadiantScene {
    /// Whether the scene gives true surface temperatures ("temperatures": "surface") of elements
    /// that are not black: their radiosities must be solved before an MRT
    /// ([`crate::enclosure::solve_enclosure`]).
    pub fn gives_grey_surface_temperatures(&self) -> bool {
        self.temperatures == Some(TemperatureKind::Surface)
            && self
                .surfaces
                .iter()
                .any(|s| s.emissivity < 1.0 || s.features.iter().any(|f| f.emissivity < 1.0))
    }

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
mod tests {
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
