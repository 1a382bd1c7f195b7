//! RTAB-Map databases (`.db`, SQLite): node poses (optimised when the database saved them, else
//! odometry, and it says which), colour (JPEG/PNG) and depth (RVL or PNG) per node, the camera
//! calibration blob (intrinsics and the base → optical local transform).
//!
//! Supported schemas: 0.18 and later (the calibration layout below). Two variants are read and
//! tested: current (≥ 0.21.9: RVL depth, `Admin.opt_ids`/`opt_poses`) and legacy (PNG depth, no
//! optimised poses). The version in `Admin.version` is checked first; columns are looked up with
//! `PRAGMA table_info`. Every blob's size is checked before it is used.

pub mod convert;
pub mod rvl;

use std::io::Read;
use std::path::Path;

use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion};
use rusqlite::{Connection, OpenFlags};
use serde::Serialize;

use mrtmap_io::Image16;
use mrtmap_io::bytes::{Bytes, Corrupt, Endian};
use mrtmap_io::{FileError, FileErrorKind};

/// Largest image side accepted from a blob.
const MAX_SIDE: u32 = 8192;
/// Largest decompressed Admin blob (10 million poses).
const MAX_ZLIB_BYTES: usize = 480 << 20;

/// A camera model from `Data.calibration`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Calibration {
    /// Intrinsics at the colour image size.
    pub camera: PinholeCamera,
    /// base_from_optical (RTAB-Map's local transform).
    #[serde(skip)]
    pub local: Isometry3<f64>,
    /// RTAB-Map version that wrote it.
    pub version: [i32; 3],
}

/// What a database holds.
#[derive(Clone, Debug, Serialize)]
pub struct DbSummary {
    /// `Admin.version`.
    pub version: String,
    /// Nodes.
    pub nodes: usize,
    /// Nodes with a colour image.
    pub images: usize,
    /// Nodes with depth.
    pub depths: usize,
    /// Depth blobs in RVL.
    pub rvl: usize,
    /// Links by type (neighbour, loop closure, …).
    pub links: Vec<(String, usize)>,
    /// "optimised (Admin.opt_poses)" or "odometry (Node.pose)".
    pub poses: String,
    /// Optimised poses saved.
    pub optimised: usize,
    /// First and last stamp, s.
    pub span: (f64, f64),
    /// The first calibration found.
    pub calibration: Option<Calibration>,
    /// Things worth knowing.
    pub notes: Vec<String>,
}

#[allow(clippy::needless_pass_by_value)] // used as map_err(|e| sql_err(path, e))
fn sql_err(path: &Path, e: rusqlite::Error) -> FileError {
    FileError::new(
        path,
        None,
        FileErrorKind::Syntax(format!("not a readable RTAB-Map database: {e}")),
    )
}

fn corrupt(path: &Path, what: String) -> FileError {
    FileError::new(path, None, FileErrorKind::Syntax(what))
}

/// Opens read-only and checks the schema version (≥ 0.18).
pub fn open(path: &Path) -> Result<(Connection, String), FileError> {
    let c = Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(|e| sql_err(path, e))?;
    let tables: Vec<String> = c
        .prepare("SELECT name FROM sqlite_master WHERE type='table'")
        .and_then(|mut s| s.query_map([], |r| r.get(0))?.collect())
        .map_err(|e| sql_err(path, e))?;
    for t in ["Admin", "Node", "Data"] {
        if !tables.iter().any(|x| x == t) {
            return Err(corrupt(
                path,
                format!("no {t} table: not an RTAB-Map database (or one older than 0.18)"),
            ));
        }
    }
    let version: String = c
        .query_row("SELECT version FROM Admin LIMIT 1", [], |r| r.get(0))
        .map_err(|e| corrupt(path, format!("Admin.version cannot be read: {e}")))?;
    let parts: Vec<u32> = version
        .split('.')
        .map(|p| p.trim().parse().unwrap_or(0))
        .collect();
    let (ma, mi) = (
        parts.first().copied().unwrap_or(0),
        parts.get(1).copied().unwrap_or(0),
    );
    if ma == 0 && mi < 18 {
        return Err(corrupt(
            path,
            format!(
                "schema version {version} is older than 0.18, whose calibration layout is the oldest supported"
            ),
        ));
    }
    Ok((c, version))
}

fn columns(c: &Connection, table: &str) -> Vec<String> {
    c.prepare(&format!("PRAGMA table_info({table})"))
        .and_then(|mut s| s.query_map([], |r| r.get::<_, String>(1))?.collect())
        .unwrap_or_default()
}

/// 12 f32, row-major 3×4 [R|t] → isometry (rotation re-orthonormalised); the error names `what`.
pub fn pose_blob(b: &[u8], what: &str) -> Result<Isometry3<f64>, BlobError> {
    pose_words(b, what).map_err(BlobError)
}

