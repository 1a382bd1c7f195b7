//! ROS recordings: ROS 1 bags ([`bag`]), MCAP files ([`mcap`]) and ROS 2 bags in SQLite storage
//! ([`db3`]), their messages ([`msg`], ROS 1 and CDR wires), and a scan made of them:
//!
//! ```text
//!  file ──read──► messages ──survey──► Survey ──plan(RosOptions)──► Plan ──export──► recording folder
//!                                                                        (streams, rig, missing)
//!  recording folder ──write_ros──► RealSense-style bag / MCAP / .db3
//! ```

pub mod bag;
pub mod db3;
pub mod mcap;
pub mod msg;

mod export;
mod plan;
mod read;
mod survey;
mod write;

pub use export::{ExportReport, export, image_frames};
pub use plan::{Plan, PoseSource, RosOptions, plan, static_lookup};
pub use read::{Container, Input, ReadSeek, for_each, storage_files};
pub use survey::{Survey, TopicStats, survey};
pub use write::{RosWriteOptions, names, write_ros};
