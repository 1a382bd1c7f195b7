//! MCAP files (ROS 2's default bag storage since Iron; CDR or ROS 1 messages).
//!
//! The top-level records are walked here so that every error names a byte offset; the `mcap`
//! crate parses each record and decompresses chunks (zstd, lz4), after their declared size has
//! been checked against [`super::bag::MAX_CHUNK_BYTES`].

use std::collections::HashMap;
use std::io::{Read, Seek, SeekFrom};

use ::mcap::records::Record;

/// Chunk compression of written MCAP files.
pub use ::mcap::Compression as McapCompression;

use super::bag::MAX_CHUNK_BYTES;
use super::msg::{Message, Wire};
use mrtmap_io::bytes::{Bytes, Corrupt, Endian};

/// The MCAP magic.
pub const MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// What a pass found besides the messages.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct McapSummary {
    /// Chunks read.
    pub chunks: usize,
    /// Messages delivered.
    pub messages: usize,
    /// No footer: the recording was cut or never closed.
    pub unfinished: bool,
    /// Messages skipped because their encoding is neither CDR nor ROS 1.
    pub other_encoding: usize,
}

#[derive(Default)]
struct State {
    schemas: HashMap<u16, String>,
    channels: HashMap<u16, (String, u16, String)>,
}

impl State {
    fn record(
        &mut self,
        rec: Record<'_>,
        at: u64,
        summary: &mut McapSummary,
        f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
    ) -> Result<(), Corrupt> {
        match rec {
            Record::Schema { header, .. } => {
                self.schemas.insert(header.id, header.name);
            }
            Record::Channel(c) => {
                self.channels
                    .insert(c.id, (c.topic, c.schema_id, c.message_encoding));
            }
            Record::Message { header, data } => {
                let (topic, schema, enc) =
                    self.channels.get(&header.channel_id).ok_or_else(|| {
                        Corrupt::new(
                            at,
                            format!(
                                "message on channel {}, which no record defines",
                                header.channel_id
                            ),
                        )
                    })?;
                let wire = match enc.as_str() {
                    "cdr" => Wire::Cdr,
                    "ros1" => Wire::Ros1,
                    _ => {
                        summary.other_encoding += 1;
                        return Ok(());
                    }
                };
                let datatype = self.schemas.get(schema).map_or("", String::as_str);
                summary.messages += 1;
                f(Message {
                    topic,
                    datatype,
                    time: header.log_time as f64 * 1e-9,
                    data: &data,
                    wire,
                    offset: at,
                    record: None,
                })?;
            }
            _ => {}
        }
        Ok(())
    }
}

/// Opcodes parsed: schema, channel, message, chunk. Others are skipped unparsed — the `mcap`
/// crate's parser panics on a short attachment record (found by fuzzing), and a scan needs none.
const NEEDED: [u8; 4] = [0x03, 0x04, 0x05, 0x06];

/// The record at `pos`: opcode, body, position after it (the length checked against what is left).
fn record_at<'a>(b: &Bytes<'a>, pos: usize) -> Result<(u8, &'a [u8], usize), Corrupt> {
    let op = b.u8(pos, "a record opcode")?;
    let len = b.u32(pos + 1, "a record length")? as u64
        | (b.u32(pos + 5, "a record length")? as u64) << 32;
    let len = usize::try_from(len).unwrap_or(usize::MAX);
    let body = b.slice(pos + 9, len, &format!("record (opcode 0x{op:02x})"))?;
    Ok((op, body, pos + 9 + len))
}

/// Calls `f` for every CDR or ROS 1 message of an MCAP file, in file order.
pub fn for_each_message(
    file: &[u8],
    f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
) -> Result<McapSummary, Corrupt> {
    for_each_message_in(&mut std::io::Cursor::new(file), f)
}

fn io_error(at: u64, e: &std::io::Error) -> Corrupt {
    Corrupt::new(at, format!("cannot read: {e}"))
}

/// The file's length after checking its magic.
fn check_magic<R: Read + Seek + ?Sized>(r: &mut R) -> Result<u64, Corrupt> {
    let len = r.seek(SeekFrom::End(0)).map_err(|e| io_error(0, &e))?;
    r.seek(SeekFrom::Start(0)).map_err(|e| io_error(0, &e))?;
    let mut magic = [0u8; 8];
    if len < 8 || r.read_exact(&mut magic).is_err() || magic != MAGIC {
        return Err(Corrupt::new(0, "not an MCAP file (no MCAP magic)"));
    }
    Ok(len)
}

