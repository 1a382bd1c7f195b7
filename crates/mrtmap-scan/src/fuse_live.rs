//! Fusion while the scan is being recorded (`mrtmap live`): the same per-frame work as
//! [`fuse`](crate::fuse) (read, place, observe, merge into one voxel map), fed a frame at a time
//! as the recording grows.
//!
//! 1. A thermal frame is taken once the other streams have passed it: the depth list reaches
//!    past its time by the sync tolerance (so its nearest depth frame is listed) and the
//!    trajectory reaches its time. Until then it waits; nothing is read twice.
//! 2. Its depth partner is the nearest depth frame within the tolerance, as in batch fusion; a
//!    frame without one, or without a pose, is counted as skipped for that reason.
//! 3. The frames taken are fused as one chunk: read in parallel, observed and merged.
//!
//! What batch fusion does over the whole scan is left out, as it needs the scan's end: the thermal
//! clock's estimate (the rig's or the given offset is applied by whoever appends the stamps), the
//! vignetting warm-up and the check for poses that jump. The map is a preview: `mrtmap run` on the
//! finished recording makes the result.

use std::time::Instant;

use mrtmap_io::{InterpolationLimits, Recording};

use crate::frame::{DepthSampling, RayTable};
use crate::fuse::{Fuser, sync_tolerance};
use crate::radiometric::Calibrator;
use crate::sync::nearest;
use crate::{FuseParams, Fused, FusionReport, SkipReason};

/// Fusion fed as a recording grows.
pub struct LiveFusion {
    params: FuseParams,
    fuser: Fuser,
    rays: Option<RayTable>,
    limits: InterpolationLimits,
    /// The first thermal frame not yet taken.
    next: usize,
    started: Instant,
}

/// What one [`LiveFusion::advance`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Advance {
    /// The thermal frames taken (indices into the recording's thermal list), fused or skipped.
    pub taken: Vec<usize>,
    /// Of those, the frames that reached the map.
    pub fused: usize,
}

impl LiveFusion {
    /// A fusion with an empty map. ICP, when `params` enable it, registers each frame on the map
    /// fused before it, as in batch fusion.
    pub fn new(params: &FuseParams) -> Self {
        let report = FusionReport {
            parameters: *params,
            ..Default::default()
        };
        let mut fuser = Fuser::new(
            params,
            InterpolationLimits::default(),
            report,
            Calibrator::default(),
        );
        fuser.report.icp.enabled = params.icp.enabled;
        LiveFusion {
            params: *params,
            fuser,
            rays: None,
            limits: InterpolationLimits::default(),
            next: 0,
            started: Instant::now(),
        }
    }

    /// Takes every thermal frame of `rec` the other streams have now passed, and fuses it.
    pub fn advance(&mut self, rec: &Recording) -> Advance {
        if self.rays.is_none() {
            if self.params.depth.stride == 0 {
                self.params.depth.stride =
                    DepthSampling::auto_stride(&rec.rig.depth, &rec.rig.thermal);
                self.fuser.params = self.params;
                self.fuser.report.parameters = self.params;
            }
            self.rays = Some(RayTable::new(&rec.rig.depth));
        }
        let tolerance = sync_tolerance(rec, self.params.sync_tolerance_s);
        self.fuser.report.sync_tolerance_used_s = tolerance;
        let (Some(depth_end), Some(pose_end)) =
            (rec.depth.last().map(|e| e.t), rec.trajectory.stamps.last())
        else {
            return Advance::default();
        };
        let depth_t: Vec<f64> = rec.depth.iter().map(|e| e.t).collect();
        let mut usable = Vec::new();
        let mut taken = Vec::new();
        while let Some(th) = rec.thermal.get(self.next) {
            if th.t + tolerance > depth_end || th.t > *pose_end {
                break;
            }
            let i = self.next;
            self.next += 1;
            taken.push(i);
            let pair = nearest(&depth_t, th.t).filter(|&d| (depth_t[d] - th.t).abs() <= tolerance);
            match pair {
                None => self.fuser.drop_frame(SkipReason::NoDepthWithinTolerance),
                Some(d) => {
                    let traj = &rec.trajectory;
                    if traj.interpolate(th.t, &self.limits).is_some()
                        && traj.interpolate(depth_t[d], &self.limits).is_some()
                    {
                        usable.push((i, d));
                    } else {
                        self.fuser.drop_frame(SkipReason::NoPose);
                    }
                }
            }
        }
        let before = self.fuser.report.used_frames;
        if !usable.is_empty() {
            let rays = self.rays.as_ref().expect("set above");
            let chunks: Vec<&[(usize, usize)]> = usable.chunks(self.params.chunk.max(1)).collect();
            let total = rec.thermal.len() as u64;
            self.fuser
                .run(rec, rays, &chunks, total, &|_, _| {}, &|_| false);
        }
        self.fuser.report.thermal_frames = rec.thermal.len();
        self.fuser.report.depth_frames = rec.depth.len();
        Advance {
            taken,
            fused: self.fuser.report.used_frames - before,
        }
    }

    /// Thermal frames taken so far (fused or skipped).
    pub fn taken(&self) -> usize {
        self.next
    }

    /// What could not be read (the first few frames', in words).
    pub fn problems(&self) -> &[String] {
        &self.fuser.report.problems
    }

    /// The thermal frames fused so far.
    pub fn fused(&self) -> usize {
        self.fuser.report.used_frames
    }

    /// The fusion so far, as batch fusion returns it (the cloud of the map as it stands).
    pub fn snapshot(&self) -> Fused {
        let mut cloud = self.fuser.map.to_cloud();
        cloud.positions.shrink_to_fit();
        let mut report = self.fuser.report.clone();
        report.voxels = cloud.len();
        report.radiometric = self
            .fuser
            .calibrator
            .clone()
            .finish(self.params.radiometric.enabled);
        report.timing_s.total = self.started.elapsed().as_secs_f64();
        Fused {
            cloud,
            report,
            poses: self.fuser.poses.clone(),
            frames: self.fuser.frames.clone(),
        }
    }
}