/// [`pose_blob`] with its error as words, for the readers that add the row to them.
fn pose_words(b: &[u8], what: &str) -> Result<Isometry3<f64>, String> {
    if b.len() != 48 {
        return Err(format!(
            "{what} is {} bytes, expected 48 (12 floats)",
            b.len()
        ));
    }
    let v: Vec<f64> = b
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64)
        .collect();
    pose12(&v, what)
}

fn pose12(v: &[f64], what: &str) -> Result<Isometry3<f64>, String> {
    if v.iter().any(|x| !x.is_finite()) {
        return Err(format!("{what} has a non-finite value"));
    }
    let m = Matrix3::new(v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10]);
    // Checked before orthonormalising: nalgebra's from_matrix iterates until it converges, and on
    // a matrix far from a rotation that can be forever (found by fuzzing).
    let off = (m.transpose() * m - Matrix3::identity()).abs().max();
    if off > 1e-2 || (m.determinant() - 1.0).abs() > 1e-2 {
        return Err(format!(
            "{what} is not a rotation (|RᵀR − I| up to {off:.3}, determinant {:.4})",
            m.determinant()
        ));
    }
    let r = Rotation3::from_matrix_eps(&m, 1e-12, 100, Rotation3::identity());
    Ok(Isometry3::from_parts(
        Translation3::new(v[3], v[7], v[11]),
        UnitQuaternion::from_rotation_matrix(&r),
    ))
}

/// Parses the first camera of a `Data.calibration` blob (mono, schema ≥ 0.18).
pub fn calibration(blob: &[u8]) -> Result<(Calibration, usize), Corrupt> {
    let b = Bytes::new(blob, Endian::Little);
    let h: Vec<i32> = (0..11)
        .map(|i| b.i32(4 * i, "the calibration header"))
        .collect::<Result<_, _>>()?;
    if h[3] != 0 {
        return Err(b.err(12, format!("camera type {} (only mono, type 0, is supported; a stereo database needs its left camera exported)", h[3])));
    }
    let (w, hh) = (h[4], h[5]);
    let (nk, nd, nr, np, nl) = (h[6], h[7], h[8], h[9], h[10]);
    if nk != 9 || nr != 9 || np != 12 || !(0..=14).contains(&nd) || !(nl == 12 || nl == 0) {
        return Err(b.err(
            24,
            format!("calibration header sizes K {nk} D {nd} R {nr} P {np} local {nl} (expected 9, 0–14, 9, 12, 12)"),
        ));
    }
    if !(1..=MAX_SIDE as i32).contains(&w) || !(1..=MAX_SIDE as i32).contains(&hh) {
        return Err(b.err(16, format!("calibration image size {w}×{hh}")));
    }
    let nd = nd as usize;
    let mut p = 44;
    let k: Vec<f64> = (0..9)
        .map(|i| b.f64(p + 8 * i, "calibration K"))
        .collect::<Result<_, _>>()?;
    p += 72;
    let d: Vec<f64> = (0..nd)
        .map(|i| b.f64(p + 8 * i, "calibration D"))
        .collect::<Result<_, _>>()?;
    p += 8 * nd + 72 + 96;
    let local = if nl == 12 {
        let v: Vec<f64> = (0..12)
            .map(|i| b.f32(p + 4 * i, "the local transform").map(f64::from))
            .collect::<Result<_, _>>()?;
        p += 48;
        pose12(&v, "the local transform").map_err(|e| b.err(p - 48, e))?
    } else {
        Isometry3::identity()
    };
    if !(k[0] > 0.0 && k[4] > 0.0) || k.iter().any(|x| !x.is_finite()) {
        return Err(b.err(
            44,
            format!("calibration focal lengths fx {} fy {}", k[0], k[4]),
        ));
    }
    let mut cam = PinholeCamera::new(w as u32, hh as u32, k[0], k[4], k[2], k[5]);
    if nd >= 5 && d.iter().all(|x| x.is_finite()) {
        cam.distortion = BrownConrady::from_array([d[0], d[1], d[2], d[3], d[4]]);
    } else if nd == 4 {
        cam.distortion = BrownConrady::from_array([d[0], d[1], d[2], d[3], 0.0]);
    }
    Ok((
        Calibration {
            camera: cam,
            local,
            version: [h[0], h[1], h[2]],
        },
        p,
    ))
}