/// The opcode and body length of the top-level record at `at`, checked against the `len` bytes of
/// the file.
fn record_header<R: Read + Seek + ?Sized>(
    r: &mut R,
    at: u64,
    len: u64,
) -> Result<(u8, u64), Corrupt> {
    let left = len - at;
    if left < 9 {
        return Err(Corrupt::new(
            at,
            format!(
                "a record opcode and length need 9 bytes but only {left} are left (file cut short?)"
            ),
        ));
    }
    let mut h = [0u8; 9];
    r.seek(SeekFrom::Start(at)).map_err(|e| io_error(at, &e))?;
    r.read_exact(&mut h).map_err(|e| io_error(at, &e))?;
    let op = h[0];
    let blen = u64::from_le_bytes([h[1], h[2], h[3], h[4], h[5], h[6], h[7], h[8]]);
    if blen > left - 9 {
        return Err(Corrupt::new(
            at + 9,
            format!(
                "record (opcode 0x{op:02x}) needs {blen} bytes but only {} are left (file cut short?)",
                left - 9
            ),
        ));
    }
    Ok((op, blen))
}

/// A chunk's records decompressed into `chunk` (decompressed here, not by mcap's ChunkReader:
/// that one reserves whatever length a record inside the chunk claims, found by fuzzing: a 3 TB
/// reservation, an abort).
fn decompress_chunk(
    header: &::mcap::records::ChunkHeader,
    data: &[u8],
    at: u64,
    chunk: &mut Vec<u8>,
) -> Result<(), Corrupt> {
    if header.uncompressed_size > MAX_CHUNK_BYTES as u64 {
        return Err(Corrupt::new(
            at,
            format!(
                "chunk claims {} bytes decompressed (more than the {MAX_CHUNK_BYTES} accepted)",
                header.uncompressed_size
            ),
        ));
    }
    let compression = header.compression.as_str();
    let size = header.uncompressed_size as usize;
    chunk.clear();
    chunk.reserve(size.min(16 << 20));
    let res = match compression {
        "" => {
            chunk.extend_from_slice(data);
            Ok(data.len())
        }
        "zstd" => zstd::stream::read::Decoder::new(data)
            .and_then(|d| d.take(size as u64 + 1).read_to_end(chunk)),
        "lz4" => lz4_flex::frame::FrameDecoder::new(data)
            .take(size as u64 + 1)
            .read_to_end(chunk),
        other => {
            return Err(Corrupt::new(
                at,
                format!("chunk compression '{other}' is not one of none, zstd, lz4"),
            ));
        }
    };
    if let Err(e) = res {
        return Err(Corrupt::new(at, format!("broken {compression} chunk: {e}")));
    }
    if chunk.len() != size {
        return Err(Corrupt::new(
            at,
            format!(
                "{compression} chunk decompresses to {} bytes but its header says {size}",
                chunk.len()
            ),
        ));
    }
    Ok(())
}

/// The records of a decompressed chunk (found at `at`) that a scan needs.
fn chunk_records(
    chunk: &[u8],
    at: u64,
    state: &mut State,
    summary: &mut McapSummary,
    f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
) -> Result<(), Corrupt> {
    let inner = Bytes::new(chunk, Endian::Little);
    let mut p = 0;
    while p < inner.len() {
        let (op, body, next) = record_at(&inner, p)
            .map_err(|e| Corrupt::new(at, format!("inside the chunk: {}", e.what)))?;
        if NEEDED.contains(&op) {
            let r = ::mcap::parse_record(op, body).map_err(|e| {
                Corrupt::new(
                    at,
                    format!("inside the chunk, record (opcode 0x{op:02x}): {e}"),
                )
            })?;
            state.record(r, at, summary, f)?;
        }
        p = next;
    }
    Ok(())
}

/// [`for_each_message`] reading from a file (or anything seekable) a record at a time: memory
/// stays at one chunk, whatever the file's size. Records a scan does not need are skipped unread.
pub fn for_each_message_in<R: Read + Seek + ?Sized>(
    r: &mut R,
    f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
) -> Result<McapSummary, Corrupt> {
    let len = check_magic(r)?;
    let mut state = State::default();
    let mut summary = McapSummary {
        unfinished: true,
        ..Default::default()
    };
    let mut pos = MAGIC.len() as u64;
    let mut chunk = Vec::new();
    let mut body = Vec::new();
    while pos < len {
        let at = pos;
        let (op, blen) = record_header(r, at, len)?;
        pos = at + 9 + blen;
        if op == 0x02 {
            summary.unfinished = false;
            break;
        }
        if !NEEDED.contains(&op) {
            continue;
        }
        if blen > MAX_CHUNK_BYTES as u64 {
            return Err(Corrupt::new(
                at,
                format!(
                    "record (opcode 0x{op:02x}) of {blen} bytes (more than the {MAX_CHUNK_BYTES} accepted)"
                ),
            ));
        }
        body.clear();
        body.resize(blen as usize, 0);
        r.read_exact(&mut body).map_err(|e| io_error(at + 9, &e))?;
        let rec = ::mcap::parse_record(op, &body)
            .map_err(|e| Corrupt::new(at, format!("MCAP record (opcode 0x{op:02x}): {e}")))?;
        if let Record::Chunk { header, data } = rec {
            summary.chunks += 1;
            decompress_chunk(&header, &data, at, &mut chunk)?;
            chunk_records(&chunk, at, &mut state, &mut summary, f)?;
        } else {
            state.record(rec, at, &mut summary, f)?;
        }
    }
    Ok(summary)
}

