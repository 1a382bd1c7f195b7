//! Stream lists (`depth.txt`, `thermal.txt`, `rgb.txt`, `masks.txt`): "timestamp path" per line,
//! `#` starts a comment, timestamps in seconds.

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

/// Parses a stream list. Timestamps must not go backwards.
/// A byte-order mark at the start (Excel's "CSV UTF-8" and some Windows editors write one) is
/// read past; text after the path is ignored.
pub fn parse_stream_list(text: &str, list_path: &Path) -> Result<Vec<StreamEntry>, FileError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut out: Vec<StreamEntry> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let s = line.trim();
        if s.is_empty() || s.starts_with('#') {
            continue;
        }
        let mut it = s.split_whitespace();
        let (Some(ts), Some(p)) = (it.next(), it.next()) else {
            return Err(FileError::syntax(
                list_path,
                n,
                format!("expected 'timestamp path', got '{s}'"),
            ));
        };
        let t: f64 = ts
            .parse()
            .ok()
            .filter(|t: &f64| t.is_finite())
            .ok_or_else(|| FileError::syntax(list_path, n, format!("'{ts}' is not a timestamp")))?;
        if let Some(prev) = out.last()
            && t < prev.t
        {
            return Err(FileError::new(
                list_path,
                Some(n),
                FileErrorKind::TimestampBackwards {
                    t,
                    previous: prev.t,
                },
            ));
        }
        out.push(StreamEntry {
            t,
            path: PathBuf::from(p),
            line: n,
        });
    }
    Ok(out)
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
