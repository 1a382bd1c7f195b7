//! Bounds-checked reading of binary formats: every read names the byte offset it failed at, and
//! sizes read from a file are checked against what is left before anything is allocated.

use std::path::Path;

use crate::error::FileError;

/// A problem at a byte offset of a file (the path is added by [`Corrupt::in_file`]).
///
/// In a rosbag2 SQLite file a message has no file offset: `record` is then its row id in the
/// `messages` table and `offset` counts from the start of its data. In a bag split over several
/// files, `part` names the file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Corrupt {
    /// Byte offset from the start of the file (or of the record's data).
    pub offset: u64,
    /// What is wrong.
    pub what: String,
    /// The message's row id, where the file is a database.
    pub record: Option<u64>,
    /// The file of a split bag.
    pub part: Option<String>,
}

impl Corrupt {
    /// A problem at `offset`.
    pub fn new(offset: u64, what: impl Into<String>) -> Self {
        Self {
            offset,
            what: what.into(),
            record: None,
            part: None,
        }
    }

    /// The same problem, inside database message `record` (if not already placed in one).
    #[must_use]
    pub fn in_record(mut self, record: Option<u64>) -> Self {
        self.record = self.record.or(record);
        self
    }

    /// The same problem, in file `part` of a split bag.
    #[must_use]
    pub fn in_part(mut self, part: &str) -> Self {
        self.part.get_or_insert_with(|| part.to_string());
        self
    }

    /// As a file error.
    pub fn in_file(self, path: &Path) -> FileError {
        if self.record.is_none() && self.part.is_none() {
            FileError::corrupt(path, self.offset, self.what)
        } else {
            FileError::new(
                path,
                None,
                crate::error::FileErrorKind::Syntax(self.to_string()),
            )
        }
    }
}

impl std::fmt::Display for Corrupt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(p) = &self.part {
            write!(f, "{p}, ")?;
        }
        match self.record {
            Some(r) => write!(
                f,
                "message {r}, at byte {} of its data: {}",
                self.offset, self.what
            ),
            None => write!(f, "at byte {}: {}", self.offset, self.what),
        }
    }
}

/// Byte order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Endian {
    /// Least significant byte first.
    Little,
    /// Most significant byte first.
    Big,
}

/// A read-only view of bytes that start at `base` in their file.
#[derive(Clone, Copy, Debug)]
pub struct Bytes<'a> {
    /// The bytes.
    pub data: &'a [u8],
    /// File offset of `data[0]`.
    pub base: u64,
    /// Byte order of multi-byte reads.
    pub endian: Endian,
}

impl<'a> Bytes<'a> {
    /// A view of a whole file.
    pub fn new(data: &'a [u8], endian: Endian) -> Self {
        Self {
            data,
            base: 0,
            endian,
        }
    }

    /// Length.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The same bytes in another byte order.
    pub fn with_endian(self, endian: Endian) -> Self {
        Self { endian, ..self }
    }

    /// An error at `at` (relative to this view).
    pub fn err(&self, at: usize, what: impl Into<String>) -> Corrupt {
        Corrupt::new(self.base + at as u64, what)
    }

    /// `len` bytes at `at`, or an error saying what was being read.
    pub fn slice(&self, at: usize, len: usize, what: &str) -> Result<&'a [u8], Corrupt> {
        match at.checked_add(len) {
            Some(end) if end <= self.data.len() => Ok(&self.data[at..end]),
            _ => Err(self.err(
                at.min(self.data.len()),
                format!(
                    "{what} needs {len} bytes but only {} are left (file cut short?)",
                    self.data.len().saturating_sub(at)
                ),
            )),
        }
    }

    /// A sub-view of `len` bytes at `at`.
    pub fn sub(&self, at: usize, len: usize, what: &str) -> Result<Self, Corrupt> {
        Ok(Self {
            data: self.slice(at, len, what)?,
            base: self.base + at as u64,
            endian: self.endian,
        })
    }

    fn array<const N: usize>(&self, at: usize, what: &str) -> Result<[u8; N], Corrupt> {
        let s = self.slice(at, N, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        if self.endian == Endian::Big {
            a.reverse();
        }
        Ok(a)
    }

    /// u8 at `at`.
    pub fn u8(&self, at: usize, what: &str) -> Result<u8, Corrupt> {
        Ok(self.slice(at, 1, what)?[0])
    }

    /// u16 at `at`.
    pub fn u16(&self, at: usize, what: &str) -> Result<u16, Corrupt> {
        Ok(u16::from_le_bytes(self.array(at, what)?))
    }

    /// u32 at `at`.
    pub fn u32(&self, at: usize, what: &str) -> Result<u32, Corrupt> {
        Ok(u32::from_le_bytes(self.array(at, what)?))
    }

    /// i32 at `at`.
    pub fn i32(&self, at: usize, what: &str) -> Result<i32, Corrupt> {
        Ok(i32::from_le_bytes(self.array(at, what)?))
    }

    /// f32 at `at`.
    pub fn f32(&self, at: usize, what: &str) -> Result<f32, Corrupt> {
        Ok(f32::from_le_bytes(self.array(at, what)?))
    }

    /// f64 at `at`.
    pub fn f64(&self, at: usize, what: &str) -> Result<f64, Corrupt> {
        Ok(f64::from_le_bytes(self.array(at, what)?))
    }

    /// A NUL-padded string of at most `len` bytes at `at` (lossy UTF-8, trimmed).
    pub fn fixed_str(&self, at: usize, len: usize, what: &str) -> Result<String, Corrupt> {
        let s = self.slice(at, len, what)?;
        let end = s.iter().position(|&b| b == 0).unwrap_or(s.len());
        Ok(String::from_utf8_lossy(&s[..end]).trim().to_string())
    }
}

