//! One pass over a file: its topics, counts, rates, image encodings and sizes, camera infos and
//! transforms (images are not decoded).

use std::collections::{BTreeMap, HashMap};

use serde::Serialize;

use super::msg::{self as ros_msg, CameraInfoMsg, MsgKind, StampedTransform};
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