/// An RTAB-Map compressed blob: zlib stream then rows, cols, OpenCV type (3 × i32).
fn uncompress(blob: &[u8], what: &str) -> Result<(Vec<u8>, i32, i32, i32), String> {
    if blob.len() < 12 {
        return Err(format!(
            "{what} blob is {} bytes, shorter than its 12-byte trailer",
            blob.len()
        ));
    }
    let t = &blob[blob.len() - 12..];
    let rows = i32::from_le_bytes([t[0], t[1], t[2], t[3]]);
    let cols = i32::from_le_bytes([t[4], t[5], t[6], t[7]]);
    let ty = i32::from_le_bytes([t[8], t[9], t[10], t[11]]);
    let elem = match ty & 7 {
        0 | 1 => 1,
        2 | 3 => 2,
        4 | 5 => 4,
        _ => 8,
    } * (1 + (ty >> 3)) as usize;
    let n = (rows.max(0) as usize)
        .checked_mul(cols.max(0) as usize)
        .and_then(|n| n.checked_mul(elem))
        .filter(|&n| n <= MAX_ZLIB_BYTES)
        .ok_or_else(|| format!("{what}: {rows}×{cols} of type {ty} is too large"))?;
    let mut out = Vec::with_capacity(n.min(16 << 20));
    flate2::read::ZlibDecoder::new(&blob[..blob.len() - 12])
        .take(n as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("{what}: broken zlib stream: {e}"))?;
    if out.len() != n {
        return Err(format!(
            "{what}: decompresses to {} bytes, its trailer says {rows}×{cols}×{elem} = {n}",
            out.len()
        ));
    }
    Ok((out, rows, cols, ty))
}

/// The optimised poses saved in Admin, when there are any: (node id, world_from_base).
fn optimised(c: &Connection, path: &Path) -> Result<Vec<(i64, Isometry3<f64>)>, FileError> {
    let cols = columns(c, "Admin");
    if !cols.iter().any(|x| x == "opt_poses") || !cols.iter().any(|x| x == "opt_ids") {
        return Ok(Vec::new());
    }
    let (ids, poses): (Option<Vec<u8>>, Option<Vec<u8>>) = c
        .query_row("SELECT opt_ids, opt_poses FROM Admin LIMIT 1", [], |r| {
            Ok((r.get(0)?, r.get(1)?))
        })
        .map_err(|e| sql_err(path, e))?;
    let (Some(ids), Some(poses)) = (ids, poses) else {
        return Ok(Vec::new());
    };
    if ids.is_empty() || poses.is_empty() {
        return Ok(Vec::new());
    }
    let (ids, ..) = uncompress(&ids, "Admin.opt_ids").map_err(|e| corrupt(path, e))?;
    let (poses, ..) = uncompress(&poses, "Admin.opt_poses").map_err(|e| corrupt(path, e))?;
    let n = ids.len() / 4;
    if poses.len() != n * 48 {
        return Err(corrupt(
            path,
            format!(
                "Admin.opt_poses holds {} bytes for {n} ids (48 each expected)",
                poses.len()
            ),
        ));
    }
    (0..n)
        .map(|i| {
            let id =
                i32::from_le_bytes([ids[4 * i], ids[4 * i + 1], ids[4 * i + 2], ids[4 * i + 3]]);
            pose_words(
                &poses[48 * i..48 * i + 48],
                &format!("optimised pose of node {id}"),
            )
            .map(|p| (id as i64, p))
            .map_err(|e| corrupt(path, format!("Admin.opt_poses: {e}")))
        })
        .collect()
}

/// RTAB-Map's link types by number.
const LINK_TYPES: [&str; 10] = [
    "neighbour",
    "global loop closure",
    "local-space closure",
    "local-time closure",
    "user",
    "virtual",
    "neighbour merged",
    "pose prior",
    "landmark",
    "gravity",
];

/// Links by type, and how many are loop closures.
fn link_counts(c: &Connection, path: &Path) -> Result<(Vec<(String, usize)>, usize), FileError> {
    let mut links = Vec::new();
    let mut closures = 0;
    if !columns(c, "Link").iter().any(|x| x == "type") {
        return Ok((links, closures));
    }
    let mut s = c
        .prepare("SELECT type, COUNT(*) FROM Link GROUP BY type ORDER BY type")
        .map_err(|e| sql_err(path, e))?;
    let rows: Vec<(i64, i64)> = s
        .query_map([], |r| Ok((r.get(0)?, r.get(1)?)))
        .and_then(|m| m.collect())
        .map_err(|e| sql_err(path, e))?;
    for (t, n) in rows {
        if is_loop_closure(t) {
            closures += n as usize;
        }
        let name = LINK_TYPES
            .get(t as usize)
            .map_or(format!("type {t}"), |s| s.to_string());
        links.push((name, n as usize));
    }
    Ok((links, closures))
}

/// The first calibration blob's camera, with a note when it cannot be read or holds several.
fn first_calibration(c: &Connection, notes: &mut Vec<String>) -> Option<Calibration> {
    let blob: Vec<u8> = c
        .query_row(
            "SELECT calibration FROM Data WHERE calibration IS NOT NULL AND length(calibration) > 0 LIMIT 1",
            [],
            |r| r.get(0),
        )
        .ok()?;
    match calibration(&blob) {
        Ok((cal, used)) => {
            if used < blob.len() {
                notes.push(
                    "the calibration blob holds more than one camera: the first is used".into(),
                );
            }
            Some(cal)
        }
        Err(e) => {
            notes.push(format!("calibration blob: {e}"));
            None
        }
    }
}

