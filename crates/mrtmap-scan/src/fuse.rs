//! From a recording to a fused thermal point cloud (stage 3 of the seed method).
//!
//! ```text
//!  thermal frame ─ nearest depth frame (≤ 20 ms) ─ poses at both times
//!      │ depth → points + normals (camera)        [parallel, chunks of frames]
//!      │ ICP refinement against the map so far     [sequential: the map grows]
//!      │ points → world → thermal camera, z-buffer, bilinear samples, weights   [parallel]
//!      └ voxels (T⁴ radiant averages)              [merged in frame order]
//! ```
//!
//! Results do not depend on the number of threads: parallel work is per frame, merged in order.

use std::collections::BTreeMap;
use std::time::Instant;

use mrtmap_geometry::cloud::voxel_key;
use mrtmap_geometry::icp::{IcpParams, IcpTarget, icp_point_to_plane, kabsch};
use mrtmap_geometry::nalgebra::{Isometry3, Point3, Vector3};
use mrtmap_io::{InterpolationLimits, Recording, ThermalCloud};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::clock::{ClockOffset, ClockReport, ClockSearch, OffsetSource, estimate_offset_until};
use crate::frame::{DepthPoints, DepthSampling, RayTable, ThermalImage, depth_points};
use crate::jump_judge::DepthJudge;
use crate::observe::{ObservationCounts, ObservationParams, observe};
use crate::pose_check::{PoseCheck, check_poses};
use crate::radiometric::{
    Calibrator, FrameResiduals, RadiometricReport, SelfCalibration, frame_residuals,
};
use crate::sync::{SkipReason, pair_frames};
use crate::voxels::{FrameVoxels, ShardedVoxels, VoxelMap};

/// ICP refinement settings and the checks a refinement must pass.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct IcpSettings {
    /// Whether to refine poses by ICP.
    pub enabled: bool,
    /// Source points per frame.
    pub source_points: usize,
    /// ICP parameters.
    pub params: IcpParams,
    /// The map needs this many surface voxels before ICP starts.
    pub min_map_voxels: usize,
    /// Rebuild the map's k-d tree every this many frames.
    pub rebuild_every: usize,
    /// The target keeps one voxel in `target_every`³.
    pub target_every: i32,
    /// Gain of the carried drift correction: each accepted refinement moves it this fraction of the
    /// way (per-frame depth errors average out, slow drift is followed): about 4 s to follow a
    /// drift at a Lepton's 8.7 Hz. The map is built from corrected frames, so nothing holds the
    /// correction to the pose source: with exact poses a gain of 0.1 let it wander 1–3 cm over a
    /// minute and moved walls with it (L-shaped walk 12: the window wall 2.2 cm out).
    pub correction_gain: f64,
    /// The gain while the refinements' steps show a drift the carried correction does not follow
    /// (their mean over the last [`DRIFT_WINDOW`] accepted frames more than twice its standard
    /// error): plain odometry drifts faster than 4 s of lag allows.
    #[serde(default = "default_drift_gain")]
    pub drift_gain: f64,
    /// Reject refinements with a lower fitness.
    pub min_fitness: f64,
    /// Reject refinements with a larger point-to-plane RMSE (m).
    pub max_rmse_m: f64,
    /// Reject refinements that move a frame farther (m)…
    pub max_step_m: f64,
    /// …or turn it more (degrees).
    pub max_step_deg: f64,
}

impl Default for IcpSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            source_points: 1500,
            // The target is voxel centroids 6 cm apart and the depth is noisy: after a few
            // iterations the updates wander by a few millimetres as correspondences switch, so a
            // millimetre (a milliradian) is converged and ten iterations are plenty (15 at 10 µm
            // ran all 15 on almost every frame; the 343 s scan fused in 36.9 s instead of 33.2 s).
            params: IcpParams {
                max_iterations: 10,
                converged_translation_m: 1e-3,
                converged_rotation_rad: 1e-3,
                ..IcpParams::default()
            },
            min_map_voxels: 3000,
            rebuild_every: 30,
            target_every: 2,
            correction_gain: 0.03,
            drift_gain: 0.1,
            min_fitness: 0.7,
            max_rmse_m: 0.02,
            max_step_m: 0.03,
            max_step_deg: 1.0,
        }
    }
}

fn default_drift_gain() -> f64 {
    IcpSettings::default().drift_gain
}

/// Accepted refinements over which a drift is detected (3 s at 8.7 Hz).
pub const DRIFT_WINDOW: usize = 26;

/// The last accepted refinements' steps (translation, and the rotation as the displacement it
/// makes 3 m away), to tell a drift (steps with a consistent direction) from each frame's own
/// depth error (steps that average out).
#[derive(Default)]
struct Steps {
    recent: std::collections::VecDeque<[f64; 6]>,
}

impl Steps {
    /// Adds a step; whether the window's mean step is more than twice its standard error.
    fn drifting(&mut self, step: &Isometry3<f64>) -> bool {
        let (t, w) = (step.translation.vector, step.rotation.scaled_axis() * 3.0);
        self.recent.push_back([t.x, t.y, t.z, w.x, w.y, w.z]);
        if self.recent.len() > DRIFT_WINDOW {
            self.recent.pop_front();
        }
        let n = self.recent.len();
        if n < DRIFT_WINDOW {
            return false;
        }
        let nf = n as f64;
        let (mut mean2, mut var) = (0.0, 0.0);
        for k in 0..6 {
            let m = self.recent.iter().map(|s| s[k]).sum::<f64>() / nf;
            mean2 += m * m;
            var += self.recent.iter().map(|s| (s[k] - m).powi(2)).sum::<f64>() / (nf - 1.0);
        }
        mean2 > 4.0 * var / nf
    }
}

