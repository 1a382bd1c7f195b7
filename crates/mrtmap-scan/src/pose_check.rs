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
//! camera in that interval, or [`JUMP_MIN_DEG`]; with the depth to judge by, [`JUDGED_STEP_M`] or
//! [`JUDGED_STEP_DEG`]) splits the trajectory into pieces. What it was is
//! for the depth to say ([`JumpJudge`], given by fusion): the largest piece is the reference, and
//! each other piece, from the nearest outwards, is compared with the depth seen by the pieces kept
//! so far: if its frames agree with them at its own poses, the jump was motion (a pose stream
//! with a gap, a tracker that caught up) and the piece is kept as it is; if they agree once the
//! piece is moved by one rigid correction (first guessed by joining the poses either side of the
//! jump, then refined by ICP), the pose source relocalised into another frame and the piece is
//! re-anchored; if neither, the piece is left out (its frames are not fused). Without a judge (or
//! when it cannot tell), every jump cuts, and the largest piece is kept. Each jump is listed with
//! its time, size and outcome, so that a run says which part of the scan it moved or lost.

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
/// With the depth to judge by, the smallest step judged (m, degrees, beyond the same motion): a
/// relocalisation by half a metre or ten degrees mapped half the scan that far off, and a step
/// that was motion or a pose source's own correction costs nothing when the depth agrees.
pub const JUDGED_STEP_M: f64 = 0.25;
/// See [`JUDGED_STEP_M`].
pub const JUDGED_STEP_DEG: f64 = 5.0;

/// What a jump that stayed was, by the depth.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum JumpOutcome {
    /// The frames after it agree with the map at their poses: the camera moved.
    Motion,
    /// They agree after one rigid correction of the piece (a relocalisation): re-anchored.
    Reanchored {
        /// How far the piece was moved (m).
        correction_m: f64,
        /// How far it was turned (degrees).
        correction_deg: f64,
    },
    /// Neither (or nothing to judge by): the piece is left out.
    #[default]
    Cut,
}

/// A jump that stayed, and what became of the piece beyond it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoseJump {
    /// The time of the first pose after it (s).
    pub t: f64,
    /// How far the camera jumped (m).
    pub jump_m: f64,
    /// How far it turned (degrees).
    pub jump_deg: f64,
    /// What it was.
    #[serde(default)]
    pub outcome: JumpOutcome,
    /// The share of the piece's depth points that lie on the map kept so far at its own poses,
    /// and after the rigid correction (0…1), when the depth judged it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub agreement: Option<[f64; 2]>,
}

/// How well a piece of trajectory's depth agrees with the pieces kept so far.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Agreement {
    /// The share of its depth points on the kept map at its own poses (0…1).
    pub as_is: f64,
    /// The share after the best rigid correction near the guess (0…1).
    pub corrected: f64,
    /// That correction (applied on the left of the piece's poses).
    pub correction: Isometry3<f64>,
}

/// Judges a piece of trajectory beyond a jump by the depth frames in its time.
pub trait JumpJudge {
    /// How well the depth seen from `piece` agrees with that seen from `kept`, as it is and after
    /// a rigid correction of `piece` near `guess`; `None` when there is too little to judge by
    /// (no depth frames in its time).
    fn judge(
        &self,
        kept: &Trajectory,
        piece: &Trajectory,
        guess: &Isometry3<f64>,
    ) -> Option<Agreement>;
}

/// A piece agrees with the map when at least this share of its depth points lie on it.
pub const AGREE_SHARE: f64 = 0.5;

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
    /// A sentence per jump that stayed: when, how far, and what became of the piece beyond it.
    pub fn jump_lines(&self) -> Vec<String> {
        let t0 = self.start_s;
        let kept = self.kept_span_s.map_or(String::new(), |[a, b]| {
            format!("{:.2}–{:.2} s of it kept", a - t0, b - t0)
        });
        self.jumps
            .iter()
            .map(|j| {
                let head = format!(
                    "the poses jumped {:.2} m ({:.0}°) {:.2} s into the trajectory and stayed there",
                    j.jump_m,
                    j.jump_deg,
                    j.t - t0,
                );
                match j.outcome {
                    JumpOutcome::Motion => format!(
                        "{head}; the depth after it agrees with the map at those poses, so the step was motion (a gap in the pose stream) or the pose source's own correction: kept"
                    ),
                    JumpOutcome::Reanchored {
                        correction_m,
                        correction_deg,
                    } => format!(
                        "{head}; the depth after it agrees with the map once moved {correction_m:.2} m ({correction_deg:.1}°): the pose source relocalised into another frame, and the poses were re-anchored"
                    ),
                    JumpOutcome::Cut => format!(
                        "{head} (the pose source relocalising into another frame the depth cannot match): the trajectory was cut there, {kept}; {} poses and the frames in their time left out",
                        self.left_out
                    ),
                }
            })
            .collect()
    }
}

