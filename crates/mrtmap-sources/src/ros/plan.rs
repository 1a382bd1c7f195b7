//! Choosing the streams of a scan in a surveyed file and assembling the rig.
//!
//! Defaults follow the RealSense ROS driver (`/camera/aligned_depth_to_color/image_raw`,
//! `/camera/color/image_raw`, `/camera/odom/sample` of a T265, `/tf_static`); a thermal stream is
//! any `mono16` image topic (a Lepton on a PureThermal board publishes TLinear centikelvin). Every
//! choice can be named with [`RosOptions`]. Poses come from an `Odometry` / `PoseStamped` topic or
//! from `/tf`, and are carried to the depth camera through the static transforms.

use std::collections::HashMap;

use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use mrtmap_geometry::nalgebra::Isometry3;
use mrtmap_io::{RgbCamera, Rig, ThermalEncoding};
use serde::Serialize;

use super::msg::{CameraInfoMsg, MsgKind, StampedTransform};
use super::survey::{Survey, TopicStats};

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
    /// The gyro's sensor_msgs/Imu topic (a united IMU topic carries the accelerometer too).
    pub gyro: Option<String>,
    /// The accelerometer's, when on a topic of its own.
    pub accel: Option<String>,
    /// depth camera ← the gyro's and the accelerometer's frames (through /tf_static; identity
    /// when not found).
    #[serde(skip)]
    pub depth_from_imu: [Isometry3<f64>; 2],
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
/// A D435i/D455 under realsense-ros: one topic with `unite_imu_method`, else two.
const IMU_UNITED: &str = "/camera/imu";
const GYRO_DEFAULT: &str = "/camera/gyro/sample";
const ACCEL_DEFAULT: &str = "/camera/accel/sample";

/// The IMU topics: a united one, or the gyro's and the accelerometer's, or any Imu topic; with
/// their frames' rotations into the depth camera.
fn imu_topics(
    s: &Survey,
    depth_frame: &str,
    notes: &mut Vec<String>,
) -> (Option<String>, Option<String>, [Isometry3<f64>; 2]) {
    let is_imu = |t: &str| {
        s.topics
            .get(t)
            .is_some_and(|x| MsgKind::of(&x.datatype) == MsgKind::Imu)
    };
    let (gyro, accel) = if is_imu(IMU_UNITED) {
        (Some(IMU_UNITED.to_string()), None)
    } else if is_imu(GYRO_DEFAULT) {
        (
            Some(GYRO_DEFAULT.to_string()),
            is_imu(ACCEL_DEFAULT).then(|| ACCEL_DEFAULT.to_string()),
        )
    } else {
        let any = s
            .topics
            .values()
            .find(|t| MsgKind::of(&t.datatype) == MsgKind::Imu)
            .map(|t| t.topic.clone());
        (any, None)
    };
    let mut rot = |t: &Option<String>| {
        let frame = frame_of(s, t)?;
        match static_lookup(&s.static_tf, depth_frame, &frame) {
            Some(x) => Some(x),
            None => {
                notes.push(format!(
                    "no static transform from the IMU frame {frame} to the depth camera {depth_frame}: its axes are taken as the depth camera's"
                ));
                None
            }
        }
    };
    let g = rot(&gyro).unwrap_or_else(Isometry3::identity);
    let a = if accel.is_some() {
        rot(&accel).unwrap_or_else(Isometry3::identity)
    } else {
        g
    };
    if let Some(t) = &gyro {
        notes.push(match &accel {
            Some(a) => {
                format!("inertial samples from {t} (gyro) and {a} (accelerometer) into imu.txt")
            }
            None => format!("inertial samples from {t} into imu.txt"),
        });
    }
    (gyro, accel, [g, a])
}

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

fn is_image(t: &TopicStats) -> bool {
    matches!(
        MsgKind::of(&t.datatype),
        MsgKind::Image | MsgKind::CompressedImage
    )
}

/// The image topics of a scan: depth, thermal and colour.
fn image_topics(
    s: &Survey,
    o: &RosOptions,
    missing: &mut Vec<String>,
) -> (Option<String>, Option<String>, Option<String>) {
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
        missing,
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
        missing,
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
        missing,
    );
    if depth.is_none() && o.depth_topic.is_none() {
        missing.push(
            "depth images: no 16UC1/32FC1 depth image topic (name one with --depth-topic)".into(),
        );
    }
    if thermal.is_none() && o.thermal_topic.is_none() {
        missing
            .push("thermal images: no mono16 image topic (name one with --thermal-topic)".into());
    }
    (depth, thermal, rgb)
}