/// Writes an MCAP file of CDR messages (for tests and round trips).
pub struct McapWriter {
    w: ::mcap::Writer<std::io::Cursor<Vec<u8>>>,
    channels: HashMap<String, u16>,
}

impl McapWriter {
    /// A writer whose chunks are compressed by `compression` (zstd, LZ4) or stored.
    pub fn new(
        compression: Option<::mcap::Compression>,
        chunk_size: u64,
    ) -> Result<Self, ::mcap::McapError> {
        let w = ::mcap::WriteOptions::new()
            .compression(compression)
            .chunk_size(Some(chunk_size))
            .profile("ros2")
            .create(std::io::Cursor::new(Vec::new()))?;
        Ok(Self {
            w,
            channels: HashMap::new(),
        })
    }

    /// Adds a CDR message.
    pub fn write(
        &mut self,
        topic: &str,
        datatype: &str,
        time: f64,
        data: &[u8],
    ) -> Result<(), ::mcap::McapError> {
        let id = match self.channels.get(topic) {
            Some(&id) => id,
            None => {
                let s = self.w.add_schema(datatype, "ros2msg", b"")?;
                let id = self.w.add_channel(s, topic, "cdr", &Default::default())?;
                self.channels.insert(topic.to_string(), id);
                id
            }
        };
        let ns = (time * 1e9).round() as u64;
        self.w.write_to_known_channel(
            &::mcap::records::MessageHeader {
                channel_id: id,
                sequence: 0,
                log_time: ns,
                publish_time: ns,
            },
            data,
        )
    }

    /// The file's bytes.
    pub fn finish(mut self) -> Result<Vec<u8>, ::mcap::McapError> {
        self.w.finish()?;
        Ok(self.w.into_inner().into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_compressed_and_not_and_cut_files_are_errors() {
        for c in [
            None,
            Some(::mcap::Compression::Zstd),
            Some(::mcap::Compression::Lz4),
        ] {
            let mut w = McapWriter::new(c, 300).unwrap();
            for i in 0..30 {
                let data = vec![0u8, 1, 0, 0, i as u8, 7, 7, 7];
                w.write(
                    if i % 3 == 0 { "/x" } else { "/y" },
                    "std_msgs/msg/String",
                    5.0 + i as f64,
                    &data,
                )
                .unwrap();
            }
            let file = w.finish().unwrap();
            let mut got = Vec::new();
            let s = for_each_message(&file, &mut |m| {
                got.push((m.topic.to_string(), m.time, m.data[4], m.wire));
                Ok(())
            })
            .unwrap();
            assert!(!s.unfinished, "{c:?}");
            assert_eq!(got.len(), 30);
            assert_eq!(got[4], ("/y".to_string(), 9.0, 4, Wire::Cdr));
            for cut in (0..file.len()).step_by(53) {
                match for_each_message(&file[..cut], &mut |_| Ok(())) {
                    Err(_) => {}
                    Ok(s) => assert!(s.unfinished, "{c:?} cut at {cut}"),
                }
            }
        }
    }

    #[test]
    fn a_record_inside_a_chunk_claiming_terabytes_is_an_error_not_an_abort() {
        // Found by fuzzing: mcap's ChunkReader reserved the claimed length.
        let mut w = McapWriter::new(None, 1 << 20).unwrap();
        w.write("/x", "std_msgs/msg/String", 1.0, &[0, 1, 0, 0, 9])
            .unwrap();
        let mut file = w.finish().unwrap();
        let mut pos = MAGIC.len();
        let chunk = loop {
            let len = u64::from_le_bytes(file[pos + 1..pos + 9].try_into().unwrap()) as usize;
            if file[pos] == 0x06 {
                break pos;
            }
            pos += 9 + len;
        };
        // Chunk body: start, end, size, crc, compression "", records length, then the records.
        let first = chunk + 9 + 8 + 8 + 8 + 4 + 4 + 8;
        file[first + 1..first + 9].copy_from_slice(&(3u64 << 40).to_le_bytes());
        let e = for_each_message(&file, &mut |_| Ok(())).unwrap_err();
        assert_eq!(e.offset, chunk as u64, "{e}");
        assert!(e.what.contains("inside the chunk"), "{e}");
    }

    #[test]
    fn a_short_attachment_record_is_skipped_not_a_panic() {
        // Found by fuzzing: mcap::parse_record slices past the end of a short attachment.
        let mut w = McapWriter::new(None, 1 << 20).unwrap();
        w.write("/x", "std_msgs/msg/String", 1.0, &[0, 1, 0, 0, 9])
            .unwrap();
        let file = w.finish().unwrap();
        let mut bad = file[..MAGIC.len()].to_vec();
        bad.push(0x09);
        // Times, two empty strings and a data length: 32 bytes, then one more (no room for the CRC).
        bad.extend_from_slice(&33u64.to_le_bytes());
        bad.extend_from_slice(&[0u8; 33]);
        bad.extend_from_slice(&file[MAGIC.len()..]);
        let s = for_each_message(&bad, &mut |_| Ok(())).unwrap();
        assert_eq!(s.messages, 1);
    }
}
