//! A scan from a ROS 1 bag or an MCAP file: survey the topics, choose the streams, assemble the
//! rig, and write the recording layout.
//!
//! Defaults follow the RealSense ROS driver (`/camera/aligned_depth_to_color/image_raw`,
//! `/camera/color/image_raw`, `/camera/odom/sample` of a T265, `/tf_static`); a thermal stream is
//! any `mono16` image topic (a Lepton on a PureThermal board publishes TLinear centikelvin). Every
//! choice can be named with [`RosOptions`]. Poses come from an `Odometry` / `PoseStamped` topic or
//! from `/tf`, and are carried to the depth camera through the static transforms.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use nalgebra::Isometry3;
use serde::Serialize;

use crate::bytes::Corrupt;
use crate::error::{FileError, FileErrorKind};
use crate::image16::{Image16, encode_png_rgb8};
use crate::layout_writer::LayoutWriter;
use crate::rig::{RgbCamera, Rig, ThermalEncoding};
use crate::ros_msg::{self, CameraInfoMsg, Message, MsgKind, StampedTransform, Wire};

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
                Input::Bytes(b) => crate::rosbag2::open_bytes(b)?,
                Input::File(p) => crate::rosbag2::open_file(p)?,
            };
            crate::rosbag2::for_each_message(&c, f).map(|_| false)
        }
        Container::Bag => {
            crate::bag::for_each_message_in(&mut *input.open()?, f).map(|s| s.unindexed)
        }
        Container::Mcap => {
            // ROS 2 bags recorded with per-message compression keep each message zstd-compressed.
            let mut buf = Vec::new();
            let mut g = |m: Message<'_>| {
                if m.wire != Wire::Cdr {
                    return f(m);
                }
                let data = crate::rosbag2::inflate(m.data, &mut buf)
                    .map_err(|e| Corrupt::new(m.offset, e))?;
                f(Message { data, ..m })
            };
            crate::mcap_file::for_each_message_in(&mut *input.open()?, &mut g).map(|s| s.unfinished)
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

/// Stream choices and rig overrides.
#[derive(Clone, Debug, Default)]
pub struct RosOptions {
    /// Depth image topic.
    pub depth_topic: Option<String>,
    /// Thermal image topic.
    pub thermal_topic: Option<String>,
    /// Colour image topic.
    pub rgb_topic: Option<String>,
    /// Pose topic (Odometry or PoseStamped).
    pub pose_topic: Option<String>,
    /// Raw depth units per metre for 16-bit depth (default 1000).
    pub depth_scale: Option<f64>,
    /// A rig (from `mrtmap calibrate`): its thermal camera and extrinsic replace what the file
    /// has (or lacks); its depth and colour cameras are used when the file has no CameraInfo.
    pub rig: Option<Rig>,
}

/// One topic as surveyed.
#[derive(Clone, Debug, Default, Serialize)]
pub struct TopicStats {
    /// Topic.
    pub topic: String,
    /// Type.
    pub datatype: String,
    /// Messages.
    pub count: usize,
    /// First stamp, s.
    pub t0: f64,
    /// Last stamp, s.
    pub t1: f64,
    /// Image encoding or compressed format, when an image topic.
    pub encoding: String,
    /// Frame id.
    pub frame_id: String,
    /// Child frame (Odometry).
    pub child_frame: String,
    /// Image size.
    pub size: Option<(u32, u32)>,
    /// Messages that did not decode.
    pub undecodable: usize,
    /// The first decoding error.
    pub first_error: Option<String>,
}

impl TopicStats {
    /// Messages per second over the span.
    pub fn rate_hz(&self) -> f64 {
        if self.count > 1 && self.t1 > self.t0 {
            (self.count - 1) as f64 / (self.t1 - self.t0)
        } else {
            0.0
        }
    }
}

/// What a file holds.
#[derive(Clone, Debug)]
pub struct Survey {
    /// Container.
    pub container: Container,
    /// Topics by name.
    pub topics: BTreeMap<String, TopicStats>,
    /// The last CameraInfo of each topic.
    pub infos: HashMap<String, CameraInfoMsg>,
    /// Static transforms.
    pub static_tf: Vec<StampedTransform>,
    /// Dynamic transform edges (parent, child) → count.
    pub dynamic_tf: BTreeMap<(String, String), usize>,
    /// Cut or never closed.
    pub unfinished: bool,
}

fn stamp_or(t: f64, record: f64) -> f64 {
    if t > 0.0 { t } else { record }
}

