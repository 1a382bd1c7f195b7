//! Built-in RGB-D tracking: poses for a recording that has colour and depth but no pose source.
//! This module holds the settings, the report and the tracking state machine ([`track`]); the
//! steps live beside it.
//!
//! ```text
//!  colour frame ─ FAST-9 corners (imageproc), spread over a grid ─ BRIEF-256 (fixed test pairs)
//!      │ depth frame nearest in time → z-buffer in the colour image → 3D of each corner
//!      │ match to the reference keyframe: guided by the constant-velocity prediction
//!      │   (or, failing that, over the whole image), mutual best with a ratio test
//!      │ RANSAC on 3D–3D triples (Kabsch), inliers by reprojection → Gauss–Newton on the
//!      │   reprojection error (Huber)                           = the frame's pose
//!      │ keyframe when the inliers thin out or the camera moved / turned enough
//!      └ loop closure: each new keyframe against older ones nearby (descriptors + RANSAC),
//!        pose graph over keyframes (tiny-solver), frames follow their keyframes
//! ```
//!
//! The depth frame was taken at its own time: its points are moved to the colour frame's time with
//! the camera's current velocity. Results are deterministic (fixed BRIEF pairs, RANSAC seeded per
//! frame) and do not depend on the number of threads (features are computed in parallel, tracking
//! is sequential).
//!
//! Where each step lives, in the order a frame meets them:
//!
//! - [`frames`]: a colour frame read with the depth frame nearest in time (z-buffered into the
//!   colour image, and as a point cloud);
//! - [`features`]: its FAST corners, BRIEF descriptors and 3D points;
//! - [`motion`]: the motion model that predicts the frame's pose (velocity, gyro);
//! - [`matching`]: its corners matched to a keyframe's;
//! - [`pose`]: the pose from the matches (RANSAC, then Gauss–Newton) and its information;
//! - [`depth_only`]: the pose from the depth alone where the corners do not suffice;
//! - [`loops`]: loop closure between keyframes;
//! - this module: the [`Tracker`] that places each frame, makes keyframes and optimises the
//!   keyframes' pose graph;
//! - [`evaluate`]: the trajectory against true poses (alignment, TUM's errors).

mod depth_only;
mod evaluate;
mod features;
mod frames;
mod live;
mod loops;
mod matching;
mod motion;
mod pose;

use std::collections::BTreeMap;
use std::time::Instant;

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::icp::IcpTarget;
use mrtmap_geometry::nalgebra::{Isometry3, Point3, UnitQuaternion};
use mrtmap_geometry::pose_graph::{Edge, optimise};
use mrtmap_io::{Recording, Trajectory};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use depth_only::depth_only;
use features::Features;
use frames::FrameReader;
use loops::close_loops;
use matching::match_features;
use motion::{Gyro, Twist, predict};
use pose::{Found, Seen, estimate};

pub use evaluate::{TrajectoryError, align, expressed_in, trajectory_error};
pub use live::LiveTracker;
/// Tracking settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TrackParams {
    /// FAST-9 threshold (grey levels).
    pub fast_threshold: u8,
    /// A cell without any corner at `fast_threshold` takes its corners at this lower one
    /// (ORB-SLAM's rule: low-contrast surfaces still get corners where nothing stronger is).
    pub min_fast_threshold: u8,
    /// Corners are spread over cells of this size (px)…
    pub cell_px: u32,
    /// …keeping at most this many (the strongest) per cell.
    pub per_cell: usize,
    /// A match's Hamming distance (of 256 bits) at most this.
    pub max_hamming: u32,
    /// Lowe's ratio: best distance below this fraction of the second best.
    pub ratio: f64,
    /// Guided matching: search radius around the predicted pixel (px).
    pub search_radius_px: f64,
    /// Reprojection error of an inlier (px).
    pub inlier_px: f64,
    /// A pose needs this many inliers.
    pub min_inliers: usize,
    /// RANSAC hypotheses.
    pub ransac_iterations: usize,
    /// A new keyframe when the inliers fall below this fraction of the keyframe's corners with depth…
    pub keyframe_inlier_ratio: f64,
    /// …or the camera moved this far from it (m)…
    pub keyframe_move_m: f64,
    /// …or turned this much (degrees).
    pub keyframe_turn_deg: f64,
    /// Corners farther than this have no 3D point (the depth noise grows with z²).
    pub max_depth_m: f64,
    /// Largest time between a colour frame and its depth frame (s).
    pub sync_tolerance_s: f64,
    /// Look for loop closures.
    pub loop_closure: bool,
    /// Predict each frame's rotation from the gyro (imu.txt) where the recording has one.
    pub use_imu: bool,
    /// A loop joins keyframes at least this many keyframes apart…
    pub loop_min_separation: usize,
    /// …whose estimated positions lie within this distance (m)…
    pub loop_radius_m: f64,
    /// …with at least this many inliers.
    pub loop_min_inliers: usize,
}

