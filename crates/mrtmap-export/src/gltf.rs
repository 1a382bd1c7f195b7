//! glTF 2.0 binary (`.glb`): the room's parts as meshes with temperature vertex colours (the maps'
//! palette over the scene's range), each vertex's temperature also as the custom attribute
//! `_TEMPERATURE` (°C), and the thermal point cloud as a points primitive. Metres; the scene's z-up
//! frame turned into glTF's y-up (x, y, z) → (x, z, −y). Each part's node carries its id, label,
//! temperature, ± and area in `extras`; the materials are unlit (`KHR_materials_unlit`) so viewers
//! show the colours as they are.

use mrtmap_radiation::RadiantScene;
use mrtmap_report::mesh::{MeshPart, colour_range, scene_mesh, temperature_rgb};
use serde_json::{Value, json};

use crate::CloudPoints;

const FLOAT: u32 = 5126;
const UINT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

fn y_up(p: [f64; 3]) -> [f32; 3] {
    [p[0] as f32, p[2] as f32, -p[1] as f32]
}

fn srgb_to_linear(c: u8) -> f32 {
    let s = f32::from(c) / 255.0;
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_rgb(t: f64, lo: f64, hi: f64) -> [f32; 3] {
    temperature_rgb(t, lo, hi).map(srgb_to_linear)
}

/// The binary buffer and the JSON arrays that describe it.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn view(&mut self, bytes: &[u8], target: u32) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.views.push(json!({
            "buffer": 0, "byteOffset": offset, "byteLength": bytes.len(), "target": target
        }));
        self.views.len() - 1
    }

    fn vec3(&mut self, v: &[[f32; 3]], bounds: bool) -> usize {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, ARRAY_BUFFER);
        let mut a = json!({
            "bufferView": view, "componentType": FLOAT, "count": v.len(), "type": "VEC3"
        });
        if bounds {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in v {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn scalar(&mut self, v: &[f32]) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, ARRAY_BUFFER);
        self.accessors.push(json!({
            "bufferView": view, "componentType": FLOAT, "count": v.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }

    fn indices(&mut self, t: &[[u32; 3]], vertices: usize) -> usize {
        let bytes: Vec<u8> = t.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, ELEMENT_ARRAY_BUFFER);
        self.accessors.push(json!({
            "bufferView": view, "componentType": UINT, "count": 3 * t.len(), "type": "SCALAR",
            "min": [0], "max": [vertices.saturating_sub(1)]
        }));
        self.accessors.len() - 1
    }
}

fn part_extras(p: &MeshPart) -> Value {
    let mut e = json!({
        "id": p.id,
        "label": p.label,
        "role": p.role.as_str(),
        "temperature_c": p.temperature_c,
        "area_m2": p.area_m2,
    });
    if !p.detail.is_empty() {
        e[if p.role == mrtmap_report::mesh::PartRole::Feature {
            "host"
        } else {
            "kind"
        }] = json!(p.detail);
    }
    if let Some(s) = p.temperature_std_k {
        e["temperature_std_k"] = json!(s);
    }
    if let Some(o) = p.observed_fraction {
        e["observed_fraction"] = json!(o);
    }
    e["emissivity"] = json!(p.emissivity);
    if let Some((t, s)) = p.surface_temperature {
        e["surface_temperature_c"] = json!(t);
        e["surface_temperature_std_k"] = json!(s);
    }
    e
}

/// The scene (and `cloud`, when given) as a glTF binary named `name`.
pub fn write(scene: &RadiantScene, cloud: Option<&CloudPoints>, name: &str) -> Vec<u8> {
    let parts = scene_mesh(scene);
    let (lo, hi) = colour_range(
        parts
            .iter()
            .flat_map(|p| p.vertex_temperature_c.iter().copied()),
    );
    let mut b = Builder::default();
    let mut meshes = Vec::new();
    let mut nodes = vec![json!({ "name": name, "children": [] })];
    for p in parts.iter().filter(|p| !p.triangles.is_empty()) {
        let pos: Vec<[f32; 3]> = p.positions.iter().map(|q| y_up(*q)).collect();
        let col: Vec<[f32; 3]> = p
            .vertex_temperature_c
            .iter()
            .map(|t| linear_rgb(*t, lo, hi))
            .collect();
        let temp: Vec<f32> = p.vertex_temperature_c.iter().map(|t| *t as f32).collect();
        let a_pos = b.vec3(&pos, true);
        let a_col = b.vec3(&col, false);
        let a_t = b.scalar(&temp);
        let a_idx = b.indices(&p.triangles, pos.len());
        meshes.push(json!({
            "name": p.id,
            "primitives": [{
                "attributes": { "POSITION": a_pos, "COLOR_0": a_col, "_TEMPERATURE": a_t },
                "indices": a_idx, "material": 0, "mode": 4
            }]
        }));
        nodes.push(json!({ "name": p.id, "mesh": meshes.len() - 1, "extras": part_extras(p) }));
    }
    if let Some(c) = cloud.filter(|c| !c.positions.is_empty()) {
        let pos: Vec<[f32; 3]> = c
            .positions
            .iter()
            .map(|q| y_up([f64::from(q[0]), f64::from(q[1]), f64::from(q[2])]))
            .collect();
        let col: Vec<[f32; 3]> = c
            .temperature_c
            .iter()
            .map(|t| linear_rgb(f64::from(*t), lo, hi))
            .collect();
        let a_pos = b.vec3(&pos, true);
        let a_col = b.vec3(&col, false);
        let a_t = b.scalar(&c.temperature_c);
        meshes.push(json!({
            "name": "thermal cloud",
            "primitives": [{
                "attributes": { "POSITION": a_pos, "COLOR_0": a_col, "_TEMPERATURE": a_t },
                "material": 1, "mode": 0
            }]
        }));
        nodes.push(json!({
            "name": "thermal cloud", "mesh": meshes.len() - 1,
            "extras": { "points": pos.len() }
        }));
    }
    nodes[0]["children"] = json!((1..nodes.len()).collect::<Vec<_>>());
    nodes[0]["extras"] = json!({
        "generator": "mrtmap",
        "temperature_unit": "C",
        "colour_range_c": [lo, hi],
        "frame": "the scene's frame (z up) turned y-up: glTF (x, y, z) = scene (x, z, -y)",
        "temperature_level_std_k": scene.temperature_level_std_k,
    });
    let unlit = |name: &str| {
        json!({
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0
            },
            "doubleSided": true,
            "extensions": { "KHR_materials_unlit": {} }
        })
    };
    let doc = json!({
        "asset": { "version": "2.0", "generator": concat!("mrtmap ", env!("CARGO_PKG_VERSION")) },
        "extensionsUsed": ["KHR_materials_unlit"],
        "scene": 0,
        "scenes": [{ "name": name, "nodes": [0] }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": if cloud.is_some_and(|c| !c.positions.is_empty()) {
            json!([unlit("temperature"), unlit("thermal cloud")])
        } else {
            json!([unlit("temperature")])
        },
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{ "byteLength": b.bin.len() }],
    });
    glb(&doc, b.bin)
}

/// A GLB container: header, JSON chunk (space-padded), BIN chunk (zero-padded).
fn glb(doc: &Value, mut bin: Vec<u8>) -> Vec<u8> {
    let mut json = serde_json::to_vec(doc).unwrap_or_default();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut o = Vec::with_capacity(total);
    o.extend_from_slice(b"glTF");
    o.extend_from_slice(&2u32.to_le_bytes());
    o.extend_from_slice(&(total as u32).to_le_bytes());
    o.extend_from_slice(&(json.len() as u32).to_le_bytes());
    o.extend_from_slice(b"JSON");
    o.extend_from_slice(&json);
    o.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    o.extend_from_slice(b"BIN\0");
    o.extend_from_slice(&bin);
    o
}
