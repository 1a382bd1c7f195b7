//! ROS 1 bags (format 2.0, as `rosbag record` and the RealSense SDK write them): reading from
//! memory with chunk decompression (bz2, lz4), and a writer for tests and conversions.
//!
//! Written here rather than with the `rosbag` crate because that crate only memory-maps paths
//! (no fuzzing from bytes), reports no byte offsets, and reserves a chunk's claimed decompressed
//! size before checking it. Here every record length is checked against the bytes left, a
//! chunk's decompressed size is capped ([`MAX_CHUNK_BYTES`]) and filled as data arrives, and each
//! error names the byte offset of the record at fault.

use std::collections::HashMap;
use std::io::{Read, Seek, SeekFrom};

use super::msg::{Message, Wire};
use mrtmap_io::bytes::{Bytes, Corrupt, Endian};

/// The bag magic line.
pub const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
/// Largest decompressed chunk accepted (ROS's default chunk is 768 KiB).
pub const MAX_CHUNK_BYTES: usize = 512 << 20;

const OP_MSG: u8 = 0x02;
const OP_HEADER: u8 = 0x03;
const OP_INDEX: u8 = 0x04;
const OP_CHUNK: u8 = 0x05;
const OP_CHUNK_INFO: u8 = 0x06;
const OP_CONN: u8 = 0x07;

/// A connection (topic and type).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Connection {
    /// Topic.
    pub topic: String,
    /// Type.
    pub datatype: String,
}

struct Record<'a> {
    op: u8,
    fields: Vec<(&'a str, &'a [u8])>,
    data: Bytes<'a>,
    /// Offset of the record in its buffer's file coordinates.
    at: u64,
}

impl Record<'_> {
    fn field(&self, name: &str) -> Option<&[u8]> {
        self.fields
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| *v)
    }

    fn u32_field(&self, name: &str) -> Result<u32, Corrupt> {
        match self.field(name) {
            Some(v) if v.len() == 4 => Ok(u32::from_le_bytes([v[0], v[1], v[2], v[3]])),
            _ => Err(Corrupt::new(
                self.at,
                format!(
                    "record (op 0x{:02x}) lacks a 4-byte '{name}' field",
                    self.op
                ),
            )),
        }
    }

    fn str_field(&self, name: &str) -> Result<&str, Corrupt> {
        self.field(name)
            .and_then(|v| std::str::from_utf8(v).ok())
            .ok_or_else(|| {
                Corrupt::new(
                    self.at,
                    format!("record (op 0x{:02x}) lacks a text '{name}' field", self.op),
                )
            })
    }
}

/// Reads the record at `pos`; returns it and the position after it.
fn record<'a>(b: &Bytes<'a>, pos: usize) -> Result<(Record<'a>, usize), Corrupt> {
    let hlen = b.u32(pos, "a record header length")? as usize;
    let header = b.sub(pos + 4, hlen, "a record header")?;
    let dpos = pos + 4 + hlen;
    let dlen = b.u32(dpos, "a record data length")? as usize;
    let data = b.sub(dpos + 4, dlen, "a record's data")?;
    let mut fields = Vec::new();
    let mut p = 0;
    while p < header.len() {
        let flen = header.u32(p, "a header field length")? as usize;
        let f = header.slice(p + 4, flen, "a header field")?;
        let eq = f
            .iter()
            .position(|&c| c == b'=')
            .ok_or_else(|| header.err(p + 4, "a header field without '='"))?;
        let name = std::str::from_utf8(&f[..eq])
            .map_err(|_| header.err(p + 4, "a header field name that is not text"))?;
        fields.push((name, &f[eq + 1..]));
        p += 4 + flen;
    }
    let op = match fields.iter().find(|(n, _)| *n == "op") {
        Some((_, v)) if v.len() == 1 => v[0],
        _ => return Err(b.err(pos, "a record without a one-byte 'op' field")),
    };
    Ok((
        Record {
            op,
            fields,
            data,
            at: b.base + pos as u64,
        },
        dpos + 4 + dlen,
    ))
}

