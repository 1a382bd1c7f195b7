//! # mrtmap-io
//!
//! The file formats every stage of mrtmap shares, in three families:
//!
//! - [`layout`]: the recording layout, one folder per scan (docs/recording.md):
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
//! - [`thermal`]: single thermal images in camera formats (FLIR R-JPEG/FFF, Lepton, radiometric
//!   TIFF).
//! - thermal point clouds as PLY ([`write_cloud_ply`], [`read_cloud_ply`]), 16-bit images
//!   ([`Image16`]), atomic files and folders ([`write_atomic`], [`PartialDir`]), and bounds-checked
//!   byte readers whose errors carry the offset ([`bytes`]).
//!
//! ROS bags, MCAP files and RTAB-Map databases live in `mrtmap-sources`, which turns them into
//! this layout; crates that need only the layout do not compile SQLite or the compressors.
//!
//! Accepted beyond the layout's contract: `masks.txt` (instance masks, see [`masks`]),
//! `distortion` for the depth and colour cameras, duplicate timestamps in a trajectory (the first
//! pose is kept). Errors name the file and line (or the image size); [`write_atomic`] and
//! [`PartialDir`] make outputs appear only when complete.

mod atomic;
pub mod bytes;
pub mod depth;
pub mod epw;
mod error;
mod image16;
pub mod layout;
mod ply;
pub mod thermal;

pub use atomic::{MADE, PartialDir, check_replaceable, claim_dir, record_made, write_atomic};
pub use error::{EncodeError, FileError, FileErrorKind, io_words};
pub use image16::{Image16, encode_png_rgb8, encode_png16, gaussian_blur, read_image16};
pub use layout::masks;
pub use layout::{
    ImuSample, InterpolationLimits, LayoutWriter, LineSkip, ListLine, MAX_SKIPPED_SHARE, PoseFile,
    QUATERNION_NORM_TOLERANCE, Recording, RecordingFile, RecordingWarning, RgbCamera, Rig,
    SkippedLine, StreamEntry, StreamLines, ThermalEncoding, Trajectory, imu_text, parse_imu,
    parse_stream_list, quaternion_xyzw, read_imu, read_stream_list, stream_list_text,
    unit_quaternion,
};
pub use ply::{ReadCloud, ThermalCloud, cloud_ply_bytes, iron, read_cloud_ply, write_cloud_ply};
pub use thermal::{
    ThermalFileKind, ThermalImage, ThermalOptions, decode_thermal, flir, read_thermal_file,
};