/// A sequential reader over [`Bytes`] (ROS 1 serialisation and CDR).
#[derive(Clone, Debug)]
pub struct Cursor<'a> {
    /// The bytes.
    pub bytes: Bytes<'a>,
    /// Position.
    pub pos: usize,
    /// Alignment origin for CDR (`None`: packed, as ROS 1).
    pub align_origin: Option<usize>,
}

impl<'a> Cursor<'a> {
    /// Reads packed (ROS 1) from the start.
    pub fn packed(bytes: Bytes<'a>) -> Self {
        Self {
            bytes,
            pos: 0,
            align_origin: None,
        }
    }

    /// Reads CDR with alignment counted from `origin`.
    pub fn aligned(bytes: Bytes<'a>, origin: usize) -> Self {
        Self {
            bytes,
            pos: origin,
            align_origin: Some(origin),
        }
    }

    fn align(&mut self, n: usize) {
        if let Some(o) = self.align_origin {
            let rel = self.pos - o;
            self.pos += (n - rel % n) % n;
        }
    }

    /// An error at the current position.
    pub fn err(&self, what: impl Into<String>) -> Corrupt {
        self.bytes.err(self.pos.min(self.bytes.len()), what)
    }

    /// Bytes left.
    pub fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    /// u8.
    pub fn u8(&mut self, what: &str) -> Result<u8, Corrupt> {
        let v = self.bytes.u8(self.pos, what)?;
        self.pos += 1;
        Ok(v)
    }

    /// u32.
    pub fn u32(&mut self, what: &str) -> Result<u32, Corrupt> {
        self.align(4);
        let v = self.bytes.u32(self.pos, what)?;
        self.pos += 4;
        Ok(v)
    }

    /// i32.
    pub fn i32(&mut self, what: &str) -> Result<i32, Corrupt> {
        self.align(4);
        let v = self.bytes.i32(self.pos, what)?;
        self.pos += 4;
        Ok(v)
    }

    /// f64.
    pub fn f64(&mut self, what: &str) -> Result<f64, Corrupt> {
        self.align(8);
        let v = self.bytes.f64(self.pos, what)?;
        self.pos += 8;
        Ok(v)
    }

    /// `n` f64 values (a fixed array).
    pub fn f64s(&mut self, n: usize, what: &str) -> Result<Vec<f64>, Corrupt> {
        if n.saturating_mul(8) > self.remaining() {
            return Err(self.err(format!(
                "{what}: {n} numbers need {} bytes but only {} are left",
                n.saturating_mul(8),
                self.remaining()
            )));
        }
        (0..n).map(|_| self.f64(what)).collect()
    }

    /// A length-prefixed sequence of f64.
    pub fn f64_seq(&mut self, what: &str) -> Result<Vec<f64>, Corrupt> {
        let n = self.u32(what)? as usize;
        self.f64s(n, what)
    }

    /// A length-prefixed byte sequence (checked against what is left before it is taken).
    pub fn byte_seq(&mut self, what: &str) -> Result<&'a [u8], Corrupt> {
        let n = self.u32(what)? as usize;
        let s = self.bytes.slice(self.pos, n, what)?;
        self.pos += n;
        Ok(s)
    }

    /// A string (ROS 1: length then bytes; CDR: length including a trailing NUL).
    pub fn string(&mut self, what: &str) -> Result<String, Corrupt> {
        let s = self.byte_seq(what)?;
        let s = if self.align_origin.is_some() {
            s.strip_suffix(&[0]).unwrap_or(s)
        } else {
            s
        };
        Ok(String::from_utf8_lossy(s).into_owned())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_both_byte_orders_and_names_offsets() {
        let d = [0x01u8, 0x02, 0x03, 0x04, 0x05];
        let le = Bytes::new(&d, Endian::Little);
        assert_eq!(le.u16(0, "x").unwrap(), 0x0201);
        assert_eq!(
            le.with_endian(Endian::Big).u32(1, "x").unwrap(),
            0x0203_0405
        );
        let e = le.u32(3, "the width").unwrap_err();
        assert_eq!(e.offset, 3);
        assert!(e.what.contains("the width"), "{}", e.what);
        let sub = le.sub(2, 3, "s").unwrap();
        assert_eq!(sub.err(1, "y").offset, 3);
        assert!(le.slice(usize::MAX, 2, "huge").is_err());
    }

    #[test]
    fn cdr_aligns_and_checks_sequence_lengths() {
        // u8, pad to 4, u32 = 7, then a sequence claiming 1000 bytes.
        let d = [9u8, 0, 0, 0, 7, 0, 0, 0, 0xe8, 0x03, 0, 0, 1, 2];
        let mut c = Cursor::aligned(Bytes::new(&d, Endian::Little), 0);
        assert_eq!(c.u8("a").unwrap(), 9);
        assert_eq!(c.u32("b").unwrap(), 7);
        let e = c.byte_seq("data").unwrap_err();
        assert_eq!(e.offset, 12);
    }
}