impl Default for TrackParams {
    fn default() -> Self {
        Self {
            fast_threshold: 12,
            min_fast_threshold: 7,
            cell_px: 32,
            per_cell: 6,
            max_hamming: 70,
            ratio: 0.85,
            search_radius_px: 40.0,
            inlier_px: 2.5,
            min_inliers: 25,
            ransac_iterations: 200,
            keyframe_inlier_ratio: 0.35,
            keyframe_move_m: 0.4,
            keyframe_turn_deg: 20.0,
            max_depth_m: 3.5,
            sync_tolerance_s: 0.02,
            loop_closure: true,
            use_imu: true,
            loop_min_separation: 12,
            loop_radius_m: 1.5,
            loop_min_inliers: 40,
        }
    }
}

/// What tracking did.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrackReport {
    /// Colour frames.
    pub frames: usize,
    /// Frames with a pose.
    pub tracked: usize,
    /// Frames without a depth frame near enough in time.
    pub unsynced: usize,
    /// Frames whose pose could not be found (lost).
    pub lost: usize,
    /// Frames found again against an older keyframe after being lost or off the reference.
    pub relocalised: usize,
    /// Frames placed by their depth alone (too few corners matched): point-to-plane ICP on the
    /// keyframe's depth from the constant-velocity prediction.
    pub depth_only: usize,
    /// Keyframes.
    pub keyframes: usize,
    /// Loop closures tried (candidate keyframe pairs) and accepted.
    pub loops_tried: usize,
    /// Accepted loop closures.
    pub loops_accepted: usize,
    /// Gyro samples the prediction drew on (0: no imu.txt, or not used).
    #[serde(default)]
    pub gyro_samples: usize,
    /// Mean corners per frame.
    pub mean_corners: f64,
    /// Mean inliers per tracked frame.
    pub mean_inliers: f64,
    /// Mean inlier reprojection error (px).
    pub mean_reprojection_px: f64,
    /// Pose graph: weighted squared error before and after (0 without loops).
    pub graph_cost_before: f64,
    /// After.
    pub graph_cost_after: f64,
    /// Wall time (s).
    pub seconds: f64,
    /// Against the recording's true poses (groundtruth.txt), when it has them.
    pub accuracy: Option<TrajectoryError>,
    /// Colour frames left out because their size is not the rig's colour camera's (a frame of
    /// another stream or camera mode recorded among them): how many, and the first one's file
    /// and size.
    #[serde(default)]
    pub wrong_size: usize,
    /// The first wrong-size frame: its file and its width and height.
    #[serde(default)]
    pub wrong_size_first: Option<(String, u32, u32)>,
    /// Poses left out of the trajectory written because they jumped away from their neighbours'
    /// motion and back (the frame after a lost one placed wrongly; set by the pipeline's check).
    #[serde(default)]
    pub outliers_dropped: usize,
}

impl TrackReport {
    /// What the user must know: frames lost, frames left out for their size.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.lost > 0 {
            out.push(format!(
                "tracking lost {} of {} colour frames",
                self.lost, self.frames
            ));
        }
        if self.outliers_dropped > 0 {
            out.push(format!(
                "{} tracked pose(s) left out of trajectory.txt: they jumped away from their neighbours' motion and back",
                self.outliers_dropped
            ));
        }
        if let Some((path, w, h)) = &self.wrong_size_first {
            out.push(format!(
                "{} colour frame(s) left out because their size is not the rig's colour camera's, the first {path} ({w}×{h}); check rig.toml's [rgb] width and height or remove those frames from rgb.txt",
                self.wrong_size
            ));
        }
        out
    }
}

