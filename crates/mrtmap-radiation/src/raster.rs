//! A temperature raster over a surface: the surface's background radiates texel by texel instead
//! of at one temperature, so a stratified wall, a warm strip above a radiator or a sunlit patch
//! radiates as it is. Features keep their own outlines and temperatures on top of it.
//!
//! Seen from a point, a rastered surface radiates at T_eff with
//! T_eff⁴ = Σ w(dₜ)·Ωₜ·Tₜ⁴ / Σ w(dₜ)·Ωₜ over its texels, Ωₜ the exact solid angle of texel t
//! clipped to the surface's outline, dₜ the direction to the texel's centre and w the receiver's
//! directional weight (1 for a sphere). The surface's view factor itself is unchanged (exact or
//! by rays), so occlusion by furniture acts on the surface as a whole.

use mrtmap_geometry::nalgebra::{Point3, Unit, Vector3};
use mrtmap_geometry::{clip_polygon_to_halfspace, polygon_solid_angle};
use mrtmap_physics::Temperature;
use serde::{Deserialize, Serialize};

use crate::scene::{SceneError, TEMPERATURE_RANGE_C};

/// Largest number of texels of one raster.
pub const MAX_TEXELS: usize = 1_000_000;

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
    /// Texels not observed, whose temperature was filled from their neighbours (indices).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub filled: Vec<usize>,
}

/// One texel clipped to its surface's outline.
#[derive(Clone, Debug, PartialEq)]
pub struct Texel {
    /// Its index in the raster (row · cols + col).
    pub index: usize,
    /// The clipped polygon.
    pub polygon: Vec<Point3<f64>>,
    /// Its centroid.
    pub centre: Point3<f64>,
    /// T⁴ (K⁴).
    pub t4: f64,
}

/// A validated raster.
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    /// As in the file.
    pub file: RasterFile,
    /// The texels with a temperature that overlap the surface, clipped to it.
    pub texels: Vec<Texel>,
}

fn bad(id: &str, detail: String) -> SceneError {
    SceneError::BadRaster {
        id: id.into(),
        detail,
    }
}

impl Raster {
    /// Checks `r` against its surface `polygon` (normal `normal`) and clips its texels.
    pub fn check(
        r: &RasterFile,
        id: &str,
        polygon: &[Point3<f64>],
        normal: &Unit<Vector3<f64>>,
    ) -> Result<Self, SceneError> {
        if !(r.texel_m.is_finite() && r.texel_m >= 0.005 && r.texel_m <= 10.0) {
            return Err(bad(
                id,
                format!("texel_m {} is outside 0.005…10 m", r.texel_m),
            ));
        }
        let n = r.cols.saturating_mul(r.rows);
        if n == 0 || n > MAX_TEXELS {
            return Err(bad(
                id,
                format!(
                    "{} × {} texels: give between 1 and {MAX_TEXELS}",
                    r.cols, r.rows
                ),
            ));
        }
        if r.temperature_c.len() != n {
            return Err(bad(
                id,
                format!(
                    "temperature_c has {} values, but cols × rows is {n}",
                    r.temperature_c.len()
                ),
            ));
        }
        if let Some(&i) = r.filled.iter().find(|&&i| i >= n) {
            return Err(bad(
                id,
                format!("filled names texel {i}, but there are {n}"),
            ));
        }
        let (u, v, o) = (
            Vector3::from(r.u),
            Vector3::from(r.v),
            Point3::from(r.origin),
        );
        if !o.coords.iter().all(|c| c.is_finite())
            || (u.norm() - 1.0).abs() > 1e-3
            || (v.norm() - 1.0).abs() > 1e-3
            || u.dot(&v).abs() > 1e-3
        {
            return Err(bad(
                id,
                "u and v must be perpendicular unit vectors and origin a finite point".into(),
            ));
        }
        if u.dot(normal).abs() > 1e-3 || v.dot(normal).abs() > 1e-3 {
            return Err(bad(id, "u and v must lie in the surface's plane".into()));
        }
        let off = normal.dot(&(o - polygon[0]));
        if off.abs() > 0.01 {
            return Err(bad(
                id,
                format!("origin lies {:.3} m off the surface's plane", off),
            ));
        }
        let (u, v) = (u.normalize(), v.normalize());
        let mut texels = Vec::new();
        for (i, t) in r.temperature_c.iter().enumerate() {
            let Some(t) = t else { continue };
            if !(t.is_finite() && (TEMPERATURE_RANGE_C.0..=TEMPERATURE_RANGE_C.1).contains(t)) {
                return Err(bad(
                    id,
                    format!(
                        "texel {i}: {t} °C is outside {}…{} °C",
                        TEMPERATURE_RANGE_C.0, TEMPERATURE_RANGE_C.1
                    ),
                ));
            }
            let temp = Temperature::from_celsius(*t);
            let (row, col) = ((i / r.cols) as f64, (i % r.cols) as f64);
            let lo = o + u * (col * r.texel_m) + v * (row * r.texel_m);
            let hi = lo + (u + v) * r.texel_m;
            // The outline clipped by the texel's four sides.
            let mut poly = polygon.to_vec();
            for (p, n) in [(lo, u), (lo, v), (hi, -u), (hi, -v)] {
                poly = clip_polygon_to_halfspace(&poly, &p, &n);
                if poly.len() < 3 {
                    break;
                }
            }
            if poly.len() < 3 || mrtmap_geometry::polygon::area_3d(&poly) < 1e-9 {
                continue;
            }
            texels.push(Texel {
                index: i,
                centre: mrtmap_geometry::polygon::centroid(&poly),
                polygon: poly,
                t4: temp.fourth_power(),
            });
        }
        if texels.is_empty() {
            return Err(bad(
                id,
                "no texel with a temperature overlaps the surface".into(),
            ));
        }
        Ok(Self {
            file: r.clone(),
            texels,
        })
    }

    /// Every texel's temperature (°C) through `f` (a camera's level carried to the truth).
    pub fn map_celsius(&mut self, f: impl Fn(f64) -> f64) {
        for t in self.file.temperature_c.iter_mut().flatten() {
            *t = f(*t);
        }
        for t in &mut self.texels {
            if let Some(c) = self.file.temperature_c[t.index] {
                t.t4 = Temperature::from_celsius(c).fourth_power();
            }
        }
    }

    /// The temperature the surface radiates at, seen from `p` by a receiver of directional weight
    /// `weight` (module docs); `None` when no texel faces `p`.
    pub fn seen_from(
        &self,
        p: &Point3<f64>,
        weight: &dyn Fn(&Vector3<f64>) -> f64,
    ) -> Option<Temperature> {
        let (mut num, mut den) = (0.0, 0.0);
        for t in &self.texels {
            let omega = polygon_solid_angle(p, &t.polygon).abs();
            if omega <= 0.0 {
                continue;
            }
            let w = match (t.centre - p).try_normalize(1e-12) {
                Some(d) => weight(&d),
                None => 1.0,
            } * omega;
            num += w * t.t4;
            den += w;
        }
        (den > 0.0).then(|| Temperature::from_fourth_power(num / den))
    }
}
