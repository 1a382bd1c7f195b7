//! ROS 2 bags in SQLite storage (`.db3`, rosbag2's default up to Iron): a `topics` table (name,
//! type, serialization format) and a `messages` table (topic id, timestamp in ns, CDR data), read
//! here with the bundled SQLite. Schemas from Foxy (no `schema` table) to Jazzy (`schema` 4 with a
//! type hash) share those columns, which is all a scan needs. Messages compressed one by one
//! (`compression_mode: message`, zstd) are decompressed; whole-file compressed bags
//! (`.db3.zstd`) are refused with the reason.
//!
//! [`Db3Writer`] writes the Humble layout (schema 3) for tests and `mrtmap convert`.

use std::path::Path;

use rusqlite::{Connection, MAIN_DB, OpenFlags};

use super::msg::{Message, Wire};
use mrtmap_io::bytes::Corrupt;

const ZSTD_MAGIC: [u8; 4] = [0x28, 0xB5, 0x2F, 0xFD];
/// A decompressed message may not exceed what a bag chunk may (512 MiB).
const MAX_MESSAGE_BYTES: usize = super::bag::MAX_CHUNK_BYTES;

fn sql(e: &rusqlite::Error) -> Corrupt {
    Corrupt::new(0, format!("SQLite: {e}"))
}

/// A message as stored, or inflated into `buf` when rosbag2 compressed it on its own
/// (`compression_mode: message`, zstd; a CDR message never starts with zstd's magic).
pub fn inflate<'a>(data: &'a [u8], buf: &'a mut Vec<u8>) -> Result<&'a [u8], InflateError> {
    if !data.starts_with(&ZSTD_MAGIC) {
        return Ok(data);
    }
    buf.clear();
    let mut d = zstd::stream::read::Decoder::new(data)?;
    let mut lim = std::io::Read::take(&mut d, MAX_MESSAGE_BYTES as u64 + 1);
    std::io::Read::read_to_end(&mut lim, buf)?;
    if buf.len() > MAX_MESSAGE_BYTES {
        return Err(InflateError::TooLarge);
    }
    Ok(&buf[..])
}

/// A zstd-compressed message that does not inflate.
#[derive(Debug, thiserror::Error)]
pub enum InflateError {
    /// The zstd stream is broken.
    #[error("zstd-compressed message: {0}")]
    Zstd(#[from] std::io::Error),
    /// It inflates past the size cap.
    #[error("zstd-compressed message inflates past {MAX_MESSAGE_BYTES} bytes")]
    TooLarge,
}

/// Whether an open SQLite database has rosbag2's `topics` and `messages` tables.
pub fn is_rosbag2(c: &Connection) -> bool {
    let has = |t: &str| {
        c.query_row(
            "SELECT count(*) FROM sqlite_master WHERE type='table' AND name=?1",
            [t],
            |r| r.get::<_, i64>(0),
        )
        .is_ok_and(|n| n > 0)
    };
    has("topics") && has("messages")
}

/// Opens a `.db3` file read-only.
pub fn open_file(path: &Path) -> Result<Connection, Corrupt> {
    Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(|e| sql(&e))
}

/// Opens a `.db3` file held in memory (read-only).
pub fn open_bytes(bytes: &[u8]) -> Result<Connection, Corrupt> {
    let mut c = Connection::open_in_memory().map_err(|e| sql(&e))?;
    c.deserialize_read_exact(MAIN_DB, bytes, bytes.len(), true)
        .map_err(|e| sql(&e))?;
    Ok(c)
}

/// Calls `f` with every message in timestamp order (ties in insertion order). Topics whose
/// serialization format is not CDR are skipped; a message whose topic is not in `topics` is an
/// error naming its row id.
pub fn for_each_message(
    c: &Connection,
    f: &mut dyn FnMut(Message<'_>) -> Result<(), Corrupt>,
) -> Result<usize, Corrupt> {
    if !is_rosbag2(c) {
        return Err(Corrupt::new(
            0,
            "an SQLite file without rosbag2's topics and messages tables",
        ));
    }
    let mut topics = std::collections::HashMap::new();
    {
        let mut st = c
            .prepare("SELECT id, name, type, serialization_format FROM topics")
            .map_err(|e| sql(&e))?;
        let mut rows = st.query([]).map_err(|e| sql(&e))?;
        while let Some(r) = rows.next().map_err(|e| sql(&e))? {
            let id: i64 = r.get(0).map_err(|e| sql(&e))?;
            let name: String = r.get(1).map_err(|e| sql(&e))?;
            let ty: String = r.get(2).map_err(|e| sql(&e))?;
            let ser: String = r.get(3).map_err(|e| sql(&e))?;
            topics.insert(id, (name, ty, ser == "cdr"));
        }
    }
    let mut st = c
        .prepare("SELECT id, topic_id, timestamp, data FROM messages ORDER BY timestamp, id")
        .map_err(|e| sql(&e))?;
    let mut rows = st.query([]).map_err(|e| sql(&e))?;
    let mut n = 0;
    let mut buf = Vec::new();
    while let Some(r) = rows.next().map_err(|e| sql(&e))? {
        let id: i64 = r.get(0).map_err(|e| sql(&e))?;
        let record = Some(u64::try_from(id).unwrap_or(0));
        let bad = |what: String| Corrupt::new(0, what).in_record(record);
        let topic_id: i64 = r.get(1).map_err(|e| bad(format!("topic id: {e}")))?;
        let ns: i64 = r.get(2).map_err(|e| bad(format!("timestamp: {e}")))?;
        let data = r
            .get_ref(3)
            .and_then(|v| v.as_blob().map_err(Into::into))
            .map_err(|e| bad(format!("data: {e}")))?;
        let Some((topic, datatype, cdr)) = topics.get(&topic_id) else {
            return Err(bad(format!(
                "topic id {topic_id}, which the topics table does not list"
            )));
        };
        if !cdr {
            continue;
        }
        let data = inflate(data, &mut buf).map_err(|e| bad(e.to_string()))?;
        n += 1;
        f(Message {
            topic,
            datatype,
            time: ns as f64 * 1e-9,
            data,
            wire: Wire::Cdr,
            offset: 0,
            record,
        })
        .map_err(|e| e.in_record(record))?;
    }
    Ok(n)
}

/// Writes a rosbag2 SQLite file (Humble layout, schema 3) in memory.
pub struct Db3Writer {
    c: Connection,
    topics: std::collections::HashMap<String, i64>,
}

impl Db3Writer {
    /// An empty bag.
    pub fn new() -> Result<Self, rusqlite::Error> {
        let c = Connection::open_in_memory()?;
        c.execute_batch(
            "BEGIN;
             CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
             INSERT INTO schema VALUES(3, 'humble');
             CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);
             CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
             CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL);
             CREATE INDEX timestamp_idx ON messages (timestamp ASC);",
        )?;
        Ok(Self {
            c,
            topics: std::collections::HashMap::new(),
        })
    }

