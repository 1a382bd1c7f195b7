//! Matching streams by timestamp: each thermal frame takes the nearest depth frame within a
//! tolerance; poses are interpolated at each frame's own time.

use mrtmap_geometry::nalgebra::Isometry3;
use mrtmap_io::{InterpolationLimits, Recording};
use serde::{Deserialize, Serialize};

/// Why a thermal frame was not used (in fusion.json by its phrase, [`SkipReason::describe`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum SkipReason {
    /// No depth frame within the sync tolerance.
    #[serde(rename = "no depth frame within the sync tolerance")]
    NoDepthWithinTolerance,
    /// No pose at the thermal or the depth frame's time.
    #[serde(rename = "no pose at the frame time")]
    NoPose,
    /// An image could not be read.
    #[serde(rename = "an image could not be read")]
    UnreadableImage,
    /// Too few valid depth points.
    #[serde(rename = "too few valid depth points")]
    TooFewDepthPoints,
    /// Nothing of the depth frame is visible in the thermal camera.
    #[serde(rename = "no depth point visible in the thermal image")]
    NothingVisible,
}

impl std::fmt::Display for SkipReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.describe())
    }
}

impl SkipReason {
    /// A phrase for people.
    pub fn describe(self) -> &'static str {
        match self {
            Self::NoDepthWithinTolerance => "no depth frame within the sync tolerance",
            Self::NoPose => "no pose at the frame time",
            Self::UnreadableImage => "an image could not be read",
            Self::TooFewDepthPoints => "too few valid depth points",
            Self::NothingVisible => "no depth point visible in the thermal image",
        }
    }
}

/// A thermal frame with its depth frame, or why it has none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pairing {
    /// Index into `recording.thermal`.
    pub thermal: usize,
    /// Index into `recording.depth`, or why not.
    pub depth: Result<usize, SkipReason>,
}

/// Pairs every thermal frame with the nearest depth frame within `tolerance_s` that has poses at
/// both times.
pub fn pair_frames(
    rec: &Recording,
    tolerance_s: f64,
    limits: &InterpolationLimits,
) -> Vec<Pairing> {
    let depth_t: Vec<f64> = rec.depth.iter().map(|e| e.t).collect();
    rec.thermal
        .iter()
        .enumerate()
        .map(|(i, th)| {
            let best = nearest(&depth_t, th.t);
            let depth = match best {
                Some(d) if (depth_t[d] - th.t).abs() <= tolerance_s => {
                    if rec.trajectory.interpolate(th.t, limits).is_some()
                        && rec.trajectory.interpolate(depth_t[d], limits).is_some()
                    {
                        Ok(d)
                    } else {
                        Err(SkipReason::NoPose)
                    }
                }
                _ => Err(SkipReason::NoDepthWithinTolerance),
            };
            Pairing { thermal: i, depth }
        })
        .collect()
}

/// The index of the time in `times` (sorted) nearest `t`.
pub(crate) fn nearest(times: &[f64], t: f64) -> Option<usize> {
    let k = times.partition_point(|&x| x < t);
    [k.checked_sub(1), (k < times.len()).then_some(k)]
        .into_iter()
        .flatten()
        .min_by(|&a, &b| (times[a] - t).abs().total_cmp(&(times[b] - t).abs()))
}

/// The refined pose at any time: the recording's trajectory corrected by fusion's ICP correction
/// (`fused` = the refined world_from_depth of the fused frames), interpolated between the fused
/// frames. For placing mask frames, which run on their own clock.
pub fn refined_poses(
    rec: &Recording,
    fused: &mrtmap_io::Trajectory,
) -> impl Fn(f64) -> Option<Isometry3<f64>> + Sync + use<> {
    let wide = InterpolationLimits {
        max_gap_secs: 5.0,
        max_extrapolation_secs: 5.0,
    };
    let corrections = mrtmap_io::Trajectory {
        stamps: fused.stamps.clone(),
        poses: fused
            .stamps
            .iter()
            .zip(&fused.poses)
            .map(|(t, p)| {
                rec.trajectory
                    .interpolate(*t, &InterpolationLimits::default())
                    .map_or(Isometry3::identity(), |s| p * s.inverse())
            })
            .collect(),
    };
    let traj = rec.trajectory.clone();
    move |t| {
        let s = traj.interpolate(t, &InterpolationLimits::default())?;
        Some(
            corrections
                .interpolate(t, &wide)
                .unwrap_or(Isometry3::identity())
                * s,
        )
    }
}
