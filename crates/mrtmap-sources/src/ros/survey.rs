//! One pass over a file: its topics, counts, rates, image encodings and sizes, camera infos and
//! transforms (images are not decoded).

use std::collections::{BTreeMap, HashMap};

use serde::Serialize;

use super::msg::{self as ros_msg, CameraInfoMsg, Message, MsgKind, StampedTransform};
use super::read::{Container, Input, for_each};
use mrtmap_io::bytes::Corrupt;

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

pub(super) fn stamp_or(t: f64, record: f64) -> f64 {
    if t > 0.0 { t } else { record }
}

impl Survey {
    /// Takes in one message: decodes what a scan needs to know (encodings, sizes, frames, camera
    /// infos, transforms) into `st`, the message's topic; returns the message's stamp.
    fn take(&mut self, m: &Message<'_>, st: &mut TopicStats) -> Result<f64, Corrupt> {
        let (data, wire, at) = (m.data, m.wire, m.offset);
        let kind = MsgKind::of(m.datatype);
        let t = match kind {
            MsgKind::Image => {
                let i = ros_msg::image(data, wire, at)?;
                st.encoding = i.encoding;
                st.frame_id = i.header.frame_id;
                st.size = Some((i.width, i.height));
                i.header.stamp
            }
            MsgKind::CompressedImage => {
                let i = ros_msg::compressed_image(data, wire, at)?;
                st.encoding = i.format;
                st.frame_id = i.header.frame_id;
                i.header.stamp
            }
            MsgKind::CameraInfo => {
                let i = ros_msg::camera_info(data, wire, at)?;
                st.frame_id = i.header.frame_id.clone();
                st.size = Some((i.width, i.height));
                let t = i.header.stamp;
                self.infos.insert(m.topic.to_string(), i);
                t
            }
            MsgKind::Odometry | MsgKind::PoseStamped => {
                let p = if kind == MsgKind::Odometry {
                    ros_msg::odometry(data, wire, at)?
                } else {
                    ros_msg::pose_stamped(data, wire, at)?
                };
                st.frame_id = p.parent;
                st.child_frame = p.child;
                p.stamp
            }
            MsgKind::Imu => {
                let i = ros_msg::imu(data, wire, at)?;
                st.frame_id = i.header.frame_id;
                i.header.stamp
            }
            MsgKind::Tf | MsgKind::TransformStamped => {
                let tfs = if kind == MsgKind::Tf {
                    ros_msg::tf_message(data, wire, at)?
                } else {
                    vec![ros_msg::transform_stamped_msg(data, wire, at)?]
                };
                let is_static = m.topic.ends_with("tf_static");
                for tf in tfs {
                    if is_static {
                        self.static_tf.push(tf);
                    } else {
                        *self.dynamic_tf.entry((tf.parent, tf.child)).or_default() += 1;
                    }
                }
                return Ok(m.time);
            }
            MsgKind::Other => return Ok(m.time),
        };
        Ok(stamp_or(t, m.time))
    }
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
        let mut st = s.topics.remove(m.topic).unwrap_or_else(|| TopicStats {
            topic: m.topic.to_string(),
            datatype: m.datatype.to_string(),
            t0: f64::INFINITY,
            t1: f64::NEG_INFINITY,
            ..Default::default()
        });
        st.count += 1;
        let t = match s.take(&m, &mut st) {
            Ok(t) => t,
            Err(e) => {
                st.undecodable += 1;
                if st.first_error.is_none() {
                    st.first_error = Some(e.in_record(m.record).to_string());
                }
                m.time
            }
        };
        st.t0 = st.t0.min(t);
        st.t1 = st.t1.max(t);
        s.topics.insert(m.topic.to_string(), st);
        Ok(())
    })?;
    s.unfinished = unfinished;
    Ok(s)
}
