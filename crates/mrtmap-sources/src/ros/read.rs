//! Reading messages from a ROS 1 bag, an MCAP file or a ROS 2 `.db3`, in memory or from a file a
//! record at a time, and from a ROS 2 bag split over several files.

use std::path::Path;

use serde::Serialize;

use super::msg::{Message, Wire};
use mrtmap_io::bytes::Corrupt;

/// The container.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Container {
    /// ROS 1 bag.
    Bag,
    /// MCAP.
    Mcap,
    /// ROS 2 bag in SQLite storage (`.db3`).
    Db3,
}

/// Where a bag, MCAP or `.db3` file is read from: bytes in memory, or a file read a record at a
/// time. A folder stands for a ROS 2 bag split into several files, read in order.
#[derive(Clone, Copy, Debug)]
pub enum Input<'a> {
    /// In memory.
    Bytes(&'a [u8]),
    /// A file.
    File(&'a Path),
}

impl<'a> From<&'a [u8]> for Input<'a> {
    fn from(b: &'a [u8]) -> Self {
        Self::Bytes(b)
    }
}

impl<'a> From<&'a Vec<u8>> for Input<'a> {
    fn from(b: &'a Vec<u8>) -> Self {
        Self::Bytes(b)
    }
}

impl<'a> From<&'a Path> for Input<'a> {
    fn from(p: &'a Path) -> Self {
        Self::File(p)
    }
}

/// Something to read records from.
pub trait ReadSeek: std::io::Read + std::io::Seek {}
impl<T: std::io::Read + std::io::Seek> ReadSeek for T {}

impl<'a> Input<'a> {
    fn open(self) -> Result<Box<dyn ReadSeek + 'a>, Corrupt> {
        match self {
            Self::Bytes(b) => Ok(Box::new(std::io::Cursor::new(b))),
            Self::File(p) => {
                let f = std::fs::File::open(p)
                    .map_err(|e| Corrupt::new(0, format!("cannot open: {e}")))?;
                Ok(Box::new(std::io::BufReader::with_capacity(1 << 20, f)))
            }
        }
    }
}

/// Reads every message; returns whether the file was cut or never closed.
pub fn for_each<'a>(
    container: Container,
    input: impl Into<Input<'a>>,
    f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
) -> Result<bool, Corrupt> {
    let input = input.into();
    if let Input::File(dir) = input
        && dir.is_dir()
    {
        let mut unfinished = false;
        for file in storage_files(dir, container)? {
            let name = file
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            unfinished |=
                for_each(container, Input::File(&file), f).map_err(|e| e.in_part(&name))?;
        }
        return Ok(unfinished);
    }
    match container {
        Container::Db3 => {
            let c = match input {
                Input::Bytes(b) => super::db3::open_bytes(b)?,
                Input::File(p) => super::db3::open_file(p)?,
            };
            super::db3::for_each_message(&c, f).map(|_| false)
        }
        Container::Bag => {
            super::bag::for_each_message_in(&mut *input.open()?, f).map(|s| s.unindexed)
        }
        Container::Mcap => {
            // ROS 2 bags recorded with per-message compression keep each message zstd-compressed.
            let mut buf = Vec::new();
            let mut g = |m: Message<'_>| {
                if m.wire != Wire::Cdr {
                    return f(m);
                }
                let data = super::db3::inflate(m.data, &mut buf)
                    .map_err(|e| Corrupt::new(m.offset, e.to_string()))?;
                f(Message { data, ..m })
            };
            super::mcap::for_each_message_in(&mut *input.open()?, &mut g).map(|s| s.unfinished)
        }
    }
}

/// The storage files of a ROS 2 bag folder for `container` (`.mcap` or `.db3`), in recording
/// order: rosbag2 names them `<bag>_<n>`, so they are sorted by that trailing number.
pub fn storage_files(dir: &Path, container: Container) -> Result<Vec<std::path::PathBuf>, Corrupt> {
    let ext = match container {
        Container::Mcap => "mcap",
        Container::Db3 => "db3",
        Container::Bag => "bag",
    };
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| Corrupt::new(0, format!("cannot list the folder: {e}")))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == ext))
        .collect();
    files.sort_by_key(|p| {
        let stem = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let digits = stem.len() - stem.trim_end_matches(|c: char| c.is_ascii_digit()).len();
        let (head, n) = stem.split_at(stem.len() - digits);
        (
            head.to_string(),
            n.parse::<u64>().unwrap_or(0),
            stem.clone(),
        )
    });
    if files.is_empty() {
        return Err(Corrupt::new(0, format!("a folder without .{ext} files")));
    }
    Ok(files)
}