/// Which poses a database offers, in words.
fn poses_said(optimised: usize, closures: usize) -> String {
    if optimised > 0 {
        "optimised (Admin.opt_poses)".into()
    } else if closures > 0 {
        format!(
            "odometry (Node.pose; no optimised poses saved) — the Link graph has {closures} loop closure{}: convert optimises it",
            if closures == 1 { "" } else { "s" }
        )
    } else {
        "odometry (Node.pose; no optimised poses saved, no loop closures in Link)".into()
    }
}

/// Summarises a database (no image is decoded).
pub fn summarize(path: &Path) -> Result<DbSummary, FileError> {
    let (c, version) = open(path)?;
    let mut notes = Vec::new();
    let q = |sql: &str| -> Result<usize, FileError> {
        c.query_row(sql, [], |r| r.get::<_, i64>(0))
            .map(|n| n as usize)
            .map_err(|e| sql_err(path, e))
    };
    let nodes = q("SELECT COUNT(*) FROM Node")?;
    let images = q("SELECT COUNT(*) FROM Data WHERE image IS NOT NULL AND length(image) > 0")?;
    let depths = q("SELECT COUNT(*) FROM Data WHERE depth IS NOT NULL AND length(depth) > 0")?;
    let rvl = q("SELECT COUNT(*) FROM Data WHERE substr(depth, 1, 8) = CAST('DEPTHRVL' AS BLOB)")?;
    let span: (f64, f64) = c
        .query_row("SELECT MIN(stamp), MAX(stamp) FROM Node", [], |r| {
            Ok((
                r.get::<_, Option<f64>>(0)?.unwrap_or(0.0),
                r.get::<_, Option<f64>>(1)?.unwrap_or(0.0),
            ))
        })
        .map_err(|e| sql_err(path, e))?;
    let (links, closures) = link_counts(&c, path)?;
    let optimised = optimised(&c, path)?.len();
    let calibration = first_calibration(&c, &mut notes);
    Ok(DbSummary {
        poses: poses_said(optimised, closures),
        version,
        nodes,
        images,
        depths,
        rvl,
        links,
        optimised,
        span,
        calibration,
        notes,
    })
}

/// A database blob that cannot be decoded, and why.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct BlobError(pub String);

/// Decodes a depth blob: RVL (`DEPTHRVL`), 16-bit PNG, or a 4×u8 PNG holding f32 metres.
pub fn depth_blob(b: &[u8]) -> Result<Image16, BlobError> {
    if let Some(rest) = b.strip_prefix(MAGIC_RVL) {
        if rest.len() < 8 {
            return Err(BlobError(
                "RVL depth blob shorter than its size header".into(),
            ));
        }
        let w = u32::from_le_bytes([rest[0], rest[1], rest[2], rest[3]]);
        let h = u32::from_le_bytes([rest[4], rest[5], rest[6], rest[7]]);
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
            return Err(BlobError(format!("RVL depth blob says {w}×{h} pixels")));
        }
        let px = rvl::decode(&rest[8..], (w * h) as usize, 16)
            .map_err(|e| BlobError(format!("RVL depth: {e}")))?;
        return Ok(Image16 {
            width: w,
            height: h,
            data: px,
        });
    }
    let img = image::load_from_memory_with_format(b, image::ImageFormat::Png)
        .map_err(|e| BlobError(format!("depth blob is neither RVL nor a PNG: {e}")))?;
    match img {
        image::DynamicImage::ImageLuma16(i) => {
            let (w, h) = i.dimensions();
            Ok(Image16 {
                width: w,
                height: h,
                data: i.into_raw(),
            })
        }
        image::DynamicImage::ImageRgba8(i) => {
            let (w, h) = i.dimensions();
            let data = i
                .into_raw()
                .chunks_exact(4)
                .map(|c| {
                    let m = f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64;
                    if m.is_finite() && m > 0.0 {
                        (m * 1000.0).round().min(65535.0) as u16
                    } else {
                        0
                    }
                })
                .collect();
            Ok(Image16 {
                width: w,
                height: h,
                data,
            })
        }
        other => Err(BlobError(format!(
            "depth PNG is {:?}, not 16-bit or float-in-RGBA",
            other.color()
        ))),
    }
}

const MAGIC_RVL: &[u8] = rvl::MAGIC;

/// Whether a `Link` type is a loop closure: global, local-space, local-time or user.
pub fn is_loop_closure(kind: i64) -> bool {
    matches!(kind, 1..=4)
}

/// One row of the `Link` table.
#[derive(Clone, Debug)]
pub struct GraphLink {
    /// From node.
    pub from: i64,
    /// To node.
    pub to: i64,
    /// RTAB-Map's link type (0 neighbour, 1 global closure, 2 local-space, 3 local-time, 4 user,
    /// 5 virtual, 6 neighbour merged, 7 pose prior, 8 landmark, 9 gravity).
    pub kind: i64,
    /// Pose of `to` in `from`'s frame.
    pub transform: Isometry3<f64>,
    /// 6×6 information over (x, y, z, roll, pitch, yaw), row-major; zeros when not stored.
    pub information: [f64; 36],
}

