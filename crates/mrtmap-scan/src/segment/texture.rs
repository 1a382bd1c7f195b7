//! Thermal texturing on the room model: every thermal pixel of the fused frames cast onto the
//! surfaces segmentation found, so that what the depth camera did not see still gets its
//! temperature from the thermal camera.
//!
//! An active-stereo depth camera gets no depth from window glass (its projector's pattern passes
//! through), from black or shiny surfaces, beyond its range and in its dropouts; the fused cloud
//! has holes there, while the thermal camera saw those places (glass is opaque at 8–14 µm). Once
//! the envelope and the furniture are known, each thermal pixel's ray is cast against that model
//! (the nearest surface or piece of furniture); the frame's measured depth is the occlusion test:
//! where the depth camera measured something nearer than the model along that line (a person, a
//! chair, clutter), the pixel is not the surface's. Where it measured nothing, or something
//! farther (glass seen through), the pixel is. Texels the cloud already covers keep the cloud's
//! temperatures; each texel the cloud left empty and texturing saw becomes a sample on the surface
//! with the pixels' weighted mean temperature (each corrected by the frame's self-calibration
//! offset and the vignetting) and the number of pixels behind it, for the feature and background
//! analysis as a cloud point would be.

use std::collections::{HashMap, HashSet};

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Point2, Point3, Vector3};
use mrtmap_geometry::{BOX_TRIANGLES, PlaneFrame, ray_triangle};
use mrtmap_io::Recording;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::SegmentParams;
use super::membership::{Points, SurfaceGeom};
use crate::frame::ThermalImage;
use crate::fuse::{FusedFrame, from_pose7};

/// What texturing needs: the recording (its thermal and depth images), the fused frames with
/// their poses and offsets, and the vignetting self-calibration found.
pub struct TextureInput<'a> {
    /// The recording.
    pub recording: &'a Recording,
    /// The fused frames.
    pub frames: &'a [FusedFrame],
    /// Vignetting (K at the image corner, ρ = 1).
    pub vignetting_k: f64,
}

/// Texturing settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureParams {
    /// Frames used at most (spread evenly over the scan).
    pub max_frames: usize,
    /// Rays beyond this incidence are not used (degrees from the normal).
    pub max_incidence_deg: f64,
    /// A pixel whose 3×3 neighbourhood spans more than this (K) mixes two surfaces: not used.
    pub edge_drop_k: f64,
    /// A texel needs this many pixels.
    pub min_pixels: u32,
    /// Texels whose centre lies closer than this to their surface's outline are not filled
    /// (m): there the next surface's temperature is blurred in (optics, the bolometer's time
    /// constant). On an L-shaped walk a row of filled texels under the ceiling, 1 K warm, joined
    /// the warm blur above a radiator into one 9 m² "feature" whose outline swallowed the window
    /// (the field study's walk 3: 1.22 K at the grid's worst node).
    pub edge_clearance_m: f64,
    /// Each piece of furniture is grown by this much on every side for the cast (m): a ray that
    /// passes this close to a box is the box's (the thermal pixel's blur and the box's own
    /// placement reach that far). Without it the top rows of a bookcase's pixels passed over the
    /// box found 3 cm lower than the real one and landed on the wall behind: a 1.4 m², 0.6 K warm
    /// "feature" above the L-shaped room's bookcase on the field study's walks 1-3.
    pub furniture_margin_m: f64,
    /// The person holding the rig, whom glass mirrors, as seen from the camera: a vertical cylinder
    /// of this radius (m) whose axis stands [`TextureParams::operator_behind_m`] behind the camera
    /// (opposite its horizontal view), from [`TextureParams::operator_below_m`] under the camera to
    /// [`TextureParams::operator_above_m`] over it. A pixel whose ray, mirrored by the surface it
    /// lands on, passes through it may show the operator's reflection rather than the surface (a
    /// 34 °C body in glass of emissivity 0.84: about +1.5 K in the middle of the pane, moving
    /// with the camera): it is not used where other pixels saw the texel. Only texels the cloud left empty are textured, and glass
    /// is where that happens. 0: keep every pixel.
    pub operator_radius_m: f64,
    /// How far behind the camera the operator's body's axis stands (m).
    pub operator_behind_m: f64,
    /// How far the operator's body reaches below the camera (m).
    pub operator_below_m: f64,
    /// How far above the camera (m).
    pub operator_above_m: f64,
}