fn connection(r: &Record<'_>) -> Result<(u32, Connection), Corrupt> {
    let id = r.u32_field("conn")?;
    let topic = r.str_field("topic")?.to_string();
    // The data is a connection header of its own: type=…, md5sum=…, message_definition=…
    let mut datatype = String::new();
    let mut p = 0;
    while p < r.data.len() {
        let flen = r.data.u32(p, "a connection field length")? as usize;
        let f = r.data.slice(p + 4, flen, "a connection field")?;
        if let Some(t) = f.strip_prefix(b"type=") {
            datatype = String::from_utf8_lossy(t).into_owned();
        }
        p += 4 + flen;
    }
    if datatype.is_empty() {
        return Err(Corrupt::new(
            r.at,
            format!("connection {id} ({topic}) has no message type"),
        ));
    }
    Ok((id, Connection { topic, datatype }))
}

/// The output buffer, reused from chunk to chunk: allocating (and zeroing) it afresh for each
/// chunk cost more than decompressing it. Each LZ4 chunk gets a decoder of its own: one reused
/// across frames of different block sizes broke lz4_flex's own assertion (a bag whose chunks
/// came out with 4 MB and 256 KB blocks panicked in a debug build).
#[derive(Default)]
struct Buffers {
    out: Vec<u8>,
}

/// Decompresses a chunk into `bufs.out`.
fn decompress(r: &Record<'_>, bufs: &mut Buffers) -> Result<(), Corrupt> {
    let out = &mut bufs.out;
    let size = r.u32_field("size")? as usize;
    let compression = r.str_field("compression")?;
    if size > MAX_CHUNK_BYTES {
        return Err(Corrupt::new(
            r.at,
            format!(
                "chunk claims {size} bytes decompressed (more than the {MAX_CHUNK_BYTES} accepted)"
            ),
        ));
    }
    let src = r.data.data;
    out.clear();
    out.reserve(size.min(16 << 20));
    let res = match compression {
        "none" => {
            out.extend_from_slice(src);
            Ok(src.len())
        }
        "bz2" => bzip2::read::BzDecoder::new(src)
            .take(size as u64 + 1)
            .read_to_end(out),
        "lz4" => lz4_flex::frame::FrameDecoder::new(src)
            .take(size as u64 + 1)
            .read_to_end(out),
        other => {
            return Err(Corrupt::new(
                r.at,
                format!("chunk compression '{other}' is not one of none, bz2, lz4"),
            ));
        }
    };
    if let Err(e) = res {
        return Err(Corrupt::new(
            r.data.base,
            format!("broken {compression} chunk: {e}"),
        ));
    }
    if out.len() != size {
        return Err(Corrupt::new(
            r.data.base,
            format!(
                "{compression} chunk decompresses to {} bytes but its header says {size}",
                out.len()
            ),
        ));
    }
    Ok(())
}

/// What a pass over a bag found besides its messages.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BagSummary {
    /// Chunks read.
    pub chunks: usize,
    /// Messages delivered.
    pub messages: usize,
    /// The header's index position lies beyond the end, or is 0 (a recording that was cut or
    /// never closed, e.g. `.bag.active`): what was read is all there is.
    pub unindexed: bool,
}

/// Largest record header accepted (headers hold a few short fields).
const MAX_HEADER_BYTES: usize = 1 << 20;

fn io_err(at: u64, e: &std::io::Error) -> Corrupt {
    Corrupt::new(at, format!("cannot read: {e}"))
}

/// The op of a record header (its fields, unparsed otherwise).
fn header_op(h: &[u8]) -> Option<u8> {
    let mut p = 0;
    while p + 4 <= h.len() {
        let n = u32::from_le_bytes([h[p], h[p + 1], h[p + 2], h[p + 3]]) as usize;
        let f = h.get(p + 4..p + 4 + n)?;
        if let Some(v) = f.strip_prefix(b"op=") {
            return (v.len() == 1).then(|| v[0]);
        }
        p += 4 + n;
    }
    None
}