/// The pose graph: every node's odometry pose (world_from_base) and the links, with the rows
/// that could not be read as (what, reason).
pub type Graph = (
    std::collections::BTreeMap<i64, Isometry3<f64>>,
    Vec<GraphLink>,
    Vec<String>,
);

/// Reads the odometry poses and the `Link` table (for optimising a graph RTAB-Map did not save).
pub fn graph(path: &Path) -> Result<Graph, FileError> {
    let (c, _) = open(path)?;
    let mut bad = Vec::new();
    let mut nodes = std::collections::BTreeMap::new();
    {
        let mut st = c
            .prepare("SELECT id, pose FROM Node ORDER BY id")
            .map_err(|e| sql_err(path, e))?;
        let mut rows = st.query([]).map_err(|e| sql_err(path, e))?;
        while let Some(r) = rows.next().map_err(|e| sql_err(path, e))? {
            let id: i64 = r.get(0).map_err(|e| sql_err(path, e))?;
            let b: Option<Vec<u8>> = r.get(1).unwrap_or(None);
            match pose_words(&b.unwrap_or_default(), "pose blob") {
                Ok(p) => {
                    nodes.insert(id, p);
                }
                Err(e) => bad.push(format!("node {id}: {e}")),
            }
        }
    }
    let cols = columns(&c, "Link");
    let has_info = cols.iter().any(|x| x == "information_matrix");
    let sql = format!(
        "SELECT from_id, to_id, type, transform, {} FROM Link",
        if has_info {
            "information_matrix"
        } else {
            "NULL"
        }
    );
    let mut st = c.prepare(&sql).map_err(|e| sql_err(path, e))?;
    let mut rows = st.query([]).map_err(|e| sql_err(path, e))?;
    let mut links = Vec::new();
    while let Some(r) = rows.next().map_err(|e| sql_err(path, e))? {
        let row: Result<GraphLink, String> = (|| {
            let from: i64 = r.get(0).map_err(|e| e.to_string())?;
            let to: i64 = r.get(1).map_err(|e| e.to_string())?;
            let kind: i64 = r.get(2).map_err(|e| e.to_string())?;
            let t: Option<Vec<u8>> = r.get(3).map_err(|e| e.to_string())?;
            let transform = pose_words(
                &t.unwrap_or_default(),
                &format!("link {from} → {to} transform"),
            )?;
            let info: Option<Vec<u8>> = r.get(4).map_err(|e| e.to_string())?;
            let mut information = [0.0; 36];
            if let Some(b) = info.filter(|b| b.len() == 288) {
                for (k, v) in information.iter_mut().enumerate() {
                    let mut x = [0u8; 8];
                    x.copy_from_slice(&b[8 * k..8 * k + 8]);
                    *v = f64::from_le_bytes(x);
                }
            }
            Ok(GraphLink {
                from,
                to,
                kind,
                transform,
                information,
            })
        })();
        match row {
            Ok(l) => links.push(l),
            Err(e) => bad.push(format!("link: {e}")),
        }
    }
    Ok((nodes, links, bad))
}

/// One node read back.
#[derive(Clone, Debug)]
pub struct Node {
    /// Id.
    pub id: i64,
    /// Stamp, s.
    pub stamp: f64,
    /// world_from_base (optimised when saved, else odometry).
    pub pose: Isometry3<f64>,
    /// Colour image bytes (JPEG or PNG).
    pub image: Option<Vec<u8>>,
    /// Depth, mm.
    pub depth: Option<Image16>,
}