impl Default for TextureParams {
    fn default() -> Self {
        Self {
            max_frames: 600,
            max_incidence_deg: 75.0,
            edge_drop_k: 3.0,
            min_pixels: 3,
            edge_clearance_m: 0.12,
            furniture_margin_m: 0.06,
            // The simulator's operator: a body of 0.2 m radius 0.25 m behind the camera, with 15 cm
            // for the blur and the pose's error; from the floor (a camera held at most 2 m up) to
            // the head. A cylinder of 0.5 m about the camera itself also left out the views that
            // pass beside it, where nobody stands: an office walk lost a fifth of its window
            // (area ×0.81, the map 0.67 K off in front of it; ×1.02 and 0.14 K black).
            operator_radius_m: 0.35,
            operator_behind_m: 0.25,
            operator_below_m: 2.0,
            operator_above_m: 0.35,
        }
    }
}

/// One surface of the model as texturing sees it.
pub(crate) struct ModelSurface<'a> {
    /// Its plane frame (2D coordinates of its texels).
    pub frame: &'a PlaneFrame,
    /// Its outline in that frame.
    pub polygon: &'a [Point2<f64>],
    /// The texel grid's origin (the outline's lower corner) and size.
    pub texel_origin: Point2<f64>,
    /// Texels (i, j) the cloud already covers.
    pub covered: HashSet<(i64, i64)>,
}

/// Texture samples for texels the cloud left empty.
#[derive(Default)]
pub(crate) struct Textured {
    /// Surface of each sample.
    pub surface: Vec<usize>,
    /// Position (world): the texel's centre on its surface.
    pub pos: Vec<Point3<f64>>,
    /// Its surface's normal.
    pub nrm: Vec<Vector3<f64>>,
    /// Temperature (K).
    pub temp_k: Vec<f64>,
    /// Pixels behind it.
    pub pixels: Vec<u32>,
}

/// What texturing did, for segment.json.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TextureReport {
    /// Frames cast.
    pub frames: usize,
    /// Pixels that landed on a surface and were used.
    pub pixels_used: u64,
    /// Pixels that another object hid (measured depth nearer than the model).
    pub pixels_occluded: u64,
    /// Pixels that landed on furniture.
    pub pixels_on_furniture: u64,
    /// Pixels that could show the operator mirrored: left out of every texel that enough other
    /// pixels saw.
    #[serde(default)]
    pub pixels_mirroring_operator: u64,
    /// Texels only such pixels saw (taken from them rather than left unseen).
    #[serde(default)]
    pub texels_only_mirroring: u64,
    /// Texels the cloud had left empty that texturing filled, per surface index.
    pub texels_filled: Vec<usize>,
    /// Time it took (s, wall).
    #[serde(default)]
    pub seconds: f64,
}

impl TextureReport {
    /// Each surface's share seen by texturing only (its texels filled), at most its observed share.
    pub(crate) fn set_fractions(&self, surfaces: &mut [super::SurfaceSummary], texel_m: f64) {
        for (summary, filled) in surfaces.iter_mut().zip(&self.texels_filled) {
            let area = *filled as f64 * texel_m * texel_m;
            summary.textured_fraction =
                (area / summary.area_m2.max(1e-9)).min(summary.observed_fraction);
        }
    }
}

/// What a ray hits first: a surface (index, distance) or furniture.
enum ModelHit {
    Surface(usize, f64),
    Furniture,
}