/// Whether pose `b` is farther from pose `a` than a hand moves a camera in `dt` by more than
/// `min` (metres, degrees); (metres, degrees).
fn jumped(a: &Isometry3<f64>, b: &Isometry3<f64>, dt: f64, min: (f64, f64)) -> Option<(f64, f64)> {
    let m = (b.translation.vector - a.translation.vector).norm();
    let deg = a.rotation.angle_to(&b.rotation).to_degrees();
    (m > min.0 + 3.0 * dt.abs() || deg > min.1 + 400.0 * dt.abs()).then_some((m, deg))
}

/// The pieces of `traj` between the jumps that stay (the next [`HALF_WINDOW`] poses do not come
/// back) larger than `min` (metres, degrees), as index ranges in time order, and the jumps (each
/// judged a cut for now).
fn pieces(traj: &Trajectory, min: (f64, f64)) -> (Vec<std::ops::Range<usize>>, Vec<PoseJump>) {
    let n = traj.stamps.len();
    let mut cuts = Vec::new();
    let mut jumps = Vec::new();
    for k in 0..n.saturating_sub(1) {
        let Some((m, deg)) = jumped(
            &traj.poses[k],
            &traj.poses[k + 1],
            traj.stamps[k + 1] - traj.stamps[k],
            min,
        ) else {
            continue;
        };
        // It stays when the poses after it stay with the pose after the step and the poses
        // before it were with the pose before (each within half the step): a pose that jumps
        // away and back is neither, and neither is the step back from one.
        let apart = |a: usize, b: usize| {
            let m = (traj.poses[b].translation.vector - traj.poses[a].translation.vector).norm();
            let deg = traj.poses[a]
                .rotation
                .angle_to(&traj.poses[b].rotation)
                .to_degrees();
            m / min.0 + deg / min.1
        };
        let half = 0.5 * apart(k, k + 1);
        let after = k + 2..n.min(k + 2 + HALF_WINDOW);
        let before = k.saturating_sub(HALF_WINDOW)..k;
        let stays = !after.is_empty()
            && after.into_iter().all(|j| apart(k + 1, j) < half)
            && before.into_iter().all(|i| apart(i, k) < half);
        if stays {
            cuts.push(k + 1);
            jumps.push(PoseJump {
                t: traj.stamps[k + 1],
                jump_m: m,
                jump_deg: deg,
                outcome: JumpOutcome::Cut,
                agreement: None,
            });
        }
    }
    let bounds: Vec<usize> = std::iter::once(0)
        .chain(cuts)
        .chain(std::iter::once(n))
        .collect();
    (bounds.windows(2).map(|w| w[0]..w[1]).collect(), jumps)
}

/// The poses of `range` in `traj`, each moved by `c` (on the left).
fn moved(traj: &Trajectory, range: std::ops::Range<usize>, c: &Isometry3<f64>) -> Trajectory {
    Trajectory {
        stamps: traj.stamps[range.clone()].to_vec(),
        poses: traj.poses[range].iter().map(|p| c * p).collect(),
    }
}

/// The pieces kept (`kept[i]`: piece i's correction), joined in time order.
fn joined(
    traj: &Trajectory,
    ranges: &[std::ops::Range<usize>],
    kept: &[Option<Isometry3<f64>>],
) -> Trajectory {
    let mut out = Trajectory::default();
    for (r, c) in ranges.iter().zip(kept) {
        if let Some(c) = c {
            let m = moved(traj, r.clone(), c);
            out.stamps.extend(m.stamps);
            out.poses.extend(m.poses);
        }
    }
    out
}