/// Where poses come from: an Odometry or PoseStamped topic, else a dynamic transform whose child
/// reaches the depth camera through static ones; none with colour images (tracked later).
fn pose_source(
    s: &Survey,
    o: &RosOptions,
    depth_frame: &str,
    has_colour: bool,
    missing: &mut Vec<String>,
    notes: &mut Vec<String>,
) -> Option<PoseSource> {
    let topic = pick(
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
        missing,
    );
    if topic.is_some() || o.pose_topic.is_some() {
        return topic.map(PoseSource::Topic);
    }
    let best = s
        .dynamic_tf
        .iter()
        .filter(|((_, c), _)| static_lookup(&s.static_tf, c, depth_frame).is_some())
        .max_by_key(|(_, n)| **n);
    match best {
        Some(((p, c), _)) => {
            notes.push(format!("poses from /tf: {p} → {c}"));
            Some(PoseSource::Tf(p.clone(), c.clone()))
        }
        None if has_colour => {
            notes.push(
                "no poses (no Odometry or PoseStamped topic, no /tf transform that reaches the depth camera): the recording gets no trajectory.txt, and `mrtmap run` tracks the camera from colour and depth"
                    .into(),
            );
            None
        }
        None => {
            missing.push(
                "poses: no Odometry or PoseStamped topic, and no /tf transform that reaches the depth camera (name one with --pose-topic), nor colour images to track the camera with"
                    .into(),
            );
            None
        }
    }
}

/// The pose frame's transform to the depth camera through /tf_static (identity when none).
fn child_to_depth(
    s: &Survey,
    poses: &Option<PoseSource>,
    depth_frame: &str,
    notes: &mut Vec<String>,
) -> Isometry3<f64> {
    match poses {
        Some(PoseSource::Topic(t)) => {
            let child = pose_child(s, t);
            match child
                .as_deref()
                .and_then(|c| static_lookup(&s.static_tf, c, depth_frame))
            {
                Some(x) => {
                    if x != Isometry3::identity() {
                        notes.push(format!(
                            "poses of {} carried to the depth camera {depth_frame} through /tf_static",
                            child.unwrap_or_default()
                        ));
                    }
                    x
                }
                None => {
                    notes.push(format!(
                        "no static transform from the pose frame {} to the depth camera {depth_frame}: the poses are taken as the depth camera's own",
                        child.unwrap_or_else(|| "(unnamed)".into())
                    ));
                    Isometry3::identity()
                }
            }
        }
        Some(PoseSource::Tf(_, c)) => {
            static_lookup(&s.static_tf, c, depth_frame).unwrap_or_else(Isometry3::identity)
        }
        None => Isometry3::identity(),
    }
}

/// The frame id of a topic's messages.
fn frame_of(s: &Survey, topic: &Option<String>) -> Option<String> {
    topic.as_ref().map(|t| s.topics[t].frame_id.clone())
}

/// The rig from CameraInfo and /tf_static, with what a rig.toml supplies; what is missing is said.
fn assemble_rig(
    s: &Survey,
    o: &RosOptions,
    (depth, thermal, rgb): (&Option<String>, &Option<String>, &Option<String>),
    missing: &mut Vec<String>,
) -> Option<Rig> {
    let info_of = |topic: &Option<String>| {
        topic
            .as_ref()
            .and_then(|t| s.infos.get(&info_topic_for(t)).and_then(camera_from_info))
    };
    let depth_frame = frame_of(s, depth).unwrap_or_default();
    let depth_cam = info_of(depth).or(o.rig.map(|r| r.depth));
    let rgb_cam = info_of(rgb).or(o.rig.and_then(|r| r.rgb.map(|c| c.camera)));
    let thermal_cam = o.rig.map(|r| r.thermal).or_else(|| info_of(thermal));
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
    let thermal_frame = frame_of(s, thermal).unwrap_or_default();
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
    let (d, t, x) = (depth_cam?, thermal_cam?, depth_from_thermal?);
    let rgb_frame = frame_of(s, rgb);
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
        thermal_accuracy_k: None,
        thermal_time_offset_s: None,
        depth_from_thermal: x,
        rgb: rgb_cam,
    })
}

/// Chooses streams and assembles the rig.
pub fn plan(s: &Survey, o: &RosOptions) -> Plan {
    let mut missing = Vec::new();
    let mut notes = Vec::new();
    let (depth, thermal, rgb) = image_topics(s, o, &mut missing);
    let depth_frame = frame_of(s, &depth).unwrap_or_default();
    let poses = pose_source(s, o, &depth_frame, rgb.is_some(), &mut missing, &mut notes);
    let child_from_depth = child_to_depth(s, &poses, &depth_frame, &mut notes);
    let rig = assemble_rig(s, o, (&depth, &thermal, &rgb), &mut missing);
    let (gyro, accel, depth_from_imu) = imu_topics(s, &depth_frame, &mut notes);
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
        gyro,
        accel,
        depth_from_imu,
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
