//! The ROS messages a scan needs, decoded from ROS 1 serialisation (bags) or CDR (ROS 2, MCAP):
//! `sensor_msgs/Image`, `CompressedImage`, `CameraInfo`, `nav_msgs/Odometry`,
//! `geometry_msgs/PoseStamped`, `TransformStamped`, `tf2_msgs/TFMessage`, `sensor_msgs/Imu`. One decoder serves both
//! encodings (the field order is the same; ROS 1 headers carry a `seq`, CDR aligns and
//! NUL-terminates strings), every length is checked against what is left, and errors carry the
//! byte offset.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use mrtmap_io::bytes::{Bytes, Corrupt, Cursor, Endian};

/// How a message is serialised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wire {
    /// ROS 1.
    Ros1,
    /// CDR with its 4-byte encapsulation header (ROS 2).
    Cdr,
}

/// One stored message of a bag, an MCAP file or a rosbag2 SQLite file, still serialised.
#[derive(Clone, Copy, Debug)]
pub struct Message<'a> {
    /// Topic.
    pub topic: &'a str,
    /// Type name (`sensor_msgs/Image`, `sensor_msgs/msg/Image`).
    pub datatype: &'a str,
    /// Record (log) time, s.
    pub time: f64,
    /// Serialised bytes.
    pub data: &'a [u8],
    /// Serialisation.
    pub wire: Wire,
    /// File offset of the data (inside a compressed chunk: the chunk's offset; in a database: 0).
    pub offset: u64,
    /// The row id in a rosbag2 SQLite file's `messages` table.
    pub record: Option<u64>,
}

impl Message<'_> {
    /// Where the message is, for reports: `at byte N` or `message N`.
    pub fn place(&self) -> String {
        match self.record {
            Some(r) => format!("message {r}"),
            None => format!("at byte {}", self.offset),
        }
    }
}

/// A message's stamp and frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// Seconds.
    pub stamp: f64,
    /// Frame id.
    pub frame_id: String,
}

/// `sensor_msgs/Image`.
#[derive(Clone, Debug)]
pub struct ImageMsg<'a> {
    /// Header.
    pub header: Header,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Pixel encoding (`16UC1`, `mono16`, `rgb8`, …).
    pub encoding: String,
    /// Big-endian samples.
    pub is_bigendian: bool,
    /// Bytes per row.
    pub step: u32,
    /// Pixels.
    pub data: &'a [u8],
}

/// `sensor_msgs/CompressedImage`.
#[derive(Clone, Debug)]
pub struct CompressedImageMsg<'a> {
    /// Header.
    pub header: Header,
    /// `jpeg`, `png`, or image_transport's `16UC1; compressedDepth png`.
    pub format: String,
    /// Bytes.
    pub data: &'a [u8],
}

/// `sensor_msgs/CameraInfo` (the parts a pinhole model needs).
#[derive(Clone, Debug, PartialEq)]
pub struct CameraInfoMsg {
    /// Header.
    pub header: Header,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// `plumb_bob`, `rational_polynomial`, …
    pub distortion_model: String,
    /// Distortion coefficients.
    pub d: Vec<f64>,
    /// Intrinsic matrix, row-major.
    pub k: [f64; 9],
}

/// A stamped pose of `child` in `parent`.
#[derive(Clone, Debug, PartialEq)]
pub struct StampedTransform {
    /// Stamp, s.
    pub stamp: f64,
    /// Parent frame.
    pub parent: String,
    /// Child frame (empty when the message does not name it).
    pub child: String,
    /// parent_from_child.
    pub transform: Isometry3<f64>,
}

fn cursor<'a>(data: &'a [u8], wire: Wire, base: u64) -> Result<Cursor<'a>, Corrupt> {
    let b = Bytes {
        data,
        base,
        endian: Endian::Little,
    };
    match wire {
        Wire::Ros1 => Ok(Cursor::packed(b)),
        Wire::Cdr => {
            let h = b.slice(0, 4, "the CDR encapsulation header")?;
            let endian = match h[1] {
                0 | 2 => Endian::Big,
                1 | 3 => Endian::Little,
                k => return Err(b.err(1, format!("unknown CDR representation {k}"))),
            };
            Ok(Cursor::aligned(b.with_endian(endian), 4))
        }
    }
}

