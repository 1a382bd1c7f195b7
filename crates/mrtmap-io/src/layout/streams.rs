//! Stream lists (`depth.txt`, `thermal.txt`, `rgb.txt`, `masks.txt`): "timestamp path" per line,
//! `#` starts a comment, timestamps in seconds.
//!
//! One set of rules, line by line ([`StreamLines`]), read by the batch reader
//! ([`crate::Recording::open`]) and by `mrtmap live`'s follower alike, so both take the same
//! frames from the same list:
//!
//! - a byte-order mark at the start is read past; blank lines and `#` comments are skipped;
//!   text after the path is ignored;
//! - a line that is not "timestamp path" (or whose timestamp is not a finite number), and a line
//!   whose time goes back before the line above's, are left out and named ([`LineSkip`]);
//! - a line that repeats the line above (time and file) is left out: a frame listed twice would
//!   count twice;
//! - a line whose file is not there is left out (live waits for it a while first).
//!
//! The batch reader refuses a list in which more than a tenth of the frame lines are left out
//! for the first three reasons (it is not a damaged list but a wrong one: [`MAX_SKIPPED_SHARE`]).

use std::path::{Path, PathBuf};

use crate::error::{FileError, FileErrorKind};

/// One listed frame.
#[derive(Clone, Debug, PartialEq)]
pub struct StreamEntry {
    /// Timestamp (s).
    pub t: f64,
    /// Path relative to the recording folder, as listed.
    pub path: PathBuf,
    /// Line in the list (1-based).
    pub line: usize,
}

/// Why a line of a stream list was left out.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum LineSkip {
    /// Not "timestamp path", as written (trimmed).
    NotAnEntry(String),
    /// A timestamp that is not a finite number, as written.
    NotATimestamp(String),
    /// Its time goes back before the line above's.
    Backwards {
        /// This line's time (s).
        t: f64,
        /// The line above's (s).
        previous: f64,
    },
    /// It repeats the line above (time and file).
    Repeated,
    /// Its file is not there.
    Missing(PathBuf),
}

/// A line left out, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct SkippedLine {
    /// The line (1-based).
    pub line: usize,
    /// Why.
    pub why: LineSkip,
}

impl SkippedLine {
    /// As a file error of `list_path` (what a strict reader refuses with).
    pub fn to_error(&self, list_path: &Path) -> FileError {
        let kind = match &self.why {
            LineSkip::NotAnEntry(s) => {
                FileErrorKind::Syntax(format!("expected 'timestamp path', got '{s}'"))
            }
            LineSkip::NotATimestamp(s) => {
                FileErrorKind::Syntax(format!("'{s}' is not a timestamp"))
            }
            LineSkip::Backwards { t, previous } => FileErrorKind::TimestampBackwards {
                t: *t,
                previous: *previous,
            },
            LineSkip::Repeated => FileErrorKind::Syntax("repeats the line above".into()),
            LineSkip::Missing(p) => FileErrorKind::Missing(p.display().to_string()),
        };
        FileError::new(list_path, Some(self.line), kind)
    }
}

impl std::fmt::Display for LineSkip {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NotAnEntry(s) => write!(f, "expected 'timestamp path', got '{s}'"),
            Self::NotATimestamp(s) => write!(f, "'{s}' is not a timestamp"),
            Self::Backwards { t, previous } => write!(
                f,
                "its time {t:.6} goes back before the line above ({previous:.6}); the recorder's clock or its lists are out of order"
            ),
            Self::Repeated => f.write_str("it repeats the line above (time and file)"),
            Self::Missing(p) => write!(f, "its file {} is not there", p.display()),
        }
    }
}

/// More than this share of a list's frame lines left out (not counting repeats) and the batch
/// reader refuses the list.
pub const MAX_SKIPPED_SHARE: f64 = 0.1;

/// What one line of a stream list gives.
#[derive(Clone, Debug, PartialEq)]
pub enum ListLine {
    /// A frame.
    Entry(StreamEntry),
    /// A line left out.
    Skipped(SkippedLine),
    /// A blank line or a comment.
    Nothing,
}

/// The rules of a stream list, fed one line at a time in order (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct StreamLines {
    line: usize,
    last: Option<(f64, PathBuf)>,
}

impl StreamLines {
    /// Rules for a list read from its first line.
    pub fn new() -> Self {
        Self::default()
    }

    /// Lines fed so far.
    pub fn lines(&self) -> usize {
        self.line
    }

    /// The next line (without its end of line).
    pub fn next_line(&mut self, raw: &str) -> ListLine {
        self.line += 1;
        let n = self.line;
        let raw = if n == 1 {
            raw.strip_prefix('\u{feff}').unwrap_or(raw)
        } else {
            raw
        };
        let s = raw.trim();
        if s.is_empty() || s.starts_with('#') {
            return ListLine::Nothing;
        }
        let skip = |why| ListLine::Skipped(SkippedLine { line: n, why });
        let mut it = s.split_whitespace();
        let (Some(ts), Some(p)) = (it.next(), it.next()) else {
            return skip(LineSkip::NotAnEntry(s.to_string()));
        };
        let Some(t) = ts.parse::<f64>().ok().filter(|t| t.is_finite()) else {
            return skip(LineSkip::NotATimestamp(ts.to_string()));
        };
        let path = PathBuf::from(p);
        if let Some((previous, prev_path)) = &self.last {
            if t < *previous {
                return skip(LineSkip::Backwards {
                    t,
                    previous: *previous,
                });
            }
            if t == *previous && path == *prev_path {
                return skip(LineSkip::Repeated);
            }
        }
        self.last = Some((t, path.clone()));
        ListLine::Entry(StreamEntry { t, path, line: n })
    }
}

/// A whole list by [`StreamLines`]: its frames and the lines left out (files not checked).
pub fn read_stream_list(text: &str) -> (Vec<StreamEntry>, Vec<SkippedLine>) {
    let mut rules = StreamLines::new();
    let (mut entries, mut skipped) = (Vec::new(), Vec::new());
    for raw in text.lines() {
        match rules.next_line(raw) {
            ListLine::Entry(e) => entries.push(e),
            ListLine::Skipped(s) => skipped.push(s),
            ListLine::Nothing => {}
        }
    }
    (entries, skipped)
}

/// Parses a stream list strictly: the first line [`StreamLines`] would leave out is an error
/// (a repeated line is left out without one).
pub fn parse_stream_list(text: &str, list_path: &Path) -> Result<Vec<StreamEntry>, FileError> {
    let (entries, skipped) = read_stream_list(text);
    match skipped.iter().find(|s| s.why != LineSkip::Repeated) {
        Some(s) => Err(s.to_error(list_path)),
        None => Ok(entries),
    }
}

/// Stream list text.
pub fn stream_list_text(header: &str, entries: &[(f64, String)]) -> String {
    let mut s = String::with_capacity(entries.len() * 40);
    for l in header.lines() {
        s.push_str(&format!("# {l}\n"));
    }
    for (t, p) in entries {
        s.push_str(&format!("{t:.6} {p}\n"));
    }
    s
}
