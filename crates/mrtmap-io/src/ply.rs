//! Thermal point clouds and PLY.
//!
//! `cloud.ply` is binary little-endian with, per vertex: `x y z` (float, m), `nx ny nz` (float),
//! `temperature_c` (float, °C: the radiant T⁴ average), `temperature_std` (float, K),
//! `observations` (int: Open3D's tensor reader skips uint), `red green blue` (uchar, an iron colour map of the temperature), and any
//! extra integer fields (segments.ply adds `surface_id`, `feature_id`). CloudCompare shows the
//! non-standard properties as scalar fields; Open3D's tensor API
//! (`open3d.t.io.read_point_cloud`) keeps them as attributes.

use std::path::Path;

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{Property, PropertyAccess, PropertyAccessResult};

use crate::error::{FileError, FileErrorKind};

/// A fused thermal point cloud, struct of arrays. Temperatures in kelvin.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ThermalCloud {
    /// Positions (m).
    pub positions: Vec<[f32; 3]>,
    /// Unit normals (zero when unknown).
    pub normals: Vec<[f32; 3]>,
    /// Radiant (T⁴) average temperature (K).
    pub temperature_k: Vec<f32>,
    /// Standard deviation of the observations (K).
    pub temperature_std_k: Vec<f32>,
    /// Observations fused.
    pub observations: Vec<u32>,
}

impl ThermalCloud {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether it is empty.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Appends a point.
    pub fn push(&mut self, p: [f32; 3], n: [f32; 3], t_k: f32, std_k: f32, obs: u32) {
        self.positions.push(p);
        self.normals.push(n);
        self.temperature_k.push(t_k);
        self.temperature_std_k.push(std_k);
        self.observations.push(obs);
    }
}

/// The iron colour map (black → purple → red → orange → yellow → white) at `t` in 0…1.
pub fn iron(t: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 6] = [
        [0.0, 0.0, 0.0],
        [80.0, 0.0, 130.0],
        [200.0, 30.0, 90.0],
        [250.0, 120.0, 0.0],
        [255.0, 220.0, 40.0],
        [255.0, 255.0, 255.0],
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let c = |k: usize| (STOPS[i][k] + f * (STOPS[i + 1][k] - STOPS[i][k])).round() as u8;
    [c(0), c(1), c(2)]
}

/// Binary little-endian PLY bytes of a cloud, coloured over the 2nd–98th percentile of its
/// temperatures, with extra integer properties (each of the cloud's length).
pub fn cloud_ply_bytes(cloud: &ThermalCloud, comment: &str, extra: &[(&str, &[i32])]) -> Vec<u8> {
    let n = cloud.len();
    let mut sorted: Vec<f32> = cloud.temperature_k.clone();
    sorted.sort_by(f32::total_cmp);
    let (lo, hi) = if n == 0 {
        (0.0, 1.0)
    } else {
        (sorted[n * 2 / 100], sorted[(n * 98 / 100).min(n - 1)])
    };
    let span = (hi - lo).max(1e-3);
    let mut out = Vec::with_capacity(256 + n * (40 + 4 * extra.len()));
    let mut header = String::from("ply\nformat binary_little_endian 1.0\n");
    for l in comment.lines() {
        header.push_str(&format!("comment {l}\n"));
    }
    header.push_str(&format!("element vertex {n}\n"));
    for p in [
        "x",
        "y",
        "z",
        "nx",
        "ny",
        "nz",
        "temperature_c",
        "temperature_std",
    ] {
        header.push_str(&format!("property float {p}\n"));
    }
    header.push_str("property int observations\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n");
    for (name, _) in extra {
        header.push_str(&format!("property int {name}\n"));
    }
    header.push_str("end_header\n");
    out.extend_from_slice(header.as_bytes());
    for i in 0..n {
        for v in cloud.positions[i].iter().chain(cloud.normals[i].iter()) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        let t = cloud.temperature_k[i];
        out.extend_from_slice(&((t as f64 - 273.15) as f32).to_le_bytes());
        out.extend_from_slice(&cloud.temperature_std_k[i].to_le_bytes());
        out.extend_from_slice(&(cloud.observations[i].min(i32::MAX as u32) as i32).to_le_bytes());
        out.extend_from_slice(&iron((t - lo) / span));
        for (_, vals) in extra {
            out.extend_from_slice(&vals[i].to_le_bytes());
        }
    }
    out
}