/// Fusion settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FuseParams {
    /// Voxel size (m).
    pub voxel_m: f64,
    /// Largest time between a thermal frame and its depth frame (s).
    pub sync_tolerance_s: f64,
    /// Depth pixel stride, normal baseline and range.
    #[serde(skip)]
    pub depth: DepthSampling,
    /// Observation model.
    pub observation: ObservationParams,
    /// ICP.
    pub icp: IcpSettings,
    /// Frames prepared in parallel at a time.
    pub chunk: usize,
    /// Radiometric self-calibration (per-frame offsets, vignetting).
    #[serde(default)]
    pub radiometric: SelfCalibration,
    /// The thermal stamps' offset from the depth clock: given, from rig.toml, or estimated.
    #[serde(default = "default_clock")]
    pub clock: ClockOffset,
    /// How the offset is searched for when estimated.
    #[serde(default)]
    pub clock_search: ClockSearch,
}

fn default_clock() -> ClockOffset {
    ClockOffset::Auto
}

impl Default for FuseParams {
    fn default() -> Self {
        Self {
            voxel_m: 0.03,
            sync_tolerance_s: 0.020,
            depth: DepthSampling::default(),
            observation: ObservationParams::default(),
            icp: IcpSettings::default(),
            chunk: 8,
            radiometric: SelfCalibration::default(),
            clock: ClockOffset::Auto,
            clock_search: ClockSearch::default(),
        }
    }
}

/// ICP statistics of a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct IcpReport {
    /// Whether ICP was on.
    pub enabled: bool,
    /// Frames ICP ran on.
    pub attempted: usize,
    /// Refinements accepted.
    pub accepted: usize,
    /// Refinements rejected, by reason.
    pub rejected: BTreeMap<String, usize>,
    /// Mean fitness of accepted refinements.
    pub mean_fitness: f64,
    /// Mean point-to-point inlier RMSE of accepted refinements (m).
    pub mean_inlier_rmse_m: f64,
    /// Mean number of iterations of the refinements run.
    #[serde(default)]
    pub mean_iterations: f64,
    /// Frames where some directions were unconstrained (left unchanged).
    pub degenerate_frames: usize,
    /// Accepted refinements that followed a detected drift with the higher gain.
    #[serde(default)]
    pub drift_frames: usize,
    /// The rigid move that put the finished map back where the pose source puts it on average
    /// (translation m, rotation degrees); `None` when it stayed (ICP off, or a pose source that
    /// drifts: see [`anchor_to_poses`]).
    #[serde(default)]
    pub anchored: Option<(f64, f64)>,
    /// The final correction applied to the trajectory: translation (m) and rotation (degrees).
    pub final_correction_m: f64,
    /// Rotation of the final correction (degrees).
    pub final_correction_deg: f64,
}

/// Time spent per phase (s), summed over threads for the parallel phases.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// Setting the thermal clock: the pose check and the offset search (wall).
    #[serde(default)]
    pub clock: f64,
    /// Reading and decoding images, back-projecting depth (CPU seconds).
    pub read_cpu: f64,
    /// ICP (wall).
    pub icp: f64,
    /// Projection into thermal, sampling and voxel gathering (CPU seconds: the frames' times summed).
    pub observe_cpu: f64,
    /// Merging into the voxel map and rebuilding the ICP tree (wall).
    pub merge: f64,
    /// Building the output cloud (wall).
    pub output: f64,
    /// The first pass over the scan's first frames that estimates the vignetting (wall).
    #[serde(default)]
    pub vignetting_warm_up: f64,
    /// Whole run (wall).
    pub total: f64,
}

/// What `fuse` did: `fusion.json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FusionReport {
    /// The recording fused.
    pub recording: String,
    /// Thermal frames listed.
    pub thermal_frames: usize,
    /// Depth frames listed.
    pub depth_frames: usize,
    /// Thermal frames fused.
    pub used_frames: usize,
    /// Every this many depth pixels were used, in each direction.
    #[serde(default)]
    pub depth_stride: u32,
    /// The largest time between a thermal frame and the depth frame it took (s): the setting, or
    /// just over half the depth frames' median interval where that is longer, so that every
    /// thermal frame finds a depth frame whatever the depth rate (each is placed by the pose at its
    /// own time).
    #[serde(default)]
    pub sync_tolerance_used_s: f64,
    /// The thermal clock's offset applied to the thermal stamps, and how it was found.
    #[serde(default)]
    pub clock: ClockReport,
    /// Poses of the pose source dropped because they jumped away from their neighbours' motion
    /// and back.
    #[serde(default)]
    pub pose_check: PoseCheck,
    /// Frames skipped, by reason.
    pub skipped: BTreeMap<SkipReason, usize>,
    /// The first few problems, with file names.
    pub problems: Vec<String>,
    /// What happened to the depth points.
    pub observations: ObservationCounts,
    /// Voxels with a temperature.
    pub voxels: usize,
    /// ICP.
    pub icp: IcpReport,
    /// Timing.
    pub timing_s: Timing,
    /// Thermal frames per second of wall time.
    pub frames_per_second: f64,
    /// Radiometric self-calibration: offsets removed per frame, vignetting, consistency.
    #[serde(default)]
    pub radiometric: RadiometricReport,
    /// The parameters used.
    pub parameters: FuseParams,
}

