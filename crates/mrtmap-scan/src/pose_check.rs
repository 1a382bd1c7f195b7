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
//! interpolated across the gap. A small jump that stays (a relocalisation or loop closure that
//! moves every later pose by centimetres) is not there-and-back and is not dropped: it is the pose
//! source's frame correcting itself.
//!
//! A jump that stays and is larger than a correction ([`JUMP_MIN_M`] beyond what a hand moves the
//! camera in that interval, or [`JUMP_MIN_DEG`]) is a relocalisation into another frame: the poses
//! either side of it are in two frames that no longer agree. The trajectory is cut there first;
//! the piece with the most poses is kept and the others are left out (their frames are not fused),
//! each jump listed with its time and size so that a run says which part of the scan it lost.
//! Re-registering a piece to the map is not attempted.

use mrtmap_geometry::nalgebra::{Isometry3, Vector3};
use mrtmap_io::Trajectory;
use serde::{Deserialize, Serialize};

/// Poses either side of a pose in its fit.
const HALF_WINDOW: usize = 3;

/// The smallest jump that stays which cuts the trajectory (m, beyond 3 m/s times the interval):
/// a pose source's corrections move its poses by centimetres, a relocalisation into another frame
/// by metres (issue 54: a 50 m jump mapped 1.8 K off).
pub const JUMP_MIN_M: f64 = 1.0;
/// The same for the rotation (degrees, beyond 400°/s times the interval).
pub const JUMP_MIN_DEG: f64 = 45.0;

/// A jump that stayed: the trajectory was cut there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoseJump {
    /// The time of the first pose after it (s).
    pub t: f64,
    /// How far the camera jumped (m).
    pub jump_m: f64,
    /// How far it turned (degrees).
    pub jump_deg: f64,
}

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
    /// Jumps that stayed (relocalisations), where the trajectory was cut.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub jumps: Vec<PoseJump>,
    /// Poses left out with the pieces not kept.
    #[serde(default)]
    pub left_out: usize,
    /// The trajectory's first stamp (s): the jumps' and the kept span's times are said from it.
    #[serde(default)]
    pub start_s: f64,
    /// The time span of the piece kept (s), when the trajectory was cut.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kept_span_s: Option<[f64; 2]>,
}

impl PoseCheck {
    /// A sentence per jump that cut the trajectory: when, how far, and what was left out.
    pub fn jump_lines(&self) -> Vec<String> {
        let t0 = self.start_s;
        let kept = self.kept_span_s.map_or(String::new(), |[a, b]| {
            format!("only {:.2}–{:.2} s of it kept", a - t0, b - t0)
        });
        self.jumps
            .iter()
            .map(|j| {
                format!(
                    "the poses jumped {:.2} m ({:.0}°) {:.2} s into the trajectory and stayed there (the pose source relocalising into another frame): the trajectory was cut there, {kept}; {} poses and the frames in their time left out",
                    j.jump_m,
                    j.jump_deg,
                    j.t - t0,
                    self.left_out
                )
            })
            .collect()
    }
}

/// Whether pose `b` is farther from pose `a` than a hand moves a camera in `dt` by more than
/// [`JUMP_MIN_M`] or [`JUMP_MIN_DEG`]; (metres, degrees).
fn jumped(a: &Isometry3<f64>, b: &Isometry3<f64>, dt: f64) -> Option<(f64, f64)> {
    let m = (b.translation.vector - a.translation.vector).norm();
    let deg = a.rotation.angle_to(&b.rotation).to_degrees();
    (m > JUMP_MIN_M + 3.0 * dt.abs() || deg > JUMP_MIN_DEG + 400.0 * dt.abs()).then_some((m, deg))
}

