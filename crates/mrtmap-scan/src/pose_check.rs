//! Pose sanity: a pose that jumps away from its neighbours' motion and back is dropped.
//!
//! A tracking camera (T265) or a SLAM system can write one bad pose among good ones when it
//! relocalises or loses track for a moment, and the built-in tracker can too. Such a pose shows as
//! motion no handheld camera makes: tens of centimetres (or degrees) within one pose interval,
//! there and back. Each pose is compared with a robust straight-line fit (Theil–Sen, per axis,
//! over time) to its neighbours three either side, the pose itself left out, so that up to two bad
//! poses in a row do not hide each other; it is dropped when it lies farther from that line than a
//! hand can move the camera off a straight line in that time (5 cm plus 20 m/s² · Δt²/2 over the
//! window's span Δt; 8° plus 300°/s² · Δt²/2 for the rotation). The trajectory is then
//! interpolated across the gap. A jump that stays (a relocalisation that moves every later pose)
//! is not there-and-back and is not dropped: it is the pose source's frame changing.

use mrtmap_geometry::nalgebra::{Isometry3, Vector3};
use mrtmap_io::Trajectory;
use serde::{Deserialize, Serialize};

/// Poses either side of a pose in its fit.
const HALF_WINDOW: usize = 3;

/// A pose dropped.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DroppedPose {
    /// Its time (s).
    pub t: f64,
    /// How far it lay from its neighbours' motion (m).
    pub off_m: f64,
    /// How far it was turned from it (degrees).
    pub off_deg: f64,
}

/// What the check found (`fusion.json`'s `pose_check`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseCheck {
    /// Poses checked.
    pub poses: usize,
    /// Poses dropped (the first 20 listed in `examples`).
    pub dropped: usize,
    /// The first few dropped.
    pub examples: Vec<DroppedPose>,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Theil–Sen: the value at `t` of the robust line through (t_i, y_i).
fn theil_sen_at(ts: &[f64], ys: &[f64], t: f64) -> f64 {
    let mut slopes = Vec::with_capacity(ts.len() * ts.len() / 2);
    for i in 0..ts.len() {
        for j in i + 1..ts.len() {
            let dt = ts[j] - ts[i];
            if dt.abs() > 1e-12 {
                slopes.push((ys[j] - ys[i]) / dt);
            }
        }
    }
    let slope = if slopes.is_empty() {
        0.0
    } else {
        median(&mut slopes)
    };
    let mut icepts: Vec<f64> = ts.iter().zip(ys).map(|(x, y)| y - slope * x).collect();
    median(&mut icepts) + slope * t
}

/// How far pose `k` lies from the motion of its kept neighbours (up to three either side):
/// (metres, degrees, the window's half span in seconds).
fn deviation(traj: &Trajectory, k: usize, keep: &[bool]) -> Option<(f64, f64, f64)> {
    let n = traj.stamps.len();
    let before = (0..k).rev().filter(|&j| keep[j]).take(HALF_WINDOW);
    let after = (k + 1..n).filter(|&j| keep[j]).take(HALF_WINDOW);
    let idx: Vec<usize> = before.chain(after).collect();
    if idx.len() < 4 {
        return None;
    }
    let t0 = traj.stamps[k];
    let ts: Vec<f64> = idx.iter().map(|&j| traj.stamps[j] - t0).collect();
    let span = ts.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let pos = traj.poses[k].translation.vector;
    let mut pred = Vector3::zeros();
    for a in 0..3 {
        let ys: Vec<f64> = idx
            .iter()
            .map(|&j| traj.poses[j].translation.vector[a])
            .collect();
        pred[a] = theil_sen_at(&ts, &ys, 0.0);
    }
    // The rotation: each neighbour's rotation relative to pose k, as a rotation vector; a robust
    // line through them at 0 is how far pose k is turned from their motion.
    let rk = traj.poses[k].rotation;
    let mut rot_pred = Vector3::zeros();
    let rels: Vec<Vector3<f64>> = idx
        .iter()
        .map(|&j| (rk.inverse() * traj.poses[j].rotation).scaled_axis())
        .collect();
    for a in 0..3 {
        let ys: Vec<f64> = rels.iter().map(|r| r[a]).collect();
        rot_pred[a] = theil_sen_at(&ts, &ys, 0.0);
    }
    Some(((pos - pred).norm(), rot_pred.norm().to_degrees(), span))
}

/// How far beyond its limits a pose lies (a ratio; over 1: an outlier), with its deviation.
fn excess(traj: &Trajectory, k: usize, keep: &[bool]) -> Option<(f64, f64, f64)> {
    let (off_m, off_deg, span) = deviation(traj, k, keep)?;
    let (lim_m, lim_deg) = limits(span);
    Some(((off_m / lim_m).max(off_deg / lim_deg), off_m, off_deg))
}

