//! Writing a recording as a RealSense-style ROS 1 bag, MCAP file or ROS 2 `.db3`.

use mrtmap_geometry::nalgebra::{self, Isometry3};
use mrtmap_io::{FileError, FileErrorKind, Image16, Recording, StreamEntry};

use super::bag::Compression;
use super::msg::Wire;
use super::read::Container;

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
    /// Gyro and accelerometer in one topic (realsense-ros `unite_imu_method`).
    pub const IMU: &str = "/camera/imu";
    /// The IMU's frame.
    pub const IMU_FRAME: &str = "camera_imu_optical_frame";
}

/// depth_from_imu of the bags [`write_ros`] writes: the IMU 5 mm beside the depth camera, turned
/// 90° about its optical axis (so a reader must apply /tf_static to get the axes right).
pub fn depth_from_imu() -> Isometry3<f64> {
    Isometry3::from_parts(
        nalgebra::Translation3::new(-0.005, 0.0, 0.0),
        nalgebra::UnitQuaternion::from_axis_angle(
            &nalgebra::Vector3::z_axis(),
            std::f64::consts::FRAC_PI_2,
        ),
    )
}

/// How [`write_ros`] writes.
#[derive(Clone, Copy, Debug)]
pub struct RosWriteOptions {
    /// Container.
    pub container: Container,
    /// Bag chunk compression (`None`, `Bz2`, `Lz4`) / MCAP (`None`, `Lz4`, or zstd for Bz2).
    pub compression: Compression,
    /// pose_frame_from_depth: where the tracking camera sits relative to the depth camera (a T265
    /// looks along its −z with x right and y up; the default turns the optical frame into it).
    pub pose_from_depth: Isometry3<f64>,
}