fn header(c: &mut Cursor<'_>) -> Result<Header, Corrupt> {
    let ros1 = c.align_origin.is_none();
    if ros1 {
        c.u32("header.seq")?;
    }
    let sec = if ros1 {
        c.u32("header.stamp.sec")? as f64
    } else {
        c.i32("header.stamp.sec")? as f64
    };
    let nsec = c.u32("header.stamp.nsec")?;
    let frame_id = c.string("header.frame_id")?;
    Ok(Header {
        stamp: sec + nsec as f64 * 1e-9,
        frame_id,
    })
}

fn pose(c: &mut Cursor<'_>, what: &str) -> Result<Isometry3<f64>, Corrupt> {
    let v = c.f64s(7, what)?;
    let q = Quaternion::new(v[6], v[3], v[4], v[5]);
    let n = q.norm();
    if !(n.is_finite() && (n - 1.0).abs() < 1e-2) || v[..3].iter().any(|x| !x.is_finite()) {
        return Err(c.err(format!(
            "{what}: orientation (x y z w) = ({}, {}, {}, {}) is not a unit quaternion, or the position is not finite",
            v[3], v[4], v[5], v[6]
        )));
    }
    Ok(Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_quaternion(q),
    ))
}

/// Decodes `sensor_msgs/Image`, checking that `data` holds `step × height` bytes.
pub fn image(data: &[u8], wire: Wire, base: u64) -> Result<ImageMsg<'_>, Corrupt> {
    let mut c = cursor(data, wire, base)?;
    let header = header(&mut c)?;
    let height = c.u32("height")?;
    let width = c.u32("width")?;
    let encoding = c.string("encoding")?;
    let is_bigendian = c.u8("is_bigendian")? != 0;
    let step = c.u32("step")?;
    let data = c.byte_seq("data")?;
    if (step as u64) * (height as u64) > data.len() as u64 || width == 0 || height == 0 {
        return Err(c.err(format!(
            "image of {width}×{height} pixels with {step} bytes per row has {} bytes of data",
            data.len()
        )));
    }
    Ok(ImageMsg {
        header,
        height,
        width,
        encoding,
        is_bigendian,
        step,
        data,
    })
}

/// Decodes `sensor_msgs/CompressedImage`.
pub fn compressed_image(
    data: &[u8],
    wire: Wire,
    base: u64,
) -> Result<CompressedImageMsg<'_>, Corrupt> {
    let mut c = cursor(data, wire, base)?;
    Ok(CompressedImageMsg {
        header: header(&mut c)?,
        format: c.string("format")?,
        data: c.byte_seq("data")?,
    })
}

/// Decodes `sensor_msgs/CameraInfo` (ROS 1 `D`/`K` and ROS 2 `d`/`k` alike).
pub fn camera_info(data: &[u8], wire: Wire, base: u64) -> Result<CameraInfoMsg, Corrupt> {
    let mut c = cursor(data, wire, base)?;
    let header = header(&mut c)?;
    let height = c.u32("height")?;
    let width = c.u32("width")?;
    let distortion_model = c.string("distortion_model")?;
    let d = c.f64_seq("D")?;
    let kv = c.f64s(9, "K")?;
    let mut k = [0.0; 9];
    k.copy_from_slice(&kv);
    Ok(CameraInfoMsg {
        header,
        height,
        width,
        distortion_model,
        d,
        k,
    })
}

/// Decodes `nav_msgs/Odometry` → world_from_child.
pub fn odometry(data: &[u8], wire: Wire, base: u64) -> Result<StampedTransform, Corrupt> {
    let mut c = cursor(data, wire, base)?;
    let h = header(&mut c)?;
    let child = c.string("child_frame_id")?;
    let transform = pose(&mut c, "pose.pose")?;
    Ok(StampedTransform {
        stamp: h.stamp,
        parent: h.frame_id,
        child,
        transform,
    })
}

/// `sensor_msgs/Imu`: angular velocity (rad/s) and linear acceleration (m/s²) in the header's
/// frame. A RealSense publishing gyro and accelerometer on separate topics fills only one of them
/// in each message (the other zero).
#[derive(Clone, Debug, PartialEq)]
pub struct ImuMsg {
    /// Stamp and frame.
    pub header: Header,
    /// rad/s.
    pub angular_velocity: nalgebra::Vector3<f64>,
    /// m/s².
    pub linear_acceleration: nalgebra::Vector3<f64>,
}

