//! # mrtmap-scan
//!
//! The scan pipeline: from a recording (frames on their own clocks, poses) to a fused thermal
//! point cloud, then (segmentation, later) to a radiant scene.
//!
//! ```text
//!  Recording ──► pair_frames ──► depth_points ──► ICP ──► observe (z-buffer, weights) ──► VoxelMap ──► ThermalCloud
//! ```
//!
//! See [`fuse`] for the pipeline and [`observe`](mod@observe) for the observation weights.

pub mod clock;
pub mod frame;
mod fuse;
mod fuse_live;
mod jump_judge;
pub mod observe;
pub mod pose_check;
pub mod radiometric;
pub mod segment;
mod sync;
pub mod voxels;

pub use fuse::{
    FuseParams, Fused, FusedFrame, FusionReport, IcpReport, IcpSettings, Timing, from_pose7, fuse,
    fuse_until, pose7,
};
pub use fuse_live::{Advance, LiveFusion};
pub use sync::{Pairing, SkipReason, pair_frames, refined_poses};
