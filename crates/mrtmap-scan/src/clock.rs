//! The thermal camera's clock against the depth camera's, found from the scan itself.
//!
//! A USB thermal camera has no hardware clock shared with the depth camera: its frames are
//! stamped by the host when they arrive, tens to over a hundred milliseconds after the exposure.
//! Placed by the pose at its stamp, a frame taken while the camera turns lands beside where it
//! was taken (60°/s for 70 ms is 4°, ten Lepton pixels), and edges smear across the map.
//!
//! The offset (what to add to a thermal stamp to get its exposure on the depth clock) is the one
//! at which the frames agree best, as spatio-temporal calibration tools (Kalibr) find it: depth
//! points are placed once, by the depth frames' own poses, which do not depend on the offset; for
//! each candidate offset every sampled thermal frame is posed at its stamp plus the offset and
//! projected onto those points, and the mismatch is the observation-weighted variance of the
//! temperatures each 5 cm voxel receives. A coarse search over ±250 ms
//! (25 ms steps) is refined in 5 ms steps and by a V fitted to the samples near the lowest. A scan that
//! turns fast constrains the offset sharply; a slow, straight walk leaves the mismatch flat,
//! which the report says (`contrast`, `weak`).

use std::collections::HashMap;

use mrtmap_geometry::cloud::voxel_key;
use mrtmap_geometry::nalgebra::{Point3, Vector3};
use mrtmap_io::{InterpolationLimits, Recording};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::frame::{DepthPoints, DepthSampling, RayTable, ThermalImage, depth_points};
use crate::observe::{ObservationParams, observe};

/// How fusion sets the thermal clock's offset.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ClockOffset {
    /// rig.toml's `[thermal] time_offset_s` when it has one, else estimated from the scan.
    Auto,
    /// Estimated from the scan, whatever rig.toml says.
    Estimate,
    /// This offset (s), added to every thermal stamp.
    Fixed(f64),
    /// The stamps as recorded.
    Off,
}

/// Where the offset used came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OffsetSource {
    /// Not applied.
    #[default]
    None,
    /// rig.toml's `[thermal] time_offset_s`.
    RigToml,
    /// Given in the settings.
    Given,
    /// Found from the scan.
    Estimated,
}

/// The search's settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClockSearch {
    /// Offsets searched: ±this (s).
    pub range_s: f64,
    /// Coarse step (s).
    pub coarse_step_s: f64,
    /// Fine step (s).
    pub fine_step_s: f64,
    /// Thermal frames sampled, spread evenly over the scan.
    pub frames: usize,
    /// Depth pixel stride of the points the frames are projected onto; 0: twice the fusion's
    /// automatic stride (6 for a 640×480 D435 beside a Lepton, 2 at 320×240).
    pub stride: u32,
    /// Voxel whose temperatures must agree (m).
    pub voxel_m: f64,
    /// Below this relative rise of the mismatch 50 ms either side of its minimum, the offset is
    /// called weakly constrained.
    pub weak_contrast: f64,
    /// The rise must be this many times the curve's own noise.
    pub min_signal_to_noise: f64,
    /// Fewer frames than this (about 3.5 s of a Lepton) give no estimate.
    pub min_frames: usize,
}

impl Default for ClockSearch {
    fn default() -> Self {
        Self {
            range_s: 0.25,
            coarse_step_s: 0.025,
            fine_step_s: 0.005,
            frames: 90,
            stride: 0,
            voxel_m: 0.05,
            weak_contrast: 0.05,
            min_signal_to_noise: 8.0,
            min_frames: 30,
        }
    }
}

/// What the clock's offset was and how it was found (`fusion.json`'s `clock`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ClockReport {
    /// Added to every thermal stamp (s); negative when the stamps are late.
    pub offset_s: f64,
    /// Where it came from.
    pub source: OffsetSource,
    /// Thermal frames the estimate compared (0 when not estimated).
    pub frames: usize,
    /// The mismatch (K², weighted variance within voxels) at each offset tried, by offset.
    pub curve: Vec<[f64; 2]>,
    /// The mismatch's relative rise 50 ms either side of the minimum: how sharply the scan
    /// constrains the offset.
    pub contrast: f64,
    /// Whether the scan constrains the offset only weakly (too few frames, too little turning,
    /// a curve whose noise rivals its rise, or a minimum at the search's edge): the offset is then
    /// not applied.
    pub weak: bool,
    /// The weak estimate that was not applied (s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unapplied_s: Option<f64>,
}

/// One sampled frame, ready to be projected at any offset.
struct Sample {
    t: f64,
    points: Vec<Point3<f64>>,
    normals: Vec<Vector3<f64>>,
    /// Each point's voxel, numbered over all the samples.
    voxels: Vec<u32>,
    thermal: ThermalImage,
}