/// Reads the top-level record at `pos` into `buf` in file layout (its data only when `want`
/// says so; otherwise with an empty data part) and returns (op, position after it).
fn read_record<R: Read + Seek + ?Sized>(
    r: &mut R,
    len: u64,
    pos: u64,
    buf: &mut Vec<u8>,
    want: fn(u8) -> bool,
) -> Result<(u8, u64), Corrupt> {
    let left = |at: u64| len.saturating_sub(at);
    let need = |at: u64, n: u64, what: &str| {
        if n > left(at) {
            Err(Corrupt::new(
                at,
                format!(
                    "{what} needs {n} bytes but only {} are left (file cut short?)",
                    left(at)
                ),
            ))
        } else {
            Ok(())
        }
    };
    need(pos, 4, "a record header length")?;
    r.seek(SeekFrom::Start(pos)).map_err(|e| io_err(pos, &e))?;
    let mut n4 = [0u8; 4];
    r.read_exact(&mut n4).map_err(|e| io_err(pos, &e))?;
    let hlen = u32::from_le_bytes(n4) as u64;
    need(pos + 4, hlen, "a record header")?;
    if hlen as usize > MAX_HEADER_BYTES {
        return Err(Corrupt::new(
            pos,
            format!("record header of {hlen} bytes (more than 1 MiB)"),
        ));
    }
    buf.clear();
    buf.extend_from_slice(&n4);
    buf.resize(4 + hlen as usize, 0);
    r.read_exact(&mut buf[4..])
        .map_err(|e| io_err(pos + 4, &e))?;
    let dpos = pos + 4 + hlen;
    need(dpos, 4, "a record data length")?;
    r.read_exact(&mut n4).map_err(|e| io_err(dpos, &e))?;
    let dlen = u32::from_le_bytes(n4) as u64;
    need(dpos + 4, dlen, "a record's data")?;
    let op = header_op(&buf[4..])
        .ok_or_else(|| Corrupt::new(pos, "a record without a one-byte 'op' field"))?;
    if want(op) {
        if dlen as usize > MAX_CHUNK_BYTES {
            return Err(Corrupt::new(
                dpos,
                format!("record data of {dlen} bytes (more than the {MAX_CHUNK_BYTES} accepted)"),
            ));
        }
        buf.extend_from_slice(&n4);
        let at = buf.len();
        buf.resize(at + dlen as usize, 0);
        r.read_exact(&mut buf[at..])
            .map_err(|e| io_err(dpos + 4, &e))?;
    } else {
        buf.extend_from_slice(&0u32.to_le_bytes());
    }
    Ok((op, dpos + 4 + dlen))
}

/// Calls `f` for every message of a bag, in file order (chunks decompressed one at a time).
pub fn for_each_message(
    file: &[u8],
    f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
) -> Result<BagSummary, Corrupt> {
    for_each_message_in(&mut std::io::Cursor::new(file), f)
}

/// The bag's length after checking its magic line.
fn check_magic<R: Read + Seek + ?Sized>(r: &mut R) -> Result<u64, Corrupt> {
    let len = r.seek(SeekFrom::End(0)).map_err(|e| io_err(0, &e))?;
    let mut magic = [0u8; 13];
    r.seek(SeekFrom::Start(0)).map_err(|e| io_err(0, &e))?;
    if len < MAGIC.len() as u64 || r.read_exact(&mut magic).is_err() || magic != MAGIC {
        return Err(Corrupt::new(
            0,
            "not a ROS 1 bag (no \"#ROSBAG V2.0\" line)",
        ));
    }
    Ok(len)
}

/// The record held in `buf`, read at file offset `at`.
fn record_at(buf: &[u8], at: u64) -> Result<Record<'_>, Corrupt> {
    let bytes = Bytes {
        data: buf,
        base: at,
        endian: Endian::Little,
    };
    Ok(record(&bytes, 0)?.0)
}

/// A message's time field.
fn message_time(r: &Record<'_>) -> Result<f64, Corrupt> {
    match r.field("time") {
        Some(v) if v.len() == 8 => Ok(u32::from_le_bytes([v[0], v[1], v[2], v[3]]) as f64
            + u32::from_le_bytes([v[4], v[5], v[6], v[7]]) as f64 * 1e-9),
        _ => Err(Corrupt::new(r.at, "message record without an 8-byte time")),
    }
}