/// Surveys a bag, MCAP or `.db3` file, or a split ROS 2 bag's folder (one pass; images are not
/// decoded).
pub fn survey<'a>(container: Container, file: impl Into<Input<'a>>) -> Result<Survey, Corrupt> {
    let file = file.into();
    let mut s = Survey {
        container,
        topics: BTreeMap::new(),
        infos: HashMap::new(),
        static_tf: Vec::new(),
        dynamic_tf: BTreeMap::new(),
        unfinished: false,
    };
    let unfinished = for_each(container, file, &mut |m| {
        let st = s
            .topics
            .entry(m.topic.to_string())
            .or_insert_with(|| TopicStats {
                topic: m.topic.to_string(),
                datatype: m.datatype.to_string(),
                t0: f64::INFINITY,
                t1: f64::NEG_INFINITY,
                ..Default::default()
            });
        let mut t = m.time;
        let res: Result<(), Corrupt> = (|| {
            match MsgKind::of(m.datatype) {
                MsgKind::Image => {
                    let i = ros_msg::image(m.data, m.wire, m.offset)?;
                    t = stamp_or(i.header.stamp, m.time);
                    st.encoding = i.encoding;
                    st.frame_id = i.header.frame_id;
                    st.size = Some((i.width, i.height));
                }
                MsgKind::CompressedImage => {
                    let i = ros_msg::compressed_image(m.data, m.wire, m.offset)?;
                    t = stamp_or(i.header.stamp, m.time);
                    st.encoding = i.format;
                    st.frame_id = i.header.frame_id;
                }
                MsgKind::CameraInfo => {
                    let i = ros_msg::camera_info(m.data, m.wire, m.offset)?;
                    t = stamp_or(i.header.stamp, m.time);
                    st.frame_id = i.header.frame_id.clone();
                    st.size = Some((i.width, i.height));
                    s.infos.insert(m.topic.to_string(), i);
                }
                MsgKind::Odometry | MsgKind::PoseStamped => {
                    let p = if MsgKind::of(m.datatype) == MsgKind::Odometry {
                        ros_msg::odometry(m.data, m.wire, m.offset)?
                    } else {
                        ros_msg::pose_stamped(m.data, m.wire, m.offset)?
                    };
                    t = stamp_or(p.stamp, m.time);
                    st.frame_id = p.parent;
                    st.child_frame = p.child;
                }
                MsgKind::Tf | MsgKind::TransformStamped => {
                    let tfs = if MsgKind::of(m.datatype) == MsgKind::Tf {
                        ros_msg::tf_message(m.data, m.wire, m.offset)?
                    } else {
                        vec![ros_msg::transform_stamped_msg(m.data, m.wire, m.offset)?]
                    };
                    let is_static = m.topic.ends_with("tf_static");
                    for tf in tfs {
                        if is_static {
                            s.static_tf.push(tf);
                        } else {
                            *s.dynamic_tf.entry((tf.parent, tf.child)).or_default() += 1;
                        }
                    }
                }
                MsgKind::Other => {}
            }
            Ok(())
        })();
        st.count += 1;
        if let Err(e) = res {
            st.undecodable += 1;
            if st.first_error.is_none() {
                st.first_error = Some(e.in_record(m.record).to_string());
            }
        }
        st.t0 = st.t0.min(t);
        st.t1 = st.t1.max(t);
        Ok(())
    })?;
    s.unfinished = unfinished;
    Ok(s)
}

/// Where poses come from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum PoseSource {
    /// An Odometry or PoseStamped topic.
    Topic(String),
    /// A dynamic transform parent → child on /tf.
    Tf(String, String),
}

/// The streams chosen and the rig assembled (or what is missing for a scan).
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    /// Depth topic.
    pub depth: Option<String>,
    /// Thermal topic.
    pub thermal: Option<String>,
    /// Colour topic.
    pub rgb: Option<String>,
    /// Poses.
    pub poses: Option<PoseSource>,
    /// depth frame ← pose child frame, when found in the static transforms.
    #[serde(skip)]
    pub child_from_depth: Isometry3<f64>,
    /// The rig.
    #[serde(skip)]
    pub rig: Option<Rig>,
    /// What a scan needs and the file lacks.
    pub missing: Vec<String>,
    /// How things were decided.
    pub notes: Vec<String>,
}

const DEPTH_DEFAULTS: [&str; 3] = [
    "/camera/aligned_depth_to_color/image_raw",
    "/camera/depth/image_rect_raw",
    "/camera/depth/image_raw",
];
const RGB_DEFAULTS: [&str; 2] = [
    "/camera/color/image_raw",
    "/camera/color/image_raw/compressed",
];
const POSE_DEFAULTS: [&str; 2] = ["/camera/odom/sample", "/rtabmap/odom"];

fn info_topic_for(image_topic: &str) -> String {
    let t = image_topic
        .strip_suffix("/compressed")
        .unwrap_or(image_topic);
    match t.rsplit_once('/') {
        Some((ns, _)) => format!("{ns}/camera_info"),
        None => "camera_info".into(),
    }
}

fn camera_from_info(i: &CameraInfoMsg) -> Option<PinholeCamera> {
    let k = &i.k;
    if !(k[0] > 0.0 && k[4] > 0.0 && i.width > 0 && i.height > 0) {
        return None;
    }
    let mut c = PinholeCamera::new(i.width, i.height, k[0], k[4], k[2], k[5]);
    if i.d.len() >= 5 && i.distortion_model != "equidistant" {
        let d = [i.d[0], i.d[1], i.d[2], i.d[3], i.d[4]];
        if d.iter().all(|x| x.is_finite()) {
            c.distortion = BrownConrady::from_array(d);
        }
    }
    Some(c)
}