/// Decodes `sensor_msgs/Imu` (the orientation and covariances are skipped).
pub fn imu(data: &[u8], wire: Wire, base: u64) -> Result<ImuMsg, Corrupt> {
    let mut c = cursor(data, wire, base)?;
    let header = header(&mut c)?;
    c.f64s(4 + 9, "orientation")?;
    let w = c.f64s(3, "angular_velocity")?;
    c.f64s(9, "angular_velocity_covariance")?;
    let a = c.f64s(3, "linear_acceleration")?;
    if w.iter().chain(a.iter()).any(|x| !x.is_finite()) {
        return Err(c.err("angular velocity or acceleration is not finite"));
    }
    Ok(ImuMsg {
        header,
        angular_velocity: nalgebra::Vector3::new(w[0], w[1], w[2]),
        linear_acceleration: nalgebra::Vector3::new(a[0], a[1], a[2]),
    })
}

/// Decodes `geometry_msgs/PoseStamped` → world_from_body (child unnamed).
pub fn pose_stamped(data: &[u8], wire: Wire, base: u64) -> Result<StampedTransform, Corrupt> {
    let mut c = cursor(data, wire, base)?;
    let h = header(&mut c)?;
    let transform = pose(&mut c, "pose")?;
    Ok(StampedTransform {
        stamp: h.stamp,
        parent: h.frame_id,
        child: String::new(),
        transform,
    })
}

fn transform_stamped(c: &mut Cursor<'_>) -> Result<StampedTransform, Corrupt> {
    let h = header(c)?;
    let child = c.string("child_frame_id")?;
    let transform = pose(c, "transform")?;
    Ok(StampedTransform {
        stamp: h.stamp,
        parent: h.frame_id,
        child,
        transform,
    })
}

/// Decodes `tf2_msgs/TFMessage` (also `tf/tfMessage`).
pub fn tf_message(data: &[u8], wire: Wire, base: u64) -> Result<Vec<StampedTransform>, Corrupt> {
    let mut c = cursor(data, wire, base)?;
    let n = c.u32("transforms")? as usize;
    // A TransformStamped takes at least 72 bytes: check the count before reserving.
    if n > c.remaining() / 72 {
        return Err(c.err(format!(
            "{n} transforms cannot fit in the {} bytes left",
            c.remaining()
        )));
    }
    (0..n).map(|_| transform_stamped(&mut c)).collect()
}

/// Decodes `geometry_msgs/TransformStamped`.
pub fn transform_stamped_msg(
    data: &[u8],
    wire: Wire,
    base: u64,
) -> Result<StampedTransform, Corrupt> {
    let mut c = cursor(data, wire, base)?;
    transform_stamped(&mut c)
}

/// Which decoder a ROS type name needs (ROS 1 `pkg/Type`, ROS 2 `pkg/msg/Type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MsgKind {
    /// sensor_msgs/Image.
    Image,
    /// sensor_msgs/CompressedImage.
    CompressedImage,
    /// sensor_msgs/CameraInfo.
    CameraInfo,
    /// nav_msgs/Odometry.
    Odometry,
    /// geometry_msgs/PoseStamped.
    PoseStamped,
    /// geometry_msgs/TransformStamped.
    TransformStamped,
    /// sensor_msgs/Imu.
    Imu,
    /// tf2_msgs/TFMessage.
    Tf,
    /// Anything else.
    Other,
}

impl MsgKind {
    /// From a type name.
    pub fn of(datatype: &str) -> Self {
        let name = datatype.rsplit('/').next().unwrap_or("");
        let pkg = datatype.split('/').next().unwrap_or("");
        match (pkg, name) {
            ("sensor_msgs", "Image") => Self::Image,
            ("sensor_msgs", "CompressedImage") => Self::CompressedImage,
            ("sensor_msgs", "CameraInfo") => Self::CameraInfo,
            ("nav_msgs", "Odometry") => Self::Odometry,
            ("geometry_msgs", "PoseStamped") => Self::PoseStamped,
            ("geometry_msgs", "TransformStamped") => Self::TransformStamped,
            ("sensor_msgs", "Imu") => Self::Imu,
            ("tf2_msgs" | "tf", "TFMessage" | "tfMessage") => Self::Tf,
            _ => Self::Other,
        }
    }
}

/// Serialisers for tests, fuzz seeds and `convert`'s round trips: the same layouts as ROS.
pub mod encode {
    use super::Wire;
    use nalgebra::Isometry3;

    /// A message being written.
    pub struct Writer {
        wire: Wire,
        buf: Vec<u8>,
    }

    impl Writer {
        /// Starts a message (CDR gets its little-endian encapsulation header).
        pub fn new(wire: Wire) -> Self {
            let buf = match wire {
                Wire::Ros1 => Vec::new(),
                Wire::Cdr => vec![0, 1, 0, 0],
            };
            Self { wire, buf }
        }