/// Reads every node in id order; `f` gets each (problems with a node's blobs are returned to
/// the caller as (id, reason) and the node is skipped). Poses are `poses` when given (a graph
/// optimised by the caller), else the saved optimised poses, else the odometry.
pub fn for_each_node(
    path: &Path,
    poses: Option<&std::collections::BTreeMap<i64, Isometry3<f64>>>,
    f: &mut dyn FnMut(Node) -> Result<(), FileError>,
) -> Result<Vec<(i64, String)>, FileError> {
    let (c, _) = open(path)?;
    let opt: std::collections::HashMap<i64, Isometry3<f64>> = match poses {
        Some(p) => p.iter().map(|(k, v)| (*k, *v)).collect(),
        None => optimised(&c, path)?.into_iter().collect(),
    };
    let mut s = c
        .prepare("SELECT Node.id, Node.stamp, Node.pose, Data.image, Data.depth FROM Node LEFT JOIN Data ON Data.id = Node.id ORDER BY Node.id")
        .map_err(|e| sql_err(path, e))?;
    let mut rows = s.query([]).map_err(|e| sql_err(path, e))?;
    let mut bad = Vec::new();
    while let Some(r) = rows.next().map_err(|e| sql_err(path, e))? {
        let id: i64 = r.get(0).map_err(|e| sql_err(path, e))?;
        let res: Result<Node, String> = (|| {
            let stamp: f64 = r.get(1).map_err(|e| format!("stamp: {e}"))?;
            let pose_b: Option<Vec<u8>> = r.get(2).map_err(|e| format!("pose: {e}"))?;
            let odom = pose_words(&pose_b.unwrap_or_default(), "pose blob")?;
            let pose = if opt.is_empty() {
                odom
            } else {
                match opt.get(&id) {
                    Some(p) => *p,
                    None => return Err("not in the optimised graph".into()),
                }
            };
            let image: Option<Vec<u8>> = r.get(3).map_err(|e| format!("image: {e}"))?;
            let depth: Option<Vec<u8>> = r.get(4).map_err(|e| format!("depth: {e}"))?;
            let depth = match depth.filter(|d| !d.is_empty()) {
                Some(d) => Some(depth_blob(&d).map_err(|e| e.0)?),
                None => None,
            };
            Ok(Node {
                id,
                stamp,
                pose,
                image: image.filter(|i| !i.is_empty()),
                depth,
            })
        })();
        match res {
            Ok(n) => f(n)?,
            Err(e) => bad.push((id, e)),
        }
    }
    Ok(bad)
}

/// Which database schema [`write_database`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Schema {
    /// 0.23: RVL depth, optimised poses in Admin.
    Current,
    /// 0.20: PNG depth, no optimised poses.
    Legacy,
}

/// A node to write.
pub struct WriteNode<'a> {
    /// Stamp.
    pub stamp: f64,
    /// Odometry pose world_from_base.
    pub odom: Isometry3<f64>,
    /// Optimised pose.
    pub optimised: Isometry3<f64>,
    /// JPEG/PNG bytes.
    pub image: &'a [u8],
    /// Depth, mm.
    pub depth: &'a Image16,
}

/// A diagonal 6×6 information matrix (f64, as RTAB-Map stores it) for standard deviations in
/// metres and radians.
fn information_bytes(sigma_t: f64, sigma_r: f64) -> Vec<u8> {
    (0..36)
        .flat_map(|k| {
            let v = match k {
                0 | 7 | 14 => sigma_t.powi(-2),
                21 | 28 | 35 => sigma_r.powi(-2),
                _ => 0.0,
            };
            v.to_le_bytes()
        })
        .collect()
}

fn pose_bytes(p: &Isometry3<f64>) -> Vec<u8> {
    let r = p.rotation.to_rotation_matrix();
    let t = p.translation.vector;
    let m = r.matrix();
    let v = [
        m[(0, 0)],
        m[(0, 1)],
        m[(0, 2)],
        t.x,
        m[(1, 0)],
        m[(1, 1)],
        m[(1, 2)],
        t.y,
        m[(2, 0)],
        m[(2, 1)],
        m[(2, 2)],
        t.z,
    ];
    v.iter().flat_map(|x| (*x as f32).to_le_bytes()).collect()
}

/// A `Data.calibration` blob for one mono camera.
pub fn calibration_blob(cam: &PinholeCamera, local: &Isometry3<f64>, version: [i32; 3]) -> Vec<u8> {
    let d = cam.distortion.to_array();
    let mut b = Vec::new();
    for v in [
        version[0],
        version[1],
        version[2],
        0,
        cam.width as i32,
        cam.height as i32,
        9,
        5,
        9,
        12,
        12,
    ] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    let k = [cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0];
    let r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let p = [
        cam.fx, 0.0, cam.cx, 0.0, 0.0, cam.fy, cam.cy, 0.0, 0.0, 0.0, 1.0, 0.0,
    ];
    for v in k.iter().chain(d.iter()).chain(r.iter()).chain(p.iter()) {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&pose_bytes(local));
    b
}

fn compress(data: &[u8], rows: i32, cols: i32, ty: i32) -> std::io::Result<Vec<u8>> {
    use std::io::Write;
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data)?;
    let mut b = e.finish()?;
    for v in [rows, cols, ty] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    Ok(b)
}