/// A fused thermal frame, for what comes after fusion (texturing the room model): which frames,
/// where the cameras were, and the offset self-calibration removed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FusedFrame {
    /// Index into the recording's thermal list.
    pub thermal: usize,
    /// Index into its depth list.
    pub depth: usize,
    /// The thermal frame's time on the depth clock (its stamp plus the clock offset).
    pub t: f64,
    /// world_from_thermal at the exposure, after ICP (and the map's anchoring).
    pub world_from_thermal: [f64; 7],
    /// world_from_depth of its depth frame, after ICP.
    pub world_from_depth: [f64; 7],
    /// The offset self-calibration removed from this frame (K): pixel − offset − vignetting·ρ.
    pub offset_k: f64,
}

/// An isometry as [tx, ty, tz, qx, qy, qz, qw].
pub fn pose7(p: &Isometry3<f64>) -> [f64; 7] {
    let (t, q) = (p.translation.vector, p.rotation.coords);
    [t.x, t.y, t.z, q.x, q.y, q.z, q.w]
}

/// The isometry of [tx, ty, tz, qx, qy, qz, qw] (the quaternion normalised).
pub fn from_pose7(a: &[f64; 7]) -> Isometry3<f64> {
    use mrtmap_geometry::nalgebra::{Quaternion, Translation3, UnitQuaternion};
    Isometry3::from_parts(
        Translation3::new(a[0], a[1], a[2]),
        UnitQuaternion::from_quaternion(Quaternion::new(a[6], a[3], a[4], a[5])),
    )
}

/// The result of fusion.
pub struct Fused {
    /// The cloud.
    pub cloud: ThermalCloud,
    /// The report.
    pub report: FusionReport,
    /// The refined world_from_depth pose of each used thermal frame's depth frame, by the depth
    /// frame's time.
    pub poses: Vec<(f64, Isometry3<f64>)>,
    /// The frames fused, in order.
    pub frames: Vec<FusedFrame>,
}

/// An accepted ICP refinement: the correction and its quality.
struct Refinement {
    delta: Isometry3<f64>,
    fitness: f64,
    rmse_m: f64,
    degenerate_dofs: usize,
}

impl Fused {
    /// The refined poses as a trajectory (`poses.txt`).
    pub fn trajectory(&self) -> mrtmap_io::Trajectory {
        mrtmap_io::Trajectory {
            stamps: self.poses.iter().map(|p| p.0).collect(),
            poses: self.poses.iter().map(|p| p.1).collect(),
        }
    }
}

/// A prepared frame.
struct Prepared {
    thermal_index: usize,
    depth_index: usize,
    thermal_t: f64,
    depth_t: f64,
    points: DepthPoints,
    thermal: ThermalImage,
}

fn rotation_deg(p: &Isometry3<f64>) -> f64 {
    p.rotation.angle().to_degrees()
}

/// Reads and back-projects a chunk of (thermal, depth) frame pairs in parallel; also returns the
/// CPU seconds spent (the frames' times summed).
fn prepare(
    rec: &Recording,
    rays: &RayTable,
    params: &FuseParams,
    chunk: &[(usize, usize)],
) -> (Vec<Result<Prepared, String>>, f64) {
    let prepared: Vec<(Result<Prepared, String>, f64)> = chunk
        .par_iter()
        .map(|&(ti, di)| {
            let t0 = Instant::now();
            let th = &rec.thermal[ti];
            let de = &rec.depth[di];
            let read = || -> Result<Prepared, String> {
                let depth = rec.read_depth(de).map_err(|e| e.to_string())?;
                let thermal = rec.read_thermal(th).map_err(|e| e.to_string())?;
                Ok(Prepared {
                    thermal_index: ti,
                    depth_index: di,
                    thermal_t: th.t,
                    depth_t: de.t,
                    points: depth_points(&depth, rays, rec.rig.depth_scale, &params.depth),
                    thermal: ThermalImage::from_raw(&thermal, rec.rig.thermal_encoding),
                })
            };
            let r = read();
            (r, t0.elapsed().as_secs_f64())
        })
        .collect();
    let cpu = prepared.iter().map(|(_, t)| t).sum();
    (prepared.into_iter().map(|(r, _)| r).collect(), cpu)
}

/// A prepared frame with its poses: world_from_depth and world_from_thermal-depth (before ICP),
/// or after it world_from_depth and world_from_thermal.
type Posed = (Prepared, Isometry3<f64>, Isometry3<f64>);