/// Why tracking could not run.
#[derive(Debug, thiserror::Error)]
pub enum TrackError {
    /// The recording has no colour stream or no colour camera in its rig.
    #[error("{0}")]
    NoColour(String),
    /// A frame could not be read.
    #[error(transparent)]
    File(#[from] mrtmap_io::FileError),
    /// A colour image could not be decoded.
    #[error("{path}: cannot read the colour image ({why}); re-export the frame as PNG or JPEG")]
    Colour {
        /// The file.
        path: String,
        /// Why.
        why: String,
    },
    /// Too few frames could be tracked.
    #[error("tracking found a pose for only {tracked} of {frames} colour frames: {why}")]
    Failed {
        /// Tracked frames.
        tracked: usize,
        /// Frames.
        frames: usize,
        /// Advice.
        why: String,
    },
}

/// The cameras tracking uses.
#[derive(Clone, Copy)]
struct Cameras {
    colour: PinholeCamera,
    depth: PinholeCamera,
    depth_scale: f64,
    /// p_colour = colour_from_depth · p_depth.
    colour_from_depth: Isometry3<f64>,
}

/// A keyframe: its corners (3D at the colour frame's time) and world_from_colour.
struct Keyframe {
    feats: Features,
    xyz: Vec<Option<Point3<f64>>>,
    with_depth: usize,
    pose: Isometry3<f64>,
    /// Its depth at its colour frame's time, for depth-only tracking.
    target: Option<IcpTarget>,
}

/// Colour frames read in parallel at a time before they are placed one after another (their
/// corners are found in parallel; the placing is sequential).
const FRAME_CHUNK: usize = 16;

/// A keyframe keeps about this many points of its depth cloud, the target of depth-only ICP.
const KEYFRAME_CLOUD_POINTS: usize = 20_000;

/// A frame too short of corners with depth still becomes a keyframe when its depth cloud has at
/// least this many points (depth-only tracking can register on it).
const MIN_KEYFRAME_CLOUD_POINTS: usize = 500;

/// The velocity is updated only from frames at least this far apart in time (s): closer stamps
/// would divide the motion by next to nothing.
const MIN_VELOCITY_DT_S: f64 = 1e-6;

/// The pose with its quaternion's norm restored (products of many poses drift from 1).
fn renormalised(t: &Isometry3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        t.translation,
        UnitQuaternion::new_normalize(t.rotation.into_inner()),
    )
}

/// The angle a pose turns by (degrees).
fn rotation_deg(t: &Isometry3<f64>) -> f64 {
    t.rotation.angle().to_degrees()
}

/// Tracks the recording's colour frames; returns world_from_depth at the colour frames' times (the
/// first frame's depth camera is the world) and what was done.
///
/// The frames are read in parallel chunks ([`FrameReader`]) and placed one after another by a
/// [`Tracker`]: against the reference keyframe, else another keyframe (relocalisation), else by
/// depth alone; then, when loops were closed, the keyframe graph is optimised.
pub fn track(
    rec: &Recording,
    params: &TrackParams,
    progress: &dyn Fn(usize, usize),
) -> Result<(Trajectory, TrackReport), TrackError> {
    match track_until(rec, params, progress, &|| false)? {
        Some(t) => Ok(t),
        // `stop` never says so.
        None => unreachable!("tracking that is never asked to stop stopped"),
    }
}

/// [`track`], asking `stop` after each chunk of frames: `Ok(None)` once it says so (a person
/// pressed Ctrl-C).
pub fn track_until(
    rec: &Recording,
    params: &TrackParams,
    progress: &dyn Fn(usize, usize),
    stop: &dyn Fn() -> bool,
) -> Result<Option<(Trajectory, TrackReport)>, TrackError> {
    let t0 = Instant::now();
    let mut tracker = Tracker::new(rec, params)?;
    let reader = FrameReader::new(params, tracker.cams);
    let n = rec.rgb.len();
    let mut start = 0;
    while start < n {
        let end = (start + FRAME_CHUNK).min(n);
        let feats: Vec<Features> = (start..end)
            .into_par_iter()
            .map(|i| reader.read(rec, i))
            .collect::<Result<_, _>>()?;
        for (i, f) in (start..end).zip(feats) {
            progress(i + 1, n);
            tracker.step(rec, i, f);
        }
        if stop() {
            return Ok(None);
        }
        start = end;
    }
    tracker.optimise_graph();
    tracker.finish(rec, t0).map(Some)
}

/// How a frame was placed.
enum Placed {
    /// Against the reference keyframe.
    Reference,
    /// Against an older keyframe (the reference was lost).
    Relocalised,
    /// By its depth alone on the reference keyframe's.
    DepthOnly,
}