        fn align(&mut self, n: usize) {
            if self.wire == Wire::Cdr {
                while !(self.buf.len() - 4).is_multiple_of(n) {
                    self.buf.push(0);
                }
            }
        }

        /// u8.
        pub fn u8(&mut self, v: u8) -> &mut Self {
            self.buf.push(v);
            self
        }

        /// u32.
        pub fn u32(&mut self, v: u32) -> &mut Self {
            self.align(4);
            self.buf.extend_from_slice(&v.to_le_bytes());
            self
        }

        /// f64.
        pub fn f64(&mut self, v: f64) -> &mut Self {
            self.align(8);
            self.buf.extend_from_slice(&v.to_le_bytes());
            self
        }

        /// A string.
        pub fn string(&mut self, s: &str) -> &mut Self {
            let extra = usize::from(self.wire == Wire::Cdr);
            self.u32((s.len() + extra) as u32);
            self.buf.extend_from_slice(s.as_bytes());
            if extra == 1 {
                self.buf.push(0);
            }
            self
        }

        /// A byte sequence.
        pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
            self.u32(b.len() as u32);
            self.buf.extend_from_slice(b);
            self
        }

        /// A std_msgs/Header.
        pub fn header(&mut self, stamp: f64, frame: &str) -> &mut Self {
            if self.wire == Wire::Ros1 {
                self.u32(0);
            }
            let sec = stamp.floor();
            self.u32(sec as u32);
            self.u32(((stamp - sec) * 1e9).round().min(999_999_999.0) as u32);
            self.string(frame)
        }

        /// A geometry_msgs/Pose (or Transform: the same seven numbers).
        pub fn pose(&mut self, p: &Isometry3<f64>) -> &mut Self {
            let t = p.translation.vector;
            let q = p.rotation.quaternion();
            for v in [t.x, t.y, t.z, q.i, q.j, q.k, q.w] {
                self.f64(v);
            }
            self
        }

