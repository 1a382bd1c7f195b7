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

/// Writes a recording as a bag or MCAP file with RealSense-style topics ([`names`]): aligned
/// depth (16UC1), colour (rgb8), thermal (mono16), their CameraInfo, T265-style odometry of a
/// pose frame, and /tf_static tying the frames together.
pub fn write_ros(rec: &Recording, o: &RosWriteOptions) -> Result<Vec<u8>, FileError> {
    use super::bag::BagWriter;
    use super::msg::encode;
    let wire = match o.container {
        Container::Bag => Wire::Ros1,
        Container::Mcap | Container::Db3 => Wire::Cdr,
    };
    enum W {
        Bag(BagWriter),
        Mcap(Box<super::mcap::McapWriter>),
        Db3(super::db3::Db3Writer),
    }
    let syntax = |e: &dyn std::error::Error| {
        FileError::new(&rec.dir, None, FileErrorKind::Syntax(e.to_string()))
    };
    let mut w = match o.container {
        Container::Bag => W::Bag(BagWriter::new(o.compression, 768 * 1024)),
        Container::Mcap => W::Mcap(Box::new(
            super::mcap::McapWriter::new(
                match o.compression {
                    Compression::None => None,
                    Compression::Lz4 => Some(::mcap::Compression::Lz4),
                    Compression::Bz2 => Some(::mcap::Compression::Zstd),
                },
                768 * 1024,
            )
            .map_err(|e| syntax(&e))?,
        )),
        Container::Db3 => W::Db3(super::db3::Db3Writer::new().map_err(|e| syntax(&e))?),
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
            W::Mcap(m) => m.write(topic, &ty(datatype), t, data).map_err(|e| syntax(&e)),
            W::Db3(d) => d.write(topic, &ty(datatype), t, data).map_err(|e| syntax(&e)),
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
        Depth(&'a StreamEntry),
        Thermal(&'a StreamEntry),
        Rgb(&'a StreamEntry),
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
        W::Bag(b) => b.finish().map_err(|e| FileError::io(&rec.dir, e)),
        W::Mcap(m) => m.finish().map_err(|e| syntax(&e)),
        W::Db3(d) => d.finish().map_err(|e| syntax(&e)),
    }
}