/// a_from_b through the static transforms (frames compared without a leading '/').
pub fn static_lookup(tfs: &[StampedTransform], a: &str, b: &str) -> Option<Isometry3<f64>> {
    let norm = |s: &str| s.trim_start_matches('/').to_string();
    let (a, b) = (norm(a), norm(b));
    if a == b {
        return Some(Isometry3::identity());
    }
    // Breadth-first from a, carrying a_from_frame.
    let mut seen: HashMap<String, Isometry3<f64>> = HashMap::new();
    seen.insert(a.clone(), Isometry3::identity());
    let mut queue = vec![a];
    while let Some(f) = queue.pop() {
        let a_from_f = seen[&f];
        for tf in tfs {
            let (p, c) = (norm(&tf.parent), norm(&tf.child));
            let next = if p == f {
                Some((c, a_from_f * tf.transform))
            } else if c == f {
                Some((p, a_from_f * tf.transform.inverse()))
            } else {
                None
            };
            if let Some((n, x)) = next
                && !seen.contains_key(&n)
            {
                if n == b {
                    return Some(x);
                }
                seen.insert(n.clone(), x);
                queue.push(n);
            }
        }
    }
    None
}

fn pick(
    s: &Survey,
    given: &Option<String>,
    defaults: &[&str],
    what: &str,
    fallback: impl Fn(&TopicStats) -> bool,
    missing: &mut Vec<String>,
) -> Option<String> {
    if let Some(t) = given {
        if s.topics.contains_key(t) {
            return Some(t.clone());
        }
        missing.push(format!("{what}: topic {t} is not in the file"));
        return None;
    }
    defaults
        .iter()
        .find(|d| s.topics.contains_key(**d))
        .map(|d| d.to_string())
        .or_else(|| {
            s.topics
                .values()
                .find(|t| fallback(t))
                .map(|t| t.topic.clone())
        })
}

/// Chooses streams and assembles the rig.
pub fn plan(s: &Survey, o: &RosOptions) -> Plan {
    let mut missing = Vec::new();
    let mut notes = Vec::new();
    let is_image = |t: &TopicStats| {
        matches!(
            MsgKind::of(&t.datatype),
            MsgKind::Image | MsgKind::CompressedImage
        )
    };
    let depth = pick(
        s,
        &o.depth_topic,
        &DEPTH_DEFAULTS,
        "depth images",
        |t| {
            // Float images are depth wherever they are; 16-bit ones when the topic says so.
            is_image(t)
                && (t.encoding == "32FC1"
                    || (t.topic.to_ascii_lowercase().contains("depth")
                        && ["16UC1", "mono16"]
                            .iter()
                            .any(|e| t.encoding.starts_with(e))))
        },
        &mut missing,
    );
    let thermal = pick(
        s,
        &o.thermal_topic,
        &[],
        "thermal images",
        |t| {
            is_image(t)
                && Some(&t.topic) != depth.as_ref()
                && !t.topic.to_ascii_lowercase().contains("depth")
                && matches!(t.encoding.as_str(), "mono16" | "16UC1")
        },
        &mut missing,
    );
    let rgb = pick(
        s,
        &o.rgb_topic,
        &RGB_DEFAULTS,
        "colour images",
        |t| {
            is_image(t)
                && !t.topic.to_ascii_lowercase().contains("depth")
                && (matches!(t.encoding.as_str(), "rgb8" | "bgr8" | "rgba8" | "bgra8")
                    || t.encoding.contains("jpeg"))
        },
        &mut missing,
    );
    let mut poses = pick(
        s,
        &o.pose_topic,
        &POSE_DEFAULTS,
        "poses",
        |t| {
            matches!(
                MsgKind::of(&t.datatype),
                MsgKind::Odometry | MsgKind::PoseStamped
            )
        },
        &mut missing,
    )
    .map(PoseSource::Topic);
    if depth.is_none() && o.depth_topic.is_none() {
        missing.push(
            "depth images: no 16UC1/32FC1 depth image topic (name one with --depth-topic)".into(),
        );
    }
    if thermal.is_none() && o.thermal_topic.is_none() {
        missing
            .push("thermal images: no mono16 image topic (name one with --thermal-topic)".into());
    }
    let depth_frame = depth
        .as_ref()
        .map(|d| s.topics[d].frame_id.clone())
        .unwrap_or_default();
    if poses.is_none() && o.pose_topic.is_none() {
        // A dynamic transform whose child reaches the depth camera through static ones.
        let best = s
            .dynamic_tf
            .iter()
            .filter(|((_, c), _)| static_lookup(&s.static_tf, c, &depth_frame).is_some())
            .max_by_key(|(_, n)| **n);
        match best {
            Some(((p, c), _)) => {
                notes.push(format!("poses from /tf: {p} → {c}"));
                poses = Some(PoseSource::Tf(p.clone(), c.clone()));
            }
            None => missing.push(
                "poses: no Odometry or PoseStamped topic, and no /tf transform that reaches the depth camera (name one with --pose-topic)"
                    .into(),
            ),
        }
    }
    // Pose child → depth camera.
    let mut child_from_depth = Isometry3::identity();
    if let Some(PoseSource::Topic(t)) = &poses {
        let child = pose_child(s, t);
        match child.as_deref().and_then(|c| static_lookup(&s.static_tf, c, &depth_frame)) {
            Some(x) => {
                child_from_depth = x;
                if x != Isometry3::identity() {
                    notes.push(format!(
                        "poses of {} carried to the depth camera {depth_frame} through /tf_static",
                        child.unwrap_or_default()
                    ));
                }
            }
            None => notes.push(format!(
                "no static transform from the pose frame {} to the depth camera {depth_frame}: the poses are taken as the depth camera's own",
                child.unwrap_or_else(|| "(unnamed)".into())
            )),
        }
    } else if let Some(PoseSource::Tf(_, c)) = &poses
        && let Some(x) = static_lookup(&s.static_tf, c, &depth_frame)
    {
        child_from_depth = x;
    }
    // The rig.
    let info_of = |topic: &Option<String>| {
        topic
            .as_ref()
            .and_then(|t| s.infos.get(&info_topic_for(t)).and_then(camera_from_info))
    };
    let depth_cam = info_of(&depth).or(o.rig.map(|r| r.depth));
    let rgb_cam = info_of(&rgb).or(o.rig.and_then(|r| r.rgb.map(|c| c.camera)));
    let thermal_cam = o.rig.map(|r| r.thermal).or_else(|| info_of(&thermal));
    if depth.is_some() && depth_cam.is_none() {
        missing.push(format!(
            "depth intrinsics: no CameraInfo on {} (or give --rig)",
            depth.as_deref().map(info_topic_for).unwrap_or_default()
        ));
    }
    if thermal.is_some() && thermal_cam.is_none() {
        missing.push(format!(
            "thermal intrinsics: no CameraInfo with a focal length on {} (calibrate with mrtmap calibrate and give --rig)",
            thermal.as_deref().map(info_topic_for).unwrap_or_default()
        ));
    }
    let thermal_frame = thermal
        .as_ref()
        .map(|t| s.topics[t].frame_id.clone())
        .unwrap_or_default();
    let depth_from_thermal = match o.rig {
        Some(r) => Some(r.depth_from_thermal),
        None => static_lookup(&s.static_tf, &depth_frame, &thermal_frame),
    };
    if thermal.is_some() && depth_from_thermal.is_none() {
        missing.push(format!(
            "thermal extrinsic: no static transform from {depth_frame} to {thermal_frame} (give --rig from mrtmap calibrate)"
        ));
    }
    let depth_scale = o
        .depth_scale
        .or(o.rig.map(|r| r.depth_scale))
        .unwrap_or(1000.0);
    let rig = match (depth_cam, thermal_cam, depth_from_thermal) {
        (Some(d), Some(t), Some(x)) => {
            let rgb_frame = rgb.as_ref().map(|t| s.topics[t].frame_id.clone());
            let rgb_cam = rgb_cam.and_then(|c| {
                let x = rgb_frame
                    .as_deref()
                    .and_then(|f| static_lookup(&s.static_tf, &depth_frame, f))
                    .or(o.rig.and_then(|r| r.rgb.map(|c| c.depth_from_rgb)))?;
                Some(RgbCamera {
                    camera: c,
                    depth_from_rgb: x,
                })
            });
            Some(Rig {
                depth: d,
                depth_scale,
                thermal: t,
                thermal_encoding: ThermalEncoding::Centikelvin,
                depth_from_thermal: x,
                rgb: rgb_cam,
            })
        }
        _ => None,
    };
    if s.unfinished {
        notes.push("the file was cut or never closed: what was read is all there is".into());
    }
    for t in s.topics.values().filter(|t| t.undecodable > 0) {
        notes.push(format!(
            "{}: {} of {} messages do not decode ({})",
            t.topic,
            t.undecodable,
            t.count,
            t.first_error.clone().unwrap_or_default()
        ));
    }
    Plan {
        depth,
        thermal,
        rgb,
        poses,
        child_from_depth,
        rig,
        missing,
        notes,
    }
}