/// A connection record defines a connection; a message record is passed to `f` (its errors
/// naming `offset`).
fn handle_record(
    r: &Record<'_>,
    conns: &mut HashMap<u32, Connection>,
    offset: u64,
    f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
) -> Result<(), Corrupt> {
    match r.op {
        OP_CONN => {
            let (id, c) = connection(r)?;
            conns.insert(id, c);
        }
        OP_MSG => {
            let id = r.u32_field("conn")?;
            let t = message_time(r)?;
            let c = conns.get(&id).ok_or_else(|| {
                Corrupt::new(
                    r.at,
                    format!("message on connection {id}, which no record defines"),
                )
            })?;
            f(Message {
                topic: &c.topic,
                datatype: &c.datatype,
                time: t,
                data: r.data.data,
                wire: Wire::Ros1,
                offset,
                record: None,
            })?;
        }
        _ => {}
    }
    Ok(())
}

/// The header record: where the index section starts, and where the records after it start.
fn read_header<R: Read + Seek + ?Sized>(
    r: &mut R,
    len: u64,
    buf: &mut Vec<u8>,
) -> Result<(u64, u64), Corrupt> {
    let first = MAGIC.len() as u64;
    let (op, pos) = read_record(r, len, first, buf, |_| false)?;
    if op != OP_HEADER {
        return Err(Corrupt::new(first, "the bag has no header record"));
    }
    let h = record_at(buf, first)?;
    match h.field("index_pos") {
        Some(v) if v.len() == 8 => Ok((
            u64::from_le_bytes([v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]]),
            pos,
        )),
        _ => Err(Corrupt::new(
            first,
            "bag header without an 8-byte index_pos",
        )),
    }
}

/// Connections from the index section, so that messages can be named even in chunks that do not
/// repeat them.
fn index_connections<R: Read + Seek + ?Sized>(
    r: &mut R,
    (index_pos, len): (u64, u64),
    buf: &mut Vec<u8>,
    conns: &mut HashMap<u32, Connection>,
) -> Result<(), Corrupt> {
    let mut p = index_pos;
    while p < len {
        let (op, next) = read_record(r, len, p, buf, |op| op == OP_CONN)?;
        if op == OP_CONN {
            let (id, c) = connection(&record_at(buf, p)?)?;
            conns.insert(id, c);
        }
        p = next;
    }
    Ok(())
}

/// The records of a chunk, decompressed into `bufs`: offsets inside a compressed chunk do not
/// exist in the file, so its messages name the chunk.
fn chunk_records(
    rec: &Record<'_>,
    bufs: &mut Buffers,
    conns: &mut HashMap<u32, Connection>,
    f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
) -> Result<(), Corrupt> {
    decompress(rec, bufs)?;
    let compressed = rec.field("compression") != Some(b"none".as_slice());
    let inner = Bytes {
        data: &bufs.out,
        base: if compressed { rec.at } else { rec.data.base },
        endian: Endian::Little,
    };
    let mut p = 0;
    while p < inner.len() {
        let (m, next) = record(&inner, p).map_err(|e| {
            if compressed {
                Corrupt::new(rec.at, format!("inside the compressed chunk: {}", e.what))
            } else {
                e
            }
        })?;
        let off = if compressed { rec.at } else { m.data.base };
        handle_record(&m, conns, off, f)?;
        p = next;
    }
    Ok(())
}

