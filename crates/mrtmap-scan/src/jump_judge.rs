//! The depth as the judge of a jump in the poses ([`crate::pose_check::JumpJudge`]): the depth
//! frames in a piece of trajectory's time, placed by its poses, against those of the pieces kept
//! so far.

use mrtmap_geometry::icp::{IcpParams, IcpTarget, icp_point_to_plane};
use mrtmap_geometry::nalgebra::{Isometry3, Point3, Vector3};
use mrtmap_io::{InterpolationLimits, Recording, Trajectory};
use rustc_hash::FxHashMap;

use crate::frame::{DepthSampling, RayTable, depth_points};
use crate::pose_check::{Agreement, JumpJudge};

/// Depth frames read for the map kept so far, and for the piece judged.
const MAP_FRAMES: usize = 40;
const PIECE_FRAMES: usize = 20;
/// Points are thinned to one per cell of this size (m).
const CELL_M: f64 = 0.05;
/// A point lies on the map when it is this close to a map point (m).
const ON_MAP_M: f64 = 0.05;
/// Too few points to judge by.
const MIN_POINTS: usize = 200;

/// Judges by the depth frames of a recording.
pub(crate) struct DepthJudge<'a> {
    rec: &'a Recording,
    rays: RayTable,
    sampling: DepthSampling,
    limits: InterpolationLimits,
}

impl<'a> DepthJudge<'a> {
    /// A judge reading `rec`'s depth frames (every pixel of about 80 across).
    pub(crate) fn new(rec: &'a Recording, sampling: &DepthSampling) -> Self {
        Self {
            rec,
            rays: RayTable::new(&rec.rig.depth),
            sampling: DepthSampling {
                stride: sampling.stride.max(rec.rig.depth.width / 80).max(1),
                ..*sampling
            },
            limits: InterpolationLimits::default(),
        }
    }

    /// Up to `most` depth frames in `traj`'s time, evenly spread, placed by its poses: points
    /// and normals in the world, one per [`CELL_M`] cell.
    fn cloud(&self, traj: &Trajectory, most: usize) -> (Vec<Point3<f64>>, Vec<Vector3<f64>>) {
        let (Some(&t0), Some(&t1)) = (traj.stamps.first(), traj.stamps.last()) else {
            return (Vec::new(), Vec::new());
        };
        let frames: Vec<_> = self
            .rec
            .depth
            .iter()
            .filter(|e| e.t >= t0 && e.t <= t1)
            .collect();
        let step = frames.len().div_ceil(most.max(1)).max(1);
        let mut cells: FxHashMap<[i64; 3], (Point3<f64>, Vector3<f64>)> = FxHashMap::default();
        for e in frames.iter().step_by(step) {
            let Some(pose) = traj.interpolate(e.t, &self.limits) else {
                continue;
            };
            let Ok(img) = self.rec.read_depth(e) else {
                continue;
            };
            let pts = depth_points(&img, &self.rays, self.rec.rig.depth_scale, &self.sampling);
            for (p, n) in pts.points.iter().zip(&pts.normals) {
                let w = pose * p;
                let key = [
                    (w.x / CELL_M).floor() as i64,
                    (w.y / CELL_M).floor() as i64,
                    (w.z / CELL_M).floor() as i64,
                ];
                cells.entry(key).or_insert((w, pose.rotation * n));
            }
        }
        let mut v: Vec<_> = cells.into_iter().collect();
        // In a fixed order, so that the judgement does not depend on the hash.
        v.sort_by_key(|(k, _)| *k);
        v.into_iter().map(|(_, pn)| pn).unzip()
    }
}

impl JumpJudge for DepthJudge<'_> {
    fn judge(
        &self,
        kept: &Trajectory,
        piece: &Trajectory,
        guess: &Isometry3<f64>,
    ) -> Option<Agreement> {
        let (tp, tn) = self.cloud(kept, MAP_FRAMES);
        let (src, _) = self.cloud(piece, PIECE_FRAMES);
        if tp.len() < MIN_POINTS || src.len() < MIN_POINTS {
            return None;
        }
        let target = IcpTarget::new(tp, tn);
        let share_at = |t: &Isometry3<f64>| {
            let once = IcpParams {
                max_correspondence_m: ON_MAP_M,
                max_iterations: 1,
                ..IcpParams::default()
            };
            // The first iteration's share is the one at `t` (before its update).
            icp_point_to_plane(&src, &target, t, &once).fitness
        };
        let as_is = share_at(&Isometry3::identity());
        let coarse = icp_point_to_plane(
            &src,
            &target,
            guess,
            &IcpParams {
                max_correspondence_m: 0.3,
                huber_m: 0.05,
                max_iterations: 40,
                ..IcpParams::default()
            },
        );
        let fine = icp_point_to_plane(
            &src,
            &target,
            &coarse.target_from_source,
            &IcpParams {
                max_correspondence_m: ON_MAP_M,
                max_iterations: 30,
                ..IcpParams::default()
            },
        );
        let correction = fine.target_from_source;
        Some(Agreement {
            as_is,
            corrected: share_at(&correction),
            correction,
        })
    }
}