/// The state carried through a fusion, chunk after chunk.
pub(crate) struct Fuser {
    pub(crate) params: FuseParams,
    limits: InterpolationLimits,
    pub(crate) report: FusionReport,
    pub(crate) map: VoxelMap,
    target: Option<IcpTarget>,
    since_rebuild: usize,
    /// The ICP correction carried from frame to frame.
    correction: Isometry3<f64>,
    /// The recent refinements' steps.
    steps: Steps,
    fit_sum: f64,
    rmse_sum: f64,
    iterations_sum: usize,
    pub(crate) poses: Vec<(f64, Isometry3<f64>)>,
    pub(crate) frames: Vec<FusedFrame>,
    /// A few of each frame's depth points, placed by its refined and by its given pose.
    anchor: Vec<(Point3<f64>, Point3<f64>)>,
    timing: Timing,
    done: u64,
    pub(crate) calibrator: Calibrator,
}

/// A first pass for the vignetting fuses at most this share of the scan's chunks (one in …).
const WARM_UP_SHARE: usize = 4;

/// … and stops once its frames estimate the vignetting with this many times the spread in ρ the
/// estimate needs.
const WARM_UP_SPREAD: f64 = 4.0;

impl Fuser {
    /// A fuser with an empty map.
    pub(crate) fn new(
        params: &FuseParams,
        limits: InterpolationLimits,
        report: FusionReport,
        calibrator: Calibrator,
    ) -> Self {
        Fuser {
            params: *params,
            limits,
            report,
            map: VoxelMap::new(params.voxel_m),
            target: None,
            since_rebuild: 0,
            correction: Isometry3::identity(),
            steps: Steps::default(),
            fit_sum: 0.0,
            rmse_sum: 0.0,
            iterations_sum: 0,
            poses: Vec::new(),
            frames: Vec::new(),
            anchor: Vec::new(),
            timing: Timing::default(),
            done: 0,
            calibrator,
        }
    }

    /// Fuses `chunks` in order, until `enough` says so after a chunk; the next chunk is read
    /// while the current one is registered, observed and merged (ICP and merging are partly
    /// sequential, reading is not). Returns the chunks fused.
    pub(crate) fn run(
        &mut self,
        rec: &Recording,
        rays: &RayTable,
        chunks: &[&[(usize, usize)]],
        total: u64,
        progress: &(dyn Fn(u64, u64) + Sync),
        enough: &(dyn Fn(&Self) -> bool + Sync),
    ) -> usize {
        let params = &{ self.params };
        let mut next = chunks.first().map(|c| prepare(rec, rays, params, c));
        for i in 0..chunks.len() {
            let Some((prepared, cpu)) = next.take() else {
                return i;
            };
            self.timing.read_cpu += cpu;
            let (following, stop) = rayon::join(
                || chunks.get(i + 1).map(|c| prepare(rec, rays, params, c)),
                || {
                    let ready = self.posed(rec, prepared);
                    let work = self.register(rec, ready);
                    let results = self.observe(rec, &work);
                    self.record_frames(&work, &results);
                    self.merge(results, total, progress);
                    enough(self)
                },
            );
            if stop {
                return i + 1;
            }
            next = following;
        }
        chunks.len()
    }

    /// Counts a frame skipped for `r`.
    fn skip(&mut self, r: SkipReason) {
        *self.report.skipped.entry(r).or_default() += 1;
    }

    /// Counts a frame skipped for `r` before it reaches the map: it is done.
    pub(crate) fn drop_frame(&mut self, r: SkipReason) {
        self.skip(r);
        self.done += 1;
    }

    /// The frames that can be used, with their poses; the others skipped and counted.
    fn posed(&mut self, rec: &Recording, prepared: Vec<Result<Prepared, String>>) -> Vec<Posed> {
        let mut ready = Vec::with_capacity(prepared.len());
        for pr in prepared {
            let pr = match pr {
                Ok(p) => p,
                Err(msg) => {
                    self.drop_frame(SkipReason::UnreadableImage);
                    if self.report.problems.len() < 10 {
                        self.report.problems.push(msg);
                    }
                    continue;
                }
            };
            if pr.points.points.len() < 100 {
                self.drop_frame(SkipReason::TooFewDepthPoints);
                continue;
            }
            let traj = &rec.trajectory;
            let (Some(wd), Some(wt)) = (
                traj.interpolate(pr.depth_t, &self.limits),
                traj.interpolate(pr.thermal_t, &self.limits),
            ) else {
                self.drop_frame(SkipReason::NoPose);
                continue;
            };
            ready.push((pr, wd, wt));
        }
        ready
    }

    /// One frame's ICP against the map, from the correction `start`: `None` without a target.
    fn refine(
        &self,
        pr: &Prepared,
        wd: &Isometry3<f64>,
        start: &Isometry3<f64>,
    ) -> Option<(usize, Result<Refinement, &'static str>)> {
        let params = &self.params;
        let tgt = self.target.as_ref().filter(|_| params.icp.enabled)?;
        let init = start * wd;
        let step = (pr.points.points.len() / params.icp.source_points.max(1)).max(1);
        let src: Vec<Point3<f64>> = pr
            .points
            .points
            .iter()
            .step_by(step)
            .map(|p| init * p)
            .collect();
        let reg = icp_point_to_plane(&src, tgt, &Isometry3::identity(), &params.icp.params);
        let d = reg.target_from_source;
        let verdict = if reg.fitness < params.icp.min_fitness {
            Err("fitness below the limit")
        } else if reg.inlier_plane_rmse_m > params.icp.max_rmse_m {
            Err("residual above the limit")
        } else if d.translation.vector.norm() > params.icp.max_step_m
            || rotation_deg(&d) > params.icp.max_step_deg
        {
            Err("step larger than the limit")
        } else {
            Ok(Refinement {
                delta: d,
                fitness: reg.fitness,
                rmse_m: reg.inlier_rmse_m,
                degenerate_dofs: reg.degenerate_dofs,
            })
        };
        Some((reg.iterations, verdict))
    }