/// Splits `traj` at the jumps that stay and keeps its pieces as `judge` finds them (see the
/// module docs; without a judge the largest piece): (each piece kept, moved by its correction;
/// the jumps with their outcomes; the poses left out).
fn judge_pieces(
    traj: &Trajectory,
    judge: Option<&dyn JumpJudge>,
) -> (Vec<Trajectory>, Vec<PoseJump>, usize) {
    let n = traj.stamps.len();
    let min = if judge.is_some() {
        (JUDGED_STEP_M, JUDGED_STEP_DEG)
    } else {
        (JUMP_MIN_M, JUMP_MIN_DEG)
    };
    let (ranges, mut jumps) = pieces(traj, min);
    if ranges.len() <= 1 {
        return (vec![traj.clone()], jumps, 0);
    }
    let reference = ranges
        .iter()
        .enumerate()
        .max_by_key(|(i, r)| (r.len(), std::cmp::Reverse(*i)))
        .map_or(0, |(i, _)| i);
    let mut kept: Vec<Option<Isometry3<f64>>> = vec![None; ranges.len()];
    kept[reference] = Some(Isometry3::identity());
    if let Some(judge) = judge {
        // Outwards from the reference, nearest first: before it, then after it, alternately.
        let mut order: Vec<usize> = (0..ranges.len()).filter(|&i| i != reference).collect();
        order.sort_by_key(|&i| (i.abs_diff(reference), i));
        for i in order {
            // The neighbour towards the reference, and the jump between them.
            let (j, jump) = if i < reference {
                (i + 1, i)
            } else {
                (i - 1, i - 1)
            };
            let piece = moved(traj, ranges[i].clone(), &Isometry3::identity());
            // The guess: the piece joined to its neighbour where the poses jumped (the camera
            // barely moves in one pose interval).
            let guess = match kept[j] {
                Some(cj) if i > reference => {
                    cj * traj.poses[ranges[j].end - 1] * traj.poses[ranges[i].start].inverse()
                }
                Some(cj) => {
                    cj * traj.poses[ranges[j].start] * traj.poses[ranges[i].end - 1].inverse()
                }
                None => Isometry3::identity(),
            };
            let map = joined(traj, &ranges, &kept);
            let Some(a) = judge.judge(&map, &piece, &guess) else {
                continue;
            };
            jumps[jump].agreement = Some([a.as_is, a.corrected]);
            if a.as_is >= AGREE_SHARE && a.as_is + 0.05 >= a.corrected {
                kept[i] = Some(Isometry3::identity());
                jumps[jump].outcome = JumpOutcome::Motion;
            } else if a.corrected >= AGREE_SHARE && kept[j].is_some() {
                kept[i] = Some(a.correction);
                jumps[jump].outcome = JumpOutcome::Reanchored {
                    correction_m: a.correction.translation.vector.norm(),
                    correction_deg: a.correction.rotation.angle().to_degrees(),
                };
            }
        }
    }
    // The pieces kept are put in the frame of the first of them (the pose source's frame at the
    // start, which a reading or a point given in the scan's frame is in).
    if let Some(first) = kept.iter().flatten().next().map(Isometry3::inverse) {
        for c in kept.iter_mut().flatten() {
            *c = first * *c;
        }
    }
    let mut out = Vec::new();
    let mut left_out = 0;
    for (r, c) in ranges.iter().zip(&kept) {
        match c {
            Some(c) => out.push(moved(traj, r.clone(), c)),
            None => left_out += r.len(),
        }
    }
    debug_assert_eq!(
        out.iter().map(|t| t.stamps.len()).sum::<usize>() + left_out,
        n
    );
    (out, jumps, left_out)
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
    check_poses(traj, None)
}

/// [`drop_outlier_poses`], the jumps that stay judged by `judge` (the depth): each piece beyond
/// one kept as it is, re-anchored or left out (see the module docs).
pub fn check_poses(traj: &Trajectory, judge: Option<&dyn JumpJudge>) -> (Trajectory, PoseCheck) {
    let (pieces, jumps, left_out) = judge_pieces(traj, judge);
    let mut out = Trajectory::default();
    let mut check = PoseCheck::default();
    for piece in &pieces {
        let (clean, c) = drop_outliers(piece);
        out.stamps.extend(clean.stamps);
        out.poses.extend(clean.poses);
        check.dropped += c.dropped;
        check.examples.extend(c.examples);
    }
    check.examples.truncate(20);
    check.poses = traj.stamps.len();
    check.jumps = jumps;
    check.left_out = left_out;
    check.kept_span_s = (left_out > 0 && !out.stamps.is_empty())
        .then(|| [out.stamps[0], out.stamps[out.stamps.len() - 1]]);
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
                && said[0].contains("0.00–6.63 s of it kept; 100 poses"),
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
