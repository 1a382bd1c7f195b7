//! One thermal frame made ready for fusion: its depth frame back-projected (camera frame, at a
//! pixel stride, with normals from a wider baseline), and its thermal image in kelvin.

use mrtmap_io::{Image16, ThermalEncoding};

/// Depth back-projection lives in mrtmap-io, where tracking uses it too.
pub use mrtmap_io::depth::{DepthPoints, DepthSampling, RayTable, depth_points};

/// A thermal image in kelvin (f32), row-major.
#[derive(Clone, Debug, Default)]
pub struct ThermalImage {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Kelvin.
    pub kelvin: Vec<f32>,
}

impl ThermalImage {
    /// Decodes raw pixels.
    pub fn from_raw(img: &Image16, enc: ThermalEncoding) -> Self {
        Self {
            width: img.width,
            height: img.height,
            kelvin: img.data.iter().map(|&r| enc.kelvin(r) as f32).collect(),
        }
    }

    /// Bilinear sample at pixel position (u, v) (centres at integers) and the local contrast
    /// (max − min of the four pixels used), or `None` outside the image.
    pub fn sample(&self, u: f64, v: f64) -> Option<(f64, f64)> {
        let (w, h) = (self.width as i64, self.height as i64);
        if u < -0.5 || v < -0.5 || u > w as f64 - 0.5 || v > h as f64 - 0.5 {
            return None;
        }
        let u = u.clamp(0.0, (w - 1) as f64);
        let v = v.clamp(0.0, (h - 1) as f64);
        let (u0, v0) = (
            (u.floor() as i64).min(w - 2).max(0),
            (v.floor() as i64).min(h - 2).max(0),
        );
        let (fu, fv) = (u - u0 as f64, v - v0 as f64);
        let at = |x: i64, y: i64| self.kelvin[(y * w + x) as usize] as f64;
        let (a, b, c, d) = (
            at(u0, v0),
            at(u0 + 1, v0),
            at(u0, v0 + 1),
            at(u0 + 1, v0 + 1),
        );
        let t = (1.0 - fv) * ((1.0 - fu) * a + fu * b) + fv * ((1.0 - fu) * c + fu * d);
        let contrast = a.max(b).max(c).max(d) - a.min(b).min(c).min(d);
        Some((t, contrast))
    }
}