/// [`for_each_message`] reading from a file (or anything seekable), a record at a time: memory
/// stays at one chunk, whatever the bag's size.
pub fn for_each_message_in<R: Read + Seek + ?Sized>(
    r: &mut R,
    f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
) -> Result<BagSummary, Corrupt> {
    let len = check_magic(r)?;
    let mut conns: HashMap<u32, Connection> = HashMap::new();
    let mut buf = Vec::new();
    let mut summary = BagSummary::default();
    let mut bufs = Buffers::default();
    let mut count = |m: Message<'_>| {
        summary.messages += 1;
        f(m)
    };
    let f = &mut count;
    let (index_pos, mut pos) = read_header(r, len, &mut buf)?;
    let unindexed = index_pos <= MAGIC.len() as u64 || index_pos >= len;
    if !unindexed {
        index_connections(r, (index_pos, len), &mut buf, &mut conns)?;
    }
    let end = if unindexed { len } else { index_pos };
    let mut chunks = 0;
    while pos < end {
        let at = pos;
        let (op, next) = read_record(r, len, at, &mut buf, |op| {
            matches!(op, OP_CHUNK | OP_MSG | OP_CONN)
        })?;
        pos = next;
        let rec = record_at(&buf, at)?;
        match op {
            OP_CHUNK => {
                chunks += 1;
                chunk_records(&rec, &mut bufs, &mut conns, f)?;
            }
            OP_MSG | OP_CONN => handle_record(&rec, &mut conns, rec.data.base, f)?,
            OP_INDEX | OP_CHUNK_INFO => {}
            op => {
                return Err(Corrupt::new(at, format!("unknown record op 0x{op:02x}")));
            }
        }
    }
    summary.chunks = chunks;
    summary.unindexed = unindexed;
    Ok(summary)
}

/// Chunk compression for [`BagWriter`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compression {
    /// Stored.
    None,
    /// bzip2.
    Bz2,
    /// LZ4 frames.
    Lz4,
}

/// (chunk position, first time, last time, (connection, count) pairs).
type ChunkInfo = (u64, f64, f64, Vec<(u32, u32)>);

/// Writes ROS 1 bags: chunks with their index records, then connections and chunk infos.
pub struct BagWriter {
    out: Vec<u8>,
    compression: Compression,
    chunk_bytes: usize,
    conns: Vec<(String, String)>,
    chunk: Vec<u8>,
    chunk_index: Vec<(u32, f64, u32)>,
    chunk_conns_defined: Vec<u32>,
    chunk_infos: Vec<ChunkInfo>,
    /// The first error compressing a chunk, reported by `finish`.
    error: Option<std::io::Error>,
}

/// A chunk's bytes compressed as `c`, with the compression's name in the bag.
fn compress_chunk(c: Compression, chunk: &[u8]) -> std::io::Result<(&'static str, Vec<u8>)> {
    use std::io::Write;
    Ok(match c {
        Compression::None => ("none", chunk.to_vec()),
        Compression::Bz2 => {
            let mut e = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::default());
            e.write_all(chunk)?;
            ("bz2", e.finish()?)
        }
        Compression::Lz4 => {
            let mut e = lz4_flex::frame::FrameEncoder::new(Vec::new());
            e.write_all(chunk)?;
            ("lz4", e.finish().map_err(std::io::Error::other)?)
        }
    })
}

fn field(out: &mut Vec<u8>, name: &str, value: &[u8]) {
    out.extend_from_slice(&((name.len() + 1 + value.len()) as u32).to_le_bytes());
    out.extend_from_slice(name.as_bytes());
    out.push(b'=');
    out.extend_from_slice(value);
}

fn time_bytes(t: f64) -> [u8; 8] {
    let s = t.floor();
    let ns = ((t - s) * 1e9).round().min(999_999_999.0) as u32;
    let mut b = [0u8; 8];
    b[..4].copy_from_slice(&(s as u32).to_le_bytes());
    b[4..].copy_from_slice(&ns.to_le_bytes());
    b
}

fn write_record(out: &mut Vec<u8>, fields: &[(&str, &[u8])], data: &[u8]) {
    let mut h = Vec::new();
    for (n, v) in fields {
        field(&mut h, n, v);
    }
    out.extend_from_slice(&(h.len() as u32).to_le_bytes());
    out.extend_from_slice(&h);
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
}