/// The child frame of a pose topic (Odometry names it; PoseStamped does not).
fn pose_child(s: &Survey, topic: &str) -> Option<String> {
    s.topics
        .get(topic)
        .map(|t| t.child_frame.clone())
        .filter(|c| !c.is_empty())
}

/// Decodes a depth image to 16-bit raw units (32FC1 metres → units of `scale`).
fn depth_image(i: &ros_msg::ImageMsg<'_>, scale: f64) -> Result<Image16, String> {
    let (w, h) = (i.width as usize, i.height as usize);
    let row = |y: usize| &i.data[y * i.step as usize..];
    let mut data = Vec::with_capacity(w * h);
    match i.encoding.as_str() {
        "16UC1" | "mono16" => {
            if (i.step as usize) < 2 * w {
                return Err(format!("step {} is below 2 × width {w}", i.step));
            }
            for y in 0..h {
                for c in row(y)[..2 * w].chunks_exact(2) {
                    data.push(if i.is_bigendian {
                        u16::from_be_bytes([c[0], c[1]])
                    } else {
                        u16::from_le_bytes([c[0], c[1]])
                    });
                }
            }
        }
        "32FC1" => {
            if (i.step as usize) < 4 * w {
                return Err(format!("step {} is below 4 × width {w}", i.step));
            }
            for y in 0..h {
                for c in row(y)[..4 * w].chunks_exact(4) {
                    let b = [c[0], c[1], c[2], c[3]];
                    let m = if i.is_bigendian {
                        f32::from_be_bytes(b)
                    } else {
                        f32::from_le_bytes(b)
                    } as f64;
                    data.push(if m.is_finite() && m > 0.0 {
                        (m * scale).round().min(65535.0) as u16
                    } else {
                        0
                    });
                }
            }
        }
        e => return Err(format!("depth encoding {e} (expected 16UC1 or 32FC1)")),
    }
    Ok(Image16 {
        width: i.width,
        height: i.height,
        data,
    })
}

