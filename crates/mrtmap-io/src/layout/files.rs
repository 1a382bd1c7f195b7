//! The files of the recording layout, by what they are: their names are spelled here once, and
//! every reader, writer and follower of a recording names them through [`RecordingFile`].

use std::path::{Path, PathBuf};

/// A file of the recording layout (docs/recording.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RecordingFile {
    /// `rig.toml`: the cameras and their extrinsics.
    Rig,
    /// `depth.txt`: the depth frames.
    Depth,
    /// `thermal.txt`: the thermal frames.
    Thermal,
    /// `rgb.txt`: the colour frames (optional).
    Rgb,
    /// `masks.txt`: the instance masks (optional).
    Masks,
    /// `trajectory.txt`: the depth camera's poses.
    Trajectory,
    /// `groundtruth.txt`: the true poses (simulated scans).
    Groundtruth,
    /// `imu.txt`: inertial samples (optional).
    Imu,
    /// `references.csv`: contact-thermometer readings (optional).
    References,
}

impl RecordingFile {
    /// The four stream lists, in the order they are read.
    pub const STREAMS: [Self; 4] = [Self::Depth, Self::Thermal, Self::Rgb, Self::Masks];

    /// Its name in the recording folder.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Rig => "rig.toml",
            Self::Depth => "depth.txt",
            Self::Thermal => "thermal.txt",
            Self::Rgb => "rgb.txt",
            Self::Masks => "masks.txt",
            Self::Trajectory => "trajectory.txt",
            Self::Groundtruth => "groundtruth.txt",
            Self::Imu => "imu.txt",
            Self::References => "references.csv",
        }
    }

    /// Its path in the recording folder `dir`.
    pub fn path_in(self, dir: &Path) -> PathBuf {
        dir.join(self.name())
    }
}

impl std::fmt::Display for RecordingFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
