//! A temperature raster over a surface: the surface's background radiates texel by texel instead
//! of at one temperature, so a stratified wall, a warm strip above a radiator or a sunlit patch
//! radiates as it is. Features keep their own outlines and temperatures on top of it.
//!
//! Seen from a point, a rastered surface radiates at T_eff with
//! T_eff⁴ = Σ w(dₜ)·Ωₜ·Tₜ⁴ / Σ w(dₜ)·Ωₜ over its texels, Ωₜ the exact solid angle of texel t
//! clipped to the surface's outline, dₜ the direction to the texel's centre and w the receiver's
//! directional weight (1 for a sphere). The surface's view factor itself is unchanged (exact or
//! by rays), so occlusion by furniture acts on the surface as a whole.
//!
//! The raster as scene.json writes it is a [`RasterFile`]; here it is checked against its surface
//! ([`Raster::check`]: texel size and count, axes in the surface's plane, temperatures and unseen
//! patches within the scene's limits) and its texels clipped to the surface's outline.

use mrtmap_geometry::nalgebra::{Point3, Unit, Vector3};
use mrtmap_geometry::{clip_polygon_to_halfspace, polygon_solid_angle};
use mrtmap_physics::Temperature;

use super::error::SceneError;
use super::file::RasterFile;
use super::limits::TEMPERATURE_RANGE_C;

/// Largest number of texels of one raster.
pub const MAX_TEXELS: usize = 1_000_000;

/// The smallest texel (m).
const MIN_TEXEL_M: f64 = 0.005;

/// The largest texel (m).
const MAX_TEXEL_M: f64 = 10.0;

/// `u` and `v` must be unit length, perpendicular to each other and lie in the surface's plane
/// to within this (as a length, or a cosine).
const AXIS_TOLERANCE: f64 = 1e-3;

/// The raster's origin must lie within this of the surface's plane (m).
const ORIGIN_OFF_PLANE_M: f64 = 0.01;

/// How much of a surface, as seen from a point, is one unseen patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnseenShare {
    /// The patch's share of the surface's weighted solid angle (0…1).
    pub share: f64,
    /// The temperature the raster gives the patch, seen from the point.
    pub filled: Temperature,
    /// The patch's standard deviation about `filled` (K): the root mean square of T − filled for
    /// T uniform over the patch's range.
    pub std_k: f64,
}

/// √E[(T − f)²] for T uniform on [lo, hi] (K).
fn uniform_rms_about(lo: f64, hi: f64, f: f64) -> f64 {
    if hi - lo < 1e-9 {
        return (lo - f).abs();
    }
    (((hi - f).powi(3) - (lo - f).powi(3)) / (3.0 * (hi - lo)))
        .max(0.0)
        .sqrt()
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
    /// For each of `texels`, the unseen patch it belongs to (index into `file.unseen`).
    pub patch_of: Vec<Option<usize>>,
}

