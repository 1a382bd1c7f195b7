//! What a source conversion is told, what it reports, and how it fails (shared by the ROS and
//! RTAB-Map conversions).

use std::path::PathBuf;

use mrtmap_io::{FileError, Rig};
use serde::Serialize;

use crate::ros::RosOptions;

/// Why a source could not be converted.
#[derive(Debug, thiserror::Error)]
pub enum ConvertError {
    /// A file could not be read or written.
    #[error(transparent)]
    File(#[from] FileError),
    /// The source cannot be made into a scan, or cannot be read as one.
    #[error("{}: {problem}", path.display())]
    Source {
        /// The source.
        path: PathBuf,
        /// What is wrong or missing, and what to do.
        problem: String,
    },
    /// The source lacks what a scan needs.
    #[error("{}: cannot make a scan of it: {}", path.display(), missing.join("; "))]
    NotAScan {
        /// The source.
        path: PathBuf,
        /// What it lacks.
        missing: Vec<String>,
    },
    /// A reading option is out of range.
    #[error("{setting} {problem}")]
    Setting {
        /// The option.
        setting: String,
        /// What is wrong with it.
        problem: String,
    },
}

impl ConvertError {
    /// A source problem.
    pub fn source(path: &std::path::Path, problem: impl Into<String>) -> Self {
        Self::Source {
            path: path.to_path_buf(),
            problem: problem.into(),
        }
    }
}

/// A conversion's result.
pub type Result<T> = std::result::Result<T, ConvertError>;

/// How to read a bag, MCAP file or RTAB-Map database as a scan (also the flags of the commands
/// that read one; the doc comments are their `--help`).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct SourceOptions {
    /// A rig.toml (from mrtmap calibrate): its thermal camera and extrinsic are used, and its
    /// depth/colour cameras where the source has no CameraInfo.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub rig: Option<PathBuf>,
    /// Depth image topic (default: /camera/aligned_depth_to_color/image_raw, or any 16UC1 depth).
    #[cfg_attr(feature = "clap", arg(long, value_name = "TOPIC"))]
    pub depth_topic: Option<String>,
    /// Thermal image topic (default: any mono16 image topic).
    #[cfg_attr(feature = "clap", arg(long, value_name = "TOPIC"))]
    pub thermal_topic: Option<String>,
    /// Colour image topic (default: /camera/color/image_raw).
    #[cfg_attr(feature = "clap", arg(long, value_name = "TOPIC"))]
    pub rgb_topic: Option<String>,
    /// Pose topic, nav_msgs/Odometry or geometry_msgs/PoseStamped (default: /camera/odom/sample,
    /// else any; else /tf).
    #[cfg_attr(feature = "clap", arg(long, value_name = "TOPIC"))]
    pub pose_topic: Option<String>,
    /// Raw depth units per metre of 16-bit depth (default 1000, RealSense).
    #[cfg_attr(feature = "clap", arg(long))]
    pub depth_scale: Option<f64>,
    /// Thermal frames for a source without them (an RTAB-Map database): a bag/MCAP/ROS 2 bag with
    /// a mono16 topic, or a folder of 16-bit thermal images named by timestamp.
    #[cfg_attr(feature = "clap", arg(long, value_name = "SRC"))]
    pub thermal: Option<PathBuf>,
}

impl SourceOptions {
    /// The ROS reader's options (reads the rig).
    pub fn ros(&self) -> Result<RosOptions> {
        if let Some(s) = self.depth_scale
            && !(s > 0.0 && s.is_finite())
        {
            return Err(ConvertError::Setting {
                setting: format!("--depth-scale {s}"),
                problem: "must be a positive number of raw units per metre".into(),
            });
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
