//! The recording layout: one folder per scan, read by [`Recording`] and written frame by frame by
//! [`LayoutWriter`] (see the crate docs for the files and what is accepted beyond them).

mod files;
mod imu;
pub mod masks;
mod recording;
mod rig;
mod streams;
mod trajectory;
mod writer;

pub use files::RecordingFile;
pub use imu::{ImuSample, imu_text, parse_imu, read_imu};
pub use recording::{Recording, RecordingWarning};
pub use rig::{PoseFile, RgbCamera, Rig, ThermalEncoding};
pub use streams::{
    LineSkip, ListLine, MAX_SKIPPED_SHARE, SkippedLine, StreamEntry, StreamLines,
    parse_stream_list, read_stream_list, stream_list_text,
};
pub use trajectory::{
    InterpolationLimits, QUATERNION_NORM_TOLERANCE, Trajectory, quaternion_xyzw, unit_quaternion,
};
pub use writer::LayoutWriter;
