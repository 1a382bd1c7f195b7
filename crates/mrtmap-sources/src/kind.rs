//! What kind of scan source a path is: a recording folder, a ROS 1 bag, an MCAP file, a ROS 2
//! bag (folder, `.mcap` or `.db3`) or an RTAB-Map database.

use std::path::Path;

use mrtmap_io::{FileError, FileErrorKind};
use serde::Serialize;

use crate::ros::{Container, storage_files};

/// What kind of scan source a path is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum SourceKind {
    /// The recording layout.
    Folder,
    /// ROS 1 bag.
    Bag,
    /// MCAP.
    Mcap,
    /// ROS 2 bag in SQLite storage (`.db3`).
    Db3,
    /// RTAB-Map database (SQLite).
    RtabMap,
}

impl SourceKind {
    /// The message container, for the kinds that have one.
    pub fn container(self) -> Option<Container> {
        match self {
            Self::Bag => Some(Container::Bag),
            Self::Mcap => Some(Container::Mcap),
            Self::Db3 => Some(Container::Db3),
            Self::Folder | Self::RtabMap => None,
        }
    }
}

/// Tells the kind of a source by its content (a folder, or a file's magic bytes).
pub fn source_kind(path: &Path) -> Result<SourceKind, FileError> {
    resolve_source(path).map(|(k, _)| k)
}

/// The kind of a source and what to read. A ROS 2 bag folder (`metadata.yaml` beside its
/// storage files) resolves to its one `.mcap` or `.db3` file, or stays the folder when the bag is
/// split over several (they are then read in order). An SQLite file is a rosbag2 `.db3` when it
/// has rosbag2's tables, else an RTAB-Map database.
pub fn resolve_source(path: &Path) -> Result<(SourceKind, std::path::PathBuf), FileError> {
    if path.is_dir() {
        if path.join("metadata.yaml").is_file() {
            let one_or_all = |kind, v: Vec<std::path::PathBuf>| match v.as_slice() {
                [one] => Ok((kind, one.clone())),
                _ => Ok((kind, path.to_path_buf())),
            };
            let files = |c| storage_files(path, c).unwrap_or_default();
            let (mcaps, db3s) = (files(Container::Mcap), files(Container::Db3));
            let zstd = std::fs::read_dir(path)
                .map_err(|e| FileError::io(path, e))?
                .filter_map(|e| e.ok())
                .any(|e| e.path().extension().is_some_and(|x| x == "zstd"));
            let bad = |m: String| Err(FileError::new(path, None, FileErrorKind::Syntax(m)));
            return match (mcaps.is_empty(), db3s.is_empty()) {
                (false, true) => one_or_all(SourceKind::Mcap, mcaps),
                (true, false) => one_or_all(SourceKind::Db3, db3s),
                (false, false) => bad("a ROS 2 bag folder with both .mcap and .db3 files: give one file".into()),
                (true, true) if zstd => bad(
                    "a ROS 2 bag compressed file by file (.zstd): decompress it first (`ros2 bag convert`, or `zstd -d` on each file)".into(),
                ),
                (true, true) => bad("a ROS 2 bag folder without .mcap or .db3 files".into()),
            };
        }
        return Ok((SourceKind::Folder, path.to_path_buf()));
    }
    let mut head = [0u8; 16];
    let n = {
        use std::io::Read;
        let mut f = std::fs::File::open(path).map_err(|e| FileError::io(path, e))?;
        f.read(&mut head).map_err(|e| FileError::io(path, e))?
    };
    let head = &head[..n];
    let kind = if head.starts_with(crate::ros::bag::MAGIC) {
        SourceKind::Bag
    } else if head.starts_with(crate::ros::mcap::MAGIC) {
        SourceKind::Mcap
    } else if head.starts_with(b"SQLite format 3\0") {
        match crate::ros::db3::open_file(path) {
            Ok(c) if crate::ros::db3::is_rosbag2(&c) => SourceKind::Db3,
            _ => SourceKind::RtabMap,
        }
    } else {
        return Err(FileError::new(
            path,
            None,
            FileErrorKind::Syntax(
                "not a scan source: expected a recording folder, a ROS 1 bag, an MCAP file, a ROS 2 bag (folder or .db3) or an RTAB-Map database".into(),
            ),
        ));
    };
    Ok((kind, path.to_path_buf()))
}