fn cast(
    surfaces: &[ModelSurface<'_>],
    boxes: &[[Point3<f64>; 8]],
    o: &Point3<f64>,
    d: &Vector3<f64>,
) -> Option<ModelHit> {
    let mut best: Option<(f64, Option<usize>)> = None;
    for (s, m) in surfaces.iter().enumerate() {
        let n = m.frame.normal;
        let den = n.dot(d);
        if den.abs() < 1e-9 {
            continue;
        }
        let t = n.dot(&(m.frame.origin - o)) / den;
        if t <= 1e-6 || best.is_some_and(|b| t >= b.0) {
            continue;
        }
        let q = m.frame.to_2d(&(o + d * t));
        if mrtmap_geometry::polygon::point_in_polygon_fast(&q, m.polygon) {
            best = Some((t, Some(s)));
        }
    }
    for corners in boxes {
        for tri in BOX_TRIANGLES.iter() {
            let v = [&corners[tri[0]], &corners[tri[1]], &corners[tri[2]]];
            if let Some(t) = ray_triangle(o, d, v)
                && best.is_none_or(|b| t < b.0)
            {
                best = Some((t, None));
            }
        }
    }
    best.map(|(t, s)| match s {
        Some(s) => ModelHit::Surface(s, t),
        None => ModelHit::Furniture,
    })
}

/// The smallest valid depth (m) in the 3×3 pixels around (u, v), if any.
fn measured_depth(depth: &mrtmap_io::Image16, scale: f64, u: f64, v: f64) -> Option<f64> {
    let (w, h) = (depth.width as i64, depth.height as i64);
    let (iu, iv) = (u.round() as i64, v.round() as i64);
    let mut best: Option<f64> = None;
    for dv in -1..=1 {
        for du in -1..=1 {
            let (x, y) = (iu + du, iv + dv);
            if x < 0 || y < 0 || x >= w || y >= h {
                continue;
            }
            let raw = depth.data[(y * w + x) as usize];
            if raw > 0 {
                let z = raw as f64 / scale;
                best = Some(best.map_or(z, |b: f64| b.min(z)));
            }
        }
    }
    best
}

/// The 3×3 spread (max − min, K) around pixel (u, v).
fn contrast(img: &ThermalImage, u: usize, v: usize) -> f64 {
    let (w, h) = (img.width as usize, img.height as usize);
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for y in v.saturating_sub(1)..=(v + 1).min(h - 1) {
        for x in u.saturating_sub(1)..=(u + 1).min(w - 1) {
            let t = img.kelvin[y * w + x];
            lo = lo.min(t);
            hi = hi.max(t);
        }
    }
    f64::from(hi - lo)
}

/// The distance from `q` to the nearest edge of `poly` (m).
fn distance_to_outline(q: &Point2<f64>, poly: &[Point2<f64>]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let ab = b - a;
            let t = ((q - a).dot(&ab) / ab.norm_squared().max(1e-18)).clamp(0.0, 1.0);
            (q - (a + ab * t)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether the ray from `o` along `d` (unit) that meets a surface of normal `n` at `x` comes back,
/// mirrored, through the operator's body: the vertical cylinder of `params` behind the camera (which
/// looks along `forward`), with `up` the room's up.
fn mirrors_operator(
    o: &Point3<f64>,
    forward: &Vector3<f64>,
    x: &Point3<f64>,
    d: &Vector3<f64>,
    n: &Vector3<f64>,
    up: &Vector3<f64>,
    params: &TextureParams,
) -> bool {
    let r = d - n * (2.0 * d.dot(n));
    // The body's axis: behind the camera, against its horizontal view.
    let fh = forward - up * forward.dot(up);
    let behind = if fh.norm() > 1e-6 {
        -fh.normalize() * params.operator_behind_m
    } else {
        Vector3::zeros()
    };
    let v = x - (o + behind);
    let vh = v - up * v.dot(up);
    let rh = r - up * r.dot(up);
    let rad = params.operator_radius_m;
    let a = rh.norm_squared();
    let b = 2.0 * vh.dot(&rh);
    let c = vh.norm_squared() - rad * rad;
    // The stretch of the mirrored ray (s ≥ 0) within the cylinder's radius.
    let (s0, s1) = if a < 1e-12 {
        if c > 0.0 {
            return false;
        }
        (0.0, 100.0)
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return false;
        }
        let q = disc.sqrt();
        ((-b - q) / (2.0 * a), (-b + q) / (2.0 * a))
    };
    if s1 <= 0.0 {
        return false;
    }
    let s0 = s0.max(0.0);
    // Its height relative to the camera is linear in s: does it overlap the body's?
    let (h0, h1) = (v.dot(up) + s0 * r.dot(up), v.dot(up) + s1 * r.dot(up));
    h0.min(h1) <= params.operator_above_m && h0.max(h1) >= -params.operator_below_m
}

/// Per-texel sums (Σw, Σw·T, pixels) of the pixels that cannot mirror the operator, and of those
/// that could.
type TexelSums = HashMap<(usize, i64, i64), [(f64, f64, u32); 2]>;

/// What every frame's cast shares: the model, the thermal camera's pixel rays, the settings.
struct Caster<'a> {
    input: &'a TextureInput<'a>,
    surfaces: &'a [ModelSurface<'a>],
    boxes: &'a [[Point3<f64>; 8]],
    texel_m: f64,
    params: &'a TextureParams,
    rays: Vec<Vector3<f64>>,
    /// The room's up (unit).
    up: Vector3<f64>,
}