/// Cuts `traj` at the jumps that stay (the next [`HALF_WINDOW`] poses do not come back) and keeps
/// the piece with the most poses: (that piece, the jumps, the poses left out).
fn keep_largest_piece(traj: &Trajectory) -> (Trajectory, Vec<PoseJump>, usize) {
    let n = traj.stamps.len();
    let mut cuts = Vec::new();
    let mut jumps = Vec::new();
    for k in 0..n.saturating_sub(1) {
        let Some((m, deg)) = jumped(
            &traj.poses[k],
            &traj.poses[k + 1],
            traj.stamps[k + 1] - traj.stamps[k],
        ) else {
            continue;
        };
        let stays = (k + 2..n.min(k + 2 + HALF_WINDOW)).all(|j| {
            jumped(
                &traj.poses[k],
                &traj.poses[j],
                traj.stamps[j] - traj.stamps[k],
            )
            .is_some()
        });
        if stays {
            cuts.push(k + 1);
            jumps.push(PoseJump {
                t: traj.stamps[k + 1],
                jump_m: m,
                jump_deg: deg,
            });
        }
    }
    if cuts.is_empty() {
        return (traj.clone(), jumps, 0);
    }
    let bounds: Vec<usize> = std::iter::once(0)
        .chain(cuts)
        .chain(std::iter::once(n))
        .collect();
    let (a, b) = bounds
        .windows(2)
        .map(|w| (w[0], w[1]))
        .max_by_key(|(a, b)| (b - a, std::cmp::Reverse(*a)))
        .unwrap_or((0, n));
    let piece = Trajectory {
        stamps: traj.stamps[a..b].to_vec(),
        poses: traj.poses[a..b].to_vec(),
    };
    (piece, jumps, n - (b - a))
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

/// Cuts the trajectory at relocalisation jumps (keeping its largest piece), then drops the poses
/// that jump away from their neighbours' motion and back; returns the trajectory without them and
/// what was found.
pub fn drop_outlier_poses(traj: &Trajectory) -> (Trajectory, PoseCheck) {
    let (piece, jumps, left_out) = keep_largest_piece(traj);
    let kept_span_s =
        (left_out > 0).then(|| [piece.stamps[0], piece.stamps[piece.stamps.len() - 1]]);
    let (out, mut check) = drop_outliers(&piece);
    check.poses = traj.stamps.len();
    check.jumps = jumps;
    check.left_out = left_out;
    check.kept_span_s = kept_span_s;
    check.start_s = traj.stamps.first().copied().unwrap_or(0.0);
    (out, check)
}

/// The there-and-back check over one piece of trajectory.
fn drop_outliers(traj: &Trajectory) -> (Trajectory, PoseCheck) {
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
        assert!(check.jumps.is_empty(), "{check:?}");
    }

    /// Issue 54: a trajectory that jumps 50 m and stays there (a relocalisation) mapped 1.8 K off,
    /// and the poses beside the jump were reported as jumping "away and back".
    #[test]
    fn a_jump_that_stays_cuts_the_trajectory_and_the_larger_piece_is_kept() {
        let mut t = walk(300);
        for p in &mut t.poses[200..] {
            p.translation.vector.x += 50.0;
        }
        let (out, check) = drop_outlier_poses(&t);
        assert_eq!(check.jumps.len(), 1, "{check:?}");
        assert!((check.jumps[0].t - 200.0 / 30.0).abs() < 1e-9);
        assert!((check.jumps[0].jump_m - 50.0).abs() < 0.1, "{check:?}");
        assert_eq!((check.left_out, check.dropped), (100, 0), "{check:?}");
        assert_eq!(out.stamps.len(), 200);
        assert_eq!(check.kept_span_s, Some([0.0, 199.0 / 30.0]));
        let said = check.jump_lines();
        assert!(
            said[0].contains("jumped 50.02 m (1°) 6.67 s into the trajectory")
                && said[0].contains("only 0.00–6.63 s of it kept; 100 poses"),
            "{said:?}"
        );
        // The later piece kept when it is the larger.
        let mut early = walk(300);
        for p in &mut early.poses[..60] {
            p.translation.vector.x -= 50.0;
        }
        let (out, check) = drop_outlier_poses(&early);
        assert_eq!((check.left_out, out.stamps.len()), (60, 240), "{check:?}");
        assert!((out.stamps[0] - 2.0).abs() < 1e-9);
    }
}
