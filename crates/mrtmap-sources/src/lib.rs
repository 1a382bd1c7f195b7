//! # mrtmap-sources
//!
//! Scan sources other than the recording folder, each turned into the recording layout that
//! [`mrtmap_io::Recording`] reads:
//!
//! | source | module | read | written (for tests and round trips) |
//! |---|---|---|---|
//! | ROS 1 bag (none/bz2/lz4 chunks) | [`ros::bag`] | a record at a time | RealSense-style topics |
//! | MCAP (none/zstd/lz4 chunks) | [`ros::mcap`] | a record at a time | RealSense-style topics |
//! | ROS 2 bag, SQLite storage (`.db3`) | [`ros::db3`] | a row at a time | Humble's schema |
//! | ROS 2 bag folder (`metadata.yaml`, split or not) | [`ros`] | file by file | — |
//! | RTAB-Map database | [`rtabmap`] | a node at a time | current and legacy schema |
//!
//! [`resolve_source`] tells which a path is by its content. These readers compile SQLite, zstd,
//! bzip2, LZ4 and MCAP; crates that only need the recording layout depend on `mrtmap-io` alone.
//!
//! Binary parsers read through [`mrtmap_io::bytes`], so every error carries its byte offset (and
//! inside a compressed chunk, the chunk's).

pub mod convert;
pub mod ros;
pub mod rtabmap;

mod kind;

pub use kind::{SourceKind, resolve_source, source_kind};