    /// Adds one CDR message (`datatype` as `pkg/msg/Name`) at `t` seconds.
    pub fn write(
        &mut self,
        topic: &str,
        datatype: &str,
        t: f64,
        data: &[u8],
    ) -> Result<(), rusqlite::Error> {
        let id = match self.topics.get(topic) {
            Some(&id) => id,
            None => {
                let id = self.topics.len() as i64 + 1;
                self.c.execute(
                    "INSERT INTO topics VALUES(?1, ?2, ?3, 'cdr', '')",
                    rusqlite::params![id, topic, datatype],
                )?;
                self.topics.insert(topic.to_string(), id);
                id
            }
        };
        self.c
            .prepare_cached("INSERT INTO messages(topic_id, timestamp, data) VALUES(?1, ?2, ?3)")
            .and_then(|mut s| s.execute(rusqlite::params![id, (t * 1e9).round() as i64, data]))?;
        Ok(())
    }

    /// The file's bytes.
    pub fn finish(mut self) -> Result<Vec<u8>, rusqlite::Error> {
        self.c.execute_batch("COMMIT;")?;
        let data = self.c.serialize(MAIN_DB)?;
        Ok(data.to_vec())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_bags_read_back_in_time_order() {
        let mut w = Db3Writer::new().unwrap();
        w.write("/b", "std_msgs/msg/String", 2.0, &[0, 1, 0, 0, 9])
            .unwrap();
        w.write("/a", "std_msgs/msg/String", 1.0, &[0, 1, 0, 0, 7])
            .unwrap();
        let z = zstd::encode_all(&[0u8, 1, 0, 0, 5][..], 3).unwrap();
        w.write("/a", "std_msgs/msg/String", 3.0, &z).unwrap();
        let bytes = w.finish().unwrap();
        assert!(bytes.starts_with(b"SQLite format 3\0"));
        let c = open_bytes(&bytes).unwrap();
        let mut seen = Vec::new();
        let n = for_each_message(&c, &mut |m| {
            seen.push((m.topic.to_string(), m.time, m.data.to_vec(), m.record));
            Ok(())
        })
        .unwrap();
        assert_eq!(n, 3);
        assert_eq!(seen[0], ("/a".into(), 1.0, vec![0, 1, 0, 0, 7], Some(2)));
        assert_eq!(seen[1], ("/b".into(), 2.0, vec![0, 1, 0, 0, 9], Some(1)));
        assert_eq!(seen[2].2, vec![0, 1, 0, 0, 5], "zstd message decompressed");
    }

    #[test]
    fn errors_name_the_message_row() {
        let mut w = Db3Writer::new().unwrap();
        w.write("/a", "std_msgs/msg/String", 1.0, &[1]).unwrap();
        let c = open_bytes(&w.finish().unwrap()).unwrap();
        let e = for_each_message(&c, &mut |_| Err(Corrupt::new(4, "short"))).unwrap_err();
        assert_eq!(e.to_string(), "message 1, at byte 4 of its data: short");
        // A message whose topic is not listed.
        let mut w = Db3Writer::new().unwrap();
        w.write("/a", "std_msgs/msg/String", 1.0, &[1]).unwrap();
        w.c.execute("UPDATE messages SET topic_id = 7", []).unwrap();
        let c = open_bytes(&w.finish().unwrap()).unwrap();
        let e = for_each_message(&c, &mut |_| Ok(())).unwrap_err();
        assert!(
            e.to_string().contains("message 1") && e.to_string().contains("topic id 7"),
            "{e}"
        );
        // Not a rosbag2 file.
        let c = Connection::open_in_memory().unwrap();
        assert!(for_each_message(&c, &mut |_| Ok(())).is_err());
        assert!(
            open_bytes(b"not a database at all, just text").is_err() || {
                let c = open_bytes(b"not a database at all, just text").unwrap();
                for_each_message(&c, &mut |_| Ok(())).is_err()
            }
        );
    }
}