#[derive(Default)]
struct Vertex {
    p: [f32; 3],
    n: [f32; 3],
    t_c: Option<f32>,
    std: f32,
    obs: u32,
    ints: Vec<(String, i32)>,
}

fn as_f32(p: &Property) -> Option<f32> {
    Some(match *p {
        Property::Float(v) => v,
        Property::Double(v) => v as f32,
        Property::Char(v) => v as f32,
        Property::UChar(v) => v as f32,
        Property::Short(v) => v as f32,
        Property::UShort(v) => v as f32,
        Property::Int(v) => v as f32,
        Property::UInt(v) => v as f32,
        _ => return None,
    })
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, key: &str, property: Property) -> PropertyAccessResult {
        let Some(v) = as_f32(&property) else {
            return PropertyAccessResult::Set;
        };
        match key {
            "x" => self.p[0] = v,
            "y" => self.p[1] = v,
            "z" => self.p[2] = v,
            "nx" => self.n[0] = v,
            "ny" => self.n[1] = v,
            "nz" => self.n[2] = v,
            "temperature_c" => self.t_c = Some(v),
            "temperature_std" => self.std = v,
            "observations" => self.obs = v.max(0.0) as u32,
            "red" | "green" | "blue" => {}
            other => self.ints.push((other.to_string(), v as i32)),
        }
        PropertyAccessResult::Set
    }
}

/// A cloud read from PLY, with any extra per-vertex fields (as integers) by name.
#[derive(Clone, Debug)]
pub struct ReadCloud {
    /// The cloud.
    pub cloud: ThermalCloud,
    /// Extra fields.
    pub extra: Vec<(String, Vec<i32>)>,
}

/// Reads a thermal cloud from a PLY file (binary or ASCII; needs x, y, z and temperature_c).
pub fn read_cloud_ply(path: &Path) -> Result<ReadCloud, FileError> {
    let bad = |m: String| FileError::new(path, None, FileErrorKind::Syntax(m));
    let f = std::fs::File::open(path).map_err(|e| FileError::io(path, e))?;
    let mut reader = ply_rs_bw::parser::Reader::new(std::io::BufReader::new(f));
    let parser = Parser::<Vertex>::new();
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| bad(format!("not a PLY file: {e}")))?;
    let el = header
        .elements
        .get("vertex")
        .ok_or_else(|| bad("the PLY file has no vertex element".into()))?;
    for required in ["x", "y", "z", "temperature_c"] {
        if !el.properties.contains_key(required) {
            return Err(bad(format!("the vertices have no '{required}' property")));
        }
    }
    let verts = parser
        .read_payload_for_element(&mut reader, el, &header)
        .map_err(|e| bad(format!("cannot read the vertices: {e}")))?;
    let mut cloud = ThermalCloud::default();
    let mut extra: Vec<(String, Vec<i32>)> = Vec::new();
    for (k, v) in verts.into_iter().enumerate() {
        let t_c = v.t_c.unwrap_or(f32::NAN);
        if !(t_c.is_finite() && v.p.iter().all(|c| c.is_finite())) {
            return Err(bad(format!(
                "vertex {k} has a coordinate or temperature that is not finite"
            )));
        }
        cloud.push(v.p, v.n, (t_c as f64 + 273.15) as f32, v.std, v.obs);
        for (name, val) in v.ints {
            match extra.iter_mut().find(|e| e.0 == name) {
                Some(e) => e.1.push(val),
                None => extra.push((name, vec![val])),
            }
        }
    }
    Ok(ReadCloud { cloud, extra })
}

/// Writes a cloud atomically.
pub fn write_cloud_ply(
    path: &Path,
    cloud: &ThermalCloud,
    comment: &str,
    extra: &[(&str, &[i32])],
) -> Result<(), FileError> {
    let bytes = cloud_ply_bytes(cloud, comment, extra);
    crate::atomic::write_atomic(path, &bytes)
}