/// The limits a pose may lie off its neighbours' line, for a window spanning `span_s`.
fn limits(span_s: f64) -> (f64, f64) {
    (
        0.05 + 20.0 * span_s * span_s / 2.0,
        8.0 + 300.0 * span_s * span_s / 2.0,
    )
}

/// Drops the poses that jump away from their neighbours' motion and back; returns the trajectory
/// without them and what was dropped.
pub fn drop_outlier_poses(traj: &Trajectory) -> (Trajectory, PoseCheck) {
    let n = traj.stamps.len();
    let mut check = PoseCheck {
        poses: n,
        ..Default::default()
    };
    let mut keep = vec![true; n];
    // Candidates first, then dropped worst first, each judged again against the neighbours kept
    // so far: two bad poses in a row would otherwise drag their good neighbours' lines off too.
    let all = vec![true; n];
    let mut candidates: Vec<(usize, f64)> = (0..n)
        .filter_map(|k| {
            excess(traj, k, &all)
                .filter(|e| e.0 > 1.0)
                .map(|e| (k, e.0))
        })
        .collect();
    candidates.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut dropped: Vec<DroppedPose> = Vec::new();
    for (k, _) in candidates {
        if let Some((e, off_m, off_deg)) = excess(traj, k, &keep)
            && e > 1.0
        {
            keep[k] = false;
            dropped.push(DroppedPose {
                t: traj.stamps[k],
                off_m,
                off_deg,
            });
        }
    }
    dropped.sort_by(|a, b| a.t.total_cmp(&b.t));
    check.dropped = dropped.len();
    check.examples = dropped.into_iter().take(20).collect();
    if check.dropped == 0 {
        return (traj.clone(), check);
    }
    let (stamps, poses): (Vec<f64>, Vec<Isometry3<f64>>) = traj
        .stamps
        .iter()
        .zip(&traj.poses)
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|((t, p), _)| (*t, *p))
        .unzip();
    (Trajectory { stamps, poses }, check)
}

#[cfg(test)]
mod tests {
    use mrtmap_geometry::nalgebra::{Translation3, UnitQuaternion};

    use super::*;

    /// A walk at 30 Hz: 0.5 m/s along x, turning 40°/s, swaying.
    fn walk(n: usize) -> Trajectory {
        let stamps: Vec<f64> = (0..n).map(|k| k as f64 / 30.0).collect();
        let poses = stamps
            .iter()
            .map(|&t| {
                Isometry3::from_parts(
                    Translation3::new(0.5 * t, 0.1 * (3.0 * t).sin(), 1.4),
                    UnitQuaternion::from_euler_angles(0.0, 0.0, 40f64.to_radians() * t),
                )
            })
            .collect();
        Trajectory { stamps, poses }
    }

    #[test]
    fn a_smooth_walk_keeps_every_pose() {
        let (out, check) = drop_outlier_poses(&walk(300));
        assert_eq!(check.dropped, 0, "{check:?}");
        assert_eq!(out.stamps.len(), 300);
    }

    #[test]
    fn a_pose_that_jumps_and_comes_back_is_dropped_and_one_that_stays_is_not() {
        let mut t = walk(300);
        // One pose 54 cm off, as the tracker wrote on a hidden scan; two in a row 30 cm and 12°
        // off; one turned 20°.
        t.poses[100].translation.vector.y += 0.54;
        t.poses[200].translation.vector.x -= 0.30;
        t.poses[201].rotation *= UnitQuaternion::from_euler_angles(0.0, 0.21, 0.0);
        t.poses[201].translation.vector.x -= 0.30;
        t.poses[250].rotation *= UnitQuaternion::from_euler_angles(0.35, 0.0, 0.0);
        let (out, check) = drop_outlier_poses(&t);
        let dropped: Vec<usize> = check
            .examples
            .iter()
            .map(|d| (d.t * 30.0).round() as usize)
            .collect();
        assert_eq!(dropped, vec![100, 200, 201, 250], "{check:?}");
        assert_eq!(out.stamps.len(), 296);
        assert!((check.examples[0].off_m - 0.54).abs() < 0.01, "{check:?}");
        // A relocalisation that moves every later pose by 20 cm is a step, not an outlier.
        let mut step = walk(300);
        for p in &mut step.poses[150..] {
            p.translation.vector.y += 0.2;
        }
        let (_, check) = drop_outlier_poses(&step);
        assert_eq!(check.dropped, 0, "{check:?}");
    }
}
