//! Pinhole cameras with Brown–Conrady distortion, in OpenCV's conventions: x right, y down,
//! z forward; pixel (u, v) has its centre at integer coordinates; u = fx·x_d + cx.

use nalgebra::{Point2, Point3, Vector3};
use serde::{Deserialize, Serialize};

/// Brown–Conrady distortion coefficients in OpenCV order (k1, k2, p1, p2, k3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BrownConrady {
    /// Radial r².
    pub k1: f64,
    /// Radial r⁴.
    pub k2: f64,
    /// Tangential.
    pub p1: f64,
    /// Tangential.
    pub p2: f64,
    /// Radial r⁶.
    pub k3: f64,
}

impl BrownConrady {
    /// From OpenCV's array order.
    pub fn from_array(a: [f64; 5]) -> Self {
        Self {
            k1: a[0],
            k2: a[1],
            p1: a[2],
            p2: a[3],
            k3: a[4],
        }
    }

    /// OpenCV's array order.
    pub fn to_array(&self) -> [f64; 5] {
        [self.k1, self.k2, self.p1, self.p2, self.k3]
    }

    /// Whether all coefficients are zero.
    pub fn is_zero(&self) -> bool {
        self.to_array().iter().all(|c| *c == 0.0)
    }

    /// Distorts normalised image coordinates.
    pub fn distort(&self, p: &Point2<f64>) -> Point2<f64> {
        let (x, y) = (p.x, p.y);
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
        Point2::new(
            x * radial + 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x),
            y * radial + self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y,
        )
    }

    /// Inverts [`BrownConrady::distort`] by Newton's method (exact to ~1e-12 for the distortion of
    /// real lenses within their field of view).
    pub fn undistort(&self, d: &Point2<f64>) -> Point2<f64> {
        if self.is_zero() {
            return *d;
        }
        let mut p = *d;
        for _ in 0..20 {
            let f = self.distort(&p) - d;
            if f.norm() < 1e-14 {
                break;
            }
            // Numerical Jacobian (the function is smooth and cheap).
            let h = 1e-7;
            let jx = (self.distort(&Point2::new(p.x + h, p.y)) - self.distort(&p)) / h;
            let jy = (self.distort(&Point2::new(p.x, p.y + h)) - self.distort(&p)) / h;
            let det = jx.x * jy.y - jy.x * jx.y;
            if det.abs() < 1e-12 {
                break;
            }
            p.x -= (jy.y * f.x - jy.x * f.y) / det;
            p.y -= (-jx.y * f.x + jx.x * f.y) / det;
        }
        p
    }
}

/// A pinhole camera with distortion.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PinholeCamera {
    /// Image width (pixels).
    pub width: u32,
    /// Image height (pixels).
    pub height: u32,
    /// Focal length x (pixels).
    pub fx: f64,
    /// Focal length y (pixels).
    pub fy: f64,
    /// Principal point x.
    pub cx: f64,
    /// Principal point y.
    pub cy: f64,
    /// Lens distortion.
    pub distortion: BrownConrady,
}

impl PinholeCamera {
    /// A camera without distortion.
    pub fn new(width: u32, height: u32, fx: f64, fy: f64, cx: f64, cy: f64) -> Self {
        Self {
            width,
            height,
            fx,
            fy,
            cx,
            cy,
            distortion: BrownConrady::default(),
        }
    }

    /// A distortion-free camera of the given horizontal field of view (radians), centred.
    pub fn from_hfov(width: u32, height: u32, hfov_rad: f64) -> Self {
        let f = (width as f64 / 2.0) / (hfov_rad / 2.0).tan();
        Self::new(
            width,
            height,
            f,
            f,
            (width as f64 - 1.0) / 2.0,
            (height as f64 - 1.0) / 2.0,
        )
    }

    /// Pixel of a point in the camera frame, or `None` behind the camera. The pixel may lie
    /// outside the image: see [`PinholeCamera::contains`].
    pub fn project(&self, p: &Point3<f64>) -> Option<Point2<f64>> {
        if p.z <= 1e-9 {
            return None;
        }
        let d = self.distortion.distort(&Point2::new(p.x / p.z, p.y / p.z));
        Some(Point2::new(
            self.fx * d.x + self.cx,
            self.fy * d.y + self.cy,
        ))
    }

    /// The ray through pixel `px` as a direction with z = 1.
    pub fn unproject(&self, px: &Point2<f64>) -> Vector3<f64> {
        let d = Point2::new((px.x - self.cx) / self.fx, (px.y - self.cy) / self.fy);
        let n = self.distortion.undistort(&d);
        Vector3::new(n.x, n.y, 1.0)
    }

    /// Whether a pixel position lies within the image (pixel centres at integers, so the image
    /// spans −0.5 … width − 0.5).
    pub fn contains(&self, px: &Point2<f64>) -> bool {
        px.x >= -0.5
            && px.y >= -0.5
            && px.x < self.width as f64 - 0.5
            && px.y < self.height as f64 - 0.5
    }

    /// Horizontal field of view (radians), ignoring distortion.
    pub fn hfov_rad(&self) -> f64 {
        2.0 * (self.width as f64 / 2.0 / self.fx).atan()
    }

    /// The same camera with every pixel dimension scaled by `s` (for image pyramids and
    /// supersampling).
    pub fn scaled(&self, s: f64) -> Self {
        let w = (self.width as f64 * s).round() as u32;
        let h = (self.height as f64 * s).round() as u32;
        Self {
            width: w,
            height: h,
            fx: self.fx * s,
            fy: self.fy * s,
            cx: (self.cx + 0.5) * s - 0.5,
            cy: (self.cy + 0.5) * s - 0.5,
            distortion: self.distortion,
        }
    }
}