/// Writes a database in RTAB-Map's layout (the tables and columns this reader uses, as RTAB-Map
/// names them): for tests, fuzz seeds and round trips.
pub fn write_database(
    path: &Path,
    schema: Schema,
    cam: &PinholeCamera,
    local: &Isometry3<f64>,
    nodes: &[WriteNode<'_>],
) -> Result<(), FileError> {
    let e = |e: rusqlite::Error| sql_err(path, e);
    let c = Connection::open(path).map_err(e)?;
    let (version, admin) = match schema {
        Schema::Current => (
            "0.23.1",
            "CREATE TABLE Admin (version TEXT, preview_image BLOB, opt_cloud BLOB, opt_ids BLOB, opt_poses BLOB, opt_last_localized BLOB, opt_map BLOB, opt_map_x_min REAL, opt_map_y_min REAL, opt_map_resolution REAL, time_enter DATE)",
        ),
        Schema::Legacy => (
            "0.20.0",
            "CREATE TABLE Admin (version TEXT, preview_image BLOB, time_enter DATE)",
        ),
    };
    c.execute_batch(&format!(
        "{admin};
         CREATE TABLE Node (id INTEGER NOT NULL, map_id INTEGER NOT NULL, weight INTEGER, stamp FLOAT, pose BLOB NOT NULL, ground_truth_pose BLOB, velocity BLOB, label TEXT, gps BLOB, env_sensors BLOB, time_enter DATE, PRIMARY KEY (id));
         CREATE TABLE Data (id INTEGER NOT NULL, image BLOB, depth BLOB, depth_confidence BLOB, calibration BLOB, scan_info BLOB, scan BLOB, user_data BLOB, ground_cells BLOB, obstacle_cells BLOB, empty_cells BLOB, cell_size FLOAT, view_point_x FLOAT, view_point_y FLOAT, view_point_z FLOAT, time_enter DATE, PRIMARY KEY (id));
         CREATE TABLE Link (from_id INTEGER NOT NULL, to_id INTEGER NOT NULL, type INTEGER NOT NULL, information_matrix BLOB NOT NULL, transform BLOB, user_data BLOB, FOREIGN KEY (from_id) REFERENCES Node(id), FOREIGN KEY (to_id) REFERENCES Node(id));"
    ))
    .map_err(e)?;
    let v: Vec<i32> = version.split('.').map(|p| p.parse().unwrap_or(0)).collect();
    let calib = calibration_blob(cam, local, [v[0], v[1], v[2]]);
    let tx = c.unchecked_transaction().map_err(e)?;
    for (i, n) in nodes.iter().enumerate() {
        let id = i as i64 + 1;
        tx.execute(
            "INSERT INTO Node (id, map_id, weight, stamp, pose) VALUES (?1, 0, 0, ?2, ?3)",
            rusqlite::params![id, n.stamp, pose_bytes(&n.odom)],
        )
        .map_err(e)?;
        let depth = match schema {
            Schema::Current => rvl::encode_rtabmap(n.depth.width, n.depth.height, &n.depth.data),
            Schema::Legacy => {
                mrtmap_io::encode_png16(n.depth).map_err(|er| FileError::encode(path, er))?
            }
        };
        tx.execute(
            "INSERT INTO Data (id, image, depth, calibration) VALUES (?1, ?2, ?3, ?4)",
            rusqlite::params![id, n.image, depth, calib],
        )
        .map_err(e)?;
        if i > 0 {
            let rel = nodes[i - 1].odom.inverse() * n.odom;
            tx.execute(
                "INSERT INTO Link (from_id, to_id, type, information_matrix, transform) VALUES (?1, ?2, 0, ?3, ?4)",
                rusqlite::params![id - 1, id, information_bytes(0.01, 0.01), pose_bytes(&rel)],
            )
            .map_err(e)?;
        }
    }
    // A global loop closure from the last node back to the first, measured on the true poses.
    if nodes.len() >= 3 {
        let (a, b) = (&nodes[nodes.len() - 1], &nodes[0]);
        tx.execute(
            "INSERT INTO Link (from_id, to_id, type, information_matrix, transform) VALUES (?1, 1, 1, ?2, ?3)",
            rusqlite::params![
                nodes.len() as i64,
                information_bytes(0.001, 0.001),
                pose_bytes(&(a.optimised.inverse() * b.optimised))
            ],
        )
        .map_err(e)?;
    }
    match schema {
        Schema::Current => {
            let ids: Vec<u8> = (1..=nodes.len() as i32)
                .flat_map(|i| i.to_le_bytes())
                .collect();
            let poses: Vec<u8> = nodes
                .iter()
                .flat_map(|n| pose_bytes(&n.optimised))
                .collect();
            let io = |er| FileError::io(path, er);
            let ids = compress(&ids, 1, nodes.len() as i32, 4).map_err(io)?;
            let poses = compress(&poses, nodes.len() as i32, 12, 5).map_err(io)?;
            tx.execute(
                "INSERT INTO Admin (version, opt_ids, opt_poses) VALUES (?1, ?2, ?3)",
                rusqlite::params![version, ids, poses],
            )
            .map_err(e)?;
        }
        Schema::Legacy => {
            tx.execute("INSERT INTO Admin (version) VALUES (?1)", [version])
                .map_err(e)?;
        }
    }
    tx.commit().map_err(e)?;
    Ok(())
}

/// RTAB-Map's local transform for a forward-looking camera: base (x forward, y left, z up) from
/// optical (x right, y down, z forward).
pub fn base_from_optical() -> Isometry3<f64> {
    let m = Matrix3::new(0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0);
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m)),
    )
}