impl Caster<'_> {
    /// One frame's pixels cast onto the model: per-texel sums of the texels the cloud left empty,
    /// and the pixels (used, hidden by something nearer, on furniture). `None` when its images
    /// cannot be read or the thermal image is not the rig's size.
    fn frame(&self, f: &FusedFrame) -> Option<(TexelSums, [u64; 4])> {
        let rec = self.input.recording;
        let cam = &rec.rig.thermal;
        let (w, h) = (cam.width as usize, cam.height as usize);
        let raw = rec.read_thermal(rec.thermal.get(f.thermal)?).ok()?;
        let img = ThermalImage::from_raw(&raw, rec.rig.thermal_encoding);
        if img.width as usize != w || img.height as usize != h {
            return None;
        }
        let depth = rec.read_depth(rec.depth.get(f.depth)?).ok()?;
        let wt = from_pose7(&f.world_from_thermal);
        let depth_from_world = from_pose7(&f.world_from_depth).inverse();
        let o = Point3::from(wt.translation.vector);
        let forward = wt.rotation * Vector3::z();
        let cos_max = self.params.max_incidence_deg.to_radians().cos();
        // The fusion's observation weights (incidence, distance, image position); mixed pixels
        // are left out here rather than weighted.
        let observation = crate::observe::ObservationParams::default();
        let rmax2 = (cam.cx.powi(2) + cam.cy.powi(2)).max(1e-9);
        let mut sums = TexelSums::new();
        let mut counts = [0u64; 4];
        for v in 0..h {
            for u in 0..w {
                let d = wt.rotation * self.rays[v * w + u];
                let (s, t) = match cast(self.surfaces, self.boxes, &o, &d) {
                    Some(ModelHit::Surface(s, t)) => (s, t),
                    Some(ModelHit::Furniture) => {
                        counts[2] += 1;
                        continue;
                    }
                    None => continue,
                };
                let m = &self.surfaces[s];
                let cos = m.frame.normal.dot(&d).abs();
                if cos < cos_max || contrast(&img, u, v) > self.params.edge_drop_k {
                    continue;
                }
                let x = o + d * t;
                // The occlusion test: what the depth camera measured along its own line of
                // sight to this point.
                let xd = depth_from_world * x;
                if xd.z > 0.0
                    && let Some(px) = rec.rig.depth.project(&xd)
                    && let Some(z) = measured_depth(&depth, rec.rig.depth_scale, px.x, px.y)
                    && z < xd.z - (0.05 + 0.03 * xd.z + 0.0125 * xd.z * xd.z)
                {
                    counts[1] += 1;
                    continue;
                }
                let q = m.frame.to_2d(&x);
                let key = (
                    ((q.x - m.texel_origin.x) / self.texel_m).floor() as i64,
                    ((q.y - m.texel_origin.y) / self.texel_m).floor() as i64,
                );
                if m.covered.contains(&key) {
                    continue;
                }
                let mirrored = self.params.operator_radius_m > 0.0
                    && mirrors_operator(
                        &o,
                        &forward,
                        &x,
                        &d,
                        &m.frame.normal,
                        &self.up,
                        self.params,
                    );
                let px = Point2::new(u as f64, v as f64);
                let rho = ((px.x - cam.cx).powi(2) + (px.y - cam.cy).powi(2)) / rmax2;
                let temp =
                    f64::from(img.kelvin[v * w + u]) - f.offset_k - self.input.vignetting_k * rho;
                let wgt = crate::observe::weight(cos, t, &px, 0.0, cam, &observation);
                let e = &mut sums.entry((s, key.0, key.1)).or_default()[usize::from(mirrored)];
                e.0 += wgt;
                e.1 += wgt * temp;
                e.2 += 1;
                counts[if mirrored { 3 } else { 0 }] += 1;
            }
        }
        Some((sums, counts))
    }
}