/// A 16-bit image from an Image (16UC1/mono16, or 32FC1 metres × `scale`) or a CompressedImage
/// (a 16-bit PNG, or image_transport's compressedDepth: a 12-byte header, then the PNG).
fn image16_msg(
    m: &Message<'_>,
    kind: MsgKind,
    scale: f64,
    thermal: bool,
) -> Result<(f64, Image16), String> {
    if kind == MsgKind::CompressedImage {
        let c = ros_msg::compressed_image(m.data, m.wire, m.offset).map_err(|e| e.to_string())?;
        let png = if c.data.starts_with(b"\x89PNG") {
            c.data
        } else if c.format.contains("compressedDepth") && c.data.len() > 12 {
            &c.data[12..]
        } else {
            return Err(format!(
                "compressed image format {:?} is not a 16-bit PNG",
                c.format
            ));
        };
        let img = image::load_from_memory_with_format(png, image::ImageFormat::Png)
            .map_err(|e| format!("compressed image: {e}"))?;
        let image::DynamicImage::ImageLuma16(b) = img else {
            return Err(format!(
                "compressed image is {:?}, not 16-bit grey",
                img.color()
            ));
        };
        let (w, h) = b.dimensions();
        return Ok((
            stamp_or(c.header.stamp, m.time),
            Image16 {
                width: w,
                height: h,
                data: b.into_raw(),
            },
        ));
    }
    let i = ros_msg::image(m.data, m.wire, m.offset).map_err(|e| e.to_string())?;
    if thermal && !matches!(i.encoding.as_str(), "mono16" | "16UC1") {
        return Err(format!(
            "thermal encoding {} is not mono16/16UC1",
            i.encoding
        ));
    }
    Ok((stamp_or(i.header.stamp, m.time), depth_image(&i, scale)?))
}

/// A colour image as PNG/JPEG bytes and extension.
fn rgb_image(i: &ros_msg::ImageMsg<'_>) -> Result<Vec<u8>, String> {
    let (w, h) = (i.width as usize, i.height as usize);
    let (n, order): (usize, [usize; 3]) = match i.encoding.as_str() {
        "rgb8" => (3, [0, 1, 2]),
        "bgr8" => (3, [2, 1, 0]),
        "rgba8" => (4, [0, 1, 2]),
        "bgra8" => (4, [2, 1, 0]),
        "mono8" => (1, [0, 0, 0]),
        e => {
            return Err(format!(
                "colour encoding {e} (expected rgb8, bgr8, rgba8, bgra8, mono8)"
            ));
        }
    };
    if (i.step as usize) < n * w {
        return Err(format!("step {} is below {n} × width {w}", i.step));
    }
    let mut rgb = Vec::with_capacity(3 * w * h);
    for y in 0..h {
        let r = &i.data[y * i.step as usize..y * i.step as usize + n * w];
        for px in r.chunks_exact(n) {
            rgb.extend(order.iter().map(|&k| px[k]));
        }
    }
    Ok(encode_png_rgb8(i.width, i.height, &rgb))
}

/// Why a message was not written: it is unusable (skipped and counted), or the output cannot be
/// written (the export stops).
enum Step {
    Skip(String),
    Write(FileError),
}

impl From<String> for Step {
    fn from(s: String) -> Self {
        Self::Skip(s)
    }
}

/// What an export wrote and skipped.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ExportReport {
    /// Depth frames written.
    pub depth: usize,
    /// Thermal frames written.
    pub thermal: usize,
    /// Colour frames written.
    pub rgb: usize,
    /// Poses written.
    pub poses: usize,
    /// Messages skipped (did not decode or had the wrong size), with the first reasons.
    pub skipped: usize,
    /// The first few reasons.
    pub skipped_reasons: Vec<String>,
}

