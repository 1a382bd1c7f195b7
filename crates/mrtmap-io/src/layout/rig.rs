//! `rig.toml`: the cameras of a recording and how they sit relative to the depth camera.

use std::path::Path;

use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use mrtmap_geometry::nalgebra::{Isometry3, Translation3};
use serde::{Deserialize, Serialize};

use super::trajectory::{quaternion_xyzw, unit_quaternion};
use crate::error::{FileError, FileErrorKind};

/// A rigid transform as written in rig.toml.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoseFile {
    /// Translation (m).
    pub translation: [f64; 3],
    /// Rotation quaternion (x, y, z, w).
    pub rotation_xyzw: [f64; 4],
}

impl PoseFile {
    /// From an isometry.
    pub fn from_isometry(p: &Isometry3<f64>) -> Self {
        let t = p.translation.vector;
        Self {
            translation: [t.x, t.y, t.z],
            rotation_xyzw: quaternion_xyzw(&p.rotation),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct DepthSection {
    width: u32,
    height: u32,
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    depth_scale: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    distortion: Option<[f64; 5]>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct ThermalSection {
    width: u32,
    height: u32,
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    #[serde(default)]
    distortion: [f64; 5],
    encoding: String,
    depth_from_thermal: PoseFile,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    absolute_accuracy_k: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    time_offset_s: Option<f64>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct RgbSection {
    width: u32,
    height: u32,
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    distortion: Option<[f64; 5]>,
    depth_from_rgb: PoseFile,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct RigFile {
    depth: DepthSection,
    thermal: ThermalSection,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    rgb: Option<RgbSection>,
}

/// How thermal pixel values encode temperature.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ThermalEncoding {
    /// 16-bit, value / 100 = kelvin (FLIR Lepton TLinear).
    Centikelvin,
}

impl ThermalEncoding {
    /// The rig.toml name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Centikelvin => "centikelvin",
        }
    }

    /// Kelvin of a raw value.
    pub fn kelvin(self, raw: u16) -> f64 {
        match self {
            Self::Centikelvin => raw as f64 / 100.0,
        }
    }

    /// Raw value of a temperature in kelvin (rounded, saturating).
    pub fn raw(self, kelvin: f64) -> u16 {
        match self {
            Self::Centikelvin => (kelvin * 100.0).round().clamp(0.0, u16::MAX as f64) as u16,
        }
    }
}

/// The colour camera of a rig.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbCamera {
    /// Intrinsics.
    pub camera: PinholeCamera,
    /// p_in_depth = depth_from_rgb · p_in_rgb.
    pub depth_from_rgb: Isometry3<f64>,
}

/// A validated rig.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rig {
    /// Depth camera intrinsics.
    pub depth: PinholeCamera,
    /// Raw depth units per metre (RealSense 1000, TUM 5000).
    pub depth_scale: f64,
    /// Thermal camera intrinsics and distortion.
    pub thermal: PinholeCamera,
    /// Thermal pixel encoding.
    pub thermal_encoding: ThermalEncoding,
    /// p_in_depth = depth_from_thermal · p_in_thermal.
    pub depth_from_thermal: Isometry3<f64>,
    /// The thermal camera's stated absolute accuracy (K, `[thermal] absolute_accuracy_k`); `None`:
    /// not stated (a Lepton 3.5's ±5 K is then assumed).
    pub thermal_accuracy_k: Option<f64>,
    /// What to add to thermal.txt's stamps to put them on the depth camera's clock (s,
    /// `[thermal] time_offset_s`): a USB thermal camera stamped on arrival is late, so this is
    /// negative (−0.07 for frames stamped 70 ms after exposure). `None`: not known (fusion
    /// estimates it from the scan).
    pub thermal_time_offset_s: Option<f64>,
    /// Optional colour camera.
    pub rgb: Option<RgbCamera>,
}

fn camera(
    section: &str,
    w: u32,
    h: u32,
    k: [f64; 4],
    d: [f64; 5],
) -> Result<PinholeCamera, String> {
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!(
            "[{section}] image size {w}×{h} is not between 1 and 16384 pixels"
        ));
    }
    if k.iter().chain(d.iter()).any(|x| !x.is_finite()) {
        return Err(format!("[{section}] a value is not a finite number"));
    }
    if k[0] <= 0.0 || k[1] <= 0.0 {
        return Err(format!(
            "[{section}] focal lengths must be positive, got fx {} fy {}",
            k[0], k[1]
        ));
    }
    // The radial distortion must not fold the image over within it (r·(1 + k1 r² + k2 r⁴ + k3 r⁶)
    // rising out to the corners) nor scale it by more than 5 or less than a fifth there: a real
    // lens's factor at its corners is near 1 (TUM's Kinect 1.07, a Lepton 0.96), and absurd
    // coefficients fused 4 % of the points without a word.
    let corner = [
        (0.0, 0.0),
        (f64::from(w), 0.0),
        (0.0, f64::from(h)),
        (f64::from(w), f64::from(h)),
    ]
    .iter()
    .map(|(u, v)| ((u - k[2]) / k[0]).hypot((v - k[3]) / k[1]))
    .fold(0.0, f64::max);
    let (k1, k2, k3) = (d[0], d[1], d[4]);
    if let Some(r) = (1..=200).map(|i| corner * f64::from(i) / 200.0).find(|r| {
        let r2 = r * r;
        let slope = 1.0 + r2 * (3.0 * k1 + r2 * (5.0 * k2 + r2 * 7.0 * k3));
        let factor = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        slope <= 0.0 || !(0.2..=5.0).contains(&factor)
    }) {
        return Err(format!(
            "[{section}] distortion = {d:?} folds or stretches the image beyond any lens {:.0} % of the way to its corners: give k1, k2, p1, p2, k3 in OpenCV's order, from a calibration",
            100.0 * r / corner
        ));
    }
    let mut c = PinholeCamera::new(w, h, k[0], k[1], k[2], k[3]);
    c.distortion = BrownConrady::from_array(d);
    Ok(c)
}