/// Reads the sampled frames: evenly spread thermal frames whose poses exist over the whole search
/// range, each with its nearest depth frame (within `tolerance_s`), placed by the depth pose.
fn samples(
    rec: &Recording,
    search: &ClockSearch,
    tolerance_s: f64,
    limits: &InterpolationLimits,
) -> Vec<Sample> {
    let depth_t: Vec<f64> = rec.depth.iter().map(|e| e.t).collect();
    let traj = &rec.trajectory;
    let usable: Vec<(usize, usize)> = rec
        .thermal
        .iter()
        .enumerate()
        .filter_map(|(i, th)| {
            let d = crate::sync::nearest(&depth_t, th.t)?;
            let ok = (depth_t[d] - th.t).abs() <= tolerance_s
                && traj.interpolate(depth_t[d], limits).is_some()
                && traj.interpolate(th.t - search.range_s, limits).is_some()
                && traj.interpolate(th.t + search.range_s, limits).is_some();
            ok.then_some((i, d))
        })
        .collect();
    let n = search.frames.min(usable.len());
    if n == 0 {
        return Vec::new();
    }
    let picked: Vec<(usize, usize)> = (0..n)
        .map(|j| usable[(j * usable.len() + usable.len() / (2 * n)) / n])
        .collect();
    let rays = RayTable::new(&rec.rig.depth);
    let stride = match search.stride {
        0 => 2 * DepthSampling::auto_stride(&rec.rig.depth, &rec.rig.thermal),
        s => s,
    };
    let sampling = DepthSampling {
        stride,
        ..DepthSampling::default()
    };
    picked
        .par_iter()
        .filter_map(|&(ti, di)| {
            let depth = rec.read_depth(&rec.depth[di]).ok()?;
            let raw = rec.read_thermal(&rec.thermal[ti]).ok()?;
            let wd = traj.interpolate(rec.depth[di].t, limits)?;
            let DepthPoints { points, normals } =
                depth_points(&depth, &rays, rec.rig.depth_scale, &sampling);
            if points.len() < 100 {
                return None;
            }
            let points: Vec<Point3<f64>> = points.iter().map(|p| wd * p).collect();
            let normals: Vec<Vector3<f64>> = normals.iter().map(|n| wd.rotation * n).collect();
            Some(Sample {
                t: rec.thermal[ti].t,
                points,
                normals,
                voxels: Vec::new(),
                thermal: ThermalImage::from_raw(&raw, rec.rig.thermal_encoding),
            })
        })
        .collect::<Vec<Sample>>()
}

/// Numbers the samples' voxels; returns how many there are.
fn number_voxels(samples: &mut [Sample], voxel_m: f64) -> usize {
    let mut ids: HashMap<[i32; 3], u32> = HashMap::new();
    for s in samples.iter_mut() {
        s.voxels = s
            .points
            .iter()
            .map(|p| {
                let n = ids.len() as u32;
                *ids.entry(voxel_key(p, voxel_m)).or_insert(n)
            })
            .collect();
    }
    ids.len()
}

/// The mismatch at `offset_s`: the weighted variance of the temperatures each voxel receives.
fn mismatch(
    rec: &Recording,
    samples: &[Sample],
    voxels: usize,
    offset_s: f64,
    limits: &InterpolationLimits,
) -> f64 {
    // Edges are the signal here: no sample is dropped or down-weighted for its contrast.
    let params = ObservationParams {
        edge_drop_k: f64::INFINITY,
        edge_scale_k: f64::INFINITY,
        ..ObservationParams::default()
    };
    let sums = samples
        .par_iter()
        .fold(
            || vec![[0.0f64; 3]; voxels],
            |mut acc, s| {
                let Some(wt) = rec.trajectory.interpolate(s.t + offset_s, limits) else {
                    return acc;
                };
                let wt = wt * rec.rig.depth_from_thermal;
                let (obs, _) = observe(
                    &s.points,
                    &s.normals,
                    &wt,
                    &rec.rig.thermal,
                    &s.thermal,
                    &params,
                );
                for o in obs {
                    let a = &mut acc[s.voxels[o.index] as usize];
                    a[0] += o.w;
                    a[1] += o.w * o.t_k;
                    a[2] += o.w * o.t_k * o.t_k;
                }
                acc
            },
        )
        .reduce_with(|mut a, b| {
            for (x, y) in a.iter_mut().zip(&b) {
                for i in 0..3 {
                    x[i] += y[i];
                }
            }
            a
        })
        .unwrap_or_default();
    let (mut num, mut den) = (0.0, 0.0);
    for a in &sums {
        if a[0] > 0.0 {
            num += (a[2] - a[1] * a[1] / a[0]).max(0.0);
            den += a[0];
        }
    }
    if den > 0.0 { num / den } else { f64::NAN }
}