/// The tracking state over the colour frames, in time order.
pub(crate) struct Tracker {
    params: TrackParams,
    cams: Cameras,
    gyro: Option<Gyro>,
    /// world_from_colour of each tracked frame.
    poses: Vec<Option<Isometry3<f64>>>,
    /// Each tracked frame's keyframe and keyframe_from_frame, for the pose graph's correction.
    anchor: Vec<Option<(usize, Isometry3<f64>)>>,
    keyframes: Vec<Keyframe>,
    edges: Vec<Edge>,
    /// Motion per second (earlier_from_later over 1 s, body frame).
    velocity: Twist,
    /// The last tracked frame and its pose.
    last: Option<(usize, Isometry3<f64>)>,
    corners_sum: usize,
    inliers_sum: usize,
    reprojection_sum: f64,
    report: TrackReport,
}

impl Tracker {
    /// Checks that the recording can be tracked (a colour camera and frames) and sets up.
    fn new(rec: &Recording, params: &TrackParams) -> Result<Self, TrackError> {
        let Some(rgb) = rec.rig.rgb else {
            return Err(TrackError::NoColour(format!(
                "{}: the rig has no [rgb] camera; tracking needs the colour camera's intrinsics and its pose in the depth camera",
                rec.dir.join("rig.toml").display()
            )));
        };
        if rec.rgb.is_empty() {
            return Err(TrackError::NoColour(format!(
                "{}: no colour frames (rgb.txt); tracking needs them",
                rec.dir.display()
            )));
        }
        let cams = Cameras {
            colour: rgb.camera,
            depth: rec.rig.depth,
            depth_scale: rec.rig.depth_scale,
            colour_from_depth: rgb.depth_from_rgb.inverse(),
        };
        let gyro = params
            .use_imu
            .then(|| Gyro::new(&rec.imu, &cams.colour_from_depth))
            .flatten();
        let n = rec.rgb.len();
        let report = TrackReport {
            frames: n,
            gyro_samples: gyro.as_ref().map_or(0, |g| g.t.len()),
            ..TrackReport::default()
        };
        Ok(Self {
            params: *params,
            cams,
            gyro,
            poses: vec![None; n],
            anchor: vec![None; n],
            keyframes: Vec::new(),
            edges: Vec::new(),
            velocity: Twist::default(),
            last: None,
            corners_sum: 0,
            inliers_sum: 0,
            reprojection_sum: 0.0,
            report,
        })
    }

    /// The motion from `t0` to `t1` (earlier_from_later) the tracker expects.
    fn predict(&self, t0: f64, t1: f64) -> Isometry3<f64> {
        predict(&self.velocity, self.gyro.as_ref(), t0, t1)
    }

    /// Places colour frame `i`, and makes it a keyframe when it has moved away from its
    /// reference.
    fn step(&mut self, rec: &Recording, i: usize, f: Features) {
        if self.poses.len() <= i {
            self.poses.resize(i + 1, None);
            self.anchor.resize(i + 1, None);
        }
        if let Some((w, h)) = f.wrong_size {
            self.report.wrong_size += 1;
            self.report
                .wrong_size_first
                .get_or_insert_with(|| (rec.path_of(&rec.rgb[i]).display().to_string(), w, h));
            return;
        }
        self.corners_sum += f.px.len();
        self.report.unsynced += f.zmap.is_none() as usize;
        let t_now = rec.rgb[i].t;
        // The depth's points at the colour frame's time: colour(t) from colour(t + dt).
        let motion = self.predict(t_now, t_now + f.dt);
        let xyz_now = f.moved(&motion, &self.cams.colour, self.params.max_depth_m);
        if self.keyframes.is_empty() {
            self.start(i, f, xyz_now, &motion);
            return;
        }
        let Some((reference, fd)) = self.locate(rec, i, &f, &xyz_now, &motion) else {
            self.report.lost += 1;
            return;
        };
        let kf_from_frame = fd.pose.inverse();
        let world = self.keyframes[reference].pose * kf_from_frame;
        if let Some((k, p)) = self.last {
            let dt = t_now - rec.rgb[k].t;
            if dt > MIN_VELOCITY_DT_S {
                self.velocity = Twist::from_motion(&(p.inverse() * world), dt);
            }
        }
        self.poses[i] = Some(world);
        self.anchor[i] = Some((reference, kf_from_frame));
        self.last = Some((i, world));
        self.report.tracked += 1;
        self.inliers_sum += fd.inliers;
        self.reprojection_sum += fd.reprojection_px;
        // A frame placed by depth alone (no inliers) starts a keyframe only by moving away.
        let by_depth = fd.inliers == 0;
        let kref = &self.keyframes[reference];
        let p = &self.params;
        let new_kf = (!by_depth
            && (fd.inliers as f64) < p.keyframe_inlier_ratio * kref.with_depth as f64)
            || kf_from_frame.translation.vector.norm() > p.keyframe_move_m
            || rotation_deg(&kf_from_frame) > p.keyframe_turn_deg
            || reference != self.keyframes.len() - 1;
        if new_kf {
            self.add_keyframe(rec, i, f, reference, &fd, world);
        }
    }

