//! Where to point the camera, in sentences a person standing in the room can follow (`mrtmap
//! coverage` and `mrtmap live`).
//!
//! Ids such as `wall-4` and coordinates in the room's frame mean nothing on site before the
//! report is open. So:
//!
//! 1. A wall is named by what is on it (its largest feature: "the wall with the window") and,
//!    when that does not single it out, by where it lies from where the scan started ("the wall
//!    to the left of where the scan started"); its id follows in brackets, for the report.
//! 2. A patch on the floor or the ceiling is placed by the wall it is nearest; a patch on a wall
//!    by its height (low, at mid-height, high).
//! 3. With the camera's pose (live), each sentence starts with the turn that brings the patch
//!    into view ("turn left about 90° and look up"), from the camera's heading and pitch now.
//! 4. The map node it affects most is placed by the furniture within a metre of it ("at the
//!    desk"), else by its distance from the nearest wall.
//!
//! Each piece of advice keeps its point (room frame), so a view can mark it.

use mrtmap_geometry::nalgebra::{Isometry3, Point3, Vector3};
use mrtmap_radiation::{OccluderShape, RadiantScene, Surface, SurfaceKind, UnseenImpact};
use serde::Serialize;

/// One piece of advice: a sentence and the point it is about (room frame, m).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Advice {
    /// What to do, in words.
    pub text: String,
    /// Where (the room's frame).
    pub point: [f64; 3],
}

/// What the advice is about.
pub(crate) enum Target<'a> {
    /// A wall never seen (placed at the floor's edge).
    Wall(&'a str),
    /// A patch never seen, with what it does to the map.
    Patch(&'a UnseenImpact),
}

/// A turn smaller than this (degrees) is "ahead".
const AHEAD_DEG: f64 = 25.0;

/// A pitch change larger than this (degrees) is "look up" or "look down".
const PITCH_DEG: f64 = 25.0;

/// Furniture within this distance (m, horizontally) of a node names it.
const FURNITURE_NEAR_M: f64 = 1.0;

fn centroid(poly: &[Point3<f64>]) -> Point3<f64> {
    let n = poly.len().max(1) as f64;
    Point3::from(poly.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n)
}

/// The horizontal angle (degrees, left positive) from `forward` to `d` about the room's up (z),
/// and the two elevations (degrees).
fn angles(forward: &Vector3<f64>, d: &Vector3<f64>) -> (f64, f64, f64) {
    let up = Vector3::z();
    let flat = |v: &Vector3<f64>| v - up * v.dot(&up);
    let (f, g) = (flat(forward), flat(d));
    let yaw = f.cross(&g).dot(&up).atan2(f.dot(&g)).to_degrees();
    let elev = |v: &Vector3<f64>| v.dot(&up).atan2(flat(v).norm()).to_degrees();
    (yaw, elev(forward), elev(d))
}

/// "turn left about 90° and look up", from a camera (room_from_camera, optical axes: z forward)
/// to a point.
pub(crate) fn turn_towards(room_from_camera: &Isometry3<f64>, p: &Point3<f64>) -> String {
    let forward = room_from_camera.rotation * Vector3::z();
    let d = p - Point3::from(room_from_camera.translation.vector);
    let (yaw, e_now, e_to) = angles(&forward, &d);
    let pitch = e_to - e_now;
    let look = if pitch > PITCH_DEG {
        Some("look up")
    } else if pitch < -PITCH_DEG {
        Some("look down")
    } else {
        None
    };
    let turn = if yaw.abs() < AHEAD_DEG {
        None
    } else if yaw.abs() > 150.0 {
        Some("turn around".to_string())
    } else {
        let deg = ((yaw.abs() / 45.0).round() * 45.0).max(45.0);
        let side = if yaw > 0.0 { "left" } else { "right" };
        Some(format!("turn {side} about {deg:.0}°"))
    };
    match (turn, look) {
        (Some(t), Some(l)) => format!("{t} and {l}"),
        (Some(t), None) => t,
        (None, Some(l)) => l.to_string(),
        (None, None) => "straight ahead".to_string(),
    }
}

/// Names surfaces for people in the room.
pub(crate) struct Namer<'a> {
    scene: &'a RadiantScene,
    /// The scan's first camera pose in the room's frame.
    start: Option<Isometry3<f64>>,
}