/// Estimates the offset to add to the thermal stamps. `tolerance_s`: how far a sampled thermal
/// frame's depth frame may lie from it.
pub fn estimate_offset(
    rec: &Recording,
    search: &ClockSearch,
    tolerance_s: f64,
    limits: &InterpolationLimits,
) -> ClockReport {
    match estimate_offset_until(rec, search, tolerance_s, limits, &|| false) {
        Some(r) => r,
        // `stop` never says so.
        None => unreachable!("an estimate that is never asked to stop stopped"),
    }
}

/// [`estimate_offset`], asking `stop` before each offset it tries: `None` once it says so. One
/// function for the search's three passes (coarse, fine, the V's neighbourhood) and the verdict:
/// they share the curve of offsets tried and the best so far.
pub fn estimate_offset_until(
    rec: &Recording,
    search: &ClockSearch,
    tolerance_s: f64,
    limits: &InterpolationLimits,
    stop: &dyn Fn() -> bool,
) -> Option<ClockReport> {
    let mut samples = samples(rec, search, tolerance_s, limits);
    let voxels = number_voxels(&mut samples, search.voxel_m);
    let mut report = ClockReport {
        source: OffsetSource::Estimated,
        frames: samples.len(),
        weak: true,
        ..Default::default()
    };
    if samples.len() < 3 {
        return Some(report);
    }
    let mut curve: Vec<[f64; 2]> = Vec::new();
    let stopped = std::cell::Cell::new(false);
    let eval = |d: f64, curve: &mut Vec<[f64; 2]>| -> f64 {
        if let Some(c) = curve.iter().find(|c| (c[0] - d).abs() < 1e-9) {
            return c[1];
        }
        if stopped.get() || stop() {
            stopped.set(true);
            return f64::NAN;
        }
        let m = mismatch(rec, &samples, voxels, d, limits);
        curve.push([d, m]);
        m
    };
    let steps = (search.range_s / search.coarse_step_s).round() as i64;
    let mut best = (0.0, f64::INFINITY);
    for k in -steps..=steps {
        let d = k as f64 * search.coarse_step_s;
        let m = eval(d, &mut curve);
        if m < best.1 {
            best = (d, m);
        }
    }
    if stopped.get() {
        return None;
    }
    if !best.1.is_finite() {
        return Some(report);
    }
    let fine = (search.coarse_step_s / search.fine_step_s).round() as i64;
    let centre = best.0;
    for k in -fine..=fine {
        let d = centre + k as f64 * search.fine_step_s;
        if d.abs() > search.range_s + 1e-9 {
            continue;
        }
        let m = eval(d, &mut curve);
        if m < best.1 {
            best = (d, m);
        }
    }
    let at_edge = best.0.abs() > search.range_s - search.coarse_step_s / 2.0;
    // The mismatch grows about linearly either side of the minimum (edges move by the motion in
    // the offset's error), so a V, y = a + b·|x − x0|, is fitted by least squares to the samples
    // within four fine steps of the best: a parabola through three points was pulled 2 ms off a
    // true 0 by one sample's noise.
    let h = search.fine_step_s;
    for k in -4i64..=4 {
        let d = best.0 + k as f64 * h;
        if d.abs() <= search.range_s + 1e-9 {
            eval(d, &mut curve);
        }
    }
    let near: Vec<[f64; 2]> = curve
        .iter()
        .copied()
        .filter(|c| (c[0] - best.0).abs() <= 4.0 * h + 1e-9 && c[1].is_finite())
        .collect();
    let offset = fit_v(&near, best.0, h).unwrap_or(best.0);
    curve.sort_by(|x, y| x[0].total_cmp(&y[0]));
    let around: Vec<f64> = [-0.05, 0.05]
        .iter()
        .filter_map(|d| {
            curve
                .iter()
                .min_by(|x, y| {
                    (x[0] - best.0 - d)
                        .abs()
                        .total_cmp(&(y[0] - best.0 - d).abs())
                })
                .filter(|x| (x[0] - best.0 - d).abs() < search.coarse_step_s)
                .map(|x| x[1])
        })
        .collect();
    let rise = if around.is_empty() {
        0.0
    } else {
        around.iter().sum::<f64>() / around.len() as f64 / best.1.max(1e-12) - 1.0
    };
    // The curve's own noise: the median distance of each fine sample from the mean of its two
    // neighbours (a smooth V is straight there, except at its vertex). The rise 50 ms either side
    // must stand well clear of it, and enough frames must have been compared.
    let fine: Vec<[f64; 2]> = curve
        .iter()
        .copied()
        .filter(|c| (c[0] - best.0).abs() <= search.coarse_step_s + 1e-9)
        .collect();
    let mut bumps: Vec<f64> = fine
        .windows(3)
        .filter(|w| (w[2][0] - w[0][0] - 2.0 * h).abs() < 1e-9)
        .map(|w| (w[1][1] - 0.5 * (w[0][1] + w[2][1])).abs())
        .collect();
    bumps.sort_by(f64::total_cmp);
    let noise = bumps.get(bumps.len() / 2).copied().unwrap_or(0.0);
    let signal = rise * best.1;
    let too_noisy = signal < search.min_signal_to_noise * noise;
    let too_few = report.frames < search.min_frames;
    report.curve = curve;
    report.contrast = rise;
    report.weak = at_edge || too_noisy || too_few || rise < search.weak_contrast;
    // A weak minimum is no estimate: the stamps are left as they are, and the report says so.
    report.offset_s = if report.weak { 0.0 } else { offset };
    report.unapplied_s = report.weak.then_some(offset);
    (!stopped.get()).then_some(report)
}