impl BagWriter {
    /// A bag whose chunks hold about `chunk_bytes` each.
    pub fn new(compression: Compression, chunk_bytes: usize) -> Self {
        let mut out = MAGIC.to_vec();
        // The header record is rewritten in finish(); reserve ROS's 4096 bytes for it.
        out.resize(MAGIC.len() + 4096, b' ');
        Self {
            out,
            compression,
            chunk_bytes,
            conns: Vec::new(),
            chunk: Vec::new(),
            chunk_index: Vec::new(),
            chunk_conns_defined: Vec::new(),
            chunk_infos: Vec::new(),
            error: None,
        }
    }

    fn conn_record(out: &mut Vec<u8>, id: u32, topic: &str, datatype: &str) {
        let mut data = Vec::new();
        field(&mut data, "topic", topic.as_bytes());
        field(&mut data, "type", datatype.as_bytes());
        field(&mut data, "md5sum", b"*");
        field(&mut data, "message_definition", b"");
        write_record(
            out,
            &[
                ("op", &[OP_CONN]),
                ("conn", &id.to_le_bytes()),
                ("topic", topic.as_bytes()),
            ],
            &data,
        );
    }

    /// Adds a message.
    pub fn write(&mut self, topic: &str, datatype: &str, time: f64, data: &[u8]) {
        let id = match self.conns.iter().position(|(t, _)| t == topic) {
            Some(i) => i as u32,
            None => {
                self.conns.push((topic.to_string(), datatype.to_string()));
                (self.conns.len() - 1) as u32
            }
        };
        if !self.chunk_conns_defined.contains(&id) {
            Self::conn_record(&mut self.chunk, id, topic, datatype);
            self.chunk_conns_defined.push(id);
        }
        let offset = self.chunk.len() as u32;
        write_record(
            &mut self.chunk,
            &[
                ("op", &[OP_MSG]),
                ("conn", &id.to_le_bytes()),
                ("time", &time_bytes(time)),
            ],
            data,
        );
        self.chunk_index.push((id, time, offset));
        if self.chunk.len() >= self.chunk_bytes {
            self.flush_chunk();
        }
    }

    fn flush_chunk(&mut self) {
        if self.chunk_index.is_empty() {
            return;
        }
        let (name, data) = match compress_chunk(self.compression, &self.chunk) {
            Ok(c) => c,
            Err(e) => {
                self.error.get_or_insert(e);
                return;
            }
        };
        let chunk_pos = self.out.len() as u64;
        write_record(
            &mut self.out,
            &[
                ("op", &[OP_CHUNK]),
                ("compression", name.as_bytes()),
                ("size", &(self.chunk.len() as u32).to_le_bytes()),
            ],
            &data,
        );
        let mut per_conn: Vec<(u32, Vec<(f64, u32)>)> = Vec::new();
        for &(id, t, off) in &self.chunk_index {
            match per_conn.iter_mut().find(|(c, _)| *c == id) {
                Some((_, v)) => v.push((t, off)),
                None => per_conn.push((id, vec![(t, off)])),
            }
        }
        for (id, entries) in &per_conn {
            let mut d = Vec::new();
            for (t, off) in entries {
                d.extend_from_slice(&time_bytes(*t));
                d.extend_from_slice(&off.to_le_bytes());
            }
            write_record(
                &mut self.out,
                &[
                    ("op", &[OP_INDEX]),
                    ("ver", &1u32.to_le_bytes()),
                    ("conn", &id.to_le_bytes()),
                    ("count", &(entries.len() as u32).to_le_bytes()),
                ],
                &d,
            );
        }
        let t0 = self
            .chunk_index
            .iter()
            .map(|e| e.1)
            .fold(f64::INFINITY, f64::min);
        let t1 = self
            .chunk_index
            .iter()
            .map(|e| e.1)
            .fold(f64::NEG_INFINITY, f64::max);
        self.chunk_infos.push((
            chunk_pos,
            t0,
            t1,
            per_conn.iter().map(|(c, v)| (*c, v.len() as u32)).collect(),
        ));
        self.chunk.clear();
        self.chunk_index.clear();
        self.chunk_conns_defined.clear();
    }

