//! File errors that name the file (and line, or pixel) and say what is wrong.

use std::fmt;
use std::path::{Path, PathBuf};

/// A problem with one file.
#[derive(Debug, thiserror::Error)]
pub struct FileError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line, where the problem is on one.
    pub line: Option<usize>,
    /// What is wrong.
    pub kind: FileErrorKind,
}

impl fmt::Display for FileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}", self.path.display(), l, self.kind),
            None => write!(f, "{}: {}", self.path.display(), self.kind),
        }
    }
}

/// What is wrong with a file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FileErrorKind {
    /// The file could not be read or written (said in words, without the OS's error number).
    #[error("{}", io_words(.0))]
    Io(#[from] std::io::Error),
    /// A file stands where a folder is needed, for the path named.
    #[error("is a file where a folder is needed (for {})", .0.display())]
    NotAFolder(PathBuf),
    /// A line or value that does not parse.
    #[error("{0}")]
    Syntax(String),
    /// A timestamp earlier than the one before it.
    #[error("timestamp {t} goes backwards (the previous line has {previous})")]
    TimestampBackwards {
        /// This line's timestamp.
        t: f64,
        /// The previous one.
        previous: f64,
    },
    /// A quaternion that is not unit length or not finite.
    #[error("quaternion (x y z w) = {q:?} is not a unit quaternion (norm {norm})")]
    BadQuaternion {
        /// As written.
        q: [f64; 4],
        /// Its norm.
        norm: f64,
    },
    /// An image whose size differs from the rig's.
    #[error("image is {width}×{height} pixels but the rig says {expected_width}×{expected_height}")]
    ImageSize {
        /// Actual width.
        width: u32,
        /// Actual height.
        height: u32,
        /// Rig width.
        expected_width: u32,
        /// Rig height.
        expected_height: u32,
    },
    /// An image that cannot be decoded or has the wrong pixel type.
    #[error("{0}")]
    Image(String),
    /// An image that could not be encoded for writing.
    #[error(transparent)]
    Encode(#[from] EncodeError),
    /// A file listed in another that does not exist.
    #[error("listed file {0} does not exist")]
    Missing(String),
    /// A binary file whose content is cut short or inconsistent at a byte offset.
    #[error("at byte {offset}: {what}")]
    Corrupt {
        /// Byte offset from the start of the file.
        offset: u64,
        /// What is wrong there.
        what: String,
    },
}

/// An OS error in words for a person, with what to do where that is clear.
pub fn io_words(e: &std::io::Error) -> String {
    use std::io::ErrorKind as K;
    match e.kind() {
        K::NotFound => "does not exist: check the path".into(),
        K::PermissionDenied => "permission denied: choose a place you may read and write".into(),
        K::AlreadyExists => "already exists: remove it or choose another name".into(),
        K::IsADirectory => "is a folder where a file is needed".into(),
        K::NotADirectory => "a part of this path is a file where a folder is needed".into(),
        K::StorageFull => "the disk is full: free some space".into(),
        K::InvalidData => "is not text in UTF-8 (is it the right file?)".into(),
        K::ReadOnlyFilesystem => "is on a read-only file system: choose another place".into(),
        K::UnexpectedEof => "ends too early (cut short?)".into(),
        _ => {
            let s = e.to_string();
            match s.find(" (os error") {
                Some(k) => s[..k].to_lowercase(),
                None => s,
            }
        }
    }
}

impl FileError {
    /// An error in `path`, at `line` if given.
    pub fn new(path: &Path, line: Option<usize>, kind: FileErrorKind) -> Self {
        Self {
            path: path.to_path_buf(),
            line,
            kind,
        }
    }

    /// An image that could not be encoded for this file.
    pub fn encode(path: &Path, e: EncodeError) -> Self {
        Self::new(path, None, FileErrorKind::Encode(e))
    }

    /// A syntax error at a line.
    pub fn syntax(path: &Path, line: usize, msg: impl Into<String>) -> Self {
        Self::new(path, Some(line), FileErrorKind::Syntax(msg.into()))
    }

    /// Corrupt or truncated content at a byte offset.
    pub fn corrupt(path: &Path, offset: u64, what: impl Into<String>) -> Self {
        Self::new(
            path,
            None,
            FileErrorKind::Corrupt {
                offset,
                what: what.into(),
            },
        )
    }

    /// A read or write failure.
    pub fn io(path: &Path, e: std::io::Error) -> Self {
        // Making a folder under a file says "already exists" (EEXIST): name the file that stands
        // where a folder is needed instead.
        if matches!(
            e.kind(),
            std::io::ErrorKind::AlreadyExists | std::io::ErrorKind::NotADirectory
        ) && let Some(file) = path.ancestors().find(|a| a.is_file())
        {
            let needed_for = if file == path {
                path.join("…")
            } else {
                path.to_path_buf()
            };
            return Self::new(file, None, FileErrorKind::NotAFolder(needed_for));
        }
        Self::new(path, None, FileErrorKind::Io(e))
    }
}

/// An image that could not be encoded (its pixels do not fill its size, or it is empty).
#[derive(Debug, thiserror::Error)]
#[error("cannot encode a {width}×{height} PNG")]
pub struct EncodeError {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Why.
    #[source]
    pub source: image::ImageError,
}
