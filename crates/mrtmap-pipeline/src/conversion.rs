//! What a source conversion is told and what it reports (shared by the ROS and RTAB-Map
//! conversions).

use std::path::PathBuf;

use mrtmap_io::Rig;
use mrtmap_sources::ros::RosOptions;
use serde::Serialize;

use crate::error::{Error, Result};

/// How to read a bag, MCAP file or RTAB-Map database as a scan (also the flags of the commands
/// that read one; the doc comments are their `--help`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, clap::Args)]
pub struct SourceOptions {
    /// A rig.toml (from mrtmap calibrate): its thermal camera and extrinsic are used, and its
    /// depth/colour cameras where the source has no CameraInfo.
    #[arg(long, value_name = "FILE")]
    pub rig: Option<PathBuf>,
    /// Depth image topic (default: /camera/aligned_depth_to_color/image_raw, or any 16UC1 depth).
    #[arg(long, value_name = "TOPIC")]
    pub depth_topic: Option<String>,
    /// Thermal image topic (default: any mono16 image topic).
    #[arg(long, value_name = "TOPIC")]
    pub thermal_topic: Option<String>,
    /// Colour image topic (default: /camera/color/image_raw).
    #[arg(long, value_name = "TOPIC")]
    pub rgb_topic: Option<String>,
    /// Pose topic, nav_msgs/Odometry or geometry_msgs/PoseStamped (default: /camera/odom/sample,
    /// else any; else /tf).
    #[arg(long, value_name = "TOPIC")]
    pub pose_topic: Option<String>,
    /// Raw depth units per metre of 16-bit depth (default 1000, RealSense).
    #[arg(long)]
    pub depth_scale: Option<f64>,
    /// Thermal frames for a source without them (an RTAB-Map database): a bag/MCAP/ROS 2 bag with
    /// a mono16 topic, or a folder of 16-bit thermal images named by timestamp.
    #[arg(long, value_name = "SRC")]
    pub thermal: Option<PathBuf>,
}

impl SourceOptions {
    /// The ROS reader's options (reads the rig).
    pub(crate) fn ros(&self) -> Result<RosOptions> {
        if let Some(s) = self.depth_scale
            && !(s > 0.0 && s.is_finite())
        {
            return Err(Error::setting(
                format!("--depth-scale {s}"),
                "must be a positive number of raw units per metre",
            ));
        }
        Ok(RosOptions {
            depth_topic: self.depth_topic.clone(),
            thermal_topic: self.thermal_topic.clone(),
            rgb_topic: self.rgb_topic.clone(),
            pose_topic: self.pose_topic.clone(),
            depth_scale: self.depth_scale,
            rig: self.rig.as_deref().map(Rig::read).transpose()?,
        })
    }
}

/// What a conversion to the recording layout wrote.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Conversion {
    /// The recording folder.
    pub out: PathBuf,
    /// Depth frames written.
    pub depth: usize,
    /// Thermal frames written.
    pub thermal: usize,
    /// Colour frames written.
    pub rgb: usize,
    /// Poses written.
    pub poses: usize,
    /// Inertial samples written (imu.txt).
    pub imu: usize,
    /// Where the thermal frames came from, when not from the source itself.
    pub thermal_from: Option<String>,
    /// Which poses were taken, when the source offers several kinds.
    pub poses_from: Option<String>,
    /// Messages (or database nodes) skipped.
    pub skipped: usize,
    /// "messages" or "nodes".
    pub skipped_unit: &'static str,
    /// The first reasons for skipping.
    pub skipped_reasons: Vec<String>,
    /// How things were decided.
    pub notes: Vec<String>,
}

impl Conversion {
    /// What a conversion wrote, in lines.
    pub fn lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        let from = |s: &Option<String>| s.as_ref().map(|s| format!(" ({s})")).unwrap_or_default();
        lines.push(format!(
            "wrote {}: {} depth, {} thermal{}, {} colour frames, {} poses{}{}{}",
            self.out.display(),
            self.depth,
            self.thermal,
            from(&self.thermal_from),
            self.rgb,
            self.poses,
            from(&self.poses_from),
            if self.imu > 0 {
                format!(", {} inertial samples", self.imu)
            } else {
                String::new()
            },
            if self.skipped > 0 {
                format!("; skipped {} {}", self.skipped, self.skipped_unit)
            } else {
                String::new()
            }
        ));
        for r in &self.skipped_reasons {
            lines.push(format!("  skipped: {r}"));
        }
        for n in &self.notes {
            lines.push(format!("  note: {n}"));
        }
        lines
    }
}