/// Casts the frames' thermal pixels onto the model; returns a sample for every texel the cloud
/// left empty and enough pixels saw.
pub(crate) fn texture(
    input: &TextureInput<'_>,
    surfaces: &[ModelSurface<'_>],
    boxes: &[[Point3<f64>; 8]],
    up: &Vector3<f64>,
    texel_m: f64,
    params: &TextureParams,
) -> (Textured, TextureReport) {
    let t0 = std::time::Instant::now();
    let cam: &PinholeCamera = &input.recording.rig.thermal;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let grown: Vec<[Point3<f64>; 8]> = boxes
        .iter()
        .map(|b| grown_box(b, params.furniture_margin_m))
        .collect();
    let caster = Caster {
        input,
        surfaces,
        boxes: &grown,
        texel_m,
        params,
        rays: (0..h)
            .flat_map(|v| (0..w).map(move |u| (u, v)))
            .map(|(u, v)| cam.unproject(&Point2::new(u as f64, v as f64)).normalize())
            .collect(),
        up: up.normalize(),
    };
    let n = input.frames.len();
    let take = params.max_frames.min(n);
    let picked: Vec<&FusedFrame> = (0..take)
        .map(|j| &input.frames[j * n / take.max(1)])
        .collect();
    let per_frame: Vec<(TexelSums, [u64; 4])> =
        picked.par_iter().filter_map(|f| caster.frame(f)).collect();
    let mut report = TextureReport {
        frames: per_frame.len(),
        texels_filled: vec![0; surfaces.len()],
        ..Default::default()
    };
    let mut all = TexelSums::new();
    for (sums, c) in per_frame {
        report.pixels_used += c[0];
        report.pixels_occluded += c[1];
        report.pixels_on_furniture += c[2];
        report.pixels_mirroring_operator += c[3];
        for (k, v) in sums {
            let e = all.entry(k).or_default();
            for (a, b) in e.iter_mut().zip(v) {
                a.0 += b.0;
                a.1 += b.1;
                a.2 += b.2;
            }
        }
    }
    let mut keys: Vec<_> = all.keys().copied().collect();
    keys.sort_unstable();
    let mut out = Textured::default();
    for key in keys {
        // The pixels that cannot mirror the operator, where enough saw the texel; else all of them:
        // a pane a kelvin or two warm where only square-on views saw it is nearer the truth than a
        // hole filled in as the wall around it (an office walk's window lost 0.3 m that way, and
        // the map was 1.3 K off in front of it).
        let [clean, mirrored] = all[&key];
        let (sw, swt, n) = if clean.2 >= params.min_pixels {
            clean
        } else {
            (
                clean.0 + mirrored.0,
                clean.1 + mirrored.1,
                clean.2 + mirrored.2,
            )
        };
        if n < params.min_pixels || sw <= 0.0 {
            continue;
        }
        if clean.2 < params.min_pixels {
            report.texels_only_mirroring += 1;
        }
        let (s, i, j) = key;
        let m = &surfaces[s];
        let centre = Point2::new(
            m.texel_origin.x + (i as f64 + 0.5) * texel_m,
            m.texel_origin.y + (j as f64 + 0.5) * texel_m,
        );
        if !mrtmap_geometry::polygon::point_in_polygon_fast(&centre, m.polygon)
            || distance_to_outline(&centre, m.polygon) < params.edge_clearance_m
        {
            continue;
        }
        report.texels_filled[s] += 1;
        out.surface.push(s);
        out.pos.push(m.frame.to_3d(&centre));
        out.nrm.push(m.frame.normal.into_inner());
        out.temp_k.push(swt / sw);
        out.pixels.push(n);
    }
    report.seconds = t0.elapsed().as_secs_f64();
    (out, report)
}

/// A box (corners in [`mrtmap_geometry::box_corners`]' order: bit 0 along, bit 1 across, bit 2
/// up) grown by `margin` on every side.
fn grown_box(corners: &[Point3<f64>; 8], margin: f64) -> [Point3<f64>; 8] {
    let axis = |k: usize| (corners[1 << k] - corners[0]).try_normalize(1e-12);
    let axes = [axis(0), axis(1), axis(2)];
    std::array::from_fn(|c| {
        let mut q = corners[c];
        for (k, a) in axes.iter().enumerate() {
            if let Some(a) = a {
                let sign = if c & (1 << k) != 0 { 1.0 } else { -1.0 };
                q += a * (sign * margin);
            }
        }
        q
    })
}

/// Texels the cloud's points of a surface cover, in the texel grid of its outline's lower corner.
pub(super) fn covered_texels(
    g: &SurfaceGeom,
    lo: &Point2<f64>,
    members: &[usize],
    pts: &Points,
    texel_m: f64,
) -> HashSet<(i64, i64)> {
    members
        .iter()
        .map(|&i| {
            let q = g.frame.to_2d(&pts.pos[i]);
            (
                ((q.x - lo.x) / texel_m).floor() as i64,
                ((q.y - lo.y) / texel_m).floor() as i64,
            )
        })
        .collect()
}

/// Thermal texturing of the texels the cloud left empty: samples appended to the points (and
/// their weights and the surfaces' members).
#[allow(clippy::too_many_arguments)]
pub(super) fn fill_from_texture(
    input: &TextureInput<'_>,
    geoms: &[SurfaceGeom],
    polys2: &[Vec<Point2<f64>>],
    furniture: &[crate::segment::furniture::FoundFurniture],
    pts: &mut Points,
    weights: &mut Vec<f64>,
    members: &mut [Vec<usize>],
    up: &Vector3<f64>,
    p: &SegmentParams,
) -> TextureReport {
    let surfaces: Vec<ModelSurface<'_>> = geoms
        .iter()
        .enumerate()
        .map(|(s, g)| {
            let lo = polys2[s]
                .iter()
                .fold(Point2::new(f64::INFINITY, f64::INFINITY), |a, q| {
                    Point2::new(a.x.min(q.x), a.y.min(q.y))
                });
            ModelSurface {
                frame: &g.frame,
                polygon: &polys2[s],
                texel_origin: lo,
                covered: covered_texels(g, &lo, &members[s], pts, p.texel_m),
            }
        })
        .collect();
    let boxes: Vec<[Point3<f64>; 8]> = furniture.iter().map(|f| f.corners).collect();
    let (tx, report) = texture(
        input,
        &surfaces,
        &boxes,
        up,
        p.texel_m,
        &TextureParams::default(),
    );
    for k in 0..tx.surface.len() {
        members[tx.surface[k]].push(pts.pos.len());
        pts.pos.push(tx.pos[k]);
        pts.nrm.push(tx.nrm[k]);
        pts.temp.push(tx.temp_k[k]);
        pts.obs.push(tx.pixels[k]);
        weights.push(f64::from(tx.pixels[k]));
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera 1.5 m from a pane (normal +x, up +z) looking square at it sees itself, and its
    /// body below, mirrored; looking 30° aside it does not.
    #[test]
    fn the_operator_is_mirrored_only_near_the_pane_s_normal() {
        let p = TextureParams::default();
        let (o, n, up) = (
            Point3::new(0.0, 0.0, 1.4),
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::z(),
        );
        let look = |yaw_deg: f64, pitch_deg: f64| {
            let (y, q) = (yaw_deg.to_radians(), pitch_deg.to_radians());
            let d = Vector3::new(y.cos() * q.cos(), y.sin() * q.cos(), q.sin());
            let t = 1.5 / d.x;
            (o + d * t, d)
        };
        for (yaw, pitch, mirrored) in [
            (0.0, 0.0, true),
            (5.0, -10.0, true),
            (0.0, -25.0, true),
            (12.0, 0.0, false),
            (30.0, 0.0, false),
            (0.0, 30.0, false),
        ] {
            let (x, d) = look(yaw, pitch);
            let forward = Vector3::x();
            assert_eq!(
                mirrors_operator(&o, &forward, &x, &d, &n, &up, &p),
                mirrored,
                "yaw {yaw}°, pitch {pitch}°"
            );
        }
    }

    #[test]
    fn a_grown_box_reaches_the_margin_beyond_every_face() {
        let b =
            mrtmap_geometry::box_corners(&Point3::new(1.0, 2.0, 0.0), &Point3::new(1.4, 3.3, 1.9));
        let g = grown_box(&b, 0.05);
        let (lo, hi) = g.iter().fold(
            (Point3::new(9.0, 9.0, 9.0), Point3::new(-9.0, -9.0, -9.0)),
            |(lo, hi), q| (lo.inf(q), hi.sup(q)),
        );
        assert!((lo - Point3::new(0.95, 1.95, -0.05)).norm() < 1e-12, "{lo}");
        assert!((hi - Point3::new(1.45, 3.35, 1.95)).norm() < 1e-12, "{hi}");
        // A ray passing 3 cm over the top hits the grown box, not the wall behind.
        let o = Point3::new(3.0, 2.5, 1.93);
        let d = Vector3::new(-1.0, 0.0, 0.0);
        let hit = BOX_TRIANGLES
            .iter()
            .any(|t| ray_triangle(&o, &d, [&g[t[0]], &g[t[1]], &g[t[2]]]).is_some());
        assert!(hit);
    }

    #[test]
    fn a_ray_meets_a_triangle_inside_and_misses_it_outside() {
        let (a, b, c) = (
            Point3::new(0.0, 0.0, 1.0),
            Point3::new(1.0, 0.0, 1.0),
            Point3::new(0.0, 1.0, 1.0),
        );
        let o = Point3::new(0.2, 0.2, 0.0);
        let t = ray_triangle(&o, &Vector3::z(), [&a, &b, &c]).expect("hit");
        assert!((t - 1.0).abs() < 1e-12);
        assert!(ray_triangle(&Point3::new(0.8, 0.8, 0.0), &Vector3::z(), [&a, &b, &c]).is_none());
        assert!(ray_triangle(&o, &-Vector3::z(), [&a, &b, &c]).is_none());
    }

    #[test]
    fn the_distance_to_an_outline_is_to_its_nearest_edge() {
        let sq = [
            Point2::new(0.0, 0.0),
            Point2::new(4.0, 0.0),
            Point2::new(4.0, 2.5),
            Point2::new(0.0, 2.5),
        ];
        assert!((distance_to_outline(&Point2::new(1.0, 0.1), &sq) - 0.1).abs() < 1e-12);
        assert!((distance_to_outline(&Point2::new(2.0, 1.25), &sq) - 1.25).abs() < 1e-12);
        assert!((distance_to_outline(&Point2::new(3.95, 2.45), &sq) - 0.05).abs() < 1e-12);
    }
}