    /// ICP: every frame of the chunk is refined in parallel from the correction at the chunk's
    /// start; the carried correction is then updated in frame order. Returns the frames with
    /// their refined world_from_depth and world_from_thermal.
    fn register(&mut self, rec: &Recording, ready: Vec<Posed>) -> Vec<Posed> {
        let t1 = Instant::now();
        let start = self.correction;
        let refinements: Vec<_> = ready
            .par_iter()
            .map(|(pr, wd, _)| self.refine(pr, wd, &start))
            .collect();
        let mut work = Vec::with_capacity(ready.len());
        for ((pr, wd, wt), refinement) in ready.into_iter().zip(refinements) {
            let mut frame_correction = start;
            match refinement {
                None => {}
                Some((iterations, Err(why))) => {
                    self.iterations_sum += iterations;
                    self.report.icp.attempted += 1;
                    *self.report.icp.rejected.entry(why.to_string()).or_default() += 1;
                }
                Some((iterations, Ok(r))) => {
                    self.iterations_sum += iterations;
                    self.report.icp.attempted += 1;
                    self.report.icp.accepted += 1;
                    self.fit_sum += r.fitness;
                    self.rmse_sum += r.rmse_m;
                    self.report.icp.degenerate_frames += (r.degenerate_dofs > 0) as usize;
                    frame_correction = r.delta * start;
                    let gain = if self.steps.drifting(&r.delta) {
                        self.report.icp.drift_frames += 1;
                        self.params.icp.drift_gain
                    } else {
                        self.params.icp.correction_gain
                    };
                    self.correction = self.correction.lerp_slerp(&frame_correction, gain);
                }
            }
            let world_from_depth = frame_correction * wd;
            let world_from_thermal = frame_correction * wt * rec.rig.depth_from_thermal;
            if self.params.icp.enabled {
                let pts = &pr.points.points;
                for p in pts.iter().step_by((pts.len() / ANCHOR_POINTS).max(1)) {
                    self.anchor.push((world_from_depth * p, wd * p));
                }
            }
            // Keyed by the depth frame's own time (two thermal frames may share one depth frame
            // when depth runs slower): the pose is the depth frame's.
            if self.poses.last().is_none_or(|l| l.0 < pr.depth_t) {
                self.poses.push((pr.depth_t, world_from_depth));
            }
            work.push((pr, world_from_depth, world_from_thermal));
        }
        self.timing.icp += t1.elapsed().as_secs_f64();
        work
    }

    /// Observes the frames' temperatures on their points, in parallel; with self-calibration,
    /// each frame is compared with the map as it stood at the chunk's start and corrected.
    fn observe(&mut self, rec: &Recording, work: &[Posed]) -> Vec<Observed> {
        let params = &{ self.params };
        let cal = params.radiometric;
        let (map, a, carried) = (
            &self.map,
            self.calibrator.vignetting(),
            self.calibrator.last_offset(),
        );
        let results: Vec<Observed> = work
            .par_iter()
            .map(|(pr, wd, wt)| {
                let t0 = Instant::now();
                let pts: Vec<Point3<f64>> = pr.points.points.iter().map(|p| wd * p).collect();
                let nrm: Vector3List = pr.points.normals.iter().map(|n| wd.rotation * n).collect();
                let (obs, counts) = observe(
                    &pts,
                    &nrm,
                    wt,
                    &rec.rig.thermal,
                    &pr.thermal,
                    &params.observation,
                );
                let vm = params.voxel_m;
                let keys: Vec<[i32; 3]> = pts.iter().map(|p| voxel_key(p, vm)).collect();
                let (residuals, offset, a) = if cal.enabled {
                    // Every third observation is plenty for a median and a slope. Neighbouring
                    // observations mostly share a voxel: the last one looked up is kept.
                    let mut last: Option<([i32; 3], Option<f64>)> = None;
                    let pairs: Vec<(f64, f64)> = obs
                        .iter()
                        .step_by(3)
                        .filter_map(|o| {
                            let k = keys[o.index];
                            let reference = match last {
                                Some((lk, r)) if lk == k => r,
                                _ => {
                                    let r = map.reference_k(
                                        k,
                                        cal.min_map_observations,
                                        cal.max_map_spread_k,
                                    );
                                    last = Some((k, r));
                                    r
                                }
                            };
                            reference.map(|t| (o.t_k - t, o.rho))
                        })
                        .collect();
                    let r = frame_residuals(&pairs, a, cal.outlier_k);
                    let offset = if r.n >= cal.min_overlap {
                        r.median_k
                    } else {
                        carried
                    };
                    (r, offset, a)
                } else {
                    (FrameResiduals::default(), 0.0, 0.0)
                };
                let mut fv = FrameVoxels::with_capacity(pts.len() / 8);
                for ((k, p), n) in keys.iter().zip(&pts).zip(&nrm) {
                    fv.add_point(*k, p, n);
                }
                for o in &obs {
                    let t = o.t_k - offset - a * o.rho;
                    fv.add_temperature(keys[o.index], t, o.w);
                }
                Observed {
                    voxels: fv.into_shards(),
                    counts,
                    thermal_t: pr.thermal_t,
                    residuals,
                    offset,
                    cpu_s: t0.elapsed().as_secs_f64(),
                }
            })
            .collect();
        self.timing.observe_cpu += results.iter().map(|o| o.cpu_s).sum::<f64>();
        results
    }