/// Writes a recording as an RTAB-Map-layout database: a node per colour frame with the nearest
/// depth frame (within 20 ms) and the interpolated pose. The odometry poses drift 1 cm per node
/// along x; a loop closure from the last node to the first is measured on the recording's poses.
/// With [`Schema::Current`] the optimised poses (the recording's) are saved, so a reader that takes
/// the wrong ones is caught; with [`Schema::Legacy`] they are not, and optimising the graph gives
/// them back. Returns the number of nodes.
pub fn write_recording(
    rec: &mrtmap_io::Recording,
    path: &Path,
    schema: Schema,
) -> Result<usize, FileError> {
    let bad = |m: &str| FileError::new(&rec.dir, None, FileErrorKind::Syntax(m.to_string()));
    let rgb = rec
        .rig
        .rgb
        .ok_or_else(|| bad("writing an RTAB-Map database needs a colour stream"))?;
    if rgb.camera != rec.rig.depth || rgb.depth_from_rgb != Isometry3::identity() {
        return Err(bad(
            "writing an RTAB-Map database needs depth registered to the colour camera (same intrinsics, identity depth_from_rgb)",
        ));
    }
    let local = base_from_optical();
    let limits = mrtmap_io::InterpolationLimits::default();
    let mut images = Vec::new();
    for e in &rec.rgb {
        let Some(d) = rec
            .depth
            .iter()
            .min_by(|a, b| (a.t - e.t).abs().total_cmp(&(b.t - e.t).abs()))
            .filter(|d| (d.t - e.t).abs() <= 0.02)
        else {
            continue;
        };
        let Some(world_from_depth) = rec.trajectory.interpolate(e.t, &limits) else {
            continue;
        };
        let p = rec.path_of(e);
        let bytes = std::fs::read(&p).map_err(|er| FileError::io(&p, er))?;
        images.push((
            e.t,
            world_from_depth * local.inverse(),
            bytes,
            rec.read_depth(d)?,
        ));
    }
    if images.is_empty() {
        return Err(bad(
            "no colour frame has a depth frame within 20 ms and a pose",
        ));
    }
    let nodes: Vec<WriteNode<'_>> = images
        .iter()
        .enumerate()
        .map(|(i, (t, pose, img, depth))| WriteNode {
            stamp: *t,
            odom: Isometry3::from_parts(
                Translation3::new(0.01 * i as f64, 0.0, 0.0),
                Default::default(),
            ) * pose,
            optimised: *pose,
            image: img,
            depth,
        })
        .collect();
    if path.exists() {
        std::fs::remove_file(path).map_err(|e| FileError::io(path, e))?;
    }
    write_database(path, schema, &rgb.camera, &local, &nodes)?;
    Ok(nodes.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn calibration_blob_round_trips_and_bad_sizes_are_errors() {
        let mut cam = PinholeCamera::new(640, 480, 615.0, 616.0, 320.5, 240.5);
        cam.distortion = BrownConrady::from_array([0.1, -0.2, 0.001, 0.002, 0.03]);
        let local = Isometry3::new(Vector3::new(0.1, 0.0, 0.2), Vector3::new(-1.2, 0.0, -1.5));
        let b = calibration_blob(&cam, &local, [0, 23, 1]);
        let (c, used) = calibration(&b).unwrap();
        assert_eq!(used, b.len());
        assert_eq!(c.camera.width, 640);
        assert!((c.camera.fy - 616.0).abs() < 1e-12);
        assert!((c.camera.distortion.to_array()[4] - 0.03).abs() < 1e-12);
        assert!((c.local.translation.vector - local.translation.vector).norm() < 1e-6);
        assert!(c.local.rotation.angle_to(&local.rotation) < 1e-6);
        for cut in [0, 10, 44, 100, b.len() - 1] {
            assert!(calibration(&b[..cut]).is_err(), "cut {cut}");
        }
        let mut stereo = b.clone();
        stereo[12] = 1;
        assert!(calibration(&stereo).unwrap_err().what.contains("stereo"));
    }

    #[test]
    fn compressed_blob_checks_its_trailer() {
        let data: Vec<u8> = (0..96u8).collect();
        let b = compress(&data, 2, 12, 5).unwrap();
        assert_eq!(uncompress(&b, "x").unwrap().0, data);
        let lie = compress(&data, 3, 12, 5).unwrap();
        assert!(uncompress(&lie, "x").unwrap_err().contains("decompresses"));
        let huge = compress(&data, i32::MAX, i32::MAX, 5).unwrap();
        assert!(uncompress(&huge, "x").unwrap_err().contains("too large"));
        assert!(pose_blob(&[0; 40], "p").is_err());
        // Determinant 1 but far from a rotation: refused (it used to loop forever).
        let skew: Vec<u8> = [
            100.0f32, 0.0, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0,
        ]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
        assert!(
            pose_blob(&skew, "p")
                .unwrap_err()
                .0
                .contains("not a rotation")
        );
    }
}
