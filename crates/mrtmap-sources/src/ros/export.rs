//! Writing the recording layout from a bag, MCAP or `.db3` file for a plan whose rig is complete.

use std::path::Path;

use mrtmap_io::bytes::Corrupt;
use mrtmap_io::layout::LayoutWriter;
use mrtmap_io::{FileError, FileErrorKind, Image16, encode_png_rgb8};
use serde::Serialize;

use super::msg::{self as ros_msg, Message, MsgKind};
use super::plan::{Plan, PoseSource, RosOptions, plan};
use super::read::{Container, Input, for_each};
use super::survey::{Survey, stamp_or, survey};

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
    encode_png_rgb8(i.width, i.height, &rgb).map_err(|e| e.to_string())
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
    /// Inertial samples written to imu.txt (one per gyro message).
    #[serde(default)]
    pub imu: usize,
    /// Messages skipped (did not decode or had the wrong size), with the first reasons.
    pub skipped: usize,
    /// The first few reasons.
    pub skipped_reasons: Vec<String>,
}

/// A colour message as PNG/JPEG bytes, its stamp and extension.
fn colour_message(m: &Message<'_>, kind: MsgKind) -> Result<(f64, Vec<u8>, &'static str), String> {
    if kind == MsgKind::CompressedImage {
        let c = ros_msg::compressed_image(m.data, m.wire, m.offset).map_err(|e| e.to_string())?;
        let ext = if c.data.starts_with(b"\x89PNG") {
            "png"
        } else {
            "jpg"
        };
        return Ok((stamp_or(c.header.stamp, m.time), c.data.to_vec(), ext));
    }
    let i = ros_msg::image(m.data, m.wire, m.offset).map_err(|e| e.to_string())?;
    Ok((stamp_or(i.header.stamp, m.time), rgb_image(&i)?, "png"))
}

/// A 16-bit image message of the size the camera has.
fn sized_image(
    m: &Message<'_>,
    kind: MsgKind,
    scale: f64,
    thermal: bool,
    cam: &mrtmap_geometry::camera::PinholeCamera,
) -> Result<(f64, Image16), String> {
    let (t, img) = image16_msg(m, kind, scale, thermal)?;
    if (img.width, img.height) != (cam.width, cam.height) {
        let what = if thermal { "thermal" } else { "depth" };
        return Err(format!(
            "{what} image is {}×{}, the {what} camera {}×{}",
            img.width, img.height, cam.width, cam.height
        ));
    }
    Ok((t, img))
}

/// Gyro and accelerometer samples (depth camera frame) as they come, paired at the end.
#[derive(Default)]
struct ImuCollect {
    gyro: Vec<(f64, nalgebra::Vector3<f64>)>,
    accel: Vec<(f64, nalgebra::Vector3<f64>)>,
}

impl ImuCollect {
    /// Each gyro sample with the accelerometer sample nearest in time (within 50 ms; else zero).
    fn into_samples(mut self) -> Vec<mrtmap_io::ImuSample> {
        self.accel.sort_by(|a, b| a.0.total_cmp(&b.0));
        self.gyro
            .iter()
            .map(|&(t, g)| {
                let k = self.accel.partition_point(|a| a.0 < t);
                let near = [k.checked_sub(1), Some(k)]
                    .into_iter()
                    .flatten()
                    .filter_map(|i| self.accel.get(i))
                    .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
                    .filter(|a| (a.0 - t).abs() <= 0.05);
                mrtmap_io::ImuSample {
                    t,
                    gyro: g,
                    accel: near.map_or_else(nalgebra::Vector3::zeros, |a| a.1),
                }
            })
            .collect()
    }
}

/// Writes one message of the plan's streams into `w` (other topics are ignored).
fn write_message(
    m: &Message<'_>,
    p: &Plan,
    rig: &mrtmap_io::Rig,
    w: &mut LayoutWriter,
    imu: &mut ImuCollect,
) -> Result<(), Step> {
    let topic = Some(m.topic.to_string());
    let kind = MsgKind::of(m.datatype);
    if kind == MsgKind::Imu && (topic == p.gyro || topic == p.accel) {
        let x = ros_msg::imu(m.data, m.wire, m.offset).map_err(|e| e.to_string())?;
        let t = stamp_or(x.header.stamp, m.time);
        let [g, a] = &p.depth_from_imu;
        if topic == p.gyro {
            imu.gyro.push((t, g.rotation * x.angular_velocity));
            if p.accel.is_none() {
                imu.accel.push((t, a.rotation * x.linear_acceleration));
            }
        } else {
            imu.accel.push((t, a.rotation * x.linear_acceleration));
        }
    } else if topic == p.depth {
        let (t, img) = sized_image(m, kind, rig.depth_scale, false, &rig.depth)?;
        w.depth(t, &img).map_err(Step::Write)?;
    } else if topic == p.thermal {
        let (t, img) = sized_image(m, kind, 1.0, true, &rig.thermal)?;
        w.thermal(t, &img).map_err(Step::Write)?;
    } else if topic == p.rgb {
        let (t, bytes, ext) = colour_message(m, kind)?;
        w.rgb(t, &bytes, ext).map_err(Step::Write)?;
    } else if matches!(&p.poses, Some(PoseSource::Topic(pt)) if Some(pt) == topic.as_ref()) {
        let x = if kind == MsgKind::Odometry {
            ros_msg::odometry(m.data, m.wire, m.offset)
        } else {
            ros_msg::pose_stamped(m.data, m.wire, m.offset)
        }
        .map_err(|e| e.to_string())?;
        w.pose(stamp_or(x.stamp, m.time), x.transform * p.child_from_depth);
    } else if let Some(PoseSource::Tf(a, b)) = &p.poses
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
    let (Some(rig), true) = (p.rig, p.missing.is_empty()) else {
        return Err(FileError::new(
            path,
            None,
            FileErrorKind::Missing(format!("what a scan needs: {}", p.missing.join("; "))),
        ));
    };
    let mut w = LayoutWriter::create(out, &format!("converted by mrtmap from {}", path.display()))?;
    let mut rep = ExportReport::default();
    let mut err: Option<FileError> = None;
    let mut imu = ImuCollect::default();
    let res = for_each(s.container, file, &mut |m| {
        match write_message(&m, p, &rig, &mut w, &mut imu) {
            Ok(()) => {}
            Err(Step::Write(e)) => {
                err = Some(e);
                return Err(Corrupt::new(m.offset, "stopped: cannot write the output"));
            }
            Err(Step::Skip(why)) => {
                rep.skipped += 1;
                if rep.skipped_reasons.len() < 5 {
                    rep.skipped_reasons
                        .push(format!("{} {}: {why}", m.topic, m.place()));
                }
            }
        }
        Ok(())
    });
    if let Some(e) = err {
        return Err(e);
    }
    res.map_err(|e| e.in_file(path))?;
    for sample in imu.into_samples() {
        w.imu(sample);
    }
    rep.imu = w.imu_count();
    (rep.depth, rep.thermal, rep.rgb, rep.poses) = w.counts();
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