    /// Records the frames that reached the map, with their poses and offsets.
    fn record_frames(&mut self, work: &[Posed], results: &[Observed]) {
        for ((pr, wd, wt), o) in work.iter().zip(results) {
            if o.counts.kept > 0 {
                self.frames.push(FusedFrame {
                    thermal: pr.thermal_index,
                    depth: pr.depth_index,
                    t: pr.thermal_t,
                    world_from_thermal: pose7(wt),
                    world_from_depth: pose7(wd),
                    offset_k: o.offset,
                });
            }
        }
    }

    /// Merges the frames into the map in frame order, and rebuilds the ICP target when due.
    fn merge(&mut self, results: Vec<Observed>, total: u64, progress: &(dyn Fn(u64, u64) + Sync)) {
        let t3 = Instant::now();
        let mut frames = Vec::with_capacity(results.len());
        for o in results {
            let (fv, counts) = (o.voxels, o.counts);
            if self.params.radiometric.enabled && counts.kept > 0 {
                self.calibrator.record(
                    o.thermal_t,
                    &o.residuals,
                    o.offset,
                    self.params.radiometric.min_overlap,
                );
            }
            if counts.kept == 0 {
                self.skip(SkipReason::NothingVisible);
            } else {
                self.report.used_frames += 1;
            }
            self.report.observations.add(&counts);
            frames.push(fv);
            self.since_rebuild += 1;
            self.done += 1;
            progress(self.done, total);
        }
        self.map.merge(&frames);
        let icp = &self.params.icp;
        if icp.enabled && (self.target.is_none() || self.since_rebuild >= icp.rebuild_every) {
            let (p, n) = self.map.surface(3, icp.target_every);
            if p.len() >= icp.min_map_voxels {
                self.target = Some(IcpTarget::new(p, n));
                self.since_rebuild = 0;
            }
        }
        self.timing.merge += t3.elapsed().as_secs_f64();
    }

    /// The cloud, and the report completed.
    fn finish(mut self, t_start: Instant) -> Fused {
        let t4 = Instant::now();
        let mut cloud = self.map.to_cloud();
        if let Some(a) = anchor_to_poses(&self.report.icp, &self.anchor) {
            move_cloud(&mut cloud, &a);
            for (_, pose) in &mut self.poses {
                *pose = a * *pose;
            }
            for f in &mut self.frames {
                f.world_from_thermal = pose7(&(a * from_pose7(&f.world_from_thermal)));
                f.world_from_depth = pose7(&(a * from_pose7(&f.world_from_depth)));
            }
            self.report.icp.anchored = Some((a.translation.vector.norm(), rotation_deg(&a)));
        }
        self.timing.output = t4.elapsed().as_secs_f64();
        self.timing.total = t_start.elapsed().as_secs_f64();
        let report = &mut self.report;
        report.voxels = cloud.len();
        if report.icp.accepted > 0 {
            report.icp.mean_fitness = self.fit_sum / report.icp.accepted as f64;
            report.icp.mean_inlier_rmse_m = self.rmse_sum / report.icp.accepted as f64;
        }
        if report.icp.attempted > 0 {
            report.icp.mean_iterations = self.iterations_sum as f64 / report.icp.attempted as f64;
        }
        report.icp.final_correction_m = self.correction.translation.vector.norm();
        report.icp.final_correction_deg = rotation_deg(&self.correction);
        report.frames_per_second = report.thermal_frames as f64 / self.timing.total.max(1e-9);
        report.radiometric =
            std::mem::take(&mut self.calibrator).finish(self.params.radiometric.enabled);
        report.timing_s = self.timing;
        Fused {
            cloud,
            report: self.report,
            poses: self.poses,
            frames: self.frames,
        }
    }
}

/// Depth points per frame kept to anchor the finished map (the 343 s scan's 3,000 frames: 48,000
/// pairs).
const ANCHOR_POINTS: usize = 16;

/// The rigid move that puts the finished map where the pose source puts it on average: the
/// Kabsch fit taking every frame's depth points as its refined pose places them to where its
/// given pose does. ICP makes each frame agree with the map built so far, and the map is built from
/// refined frames, so nothing holds the map to the pose source's frame: with exact poses the
/// carried correction moved the whole room 8–12 mm over the 343 s office scan (its shape right
/// within a few millimetres), which moves every answer asked in the scan's frame. The move is
/// made only when the pose source did not drift (at most 1 in 8 accepted refinements followed a
/// detected drift: 0–6.6 % on exact-pose walks with realistic depth noise, 22–27 % with the
/// simulator's SLAM drift, 89 % with odometry drift): a drifting source's average is not a better
/// frame than the map's own (its frame is that of its first poses, which the map keeps). Answers
/// in the room's frame do not change: the map moves as one piece. `None` when no move is made.
fn anchor_to_poses(
    icp: &IcpReport,
    pairs: &[(Point3<f64>, Point3<f64>)],
) -> Option<Isometry3<f64>> {
    if !icp.enabled || icp.accepted < 20 || icp.drift_frames * 8 > icp.accepted {
        return None;
    }
    if pairs.len() < 3 {
        return None;
    }
    let (refined, given): (Vec<Point3<f64>>, Vec<Point3<f64>>) = pairs.iter().copied().unzip();
    kabsch(&refined, &given)
}