fn pose(section: &str, p: &PoseFile) -> Result<Isometry3<f64>, String> {
    if p.translation.iter().any(|x| !x.is_finite()) {
        return Err(format!("{section}: translation is not finite"));
    }
    let q = unit_quaternion(p.rotation_xyzw).map_err(|e| format!("{section}: {e}"))?;
    Ok(Isometry3::from_parts(
        Translation3::new(p.translation[0], p.translation[1], p.translation[2]),
        q,
    ))
}

/// The keys rig.toml's sections hold (others are read past: the layout may carry more, such as
/// `mrtmap calibrate`'s `[calibration]`).
const KNOWN_KEYS: [(&str, &[&str]); 4] = [
    (
        "depth",
        &[
            "width",
            "height",
            "fx",
            "fy",
            "cx",
            "cy",
            "depth_scale",
            "distortion",
        ],
    ),
    (
        "thermal",
        &[
            "width",
            "height",
            "fx",
            "fy",
            "cx",
            "cy",
            "distortion",
            "encoding",
            "depth_from_thermal",
            "absolute_accuracy_k",
            "time_offset_s",
        ],
    ),
    (
        "rgb",
        &[
            "width",
            "height",
            "fx",
            "fy",
            "cx",
            "cy",
            "distortion",
            "depth_from_rgb",
        ],
    ),
    ("calibration", &[]),
];

/// The keys of rig.toml `text` that mrtmap does not read, as `[section] key` (or `[section]` for
/// a section it does not know): likely typos, since a misspelt optional key is otherwise read
/// past without a word.
pub fn unknown_rig_keys(text: &str) -> Vec<String> {
    let Ok(table) = text.parse::<toml::Table>() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (section, value) in &table {
        match KNOWN_KEYS.iter().find(|(s, _)| s == section) {
            None => out.push(format!("[{section}]")),
            Some((_, keys)) if !keys.is_empty() => {
                if let Some(t) = value.as_table() {
                    out.extend(
                        t.keys()
                            .filter(|k| !keys.contains(&k.as_str()))
                            .map(|k| format!("[{section}] {k}")),
                    );
                }
            }
            Some(_) => {}
        }
    }
    out
}

