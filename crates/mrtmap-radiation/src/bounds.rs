//! Where a room is: its floor outline and the height of its ceiling, so that a point outside it is
//! refused with a sentence saying where the room is, rather than answered.

use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_geometry::polygon::{Containment, point_in_polygon};

use crate::map_frame::{FieldError, MapFrame};
use crate::scene::RadiantScene;

/// Points this far outside the outline, below the floor or above the ceiling still count as in
/// the room (m): a point on a surface is in it.
pub const ROOM_TOLERANCE_M: f64 = 0.005;

/// The room's extent: the floor outline in map coordinates and the ceiling's height above it.
#[derive(Clone, Debug, PartialEq)]
pub struct RoomBounds {
    /// The floor's frame (map coordinates; height along up).
    pub frame: MapFrame,
    /// The highest point of any surface above the floor (m).
    pub ceiling_m: f64,
}

/// Where a point is relative to the room, when it is not in it.
#[derive(Clone, Debug, PartialEq)]
pub enum Outside {
    /// Below the floor by this much (m).
    BelowFloor(f64),
    /// Above the highest surface by this much (m).
    AboveCeiling(f64),
    /// Beyond the walls: outside the floor outline.
    BeyondWalls,
}

impl std::fmt::Display for Outside {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::BelowFloor(d) => write!(f, "{d:.2} m below the floor"),
            Self::AboveCeiling(d) => write!(f, "{d:.2} m above the ceiling"),
            Self::BeyondWalls => write!(f, "outside the walls"),
        }
    }
}

impl RoomBounds {
    /// The bounds of a scene with a floor (`None` without one: nothing to check against).
    pub fn of_scene(scene: &RadiantScene) -> Option<Self> {
        let frame = MapFrame::of_scene(scene).ok()?;
        let ceiling_m = scene
            .surfaces
            .iter()
            .flat_map(|s| s.polygon.iter())
            .map(|p| frame.height(p))
            .fold(0.0f64, f64::max);
        Some(Self { frame, ceiling_m })
    }

    /// Where `p` is, when it is not in the room.
    pub fn locate(&self, p: &Point3<f64>) -> Option<Outside> {
        let h = self.frame.height(p);
        if h < -ROOM_TOLERANCE_M {
            return Some(Outside::BelowFloor(-h));
        }
        if h > self.ceiling_m + ROOM_TOLERANCE_M {
            return Some(Outside::AboveCeiling(h - self.ceiling_m));
        }
        let uv = self.frame.uv(p);
        (point_in_polygon(&uv, &self.frame.floor_uv, ROOM_TOLERANCE_M) == Containment::Outside)
            .then_some(Outside::BeyondWalls)
    }

    /// The room's extent for people: "x 0.00…4.20 m, y 0.00…3.60 m, z 0.00…2.70 m above the
    /// floor" (map axes named x, y for a z-up scene, u, v otherwise).
    pub fn describe(&self) -> String {
        let (lo, hi) = self.frame.floor_bounds();
        let (u, v) = self.axis_names();
        format!(
            "{u} {:.2}…{:.2} m, {v} {:.2}…{:.2} m, and 0…{:.2} m above the floor",
            lo.x, hi.x, lo.y, hi.y, self.ceiling_m
        )
    }

    fn axis_names(&self) -> (&'static str, &'static str) {
        let p = &self.frame.plane;
        let z_up = p.normal.z > 1.0 - 1e-9;
        let x_along = p.u.x > 1.0 - 1e-9;
        if z_up && x_along {
            ("x", "y")
        } else {
            ("u", "v")
        }
    }

    /// Refuses a map height at or below the floor, or at or above the ceiling.
    pub fn check_height(&self, height_m: f64) -> Result<(), FieldError> {
        if height_m > 0.0 && height_m < self.ceiling_m {
            Ok(())
        } else {
            Err(FieldError::HeightOutsideRoom {
                height_m,
                ceiling_m: self.ceiling_m,
            })
        }
    }

    /// Whether map coordinates `uv` lie on the floor.
    pub fn on_floor(&self, uv: &Point2<f64>) -> bool {
        point_in_polygon(uv, &self.frame.floor_uv, ROOM_TOLERANCE_M) != Containment::Outside
    }
}