    /// The first frame with enough corners with depth becomes the first keyframe, at the origin.
    fn start(
        &mut self,
        i: usize,
        f: Features,
        xyz_now: Vec<Option<Point3<f64>>>,
        motion: &Isometry3<f64>,
    ) {
        let with_depth = xyz_now.iter().flatten().count();
        if with_depth < self.params.min_inliers {
            // Nothing to start from yet (no depth, or too few corners with depth).
            self.report.lost += 1;
            return;
        }
        self.poses[i] = Some(Isometry3::identity());
        self.anchor[i] = Some((0, Isometry3::identity()));
        let target = f
            .cloud_at(motion, KEYFRAME_CLOUD_POINTS)
            .map(|c| IcpTarget::new(c.points, c.normals));
        self.keyframes.push(Keyframe {
            feats: Features {
                zmap: None,
                cloud: None,
                ..f
            },
            xyz: xyz_now,
            with_depth,
            pose: Isometry3::identity(),
            target,
        });
        self.last = Some((i, Isometry3::identity()));
        self.report.tracked += 1;
    }

    /// Frame `i`'s pose against a keyframe (keyframe_from... as [`Found`]) and that keyframe:
    /// the reference, guided by the prediction, else over the image; else another keyframe,
    /// newest first; else the depth alone. `None`: lost.
    fn locate(
        &mut self,
        rec: &Recording,
        i: usize,
        f: &Features,
        xyz_now: &[Option<Point3<f64>>],
        motion: &Isometry3<f64>,
    ) -> Option<(usize, Found)> {
        let (p, cams, kfs) = (&self.params, &self.cams, &self.keyframes);
        let t_now = rec.rgb[i].t;
        let newest = kfs.len() - 1;
        let kf = &kfs[newest];
        let predicted_world = self
            .last
            .map(|(k, pose)| pose * self.predict(rec.rgb[k].t, t_now));
        let predicted = predicted_world.map(|w| w.inverse() * kf.pose);
        let seen = Seen {
            norm: &f.norm,
            xyz: xyz_now,
        };
        // The pose against keyframe `k`: guided by `guess` when given, else over the image.
        let against = |k: &Keyframe, guess: Option<&Isometry3<f64>>| {
            let m = match_features(&k.feats, &k.xyz, f, guess, &cams.colour, p);
            estimate(&k.xyz, seen, &m, guess, cams.colour.fx, p, i as u64)
        };
        let placed = predicted
            .as_ref()
            .and_then(|pr| against(kf, Some(pr)))
            .or_else(|| against(kf, None))
            .map(|fd| (newest, fd, Placed::Reference))
            .or_else(|| {
                // Lost against the reference: try the other keyframes, newest first. An older
                // keyframe's pose carries the drift since it was made: a frame placed on it is a
                // loop closure and needs a loop's evidence.
                kfs.iter().enumerate().rev().skip(1).find_map(|(k, other)| {
                    against(other, None)
                        .filter(|fd| fd.inliers >= p.loop_min_inliers)
                        .map(|fd| (k, fd, Placed::Relocalised))
                })
            })
            .or_else(|| {
                // No corners to follow (a close-up of a plain surface, motion blur): the depth
                // alone, registered on the reference keyframe's from the prediction.
                predicted
                    .as_ref()
                    .and_then(|pr| depth_only(kf, f, motion, pr))
                    .map(|fd| (newest, fd, Placed::DepthOnly))
            });
        let (k, fd, how) = placed?;
        match how {
            Placed::Reference => {}
            Placed::Relocalised => self.report.relocalised += 1,
            Placed::DepthOnly => self.report.depth_only += 1,
        }
        Some((k, fd))
    }

