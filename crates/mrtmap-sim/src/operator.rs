//! The person holding the rig, as the simulator sees them: a body behind the camera that glass
//! mirrors (its own module: the renderer, the sensors and the grey room all read it).

use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Vector3};

/// The person holding the rig: a vertical cylinder behind the camera, which glass mirrors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Operator {
    /// The body's axis on the floor plan (room frame).
    pub axis: Point2<f64>,
    /// Its radius (m).
    pub radius_m: f64,
    /// The top of the head above the floor (m).
    pub top_m: f64,
}

/// The operator's clothed body's surface temperature (°C).
pub const OPERATOR_C: f64 = 34.0;
/// How far behind the camera the body's axis stands (m).
pub const OPERATOR_BEHIND_M: f64 = 0.25;
/// The body's radius (m).
pub const OPERATOR_RADIUS_M: f64 = 0.2;
/// How far above the camera the head's top reaches (m).
pub const OPERATOR_ABOVE_M: f64 = 0.25;

impl Operator {
    /// The operator of a camera at `room_from_cam` (looking along its +z).
    pub fn behind(room_from_cam: &Isometry3<f64>) -> Self {
        let o = room_from_cam.translation.vector;
        let f = room_from_cam.rotation * Vector3::z();
        let h = Vector3::new(f.x, f.y, 0.0);
        let back = if h.norm() > 1e-6 {
            -h.normalize()
        } else {
            Vector3::zeros()
        };
        Self {
            axis: Point2::new(
                o.x + OPERATOR_BEHIND_M * back.x,
                o.y + OPERATOR_BEHIND_M * back.y,
            ),
            radius_m: OPERATOR_RADIUS_M,
            top_m: o.z + OPERATOR_ABOVE_M,
        }
    }

    /// The distance along `d` from `p` at which the ray enters the body, if it does.
    pub fn hit(&self, p: &Point3<f64>, d: &Vector3<f64>) -> Option<f64> {
        let (px, py) = (p.x - self.axis.x, p.y - self.axis.y);
        let a = d.x * d.x + d.y * d.y;
        if a < 1e-12 {
            return None;
        }
        let b = 2.0 * (px * d.x + py * d.y);
        let c = px * px + py * py - self.radius_m * self.radius_m;
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return None;
        }
        let t = (-b - disc.sqrt()) / (2.0 * a);
        let z = p.z + t * d.z;
        (t > 1e-6 && (0.0..=self.top_m).contains(&z)).then_some(t)
    }
}