/// Each texel's unseen patch (index into `r.unseen`) over the `n` texels, checking the patches:
/// ranges low then high within the scene's temperatures, texels that exist, in one patch at most.
fn patch_of_texel(r: &RasterFile, id: &str, n: usize) -> Result<Vec<Option<usize>>, SceneError> {
    let mut patch_of_index: Vec<Option<usize>> = vec![None; n];
    for (k, patch) in r.unseen.iter().enumerate() {
        let [lo, hi] = patch.range_c;
        let range = TEMPERATURE_RANGE_C.0..=TEMPERATURE_RANGE_C.1;
        if !(lo.is_finite()
            && hi.is_finite()
            && lo <= hi
            && range.contains(&lo)
            && range.contains(&hi))
        {
            return Err(bad(
                id,
                format!(
                    "unseen patch {k}: range_c [{lo}, {hi}] must be two temperatures, low then high, within {}…{} °C",
                    TEMPERATURE_RANGE_C.0, TEMPERATURE_RANGE_C.1
                ),
            ));
        }
        for &i in &patch.texels {
            match patch_of_index.get_mut(i) {
                None => {
                    return Err(bad(
                        id,
                        format!("unseen patch {k} names texel {i}, but there are {n}"),
                    ));
                }
                Some(Some(other)) => {
                    return Err(bad(
                        id,
                        format!("texel {i} is in unseen patches {other} and {k}"),
                    ));
                }
                Some(slot) => *slot = Some(k),
            }
        }
    }
    Ok(patch_of_index)
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
        if !(r.texel_m.is_finite() && r.texel_m >= MIN_TEXEL_M && r.texel_m <= MAX_TEXEL_M) {
            return Err(bad(
                id,
                format!(
                    "texel_m {} is outside {MIN_TEXEL_M}…{MAX_TEXEL_M} m",
                    r.texel_m
                ),
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
        let patch_of_index = patch_of_texel(r, id, n)?;
        let (u, v, o) = (
            Vector3::from(r.u),
            Vector3::from(r.v),
            Point3::from(r.origin),
        );
        if !o.coords.iter().all(|c| c.is_finite())
            || (u.norm() - 1.0).abs() > AXIS_TOLERANCE
            || (v.norm() - 1.0).abs() > AXIS_TOLERANCE
            || u.dot(&v).abs() > AXIS_TOLERANCE
        {
            return Err(bad(
                id,
                "u and v must be perpendicular unit vectors and origin a finite point".into(),
            ));
        }
        if u.dot(normal).abs() > AXIS_TOLERANCE || v.dot(normal).abs() > AXIS_TOLERANCE {
            return Err(bad(id, "u and v must lie in the surface's plane".into()));
        }
        let off = normal.dot(&(o - polygon[0]));
        if off.abs() > ORIGIN_OFF_PLANE_M {
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
        let patch_of = texels.iter().map(|t| patch_of_index[t.index]).collect();
        Ok(Self {
            file: r.clone(),
            texels,
            patch_of,
        })
    }

    /// Unseen patch `patch`'s area (m², clipped to the surface) and its centroid; `None` when none
    /// of its texels overlaps the surface.
    pub fn unseen_extent(&self, patch: usize) -> Option<(f64, Point3<f64>)> {
        let (mut area, mut sum) = (0.0, Vector3::zeros());
        for (t, k) in self.texels.iter().zip(&self.patch_of) {
            if *k == Some(patch) {
                let a = mrtmap_geometry::polygon::area_3d(&t.polygon);
                area += a;
                sum += t.centre.coords * a;
            }
        }
        (area > 0.0).then(|| (area, Point3::from(sum / area)))
    }

    /// Every texel's temperature (°C) through `f` (a camera's level carried to the truth).
    pub fn map_celsius(&mut self, f: impl Fn(f64) -> f64) {
        for t in self.file.temperature_c.iter_mut().flatten() {
            *t = f(*t);
        }
        for p in &mut self.file.unseen {
            let (a, b) = (f(p.range_c[0]), f(p.range_c[1]));
            p.range_c = [a.min(b), a.max(b)];
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
        self.seen_with_unseen(p, weight).map(|s| s.0)
    }

    /// As [`Self::seen_from`], with each unseen patch's share of what the point sees of the
    /// surface (one entry per patch of `file.unseen`, in order).
    pub fn seen_with_unseen(
        &self,
        p: &Point3<f64>,
        weight: &dyn Fn(&Vector3<f64>) -> f64,
    ) -> Option<(Temperature, Vec<UnseenShare>)> {
        let (mut num, mut den) = (0.0, 0.0);
        let mut per_patch = vec![(0.0f64, 0.0f64); self.file.unseen.len()];
        for (t, patch) in self.texels.iter().zip(&self.patch_of) {
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
            if let Some(k) = patch {
                per_patch[*k].0 += w;
                per_patch[*k].1 += w * t.t4;
            }
        }
        if den <= 0.0 {
            return None;
        }
        let shares = per_patch
            .iter()
            .zip(&self.file.unseen)
            .map(|(&(w, wt4), patch)| {
                if w <= 0.0 {
                    return UnseenShare {
                        share: 0.0,
                        filled: Temperature::from_celsius(patch.range_c[0]),
                        std_k: 0.0,
                    };
                }
                let filled = Temperature::from_fourth_power(wt4 / w);
                let c = filled.celsius();
                UnseenShare {
                    share: w / den,
                    filled,
                    std_k: uniform_rms_about(patch.range_c[0], patch.range_c[1], c),
                }
            })
            .collect();
        Some((Temperature::from_fourth_power(num / den), shares))
    }
}