impl RosWriteOptions {
    /// A T265-like tracking frame 3 cm above the depth camera, looking the same way.
    pub fn t265_like(container: Container, compression: Compression) -> Self {
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

/// Where messages go: a bag, MCAP or `.db3` writer, with type names in its ROS version.
enum Sink {
    Bag(super::bag::BagWriter),
    Mcap(Box<super::mcap::McapWriter>),
    Db3(super::db3::Db3Writer),
}

/// A writer's error as a file error of the recording.
fn syntax(dir: &std::path::Path, e: &dyn std::error::Error) -> FileError {
    FileError::new(dir, None, FileErrorKind::Syntax(e.to_string()))
}

impl Sink {
    fn new(o: &RosWriteOptions, dir: &std::path::Path) -> Result<Self, FileError> {
        Ok(match o.container {
            Container::Bag => Self::Bag(super::bag::BagWriter::new(o.compression, 768 * 1024)),
            Container::Mcap => {
                let compression = match o.compression {
                    Compression::None => None,
                    Compression::Lz4 => Some(::mcap::Compression::Lz4),
                    Compression::Bz2 => Some(::mcap::Compression::Zstd),
                };
                let w = super::mcap::McapWriter::new(compression, 768 * 1024)
                    .map_err(|e| syntax(dir, &e))?;
                Self::Mcap(Box::new(w))
            }
            Container::Db3 => Self::Db3(super::db3::Db3Writer::new().map_err(|e| syntax(dir, &e))?),
        })
    }

    /// The wire format of the container.
    fn wire(&self) -> Wire {
        match self {
            Self::Bag(_) => Wire::Ros1,
            Self::Mcap(_) | Self::Db3(_) => Wire::Cdr,
        }
    }

    /// Writes a message of `datatype` (ROS 1 spelling, `pkg/Name`).
    fn put(
        &mut self,
        dir: &std::path::Path,
        topic: &str,
        datatype: &str,
        t: f64,
        data: &[u8],
    ) -> Result<(), FileError> {
        let ros2 = || {
            let (pkg, name) = datatype.split_once('/').unwrap_or(("", datatype));
            format!("{pkg}/msg/{name}")
        };
        match self {
            Self::Bag(b) => {
                b.write(topic, datatype, t, data);
                Ok(())
            }
            Self::Mcap(m) => m
                .write(topic, &ros2(), t, data)
                .map_err(|e| syntax(dir, &e)),
            Self::Db3(d) => d
                .write(topic, &ros2(), t, data)
                .map_err(|e| syntax(dir, &e)),
        }
    }

    fn finish(self, dir: &std::path::Path) -> Result<Vec<u8>, FileError> {
        match self {
            Self::Bag(b) => b.finish().map_err(|e| FileError::io(dir, e)),
            Self::Mcap(m) => m.finish().map_err(|e| syntax(dir, &e)),
            Self::Db3(d) => d.finish().map_err(|e| syntax(dir, &e)),
        }
    }
}

/// The colour camera's frame: its own when it sits apart from the depth camera.
fn rgb_frame(rig: &mrtmap_io::Rig) -> &'static str {
    match &rig.rgb {
        Some(c) if c.depth_from_rgb != Isometry3::identity() => "camera_rgb_optical_frame",
        _ => names::DEPTH_FRAME,
    }
}

/// Static transforms (latched in real bags) and the cameras' CameraInfo, at `t0`.
fn write_statics(
    sink: &mut Sink,
    rec: &Recording,
    o: &RosWriteOptions,
    t0: f64,
) -> Result<(), FileError> {
    use super::msg::encode;
    let (rig, wire, dir) = (&rec.rig, sink.wire(), rec.dir.as_path());
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
        (t0, names::DEPTH_FRAME, names::IMU_FRAME, depth_from_imu()),
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
    let tf = encode::tf_message(wire, &statics);
    sink.put(dir, "/tf_static", "tf2_msgs/TFMessage", t0, &tf)?;
    let mut infos = vec![
        (names::DEPTH_INFO, names::DEPTH_FRAME, &rig.depth),
        (names::THERMAL_INFO, names::THERMAL_FRAME, &rig.thermal),
    ];
    if let Some(c) = &rig.rgb {
        infos.push((names::RGB_INFO, rgb_frame(rig), &c.camera));
    }
    for (topic, frame, cam) in infos {
        let m = encode::camera_info(wire, t0, frame, cam);
        sink.put(dir, topic, "sensor_msgs/CameraInfo", t0, &m)?;
    }
    Ok(())
}

/// One timed item of a recording.
enum Item<'a> {
    Depth(&'a StreamEntry),
    Thermal(&'a StreamEntry),
    Rgb(&'a StreamEntry),
    Pose(usize),
    Imu(usize),
}

/// Every frame and pose of a recording, in time order.
fn timeline(rec: &Recording) -> Vec<(f64, Item<'_>)> {
    let mut items: Vec<(f64, Item<'_>)> = Vec::new();
    items.extend(rec.depth.iter().map(|e| (e.t, Item::Depth(e))));
    items.extend(rec.thermal.iter().map(|e| (e.t, Item::Thermal(e))));
    if rec.rig.rgb.is_some() {
        items.extend(rec.rgb.iter().map(|e| (e.t, Item::Rgb(e))));
    }
    items.extend(
        rec.trajectory
            .stamps
            .iter()
            .enumerate()
            .map(|(i, &t)| (t, Item::Pose(i))),
    );
    items.extend(rec.imu.iter().enumerate().map(|(i, m)| (m.t, Item::Imu(i))));
    items.sort_by(|a, b| a.0.total_cmp(&b.0));
    items
}

/// One item as its message.
fn write_item(
    sink: &mut Sink,
    rec: &Recording,
    o: &RosWriteOptions,
    (t, item): (f64, Item<'_>),
) -> Result<(), FileError> {
    use super::msg::encode;
    let (wire, dir) = (sink.wire(), rec.dir.as_path());
    let le16 =
        |img: &Image16| -> Vec<u8> { img.data.iter().flat_map(|v| v.to_le_bytes()).collect() };
    let image16 = |img: &Image16, frame: &str, encoding: &str| {
        let (w, h) = (img.width, img.height);
        encode::image(wire, t, frame, w, h, encoding, 2 * w, &le16(img))
    };
    match item {
        Item::Depth(e) => {
            let m = image16(&rec.read_depth(e)?, names::DEPTH_FRAME, "16UC1");
            sink.put(dir, names::DEPTH, "sensor_msgs/Image", t, &m)
        }
        Item::Thermal(e) => {
            let m = image16(&rec.read_thermal(e)?, names::THERMAL_FRAME, "mono16");
            sink.put(dir, names::THERMAL, "sensor_msgs/Image", t, &m)
        }
        Item::Rgb(e) => {
            let p = rec.path_of(e);
            let img = image::open(&p)
                .map_err(|er| FileError::new(&p, None, FileErrorKind::Image(er.to_string())))?
                .to_rgb8();
            let (iw, ih) = img.dimensions();
            let frame = rgb_frame(&rec.rig);
            let m = encode::image(wire, t, frame, iw, ih, "rgb8", 3 * iw, img.as_raw());
            sink.put(dir, names::RGB, "sensor_msgs/Image", t, &m)
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
            sink.put(dir, names::ODOM, "nav_msgs/Odometry", t, &m)
        }
        Item::Imu(i) => {
            let imu_from_depth = depth_from_imu().rotation.inverse();
            let (g, a) = (
                imu_from_depth * rec.imu[i].gyro,
                imu_from_depth * rec.imu[i].accel,
            );
            let m = encode::imu(wire, t, names::IMU_FRAME, g.into(), a.into());
            sink.put(dir, names::IMU, "sensor_msgs/Imu", t, &m)
        }
    }
}

/// Writes a recording as a bag or MCAP file with RealSense-style topics ([`names`]): aligned
/// depth (16UC1), colour (rgb8), thermal (mono16), their CameraInfo, T265-style odometry of a
/// pose frame (when the recording has poses), the IMU (when it has imu.txt), and /tf_static
/// tying the frames together.
pub fn write_ros(rec: &Recording, o: &RosWriteOptions) -> Result<Vec<u8>, FileError> {
    let mut sink = Sink::new(o, &rec.dir)?;
    let t0 = rec
        .depth
        .first()
        .map(|e| e.t)
        .unwrap_or(0.0)
        .min(rec.trajectory.stamps.first().copied().unwrap_or(0.0));
    write_statics(&mut sink, rec, o, t0)?;
    for item in timeline(rec) {
        write_item(&mut sink, rec, o, item)?;
    }
    sink.finish(&rec.dir)
}