    /// Frame `i`, placed at `world` on keyframe `reference` by `fd`, becomes a keyframe (when
    /// its depth allows), linked to its reference, and loops are closed.
    fn add_keyframe(
        &mut self,
        rec: &Recording,
        i: usize,
        f: Features,
        reference: usize,
        fd: &Found,
        world: Isometry3<f64>,
    ) {
        let t_now = rec.rgb[i].t;
        // The motion model now holds this frame's velocity: move its depth again.
        let motion = self.predict(t_now, t_now + f.dt);
        let xyz = f.moved(&motion, &self.cams.colour, self.params.max_depth_m);
        let with_depth = xyz.iter().flatten().count();
        let target = f
            .cloud_at(&motion, KEYFRAME_CLOUD_POINTS)
            .map(|c| IcpTarget::new(c.points, c.normals));
        if with_depth < self.params.min_inliers
            && target
                .as_ref()
                .is_none_or(|t| t.len() < MIN_KEYFRAME_CLOUD_POINTS)
        {
            return;
        }
        let id = self.keyframes.len();
        self.edges.push(Edge {
            from: reference as i64,
            to: id as i64,
            measured: fd.pose.inverse(),
            information: fd.information,
        });
        self.anchor[i] = Some((id, Isometry3::identity()));
        self.keyframes.push(Keyframe {
            feats: Features {
                zmap: None,
                cloud: None,
                ..f
            },
            xyz,
            with_depth,
            pose: world,
            target,
        });
        if self.params.loop_closure {
            close_loops(
                &mut self.keyframes,
                &mut self.edges,
                &self.cams,
                &self.params,
                &mut self.report,
            );
        }
    }

    /// The pose graph over the keyframes, when loops were closed; every frame follows its
    /// keyframe.
    fn optimise_graph(&mut self) {
        if self.report.loops_accepted == 0 {
            return;
        }
        let initial: BTreeMap<i64, Isometry3<f64>> = self
            .keyframes
            .iter()
            .enumerate()
            .map(|(k, kf)| (k as i64, kf.pose))
            .collect();
        let Ok(opt) = optimise(&initial, &self.edges) else {
            return;
        };
        self.report.graph_cost_before = opt.cost_before;
        self.report.graph_cost_after = opt.cost_after;
        for (k, kf) in self.keyframes.iter_mut().enumerate() {
            if let Some(p) = opt.poses.get(&(k as i64)) {
                kf.pose = *p;
            }
        }
        for (pose, a) in self.poses.iter_mut().zip(&self.anchor) {
            if let (Some(p), Some((k, rel))) = (pose.as_mut(), a) {
                *p = self.keyframes[*k].pose * rel;
            }
        }
    }

    /// The trajectory of the depth camera (the first tracked frame's is the world) and the
    /// report; an error when too few frames were tracked.
    fn finish(
        mut self,
        rec: &Recording,
        t0: Instant,
    ) -> Result<(Trajectory, TrackReport), TrackError> {
        let n = rec.rgb.len();
        let report = &mut self.report;
        report.keyframes = self.keyframes.len();
        report.mean_corners = self.corners_sum as f64 / n.max(1) as f64;
        report.mean_inliers = self.inliers_sum as f64 / report.tracked.max(1) as f64;
        report.mean_reprojection_px = self.reprojection_sum / report.tracked.max(1) as f64;
        let mut traj = Trajectory::default();
        for (i, p) in self.poses.iter().enumerate() {
            if let Some(p) = p {
                traj.stamps.push(rec.rgb[i].t);
                // world_from_depth = world_from_colour · colour_from_depth.
                traj.poses
                    .push(renormalised(&(p * self.cams.colour_from_depth)));
            }
        }
        // The first tracked frame's depth camera is the world.
        if let Some(first) = traj.poses.first().copied() {
            let inv = first.inverse();
            for p in &mut traj.poses {
                *p = renormalised(&(inv * *p));
            }
        }
        report.seconds = t0.elapsed().as_secs_f64();
        if let Some(gt) = &rec.groundtruth {
            report.accuracy = trajectory_error(&traj, gt);
        }
        if report.tracked < 2 || report.tracked * 2 < n {
            return Err(TrackError::Failed {
                tracked: report.tracked,
                frames: n,
                why: "too few corners or matches (a textureless view, motion blur, or colour and depth out of step); scan more slowly over textured surfaces, or record poses".into(),
            });
        }
        Ok((traj, self.report))
    }
}