/// Moves a cloud's points and turns its normals by `a`.
fn move_cloud(cloud: &mut ThermalCloud, a: &Isometry3<f64>) {
    let f = |v: [f32; 3]| Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
    let g = |v: Vector3<f64>| [v.x as f32, v.y as f32, v.z as f32];
    for p in &mut cloud.positions {
        *p = g((a * Point3::from(f(*p))).coords);
    }
    for n in &mut cloud.normals {
        *n = g(a.rotation * f(*n));
    }
}

/// Normals of a frame's points.
type Vector3List = Vec<Vector3<f64>>;

/// A frame observed: its voxels, counts, and its comparison with the map.
struct Observed {
    voxels: ShardedVoxels,
    counts: ObservationCounts,
    thermal_t: f64,
    residuals: FrameResiduals,
    offset: f64,
    /// Time spent observing it (s).
    cpu_s: f64,
}

/// The sync tolerance used: the setting, or 0.55 of the depth frames' median interval where that
/// is longer (15 Hz depth: 37 ms), so that every thermal frame has a depth frame.
pub(crate) fn sync_tolerance(rec: &Recording, setting_s: f64) -> f64 {
    let mut gaps: Vec<f64> = rec.depth.windows(2).map(|w| w[1].t - w[0].t).collect();
    if gaps.is_empty() {
        return setting_s;
    }
    let mid = gaps.len() / 2;
    let (_, median, _) = gaps.select_nth_unstable_by(mid, f64::total_cmp);
    setting_s.max(0.55 * *median)
}

/// The thermal clock's offset: given, rig.toml's, or estimated from the scan.
fn thermal_clock(
    rec: &Recording,
    params: &FuseParams,
    tolerance_s: f64,
    limits: &InterpolationLimits,
    stop: &dyn Fn() -> bool,
) -> Option<ClockReport> {
    let fixed = |offset_s, source| ClockReport {
        offset_s,
        source,
        ..Default::default()
    };
    match (params.clock, rec.rig.thermal_time_offset_s) {
        (ClockOffset::Off, _) => Some(fixed(0.0, OffsetSource::None)),
        (ClockOffset::Fixed(o), _) => Some(fixed(o, OffsetSource::Given)),
        (ClockOffset::Auto, Some(o)) => Some(fixed(o, OffsetSource::RigToml)),
        (ClockOffset::Auto, None) | (ClockOffset::Estimate, _) => {
            estimate_offset_until(rec, &params.clock_search, tolerance_s, limits, stop)
        }
    }
}

/// Fuses a recording. `progress(done, total)` is called after each frame.
pub fn fuse(rec: &Recording, params: &FuseParams, progress: &(dyn Fn(u64, u64) + Sync)) -> Fused {
    match fuse_until(rec, params, progress, &|| false) {
        Some(f) => f,
        // `stop` never says so.
        None => unreachable!("a fusion that is never asked to stop stopped"),
    }
}

