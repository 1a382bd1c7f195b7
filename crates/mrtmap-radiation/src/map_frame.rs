//! The map frame: the horizontal frame maps are drawn in, and why a scene has none.
//!
//! The map frame lies in the floor's plane with its normal along up. Its axes (u, v) are the world
//! axes when up is within 1° of a world axis (x, y for a z-up scene), otherwise u runs along the
//! floor polygon's longest edge; v = up × u. Its origin is the world origin projected onto the
//! floor, so for a z-up scene (u, v) are simply (x, y).

use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Point2, Point3, Unit, Vector3};

use crate::scene::RadiantScene;

/// The floor is horizontal when its normal is within this cosine of up (about 26°).
const FLOOR_HORIZONTAL_COS: f64 = 0.9;

/// Up within this of a world axis (degrees) makes the map's axes world axes.
const AXIS_ALIGNED_DEG: f64 = 1.0;

/// Why no map frame exists.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FieldError {
    /// Neither `up` nor a floor.
    #[error(
        "the scene has no floor surface, so there is no floor to map over (add a surface of kind \"floor\")"
    )]
    NoFloor,
    /// The floor is parallel to up.
    #[error("the floor surface '{id}' is not horizontal with respect to `up`")]
    FloorNotHorizontal {
        /// Floor id.
        id: String,
    },
    /// A grid that makes no sense.
    #[error("invalid grid: {0}")]
    BadGrid(String),
    /// A map height outside the room.
    #[error(
        "a map {height_m:.2} m above the floor is not in the room: give a height between 0 and the ceiling, {ceiling_m:.2} m above the floor (1.1 m is seated head height, 1.7 m standing)"
    )]
    HeightOutsideRoom {
        /// The height asked for (m).
        height_m: f64,
        /// The ceiling's height above the floor (m).
        ceiling_m: f64,
    },
}

/// The horizontal frame maps are drawn in.
#[derive(Clone, Debug, PartialEq)]
pub struct MapFrame {
    /// Origin on the floor plane; u, v horizontal; normal = up.
    pub plane: PlaneFrame,
    /// The floor polygon in map coordinates.
    pub floor_uv: Vec<Point2<f64>>,
    /// Id of the floor surface.
    pub floor_id: String,
}

impl MapFrame {
    /// The map frame of a scene (needs a floor).
    pub fn of_scene(scene: &RadiantScene) -> Result<Self, FieldError> {
        let floor = scene.floor().ok_or(FieldError::NoFloor)?;
        let up = scene.up().ok_or(FieldError::NoFloor)?;
        let cos = floor.frame.normal.dot(&up).abs();
        if cos < FLOOR_HORIZONTAL_COS {
            return Err(FieldError::FloorNotHorizontal {
                id: floor.id.clone(),
            });
        }
        // The floor plane along up through the floor polygon's mean height.
        let h = floor.polygon.iter().map(|p| up.dot(&p.coords)).sum::<f64>()
            / floor.polygon.len() as f64;
        let origin = Point3::from(up.as_ref() * h);
        // Up within 1° of a world axis: u is the first world axis perpendicular to it.
        let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
        let aligned = axes
            .iter()
            .any(|a| a.dot(&up).abs() > AXIS_ALIGNED_DEG.to_radians().cos());
        let u_hint = match axes
            .into_iter()
            .find(|a| aligned && a.dot(&up).abs() < AXIS_ALIGNED_DEG.to_radians().sin())
        {
            Some(a) => a,
            None => {
                let n = floor.polygon.len();
                (0..n)
                    .map(|i| floor.polygon[(i + 1) % n] - floor.polygon[i])
                    .max_by(|a, b| a.norm().total_cmp(&b.norm()))
                    .unwrap_or_else(Vector3::x)
            }
        };
        let plane = PlaneFrame::new(origin, up, &u_hint);
        let floor_uv = floor.polygon.iter().map(|p| plane.to_2d(p)).collect();
        Ok(Self {
            plane,
            floor_uv,
            floor_id: floor.id.clone(),
        })
    }

    /// Up.
    pub fn up(&self) -> Unit<Vector3<f64>> {
        self.plane.normal
    }

    /// The 3D point at map coordinates `uv` and `height_m` above the floor.
    pub fn point(&self, uv: &Point2<f64>, height_m: f64) -> Point3<f64> {
        self.plane.to_3d(uv) + self.plane.normal.as_ref() * height_m
    }

    /// Map coordinates of a 3D point (projected along up).
    pub fn uv(&self, p: &Point3<f64>) -> Point2<f64> {
        self.plane.to_2d(p)
    }

    /// Height of a 3D point above the floor.
    pub fn height(&self, p: &Point3<f64>) -> f64 {
        self.plane.signed_distance(p)
    }

    /// Bounds of the floor in map coordinates: (min, max).
    pub fn floor_bounds(&self) -> (Point2<f64>, Point2<f64>) {
        let mut lo = Point2::new(f64::INFINITY, f64::INFINITY);
        let mut hi = Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in &self.floor_uv {
            lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        (lo, hi)
    }
}