    /// The bag's bytes, or the first error compressing a chunk.
    pub fn finish(mut self) -> std::io::Result<Vec<u8>> {
        self.flush_chunk();
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let index_pos = self.out.len() as u64;
        let conns = std::mem::take(&mut self.conns);
        for (i, (topic, datatype)) in conns.iter().enumerate() {
            Self::conn_record(&mut self.out, i as u32, topic, datatype);
        }
        for (pos, t0, t1, counts) in &self.chunk_infos {
            let mut d = Vec::new();
            for (c, n) in counts {
                d.extend_from_slice(&c.to_le_bytes());
                d.extend_from_slice(&n.to_le_bytes());
            }
            write_record(
                &mut self.out,
                &[
                    ("op", &[OP_CHUNK_INFO]),
                    ("ver", &1u32.to_le_bytes()),
                    ("chunk_pos", &pos.to_le_bytes()),
                    ("start_time", &time_bytes(*t0)),
                    ("end_time", &time_bytes(*t1)),
                    ("count", &(counts.len() as u32).to_le_bytes()),
                ],
                &d,
            );
        }
        let mut header = Vec::new();
        let mut fields = Vec::new();
        field(&mut fields, "op", &[OP_HEADER]);
        field(&mut fields, "index_pos", &index_pos.to_le_bytes());
        field(
            &mut fields,
            "conn_count",
            &(conns.len() as u32).to_le_bytes(),
        );
        field(
            &mut fields,
            "chunk_count",
            &(self.chunk_infos.len() as u32).to_le_bytes(),
        );
        header.extend_from_slice(&(fields.len() as u32).to_le_bytes());
        header.extend_from_slice(&fields);
        let pad = 4096 - header.len() - 4;
        header.extend_from_slice(&(pad as u32).to_le_bytes());
        header.resize(4096, b' ');
        self.out[MAGIC.len()..MAGIC.len() + 4096].copy_from_slice(&header);
        Ok(self.out)
    }
}

/// The wire format of bag messages.
pub const WIRE: Wire = Wire::Ros1;

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(c: Compression) -> Vec<u8> {
        let mut w = BagWriter::new(c, 200);
        for i in 0..20 {
            let topic = if i % 2 == 0 { "/a" } else { "/b" };
            w.write(
                topic,
                "std_msgs/String",
                10.0 + i as f64 * 0.1,
                &[i as u8; 50],
            );
        }
        w.finish().unwrap()
    }

    #[test]
    fn round_trips_with_every_compression() {
        for c in [Compression::None, Compression::Bz2, Compression::Lz4] {
            let bag = sample(c);
            let mut got = Vec::new();
            for_each_message(&bag, &mut |m| {
                got.push((m.topic.to_string(), m.time, m.data.to_vec()));
                Ok(())
            })
            .unwrap();
            assert_eq!(got.len(), 20, "{c:?}");
            assert_eq!(got[3].0, "/b");
            assert!((got[3].1 - 10.3).abs() < 1e-6);
            assert_eq!(got[3].2, vec![3u8; 50]);
        }
    }

    #[test]
    fn cut_and_corrupt_bags_are_errors() {
        for c in [Compression::None, Compression::Bz2, Compression::Lz4] {
            let bag = sample(c);
            let full = for_each_message(&bag, &mut |_| Ok(())).unwrap();
            assert!(!full.unindexed);
            assert_eq!(full.messages, 20);
            for cut in (0..bag.len()).step_by(97) {
                // Cut mid-record: an error; between records: what is there, flagged unless complete.
                match for_each_message(&bag[..cut], &mut |_| Ok(())) {
                    Err(_) => {}
                    Ok(s) => assert!(s.unindexed || s.messages == 20, "{c:?} cut at {cut}"),
                }
            }
            let mut bad = bag.clone();
            // Corrupt the first chunk's payload.
            let at = MAGIC.len() + 4096 + 80;
            for b in &mut bad[at..at + 16] {
                *b ^= 0x5a;
            }
            let r = for_each_message(&bad, &mut |_| Ok(()));
            if c != Compression::None {
                assert!(r.is_err(), "{c:?}");
            }
        }
    }
}