impl<'a> Namer<'a> {
    /// A namer for `scene`; `world_start` is the scan's first camera pose (world_from_camera).
    pub(crate) fn new(scene: &'a RadiantScene, world_start: Option<Isometry3<f64>>) -> Self {
        let room_from_world = scene
            .world_from_room
            .map_or(Isometry3::identity(), |w| w.inverse());
        Namer {
            scene,
            start: world_start.map(|s| room_from_world * s),
        }
    }

    fn surface(&self, id: &str) -> Option<&'a Surface> {
        self.scene.surfaces.iter().find(|s| s.id == id)
    }

    /// The label of a wall's largest feature.
    fn main_feature(s: &Surface) -> Option<&str> {
        s.features
            .iter()
            .filter(|f| !mrtmap_radiation::says_nothing(&f.label))
            .max_by(|a, b| {
                mrtmap_geometry::polygon::area_3d(&a.polygon)
                    .total_cmp(&mrtmap_geometry::polygon::area_3d(&b.polygon))
            })
            .map(|f| f.label.as_str())
    }

    /// Where a point lies seen from where the scan started: "ahead of", "to the left of"…
    fn seen_from_start(&self, p: &Point3<f64>) -> Option<&'static str> {
        let s = self.start?;
        let forward = s.rotation * Vector3::z();
        let (yaw, _, _) = angles(&forward, &(p - Point3::from(s.translation.vector)));
        Some(match yaw {
            y if y.abs() <= 45.0 => "ahead of",
            y if y.abs() >= 135.0 => "behind",
            y if y > 0.0 => "to the left of",
            _ => "to the right of",
        })
    }

    /// "the wall with the window (wall-1)", "the wall to the left of where the scan started
    /// (wall-3)", or the id alone.
    pub(crate) fn wall(&self, id: &str) -> String {
        let Some(s) = self.surface(id) else {
            return id.to_string();
        };
        let walls = || {
            self.scene
                .surfaces
                .iter()
                .filter(|w| w.kind == SurfaceKind::Wall)
        };
        let feature = Self::main_feature(s);
        let unique = feature
            .is_some_and(|f| walls().filter(|w| Self::main_feature(w) == Some(f)).count() == 1);
        let place = self.seen_from_start(&centroid(&s.polygon));
        match (feature, unique, place) {
            (Some(f), true, _) => format!("the wall with the {f} ({id})"),
            (Some(f), false, Some(p)) => {
                format!("the wall with the {f} {p} where the scan started ({id})")
            }
            (None, _, Some(p)) => format!("the wall {p} where the scan started ({id})"),
            _ => id.to_string(),
        }
    }

    /// The wall nearest a point (horizontally).
    fn nearest_wall(&self, p: &Point3<f64>) -> Option<(&'a Surface, f64)> {
        self.scene
            .surfaces
            .iter()
            .filter(|w| w.kind == SurfaceKind::Wall)
            .map(|w| {
                let n = w.frame.normal.into_inner();
                let d = (p - w.frame.origin).dot(&n).abs();
                (w, d)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// A patch on a surface in words: "the ceiling near the wall with the window (ceiling)",
    /// "the wall with the window (wall-1), low".
    pub(crate) fn patch(&self, id: &str, p: &Point3<f64>) -> String {
        let Some(s) = self.surface(id) else {
            return id.to_string();
        };
        match s.kind {
            SurfaceKind::Floor | SurfaceKind::Ceiling => {
                let what = if s.kind == SurfaceKind::Floor {
                    "the floor"
                } else {
                    "the ceiling"
                };
                match self.nearest_wall(p) {
                    Some((w, d)) if d < 1.0 => format!("{what} near {}", self.wall(&w.id)),
                    _ => format!("{what} in the middle of the room"),
                }
            }
            SurfaceKind::Wall => {
                let zs: Vec<f64> = s.polygon.iter().map(|q| q.z).collect();
                let (lo, hi) = zs
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &z| {
                        (a.min(z), b.max(z))
                    });
                let h = (p.z - lo) / (hi - lo).max(1e-6);
                let part = match h {
                    h if h < 1.0 / 3.0 => "low",
                    h if h > 2.0 / 3.0 => "high",
                    _ => "at mid-height",
                };
                format!("{}, {part}", self.wall(id))
            }
            SurfaceKind::Other => id.to_string(),
        }
    }

    /// A map node in words: "at the desk", "1.2 m from the wall with the window (wall-1)".
    pub(crate) fn node(&self, at: &Point3<f64>) -> String {
        let furniture = self
            .scene
            .occluders
            .iter()
            .filter_map(|o| match &o.shape {
                OccluderShape::Box { min, max } => {
                    let dx = (at.x - at.x.clamp(min.x, max.x)).abs();
                    let dy = (at.y - at.y.clamp(min.y, max.y)).abs();
                    Some((o, dx.hypot(dy)))
                }
                OccluderShape::Mesh { .. } => None,
            })
            .filter(|(o, d)| *d <= FURNITURE_NEAR_M && !o.label.trim().is_empty())
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((o, _)) = furniture {
            return format!("at the {}", o.label);
        }
        match self.nearest_wall(at) {
            Some((w, d)) => format!("{d:.1} m from {}", self.wall(&w.id)),
            None => "in the room".to_string(),
        }
    }
}

/// The advice on `targets`, most important first; with the camera's pose now
/// (`world_camera`, world_from_camera), each sentence starts with the turn to make.
pub(crate) fn advise(
    namer: &Namer<'_>,
    targets: &[Target<'_>],
    world_camera: Option<&Isometry3<f64>>,
) -> Vec<Advice> {
    let room_from_world = namer
        .scene
        .world_from_room
        .map_or(Isometry3::identity(), |w| w.inverse());
    let camera = world_camera.map(|c| room_from_world * c);
    targets
        .iter()
        .filter_map(|t| {
            let (point, what) = match t {
                Target::Wall(id) => {
                    let s = namer.surface(id)?;
                    let c = centroid(&s.polygon);
                    (
                        c,
                        format!(
                            "{}, never seen: it is placed at the floor's edge",
                            namer.wall(id)
                        ),
                    )
                }
                Target::Patch(u) => {
                    let c = Point3::from(u.centre);
                    (
                        c,
                        format!(
                            "{}, {:.1} m² never seen ({:.1}…{:.1} °C around it): up to ±{:.2} K on the map {}",
                            namer.patch(&u.surface_id, &c),
                            u.area_m2,
                            u.range_c[0],
                            u.range_c[1],
                            2.0 * u.max_std_error_k,
                            namer.node(&Point3::from(u.at)),
                        ),
                    )
                }
            };
            let text = match &camera {
                Some(cam) => format!("{}: {what}", turn_towards(cam, &point)),
                None => what,
            };
            Some(Advice {
                text,
                point: point.coords.into(),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use mrtmap_geometry::nalgebra::{Translation3, UnitQuaternion};

    use super::*;

    /// A camera at (2, 2, 1.5) looking along +x, level (optical z along x, y down).
    fn camera_along_x() -> Isometry3<f64> {
        // Optical axes: z forward = +x, x right = −y, y down = −z.
        let r = mrtmap_geometry::nalgebra::Rotation3::from_basis_unchecked(&[
            -Vector3::y(),
            -Vector3::z(),
            Vector3::x(),
        ]);
        Isometry3::from_parts(
            Translation3::new(2.0, 2.0, 1.5),
            UnitQuaternion::from_rotation_matrix(&r),
        )
    }

    #[test]
    fn the_turn_is_read_from_the_camera_heading_and_pitch() {
        let c = camera_along_x();
        assert_eq!(
            turn_towards(&c, &Point3::new(5.0, 2.0, 1.5)),
            "straight ahead"
        );
        assert_eq!(
            turn_towards(&c, &Point3::new(2.0, 5.0, 1.5)),
            "turn left about 90°"
        );
        assert_eq!(
            turn_towards(&c, &Point3::new(2.0, -1.0, 1.5)),
            "turn right about 90°"
        );
        assert_eq!(
            turn_towards(&c, &Point3::new(-2.0, 2.1, 1.5)),
            "turn around"
        );
        assert_eq!(turn_towards(&c, &Point3::new(3.0, 2.0, 2.8)), "look up");
        assert_eq!(
            turn_towards(&c, &Point3::new(2.0, 4.0, 3.5)),
            "turn left about 90° and look up"
        );
        assert_eq!(
            turn_towards(&c, &Point3::new(4.0, 4.0, 0.0)),
            "turn left about 45° and look down"
        );
    }
}