        /// The bytes.
        pub fn finish(&mut self) -> Vec<u8> {
            std::mem::take(&mut self.buf)
        }
    }

    /// sensor_msgs/Image.
    #[allow(clippy::too_many_arguments)]
    pub fn image(
        wire: Wire,
        stamp: f64,
        frame: &str,
        width: u32,
        height: u32,
        encoding: &str,
        step: u32,
        data: &[u8],
    ) -> Vec<u8> {
        Writer::new(wire)
            .header(stamp, frame)
            .u32(height)
            .u32(width)
            .string(encoding)
            .u8(0)
            .u32(step)
            .bytes(data)
            .finish()
    }

    /// sensor_msgs/CompressedImage.
    pub fn compressed_image(
        wire: Wire,
        stamp: f64,
        frame: &str,
        format: &str,
        data: &[u8],
    ) -> Vec<u8> {
        Writer::new(wire)
            .header(stamp, frame)
            .string(format)
            .bytes(data)
            .finish()
    }

    /// sensor_msgs/CameraInfo with a plumb_bob model and identity R.
    pub fn camera_info(
        wire: Wire,
        stamp: f64,
        frame: &str,
        cam: &mrtmap_geometry::camera::PinholeCamera,
    ) -> Vec<u8> {
        let mut w = Writer::new(wire);
        w.header(stamp, frame)
            .u32(cam.height)
            .u32(cam.width)
            .string("plumb_bob")
            .u32(5);
        for d in cam.distortion.to_array() {
            w.f64(d);
        }
        for k in [cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0] {
            w.f64(k);
        }
        for r in [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0] {
            w.f64(r);
        }
        for p in [
            cam.fx, 0.0, cam.cx, 0.0, 0.0, cam.fy, cam.cy, 0.0, 0.0, 0.0, 1.0, 0.0,
        ] {
            w.f64(p);
        }
        w.u32(0).u32(0);
        w.u32(0).u32(0).u32(0).u32(0).u8(0);
        w.finish()
    }

    /// nav_msgs/Odometry (zero covariances and twist).
    pub fn odometry(
        wire: Wire,
        stamp: f64,
        frame: &str,
        child: &str,
        p: &Isometry3<f64>,
    ) -> Vec<u8> {
        let mut w = Writer::new(wire);
        w.header(stamp, frame).string(child).pose(p);
        for _ in 0..36 {
            w.f64(0.0);
        }
        for _ in 0..(6 + 36) {
            w.f64(0.0);
        }
        w.finish()
    }

    /// sensor_msgs/Imu (identity orientation, zero covariances).
    pub fn imu(wire: Wire, stamp: f64, frame: &str, gyro: [f64; 3], accel: [f64; 3]) -> Vec<u8> {
        let mut w = Writer::new(wire);
        w.header(stamp, frame);
        for v in [0.0, 0.0, 0.0, 1.0] {
            w.f64(v);
        }
        for _ in 0..9 {
            w.f64(0.0);
        }
        for v in gyro {
            w.f64(v);
        }
        for _ in 0..9 {
            w.f64(0.0);
        }
        for v in accel {
            w.f64(v);
        }
        for _ in 0..9 {
            w.f64(0.0);
        }
        w.finish()
    }

    /// tf2_msgs/TFMessage.
    pub fn tf_message(wire: Wire, transforms: &[(f64, &str, &str, Isometry3<f64>)]) -> Vec<u8> {
        let mut w = Writer::new(wire);
        w.u32(transforms.len() as u32);
        for (stamp, parent, child, p) in transforms {
            w.header(*stamp, parent).string(child).pose(p);
        }
        w.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn both_wires_round_trip_every_message() {
        let p = Isometry3::new(Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.1, 0.2, -0.3));
        let cam = mrtmap_geometry::camera::PinholeCamera::new(640, 480, 600.0, 601.0, 320.5, 240.5);
        for wire in [Wire::Ros1, Wire::Cdr] {
            let px: Vec<u8> = (0..8u8).collect();
            let m = encode::image(wire, 12.25, "cam", 2, 2, "16UC1", 4, &px);
            let i = image(&m, wire, 0).unwrap();
            assert_eq!((i.width, i.height, i.encoding.as_str()), (2, 2, "16UC1"));
            assert!((i.header.stamp - 12.25).abs() < 1e-9);
            assert_eq!(i.header.frame_id, "cam");
            assert_eq!(i.data, &px[..]);
            let ci = camera_info(&encode::camera_info(wire, 1.0, "cam", &cam), wire, 0).unwrap();
            assert_eq!((ci.width, ci.height), (640, 480));
            assert_eq!(ci.k[0], 600.0);
            assert_eq!(ci.k[5], 240.5);
            let o = odometry(&encode::odometry(wire, 3.5, "odom", "base", &p), wire, 0).unwrap();
            assert_eq!((o.parent.as_str(), o.child.as_str()), ("odom", "base"));
            assert!((o.transform.translation.vector - p.translation.vector).norm() < 1e-12);
            assert!(o.transform.rotation.angle_to(&p.rotation) < 1e-12);
            let tf = tf_message(
                &encode::tf_message(wire, &[(1.0, "a", "b", p), (2.0, "b", "c", p)]),
                wire,
                0,
            )
            .unwrap();
            assert_eq!(tf.len(), 2);
            assert_eq!(tf[1].child, "c");
            let m = imu(
                &encode::imu(wire, 4.5, "imu", [0.1, -0.2, 0.3], [0.0, -9.8, 0.5]),
                wire,
                0,
            )
            .unwrap();
            assert_eq!(m.header.frame_id, "imu");
            assert!((m.header.stamp - 4.5).abs() < 1e-9);
            assert_eq!(m.angular_velocity, Vector3::new(0.1, -0.2, 0.3));
            assert_eq!(m.linear_acceleration, Vector3::new(0.0, -9.8, 0.5));
            let cm = encode::compressed_image(wire, 1.0, "f", "jpeg", b"xyz");
            let c = compressed_image(&cm, wire, 0).unwrap();
            assert_eq!((c.format.as_str(), c.data), ("jpeg", &b"xyz"[..]));
        }
    }

    #[test]
    fn short_or_lying_messages_are_errors_with_offsets() {
        let m = encode::image(Wire::Ros1, 1.0, "cam", 100, 100, "16UC1", 200, &[0; 10]);
        let e = image(&m, Wire::Ros1, 1000).unwrap_err();
        assert!(e.offset >= 1000, "{e}");
        assert!(e.what.contains("100×100"), "{e}");
        for cut in 0..m.len() {
            assert!(image(&m[..cut], Wire::Ros1, 0).is_err());
        }
        let huge = encode::Writer::new(Wire::Cdr).u32(u32::MAX).finish();
        assert!(tf_message(&huge, Wire::Cdr, 0).is_err());
        assert_eq!(MsgKind::of("sensor_msgs/msg/Image"), MsgKind::Image);
        assert_eq!(MsgKind::of("tf2_msgs/TFMessage"), MsgKind::Tf);
        assert_eq!(MsgKind::of("std_msgs/String"), MsgKind::Other);
    }
}