/// The x0 (within `h` of `centre`, on a grid of h/20) of the V y = a + b·|x − x0|, b > 0, that
/// fits `points` best by least squares.
fn fit_v(points: &[[f64; 2]], centre: f64, h: f64) -> Option<f64> {
    if points.len() < 4 {
        return None;
    }
    let mut best: Option<(f64, f64)> = None;
    for k in -20..=20 {
        let x0 = centre + k as f64 * h / 20.0;
        let n = points.len() as f64;
        let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
        for p in points {
            let x = (p[0] - x0).abs();
            sx += x;
            sy += p[1];
            sxx += x * x;
            sxy += x * p[1];
        }
        let den = n * sxx - sx * sx;
        if den <= 0.0 {
            continue;
        }
        let b = (n * sxy - sx * sy) / den;
        let a = (sy - b * sx) / n;
        if b <= 0.0 {
            continue;
        }
        let sse: f64 = points
            .iter()
            .map(|p| (p[1] - a - b * (p[0] - x0).abs()).powi(2))
            .sum();
        if best.is_none_or(|bst| sse < bst.1) {
            best = Some((x0, sse));
        }
    }
    best.map(|b| b.0)
}

impl ClockReport {
    /// One sentence for people: the offset, where it came from and how well the scan fixed it.
    pub fn describe(&self) -> String {
        let ms = self.offset_s * 1000.0;
        match self.source {
            OffsetSource::None => "thermal stamps used as recorded (no clock offset)".into(),
            OffsetSource::RigToml => {
                format!("thermal clock offset {ms:+.1} ms, from rig.toml's [thermal] time_offset_s")
            }
            OffsetSource::Given => format!("thermal clock offset {ms:+.1} ms, as given"),
            OffsetSource::Estimated if self.frames < 3 => {
                "thermal clock offset not estimated: too few frames with depth and poses; stamps used as recorded".into()
            }
            OffsetSource::Estimated if self.weak => format!(
                "thermal clock offset not applied: the scan fixes it only weakly ({} frames compared{}; best guess {:+.0} ms); stamps used as recorded: give it as [thermal] time_offset_s in rig.toml, or scan longer with some turning",
                self.frames,
                if self.frames < ClockSearch::default().min_frames {
                    ", too few"
                } else {
                    ""
                },
                self.unapplied_s.unwrap_or(0.0) * 1000.0
            ),
            OffsetSource::Estimated => format!(
                "thermal clock offset {ms:+.1} ms, estimated from {} frames (the stamps are {:.0} ms {}); the frames' mismatch rises {:.0} % 50 ms either side",
                self.frames,
                ms.abs(),
                if ms < 0.0 { "late" } else { "early" },
                self.contrast * 100.0
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_v_is_found_between_its_samples_and_despite_one_noisy_sample() {
        let v = |x0: f64| -> Vec<[f64; 2]> {
            (-4..=4)
                .map(|k| {
                    let x = k as f64 * 0.005;
                    [x, 0.12 + 2.0 * (x - x0).abs()]
                })
                .collect()
        };
        let x = fit_v(&v(0.0013), 0.0, 0.005).unwrap();
        assert!((x - 0.0013).abs() < 0.0003, "{x}");
        // One sample beside the minimum 8 % high: a parabola through the lowest three would
        // move 2 ms; the V moves less than 1.
        let mut p = v(0.0);
        p[5][1] += 0.008;
        let x = fit_v(&p, 0.0, 0.005).unwrap();
        assert!(x.abs() < 0.001, "{x}");
    }
}
