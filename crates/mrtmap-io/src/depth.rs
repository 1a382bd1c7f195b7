//! Depth images back-projected into the depth camera's frame: the rays of every pixel, and the
//! points with normals at a pixel stride. Fusion and tracking both use it.

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Point2, Point3, Vector3};

use crate::Image16;

/// Back-projection settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthSampling {
    /// Use every `stride`-th pixel in each direction; 0: about one depth point per thermal pixel
    /// (see `DepthSampling::auto_stride`).
    pub stride: u32,
    /// Normals from neighbours this many pixels away (robust to depth noise).
    pub normal_radius_px: u32,
    /// Valid range (m).
    pub min_m: f64,
    /// Valid range (m).
    pub max_m: f64,
}

impl Default for DepthSampling {
    fn default() -> Self {
        Self {
            stride: 0,
            normal_radius_px: 6,
            min_m: 0.3,
            max_m: 5.0,
        }
    }
}

impl DepthSampling {
    /// The stride that gives about one depth point per thermal pixel: the ratio of the two
    /// cameras' focal lengths in pixels, rounded (3 for a 640×480 D435 beside a Lepton 3.5, 1 for
    /// a depth image no sharper than the thermal one). Sampling the depth more densely than the
    /// thermal image adds time, not information, to the temperatures.
    pub fn auto_stride(depth: &PinholeCamera, thermal: &PinholeCamera) -> u32 {
        let ratio = depth.fx.max(depth.fy) / thermal.fx.max(thermal.fy).max(1e-9);
        (ratio.round() as u32).clamp(1, 8)
    }
}

/// Unit ray directions (z = 1) of every pixel, precomputed once per camera.
pub struct RayTable {
    width: u32,
    rays: Vec<Vector3<f64>>,
}

impl RayTable {
    /// The table of a camera.
    pub fn new(cam: &PinholeCamera) -> Self {
        let mut rays = Vec::with_capacity((cam.width * cam.height) as usize);
        for v in 0..cam.height {
            for u in 0..cam.width {
                rays.push(cam.unproject(&Point2::new(u as f64, v as f64)));
            }
        }
        Self {
            width: cam.width,
            rays,
        }
    }

    /// The unit-depth ray (z = 1) of pixel (u, v).
    pub fn ray(&self, u: u32, v: u32) -> &Vector3<f64> {
        &self.rays[(v * self.width + u) as usize]
    }
}

/// Depth points of a frame in the depth camera's frame, with unit normals facing the camera.
#[derive(Clone, Debug, Default)]
pub struct DepthPoints {
    /// Points (m).
    pub points: Vec<Point3<f64>>,
    /// Normals.
    pub normals: Vec<Vector3<f64>>,
}

/// Back-projects a depth image. Points without four consistent neighbours (edges, holes) are left
/// out, so every point has a normal.
pub fn depth_points(img: &Image16, rays: &RayTable, scale: f64, s: &DepthSampling) -> DepthPoints {
    let (w, h) = (img.width, img.height);
    let r = s.normal_radius_px.max(1);
    let z_at = |u: u32, v: u32| {
        let z = img.data[(v * w + u) as usize] as f64 / scale;
        (z >= s.min_m && z <= s.max_m).then_some(z)
    };
    let mut out = DepthPoints::default();
    let stride = s.stride.max(1);
    let mut v = r;
    while v + r < h {
        let mut u = r;
        while u + r < w {
            if let Some(z) = z_at(u, v) {
                let nb = [
                    z_at(u - r, v),
                    z_at(u + r, v),
                    z_at(u, v - r),
                    z_at(u, v + r),
                ];
                if let [Some(zl), Some(zr), Some(zu), Some(zd)] = nb {
                    // Neighbours across a depth jump would give a wrong normal.
                    let jump = 0.25 * z;
                    if (zl - z).abs() < jump
                        && (zr - z).abs() < jump
                        && (zu - z).abs() < jump
                        && (zd - z).abs() < jump
                    {
                        let p = Point3::from(rays.ray(u, v) * z);
                        let dx = rays.ray(u + r, v) * zr - rays.ray(u - r, v) * zl;
                        let dy = rays.ray(u, v + r) * zd - rays.ray(u, v - r) * zu;
                        let mut n = dy.cross(&dx);
                        if n.dot(&p.coords) > 0.0 {
                            n = -n;
                        }
                        if let Some(n) = n.try_normalize(1e-12) {
                            out.points.push(p);
                            out.normals.push(n);
                        }
                    }
                }
            }
            u += stride;
        }
        v += stride;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_automatic_stride_gives_about_one_depth_point_per_thermal_pixel() {
        let lepton = PinholeCamera::new(160, 120, 147.3, 147.3, 79.5, 59.5);
        let d435 = PinholeCamera::new(640, 480, 385.0, 385.0, 319.5, 239.5);
        assert_eq!(DepthSampling::auto_stride(&d435, &lepton), 3);
        let small = PinholeCamera::new(160, 120, 96.25, 96.25, 79.5, 59.5);
        assert_eq!(DepthSampling::auto_stride(&small, &lepton), 1);
        let boson = PinholeCamera::new(640, 512, 800.0, 800.0, 319.5, 255.5);
        assert_eq!(DepthSampling::auto_stride(&d435, &boson), 1);
    }
}