/// [`fuse`], asking `stop` after the clock's estimate and after each chunk of frames (a few
/// tenths of a second apart): `None` once it says so (a person pressed Ctrl-C).
pub fn fuse_until(
    rec: &Recording,
    params: &FuseParams,
    progress: &(dyn Fn(u64, u64) + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Option<Fused> {
    let mut params = *params;
    if params.depth.stride == 0 {
        params.depth.stride = DepthSampling::auto_stride(&rec.rig.depth, &rec.rig.thermal);
    }
    let params = &params;
    let t_start = Instant::now();
    let limits = InterpolationLimits::default();
    let tolerance = sync_tolerance(rec, params.sync_tolerance_s);
    // Poses that jump away from their neighbours' motion and back are dropped first (and jumps
    // that stay judged by the depth), then the thermal clock is set.
    let judge = DepthJudge::new(rec, &params.depth);
    let (checked, pose_check) = check_poses(&rec.trajectory, Some(&judge));
    let cleaned;
    let rec = if pose_check.dropped > 0 || !pose_check.jumps.is_empty() {
        let mut r = rec.clone();
        r.trajectory = checked;
        cleaned = r;
        &cleaned
    } else {
        rec
    };
    let clock = thermal_clock(rec, params, tolerance, &limits, &|| stop())?;
    let shifted;
    let rec = if clock.offset_s != 0.0 {
        let mut r = rec.clone();
        for e in &mut r.thermal {
            e.t += clock.offset_s;
        }
        shifted = r;
        &shifted
    } else {
        rec
    };
    let pairs = pair_frames(rec, tolerance, &limits);
    let mut report = FusionReport {
        recording: rec.dir.display().to_string(),
        thermal_frames: rec.thermal.len(),
        depth_frames: rec.depth.len(),
        depth_stride: params.depth.stride,
        sync_tolerance_used_s: tolerance,
        clock,
        pose_check,
        parameters: *params,
        ..Default::default()
    };
    report.icp.enabled = params.icp.enabled;
    let clock_s = t_start.elapsed().as_secs_f64();
    let mut usable: Vec<(usize, usize)> = Vec::new();
    let mut dropped: Vec<SkipReason> = Vec::new();
    for p in &pairs {
        match p.depth {
            Ok(d) => usable.push((p.thermal, d)),
            Err(r) => dropped.push(r),
        }
    }
    let total = rec.thermal.len() as u64;
    let rays = RayTable::new(&rec.rig.depth);
    let chunks: Vec<&[(usize, usize)]> = usable.chunks(params.chunk.max(1)).collect();
    // The vignetting is the camera's, the same in every frame, but self-calibration estimates it
    // from frames compared with the map fused before them: the first frames would be fused
    // without it, and what only they saw would keep it (on 30 s walks of the panel room a patch
    // of wall seen in three of the first frames, near the image's corner, read 0.33 K cold and
    // became a feature). A first pass over the first frames estimates it, and the fusion then
    // applies it from the first frame on.
    let t_warm = Instant::now();
    let calibrator = if params.radiometric.enabled && params.radiometric.warm_up {
        let mut warm = Fuser::new(params, limits, report.clone(), Calibrator::default());
        let most = chunks.len().div_ceil(WARM_UP_SHARE);
        let done = warm.run(rec, &rays, &chunks[..most], total, &|_, _| {}, &|f| {
            stop() || f.calibrator.vignetting_ready(WARM_UP_SPREAD)
        });
        if stop() {
            return None;
        }
        if warm.calibrator.vignetting_ready(1.0) && done < chunks.len() {
            let frames = chunks[..done].iter().map(|c| c.len()).sum();
            Calibrator::with_prior(warm.calibrator.vignetting(), frames)
        } else {
            Calibrator::default()
        }
    } else {
        Calibrator::default()
    };
    let mut fuser = Fuser::new(params, limits, report, calibrator);
    fuser.timing.clock = clock_s;
    fuser.timing.vignetting_warm_up = t_warm.elapsed().as_secs_f64();
    for r in dropped {
        fuser.drop_frame(r);
    }
    fuser.run(rec, &rays, &chunks, total, progress, &|_| stop());
    if stop() {
        return None;
    }
    Some(fuser.finish(t_start))
}

#[cfg(test)]
mod tests {
    use mrtmap_geometry::nalgebra::{Translation3, UnitQuaternion};

    use super::*;

    fn report(accepted: usize, drift_frames: usize) -> IcpReport {
        IcpReport {
            enabled: true,
            attempted: accepted,
            accepted,
            drift_frames,
            ..Default::default()
        }
    }

    /// Points placed by the refined poses (the map moved 9 mm and 0.1° away) and by the given ones.
    fn moved_pairs(moved: &Isometry3<f64>) -> Vec<(Point3<f64>, Point3<f64>)> {
        (0..200)
            .map(|k| {
                let t = k as f64 * 0.37;
                let given = Point3::new(
                    4.0 * t.sin(),
                    3.0 * (1.3 * t).cos(),
                    2.5 * (0.7 * t).sin().abs(),
                );
                (moved * given, given)
            })
            .collect()
    }

    #[test]
    fn a_map_moved_from_exact_poses_is_put_back() {
        let moved = Isometry3::from_parts(
            Translation3::new(0.006, -0.007, 0.002),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.1f64.to_radians()),
        );
        let a = anchor_to_poses(&report(300, 3), &moved_pairs(&moved)).expect("anchored");
        let back = a * moved;
        assert!(back.translation.vector.norm() < 1e-9, "{back}");
        assert!(back.rotation.angle() < 1e-9, "{back}");
        let mut cloud = ThermalCloud {
            positions: vec![[1.0, 2.0, 1.5]],
            normals: vec![[1.0, 0.0, 0.0]],
            temperature_k: vec![293.0],
            temperature_std_k: vec![0.1],
            observations: vec![3],
        };
        let p = moved * Point3::new(1.0, 2.0, 1.5);
        cloud.positions[0] = [p.x as f32, p.y as f32, p.z as f32];
        move_cloud(&mut cloud, &a);
        let q = cloud.positions[0];
        assert!(
            (q[0] - 1.0).abs() < 1e-5 && (q[1] - 2.0).abs() < 1e-5 && (q[2] - 1.5).abs() < 1e-5,
            "{q:?}"
        );
        let n = cloud.normals[0];
        assert!((n[0] - 1.0).abs() < 1e-5 && n[1].abs() < 2e-3, "{n:?}");
    }

    #[test]
    fn a_drifting_pose_source_or_no_icp_leaves_the_map_where_it_is() {
        let moved = Isometry3::translation(0.01, 0.0, 0.0);
        let pairs = moved_pairs(&moved);
        // One in five refinements followed a drift: the pose source's average is no better frame.
        assert!(anchor_to_poses(&report(300, 60), &pairs).is_none());
        assert!(anchor_to_poses(&report(300, 38), &pairs).is_none());
        // Within the limit (1 in 8) it is taken.
        assert!(anchor_to_poses(&report(300, 37), &pairs).is_some());
        let off = IcpReport {
            enabled: false,
            ..report(300, 0)
        };
        assert!(anchor_to_poses(&off, &pairs).is_none());
        assert!(anchor_to_poses(&report(10, 0), &pairs).is_none());
    }
}