/// Writes the recording layout for a plan whose rig is complete.
pub fn export<'a>(
    path: &Path,
    file: impl Into<Input<'a>>,
    s: &Survey,
    p: &Plan,
    out: &Path,
) -> Result<ExportReport, FileError> {
    let file = file.into();
    let Some(rig) = p.rig else {
        return Err(FileError::new(
            path,
            None,
            FileErrorKind::Missing(format!("what a scan needs: {}", p.missing.join("; "))),
        ));
    };
    if !p.missing.is_empty() {
        return Err(FileError::new(
            path,
            None,
            FileErrorKind::Missing(format!("what a scan needs: {}", p.missing.join("; "))),
        ));
    }
    let mut w = LayoutWriter::create(out, &format!("converted by mrtmap from {}", path.display()))?;
    let mut rep = ExportReport::default();
    let mut err: Option<FileError> = None;
    let skip = |rep: &mut ExportReport, topic: &str, place: String, why: String| {
        rep.skipped += 1;
        if rep.skipped_reasons.len() < 5 {
            rep.skipped_reasons.push(format!("{topic} {place}: {why}"));
        }
    };
    let tf_pose = match &p.poses {
        Some(PoseSource::Tf(a, b)) => Some((a.clone(), b.clone())),
        _ => None,
    };
    let pose_topic = match &p.poses {
        Some(PoseSource::Topic(t)) => Some(t.clone()),
        _ => None,
    };
    let res = for_each(s.container, file, &mut |m| {
        let topic = Some(m.topic.to_string());
        let kind = MsgKind::of(m.datatype);
        let r: Result<(), Step> = (|| {
            if topic == p.depth {
                let (t, img) = image16_msg(&m, kind, rig.depth_scale, false)?;
                if (img.width, img.height) != (rig.depth.width, rig.depth.height) {
                    return Err(Step::Skip(format!(
                        "depth image is {}×{}, the depth camera {}×{}",
                        img.width, img.height, rig.depth.width, rig.depth.height
                    )));
                }
                w.depth(t, &img).map_err(Step::Write)?;
            } else if topic == p.thermal {
                let (t, img) = image16_msg(&m, kind, 1.0, true)?;
                if (img.width, img.height) != (rig.thermal.width, rig.thermal.height) {
                    return Err(Step::Skip(format!(
                        "thermal image is {}×{}, the thermal camera {}×{}",
                        img.width, img.height, rig.thermal.width, rig.thermal.height
                    )));
                }
                w.thermal(t, &img).map_err(Step::Write)?;
            } else if topic == p.rgb {
                if kind == MsgKind::CompressedImage {
                    let c = ros_msg::compressed_image(m.data, m.wire, m.offset)
                        .map_err(|e| e.to_string())?;
                    let ext = if c.data.starts_with(b"\x89PNG") {
                        "png"
                    } else {
                        "jpg"
                    };
                    w.rgb(stamp_or(c.header.stamp, m.time), c.data, ext)
                        .map_err(Step::Write)?;
                } else {
                    let i = ros_msg::image(m.data, m.wire, m.offset).map_err(|e| e.to_string())?;
                    let png = rgb_image(&i)?;
                    w.rgb(stamp_or(i.header.stamp, m.time), &png, "png")
                        .map_err(Step::Write)?;
                }
            } else if topic == pose_topic {
                let x = if kind == MsgKind::Odometry {
                    ros_msg::odometry(m.data, m.wire, m.offset)
                } else {
                    ros_msg::pose_stamped(m.data, m.wire, m.offset)
                }
                .map_err(|e| e.to_string())?;
                w.pose(stamp_or(x.stamp, m.time), x.transform * p.child_from_depth);
            } else if let Some((a, b)) = &tf_pose
                && kind == MsgKind::Tf
                && !m.topic.ends_with("tf_static")
            {
                for x in ros_msg::tf_message(m.data, m.wire, m.offset).map_err(|e| e.to_string())? {
                    if &x.parent == a && &x.child == b {
                        w.pose(stamp_or(x.stamp, m.time), x.transform * p.child_from_depth);
                    }
                }
            }
            Ok(())
        })();
        match r {
            Ok(()) => {}
            Err(Step::Write(e)) => {
                err = Some(e);
                return Err(Corrupt::new(m.offset, "stopped: cannot write the output"));
            }
            Err(Step::Skip(why)) => skip(&mut rep, m.topic, m.place(), why),
        }
        Ok(())
    });
    if let Some(e) = err {
        return Err(e);
    }
    res.map_err(|e| e.in_file(path))?;
    let (d, t, c, n) = w.counts();
    rep.depth = d;
    rep.thermal = t;
    rep.rgb = c;
    rep.poses = n;
    let source = serde_json::json!({
        "format": "mrtmap-source/1",
        "source": path.display().to_string(),
        "container": s.container,
        "plan": p,
        "export": &rep,
    });
    w.finish(
        &rig,
        &(serde_json::to_string_pretty(&source).unwrap_or_default() + "\n"),
    )?;
    Ok(rep)
}

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
    let kind = if head.starts_with(crate::bag::MAGIC) {
        SourceKind::Bag
    } else if head.starts_with(crate::mcap_file::MAGIC) {
        SourceKind::Mcap
    } else if head.starts_with(b"SQLite format 3\0") {
        match crate::rosbag2::open_file(path) {
            Ok(c) if crate::rosbag2::is_rosbag2(&c) => SourceKind::Db3,
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

/// Topic and frame names [`write_ros`] uses (RealSense driver + a PureThermal Lepton + a T265).
pub mod names {
    /// Depth aligned to colour.
    pub const DEPTH: &str = "/camera/aligned_depth_to_color/image_raw";
    /// Its CameraInfo.
    pub const DEPTH_INFO: &str = "/camera/aligned_depth_to_color/camera_info";
    /// Colour.
    pub const RGB: &str = "/camera/color/image_raw";
    /// Colour CameraInfo.
    pub const RGB_INFO: &str = "/camera/color/camera_info";
    /// Thermal (mono16 centikelvin).
    pub const THERMAL: &str = "/thermal/image_raw";
    /// Thermal CameraInfo.
    pub const THERMAL_INFO: &str = "/thermal/camera_info";
    /// Odometry.
    pub const ODOM: &str = "/camera/odom/sample";
    /// Depth (= colour) optical frame.
    pub const DEPTH_FRAME: &str = "camera_color_optical_frame";
    /// Thermal optical frame.
    pub const THERMAL_FRAME: &str = "thermal_optical_frame";
    /// Odometry child frame.
    pub const POSE_FRAME: &str = "camera_pose_frame";
    /// Odometry parent frame.
    pub const ODOM_FRAME: &str = "camera_odom_frame";
}

/// How [`write_ros`] writes.
#[derive(Clone, Copy, Debug)]
pub struct RosWriteOptions {
    /// Container.
    pub container: Container,
    /// Bag chunk compression (`None`, `Bz2`, `Lz4`) / MCAP (`None`, `Lz4`, or zstd for Bz2).
    pub compression: crate::bag::Compression,
    /// pose_frame_from_depth: where the tracking camera sits relative to the depth camera (a T265
    /// looks along its −z with x right and y up; the default turns the optical frame into it).
    pub pose_from_depth: Isometry3<f64>,
}

impl RosWriteOptions {
    /// A T265-like tracking frame 3 cm above the depth camera, looking the same way.
    pub fn t265_like(container: Container, compression: crate::bag::Compression) -> Self {
        // Optical (x right, y down, z forward) → T265 pose frame (x right, y up, z backward).
        let r = nalgebra::UnitQuaternion::from_axis_angle(
            &nalgebra::Vector3::x_axis(),
            std::f64::consts::PI,
        );
        Self {
            container,
            compression,
            pose_from_depth: Isometry3::from_parts(nalgebra::Translation3::new(0.0, 0.03, 0.0), r),
        }
    }
}

/// Writes a recording as a bag or MCAP file with RealSense-style topics ([`names`]): aligned
/// depth (16UC1), colour (rgb8), thermal (mono16), their CameraInfo, T265-style odometry of a
/// pose frame, and /tf_static tying the frames together.
pub fn write_ros(
    rec: &crate::recording::Recording,
    o: &RosWriteOptions,
) -> Result<Vec<u8>, FileError> {
    use crate::bag::{BagWriter, Compression};
    use crate::ros_msg::encode;
    let wire = match o.container {
        Container::Bag => Wire::Ros1,
        Container::Mcap | Container::Db3 => Wire::Cdr,
    };
    enum W {
        Bag(BagWriter),
        Mcap(Box<crate::mcap_file::McapWriter>),
        Db3(crate::rosbag2::Db3Writer),
    }
    let syntax = |e: String| FileError::new(&rec.dir, None, FileErrorKind::Syntax(e));
    let mut w = match o.container {
        Container::Bag => W::Bag(BagWriter::new(o.compression, 768 * 1024)),
        Container::Mcap => W::Mcap(Box::new(
            crate::mcap_file::McapWriter::new(
                match o.compression {
                    Compression::None => None,
                    Compression::Lz4 => Some("lz4"),
                    Compression::Bz2 => Some("zstd"),
                },
                768 * 1024,
            )
            .map_err(syntax)?,
        )),
        Container::Db3 => W::Db3(crate::rosbag2::Db3Writer::new().map_err(syntax)?),
    };
    let ty = |t: &str| -> String {
        match o.container {
            Container::Bag => t.to_string(),
            Container::Mcap | Container::Db3 => {
                let (pkg, name) = t.split_once('/').unwrap_or(("", t));
                format!("{pkg}/msg/{name}")
            }
        }
    };
    let mut put = |topic: &str, datatype: &str, t: f64, data: &[u8]| -> Result<(), FileError> {
        match &mut w {
            W::Bag(b) => {
                b.write(topic, &ty(datatype), t, data);
                Ok(())
            }
            W::Mcap(m) => m.write(topic, &ty(datatype), t, data).map_err(syntax),
            W::Db3(d) => d.write(topic, &ty(datatype), t, data).map_err(syntax),
        }
    };
    let rig = &rec.rig;
    let t0 = rec
        .depth
        .first()
        .map(|e| e.t)
        .unwrap_or(0.0)
        .min(rec.trajectory.stamps.first().copied().unwrap_or(0.0));
    // Static transforms first (latched in real bags).
    let mut statics = vec![
        (
            t0,
            names::DEPTH_FRAME,
            names::THERMAL_FRAME,
            rig.depth_from_thermal,
        ),
        (
            t0,
            names::POSE_FRAME,
            names::DEPTH_FRAME,
            o.pose_from_depth.inverse(),
        ),
    ];
    if let Some(c) = &rig.rgb
        && c.depth_from_rgb != Isometry3::identity()
    {
        statics.push((
            t0,
            names::DEPTH_FRAME,
            "camera_rgb_optical_frame",
            c.depth_from_rgb,
        ));
    }
    put(
        "/tf_static",
        "tf2_msgs/TFMessage",
        t0,
        &encode::tf_message(wire, &statics),
    )?;
    put(
        names::DEPTH_INFO,
        "sensor_msgs/CameraInfo",
        t0,
        &encode::camera_info(wire, t0, names::DEPTH_FRAME, &rig.depth),
    )?;
    put(
        names::THERMAL_INFO,
        "sensor_msgs/CameraInfo",
        t0,
        &encode::camera_info(wire, t0, names::THERMAL_FRAME, &rig.thermal),
    )?;
    let rgb_frame = match &rig.rgb {
        Some(c) if c.depth_from_rgb != Isometry3::identity() => "camera_rgb_optical_frame",
        _ => names::DEPTH_FRAME,
    };
    if let Some(c) = &rig.rgb {
        let frame = rgb_frame;
        put(
            names::RGB_INFO,
            "sensor_msgs/CameraInfo",
            t0,
            &encode::camera_info(wire, t0, frame, &c.camera),
        )?;
    }
    // Everything else in time order.
    enum Item<'a> {
        Depth(&'a crate::streams::StreamEntry),
        Thermal(&'a crate::streams::StreamEntry),
        Rgb(&'a crate::streams::StreamEntry),
        Pose(usize),
    }
    let mut items: Vec<(f64, Item<'_>)> = Vec::new();
    items.extend(rec.depth.iter().map(|e| (e.t, Item::Depth(e))));
    items.extend(rec.thermal.iter().map(|e| (e.t, Item::Thermal(e))));
    if rig.rgb.is_some() {
        items.extend(rec.rgb.iter().map(|e| (e.t, Item::Rgb(e))));
    }
    items.extend(
        rec.trajectory
            .stamps
            .iter()
            .enumerate()
            .map(|(i, &t)| (t, Item::Pose(i))),
    );
    items.sort_by(|a, b| a.0.total_cmp(&b.0));
    let le16 =
        |img: &Image16| -> Vec<u8> { img.data.iter().flat_map(|v| v.to_le_bytes()).collect() };
    for (t, item) in items {
        match item {
            Item::Depth(e) => {
                let img = rec.read_depth(e)?;
                let m = encode::image(
                    wire,
                    t,
                    names::DEPTH_FRAME,
                    img.width,
                    img.height,
                    "16UC1",
                    2 * img.width,
                    &le16(&img),
                );
                put(names::DEPTH, "sensor_msgs/Image", t, &m)?;
            }
            Item::Thermal(e) => {
                let img = rec.read_thermal(e)?;
                let m = encode::image(
                    wire,
                    t,
                    names::THERMAL_FRAME,
                    img.width,
                    img.height,
                    "mono16",
                    2 * img.width,
                    &le16(&img),
                );
                put(names::THERMAL, "sensor_msgs/Image", t, &m)?;
            }
            Item::Rgb(e) => {
                let p = rec.path_of(e);
                let img = image::open(&p)
                    .map_err(|er| FileError::new(&p, None, FileErrorKind::Image(er.to_string())))?
                    .to_rgb8();
                let (iw, ih) = img.dimensions();
                let m = encode::image(wire, t, rgb_frame, iw, ih, "rgb8", 3 * iw, img.as_raw());
                put(names::RGB, "sensor_msgs/Image", t, &m)?;
            }
            Item::Pose(i) => {
                let world_from_pose = rec.trajectory.poses[i] * o.pose_from_depth.inverse();
                let m = encode::odometry(
                    wire,
                    t,
                    names::ODOM_FRAME,
                    names::POSE_FRAME,
                    &world_from_pose,
                );
                put(names::ODOM, "nav_msgs/Odometry", t, &m)?;
            }
        }
    }
    match w {
        W::Bag(b) => Ok(b.finish()),
        W::Mcap(m) => m.finish().map_err(syntax),
        W::Db3(d) => d.finish().map_err(syntax),
    }
}

/// The frames of one mono16/16UC1 image topic, raw or as 16-bit PNGs (the thermal stream for a
/// source that lacks one): (stamp, image); the topic is `topic` or the plan's thermal choice.
pub fn image_frames<'a>(
    path: &Path,
    container: Container,
    file: impl Into<Input<'a>>,
    topic: Option<&str>,
) -> Result<(String, Vec<(f64, Image16)>), FileError> {
    let file = file.into();
    let topic = match topic {
        Some(t) => t.to_string(),
        None => {
            let s = survey(container, file).map_err(|e| e.in_file(path))?;
            let p = plan(&s, &RosOptions::default());
            p.thermal.ok_or_else(|| {
                FileError::new(
                    path,
                    None,
                    FileErrorKind::Missing(
                        "a mono16 thermal image topic (name one with --thermal-topic)".into(),
                    ),
                )
            })?
        }
    };
    let mut out = Vec::new();
    for_each(container, file, &mut |m| {
        if m.topic == topic {
            // Raw or 16-bit-PNG compressed, as the export reads thermal frames.
            out.push(
                image16_msg(&m, MsgKind::of(m.datatype), 1.0, true)
                    .map_err(|e| Corrupt::new(m.offset, e))?,
            );
        }
        Ok(())
    })
    .map_err(|e| e.in_file(path))?;
    Ok((topic, out))
}

/// The identity pose (for callers that do not depend on nalgebra).
pub fn identity() -> Isometry3<f64> {
    Isometry3::identity()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn static_lookup_walks_both_directions() {
        let a_b = Isometry3::new(Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 0.0, 0.3));
        let c_b = Isometry3::new(Vector3::new(0.0, 2.0, 0.0), Vector3::new(0.2, 0.0, 0.0));
        let tfs = vec![
            StampedTransform {
                stamp: 0.0,
                parent: "a".into(),
                child: "b".into(),
                transform: a_b,
            },
            StampedTransform {
                stamp: 0.0,
                parent: "/c".into(),
                child: "b".into(),
                transform: c_b,
            },
        ];
        let a_c = static_lookup(&tfs, "a", "c").unwrap();
        let want = a_b * c_b.inverse();
        assert!((a_c.translation.vector - want.translation.vector).norm() < 1e-12);
        assert!(static_lookup(&tfs, "a", "zzz").is_none());
        assert_eq!(static_lookup(&tfs, "x", "/x"), Some(Isometry3::identity()));
        assert_eq!(
            info_topic_for("/camera/color/image_raw/compressed"),
            "/camera/color/camera_info"
        );
    }
}