impl Rig {
    /// Parses rig.toml text.
    pub fn parse(text: &str, path: &Path) -> Result<Self, FileError> {
        let f: RigFile = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            let unknown = unknown_rig_keys(text);
            let mut message = e.message().trim().to_string();
            if !unknown.is_empty() {
                message.push_str(&format!(
                    " (rig.toml also has {}, which mrtmap does not read: a misspelt key or section? The sections are [depth], [thermal] and [rgb])",
                    unknown.join(", ")
                ));
            }
            FileError::new(path, line, FileErrorKind::Syntax(message))
        })?;
        let bad = |m: String| FileError::new(path, None, FileErrorKind::Syntax(m));
        let d = &f.depth;
        let depth = camera(
            "depth",
            d.width,
            d.height,
            [d.fx, d.fy, d.cx, d.cy],
            d.distortion.unwrap_or_default(),
        )
        .map_err(bad)?;
        if !(d.depth_scale.is_finite() && d.depth_scale > 0.0) {
            return Err(bad(format!(
                "[depth] depth_scale must be positive, got {}",
                d.depth_scale
            )));
        }
        let t = &f.thermal;
        let thermal = camera(
            "thermal",
            t.width,
            t.height,
            [t.fx, t.fy, t.cx, t.cy],
            t.distortion,
        )
        .map_err(bad)?;
        let thermal_encoding = match t.encoding.as_str() {
            "centikelvin" => ThermalEncoding::Centikelvin,
            other => {
                return Err(bad(format!(
                    "[thermal] unknown encoding '{other}' (supported: centikelvin)"
                )));
            }
        };
        let depth_from_thermal =
            pose("[thermal] depth_from_thermal", &t.depth_from_thermal).map_err(bad)?;
        if let Some(a) = t.absolute_accuracy_k
            && !(a.is_finite() && (0.0..=100.0).contains(&a))
        {
            return Err(bad(format!(
                "[thermal] absolute_accuracy_k = {a} is outside 0…100 K"
            )));
        }
        if let Some(o) = t.time_offset_s
            && !(o.is_finite() && o.abs() <= 1.0)
        {
            return Err(bad(format!(
                "[thermal] time_offset_s = {o} is outside −1…1 s (a thermal camera's stamps are late by tens to a hundred milliseconds, so the offset is about −0.03 to −0.15)"
            )));
        }
        let rgb = match &f.rgb {
            None => None,
            Some(r) => Some(RgbCamera {
                camera: camera(
                    "rgb",
                    r.width,
                    r.height,
                    [r.fx, r.fy, r.cx, r.cy],
                    r.distortion.unwrap_or_default(),
                )
                .map_err(bad)?,
                depth_from_rgb: pose("[rgb] depth_from_rgb", &r.depth_from_rgb).map_err(bad)?,
            }),
        };
        Ok(Self {
            depth,
            depth_scale: d.depth_scale,
            thermal,
            thermal_encoding,
            depth_from_thermal,
            thermal_accuracy_k: t.absolute_accuracy_k,
            thermal_time_offset_s: t.time_offset_s,
            rgb,
        })
    }

    /// Reads rig.toml.
    pub fn read(path: &Path) -> Result<Self, FileError> {
        let text = std::fs::read_to_string(path).map_err(|e| FileError::io(path, e))?;
        Self::parse(&text, path)
    }

    /// rig.toml text.
    pub fn to_toml(&self) -> String {
        let dist = |c: &PinholeCamera| (!c.distortion.is_zero()).then(|| c.distortion.to_array());
        let f = RigFile {
            depth: DepthSection {
                width: self.depth.width,
                height: self.depth.height,
                fx: self.depth.fx,
                fy: self.depth.fy,
                cx: self.depth.cx,
                cy: self.depth.cy,
                depth_scale: self.depth_scale,
                distortion: dist(&self.depth),
            },
            thermal: ThermalSection {
                width: self.thermal.width,
                height: self.thermal.height,
                fx: self.thermal.fx,
                fy: self.thermal.fy,
                cx: self.thermal.cx,
                cy: self.thermal.cy,
                distortion: self.thermal.distortion.to_array(),
                encoding: self.thermal_encoding.as_str().to_string(),
                depth_from_thermal: PoseFile::from_isometry(&self.depth_from_thermal),
                absolute_accuracy_k: self.thermal_accuracy_k,
                time_offset_s: self.thermal_time_offset_s,
            },
            rgb: self.rgb.map(|r| RgbSection {
                width: r.camera.width,
                height: r.camera.height,
                fx: r.camera.fx,
                fy: r.camera.fy,
                cx: r.camera.cx,
                cy: r.camera.cy,
                distortion: dist(&r.camera),
                depth_from_rgb: PoseFile::from_isometry(&r.depth_from_rgb),
            }),
        };
        toml::to_string(&f).unwrap_or_default()
    }
}
