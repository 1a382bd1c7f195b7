//! # mrtmap-io
//!
//! Every file format in and out of mrtmap's scan pipeline. Today: the recording layout
//! (`shared/spec/recording.md`), with
//!
//! ```text
//!  scan/
//!    rig.toml          cameras and extrinsics          → Rig
//!    depth.txt …       "timestamp path" stream lists   → Vec<StreamEntry>
//!    trajectory.txt    TUM poses world_from_depth       → Trajectory (interpolated at frame times)
//!    depth/ thermal/   16-bit PNG or TIFF               → Image16
//!    masks.txt, masks/ instance PNG + labels JSON       → Image16 + MaskLabels
//! ```
//!
//! Other sources become that layout: ROS 1 bags ([`bag`]), MCAP files ([`mcap_file`]) and ROS 2
//! SQLite bags ([`rosbag2`]) through [`ros_scan`] (messages decoded by [`ros_msg`]), RTAB-Map
//! databases ([`rtabmap`], depth in [`rvl`]); [`layout_writer`] writes the folder. Single thermal images in camera formats (FLIR
//! R-JPEG/FFF in [`flir`], Lepton, radiometric TIFF) are read by [`read_thermal_file`]. Binary
//! parsers read through [`bytes`], whose errors carry the byte offset.
//!
//! Accepted beyond the spec: `masks.txt` (instance masks, see [`masks`]), `distortion` for the depth
//! and colour cameras, duplicate timestamps in a trajectory (the first pose is kept). Errors name
//! the file and line (or the image size); [`write_atomic`] and [`PartialDir`] make outputs appear
//! only when complete.

mod atomic;
pub mod bag;
pub mod bytes;
mod error;
pub mod flir;
mod image16;
pub mod layout_writer;
pub mod masks;
pub mod mcap_file;
mod ply;
mod recording;
mod rig;
pub mod ros_msg;
pub mod ros_scan;
pub mod rosbag2;
pub mod rtabmap;
pub mod rvl;
mod streams;
mod thermal_file;
mod trajectory;

pub use atomic::{PartialDir, write_atomic};
pub use error::{FileError, FileErrorKind};
pub use image16::{Image16, encode_png_rgb8, encode_png16, gaussian_blur, read_image16};
pub use ply::{ReadCloud, ThermalCloud, cloud_ply_bytes, iron, read_cloud_ply, write_cloud_ply};
pub use recording::Recording;
pub use rig::{PoseFile, RgbCamera, Rig, ThermalEncoding};
pub use streams::{StreamEntry, parse_stream_list, stream_list_text};
pub use thermal_file::{
    ThermalFileKind, ThermalImage, ThermalOptions, decode_thermal, read_thermal_file,
};
pub use trajectory::{
    InterpolationLimits, QUATERNION_NORM_TOLERANCE, Trajectory, quaternion_xyzw, unit_quaternion,
};
