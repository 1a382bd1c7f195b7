//! Honeybee models (HBJSON, Ladybug Tools): one Room whose Faces are the scene's surfaces by type
//! (Wall, Floor, RoofCeiling; `other` as Wall), windows as Apertures and doors as Doors, furniture
//! as the room's indoor Shades. The measured values go in each object's
//! `user_data["mrtmap"]` in °C: `temperature_c`, `temperature_std_k`, `emissivity`,
//! `observed_fraction`, the scene's own `id` and `label`, a surface's other features and its
//! temperature raster; the room's carries the frame (`world_from_room`) and the level's ±.
//! Faces are wound counter-clockwise seen from outside (Honeybee's convention); a face with an
//! aperture or a door is `Outdoors`, the others `Adiabatic` (a scan does not say what lies
//! behind a wall).
//!
//! [`read`] turns a Honeybee model's room back into a scene: faces, apertures and doors take their
//! temperatures from a table by identifier (or the model's own `user_data["mrtmap"]`), shades
//! that mrtmap wrote come back as furniture.

use mrtmap_radiation::ElementKind;
use std::collections::{BTreeMap, HashMap, HashSet};

use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_geometry::polygon::point_segment_distance;
use mrtmap_radiation::{
    BoxFile, FeatureFile, FramePose, OccluderFile, OccluderShape, RadiantScene, SceneFile, Surface,
    SurfaceFile, SurfaceKind,
};
use mrtmap_report::mesh::{oriented, outward_normal};
use serde_json::{Value, json};

use crate::{Identifiers, ImportError, Opening, opening};

fn pts(p: &[Point3<f64>]) -> Value {
    Value::Array(p.iter().map(|q| json!([q.x, q.y, q.z])).collect())
}

fn face3d(p: &[Point3<f64>]) -> Value {
    json!({ "type": "Face3D", "boundary": pts(p) })
}

fn outdoors() -> Value {
    json!({
        "type": "Outdoors",
        "sun_exposure": true,
        "wind_exposure": true,
        "view_factor": { "type": "Autocalculate" }
    })
}

fn measured(
    id: &str,
    label: &str,
    t_c: f64,
    std_k: Option<f64>,
    emissivity: f64,
    surface: Option<(f64, f64)>,
) -> serde_json::Map<String, Value> {
    let mut m = serde_json::Map::new();
    m.insert("id".into(), json!(id));
    m.insert("label".into(), json!(label));
    m.insert("temperature_c".into(), json!(round_c(t_c)));
    if let Some(s) = std_k {
        m.insert("temperature_std_k".into(), json!(s));
    }
    m.insert("emissivity".into(), json!(emissivity));
    if let Some((t, s)) = surface {
        m.insert("surface_temperature_c".into(), json!(round_c(t)));
        m.insert("surface_temperature_std_k".into(), json!(s));
    }
    m
}

/// The true surface temperature and its ± that a face or sub-face's `user_data` carries.
fn surface_of(v: &Value) -> (Option<f64>, Option<f64>) {
    let d = v.get("user_data").and_then(|u| u.get("mrtmap"));
    let get = |k: &str| d.and_then(|d| d.get(k)).and_then(Value::as_f64);
    (
        get("surface_temperature_c"),
        get("surface_temperature_std_k"),
    )
}

/// How far inside its face's edge a sub-face is kept (m): Honeybee refuses an aperture or door
/// that touches its face's outline (a door on the floor line), so such a one is shrunk about its
/// centroid until every vertex is this far inside.
pub const SUB_FACE_INSET_M: f64 = 0.005;

fn inset(sub: &[Point3<f64>], host: &Surface) -> Vec<Point3<f64>> {
    let outline = &host.polygon_2d;
    let q: Vec<_> = sub.iter().map(|p| host.frame.to_2d(p)).collect();
    let c = centroid_2d(&q);
    let clear = |f: f64| {
        q.iter().all(|p| {
            let r = c + (p - c) * f;
            (0..outline.len()).all(|i| {
                point_segment_distance(&r, &outline[i], &outline[(i + 1) % outline.len()])
                    >= SUB_FACE_INSET_M
            })
        })
    };
    let mut f = 1.0;
    while !clear(f) && f > 0.9 {
        f -= 0.0005;
    }
    q.iter()
        .map(|p| host.frame.to_3d(&(c + (p - c) * f)))
        .collect()
}

fn centroid_2d(q: &[Point2<f64>]) -> Point2<f64> {
    let n = q.len().max(1) as f64;
    Point2::from(q.iter().fold(Point2::origin().coords, |a, p| a + p.coords) / n)
}

/// Temperatures as written: to a microkelvin (kelvin ↔ °C leaves 20.399999999999977).
fn round_c(t: f64) -> f64 {
    (t * 1e6).round() / 1e6
}

fn face_type(kind: SurfaceKind) -> &'static str {
    match kind {
        SurfaceKind::Floor => "Floor",
        SurfaceKind::Ceiling => "RoofCeiling",
        SurfaceKind::Wall | SurfaceKind::Other => "Wall",
    }
}

/// One surface as a Honeybee Face: its windows as Apertures and doors as Doors (kept inside its
/// outline), its other features in its `user_data`.
fn face_json(scene: &RadiantScene, s: &Surface, ids: &mut Identifiers) -> Value {
    let out = outward_normal(scene, s);
    let (mut apertures, mut doors, mut other) = (Vec::new(), Vec::new(), Vec::new());
    for f in &s.features {
        let mut m = measured(
            &f.id,
            &f.label,
            f.temperature.celsius(),
            f.temperature_std_k,
            f.emissivity,
            f.surface_temperature.map(|(t, s)| (t.celsius(), s)),
        );
        let (list, kind) = match opening(&f.label) {
            Some(Opening::Window) => (&mut apertures, "Aperture"),
            Some(Opening::Door) => (&mut doors, "Door"),
            None => {
                m.insert("polygon".into(), pts(&f.polygon));
                other.push(Value::Object(m));
                continue;
            }
        };
        let mut opening_json = json!({
            "type": kind,
            "identifier": ids.make(&f.id),
            "display_name": f.label,
            "geometry": face3d(&oriented(&inset(&f.polygon, s), &out)),
            "boundary_condition": outdoors(),
            "properties": { "type": format!("{kind}PropertiesAbridged") },
            "user_data": { "mrtmap": m },
        });
        // A glazed door is a Honeybee Door with glass: it keeps letting the sun in when read back.
        if kind == "Door" && ElementKind::of_label(&f.label).is_glazing() {
            opening_json["is_glass"] = json!(true);
        }
        list.push(opening_json);
    }
    let mut m = measured(
        &s.id,
        &s.label,
        s.temperature.celsius(),
        s.temperature_std_k,
        s.emissivity,
        s.surface_temperature.map(|(t, s)| (t.celsius(), s)),
    );
    m.insert("kind".into(), json!(s.kind.as_str()));
    if let Some(o) = s.observed_fraction {
        m.insert("observed_fraction".into(), json!(o));
    }
    if !other.is_empty() {
        m.insert("features".into(), Value::Array(other));
    }
    if let Some(r) = &s.raster {
        m.insert("raster".into(), json!(r.file));
    }
    let bc = if apertures.is_empty() && doors.is_empty() {
        json!({ "type": "Adiabatic" })
    } else {
        outdoors()
    };
    let mut face = json!({
        "type": "Face",
        "identifier": ids.make(&s.id),
        "display_name": s.label,
        "geometry": face3d(&oriented(&s.polygon, &out)),
        "face_type": face_type(s.kind),
        "boundary_condition": bc,
        "properties": { "type": "FacePropertiesAbridged" },
        "user_data": { "mrtmap": m },
    });
    for (key, list) in [("apertures", apertures), ("doors", doors)] {
        if !list.is_empty() {
            face[key] = Value::Array(list);
        }
    }
    face
}

/// The furniture as Shades, one per triangle, each naming its piece in `user_data`.
fn shades_json(scene: &RadiantScene, ids: &mut Identifiers) -> Vec<Value> {
    let mut shades = Vec::new();
    for o in &scene.occluders {
        for (k, t) in o.triangles().iter().enumerate() {
            let mut m = measured(
                &o.id,
                &o.label,
                o.temperature.celsius(),
                None,
                o.emissivity,
                None,
            );
            m.insert("furniture".into(), json!(o.id));
            if let OccluderShape::Box { min, max } = &o.shape {
                m.insert(
                    "box".into(),
                    json!({ "min": [min.x, min.y, min.z], "max": [max.x, max.y, max.z] }),
                );
            }
            shades.push(json!({
                "type": "Shade",
                "identifier": ids.make(&format!("{}_{k}", o.id)),
                "display_name": o.label,
                "geometry": face3d(t),
                "properties": { "type": "ShadePropertiesAbridged" },
                "user_data": { "mrtmap": m },
            }));
        }
    }
    shades
}

/// The scene as a Honeybee model (HBJSON text) named `name`, one room, in metres.
pub fn write(scene: &RadiantScene, name: &str) -> String {
    let mut ids = Identifiers::default();
    let room_id = ids.make(name);
    let faces: Vec<Value> = scene
        .surfaces
        .iter()
        .map(|s| face_json(scene, s, &mut ids))
        .collect();
    let shades = shades_json(scene, &mut ids);
    let mut room_data = serde_json::Map::new();
    room_data.insert("temperature_unit".into(), json!("C"));
    room_data.insert(
        "temperature_level_std_k".into(),
        json!(scene.temperature_level_std_k),
    );
    if let Some(k) = scene.temperatures {
        room_data.insert("temperatures".into(), json!(k));
    }
    if let Some(w) = &scene.world_from_room {
        room_data.insert("frame".into(), json!("room"));
        room_data.insert("world_from_room".into(), json!(FramePose::from_isometry(w)));
    }
    let mut room = json!({
        "type": "Room",
        "identifier": room_id,
        "display_name": name,
        "faces": faces,
        "properties": { "type": "RoomPropertiesAbridged" },
        "user_data": { "mrtmap": room_data },
    });
    if !shades.is_empty() {
        room["indoor_shades"] = Value::Array(shades);
    }
    let model = json!({
        "type": "Model",
        "identifier": ids.make(&format!("{name}_model")),
        "display_name": name,
        "units": "Meters",
        "tolerance": 0.001,
        "angle_tolerance": 1.0,
        "properties": { "type": "ModelProperties" },
        "rooms": [room],
    });
    serde_json::to_string(&model).unwrap_or_default()
}

/// Temperatures for a Honeybee model's objects, by identifier (°C, ± in K, emissivity), with a
/// default (`*`) for the rest.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Temperatures {
    /// Identifier → (temperature °C, standard uncertainty K, emissivity).
    pub by_id: BTreeMap<String, (f64, Option<f64>, Option<f64>)>,
    /// The `*` row, when given.
    pub default: Option<(f64, Option<f64>, Option<f64>)>,
    /// The line each identifier came from (for errors).
    pub line_of: HashMap<String, usize>,
}

/// Reads a temperatures table: a header `identifier,temperature_c` (then optionally
/// `temperature_std_k`, `emissivity`), one row per Honeybee identifier, `*` for every object not
/// listed; `#` starts a comment.
pub fn parse_temperatures(text: &str) -> Result<Temperatures, ImportError> {
    let mut rows = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let Some((hl, header)) = rows.next() else {
        return Err(ImportError::Table {
            line: 1,
            problem:
                "the table is empty: write a header `identifier,temperature_c` and a row per face"
                    .into(),
        });
    };
    let cols: Vec<String> = header
        .split(',')
        .map(|c| c.trim().to_ascii_lowercase())
        .collect();
    let known = [
        "identifier",
        "temperature_c",
        "temperature_std_k",
        "emissivity",
    ];
    if cols.len() < 2 || cols[0] != "identifier" || cols[1] != "temperature_c" {
        return Err(ImportError::Table {
            line: hl,
            problem: format!(
                "the header is `{header}`; it must start `identifier,temperature_c` (then optionally temperature_std_k, emissivity)"
            ),
        });
    }
    if let Some(c) = cols.iter().find(|c| !known.contains(&c.as_str())) {
        return Err(ImportError::Table {
            line: hl,
            problem: format!("unknown column `{c}`; the columns are {}", known.join(", ")),
        });
    }
    let col = |name: &str| cols.iter().position(|c| c == name);
    let (std_col, eps_col) = (col("temperature_std_k"), col("emissivity"));
    let mut t = Temperatures::default();
    for (line, row) in rows {
        let mut cells: Vec<&str> = row.split(',').map(str::trim).collect();
        // Optional columns may be left off the end of a row.
        if (2..cols.len()).contains(&cells.len()) {
            cells.resize(cols.len(), "");
        }
        if cells.len() != cols.len() {
            return Err(ImportError::Table {
                line,
                problem: format!("{} cells where the header has {}", cells.len(), cols.len()),
            });
        }
        let number = |i: usize, what: &str, range: (f64, f64)| -> Result<f64, ImportError> {
            match cells[i].parse::<f64>() {
                Ok(v) if v.is_finite() && (range.0..=range.1).contains(&v) => Ok(v),
                _ => Err(ImportError::Table {
                    line,
                    problem: format!(
                        "{what} `{}` is not a number within {}…{}",
                        cells[i], range.0, range.1
                    ),
                }),
            }
        };
        let temp = number(1, "temperature_c", mrtmap_radiation::TEMPERATURE_RANGE_C)?;
        let opt =
            |c: Option<usize>, what: &str, range: (f64, f64)| -> Result<Option<f64>, ImportError> {
                match c {
                    Some(i) if !cells[i].is_empty() => number(i, what, range).map(Some),
                    _ => Ok(None),
                }
            };
        let std_k = opt(std_col, "temperature_std_k", (0.0, 100.0))?;
        let eps = opt(eps_col, "emissivity", (1e-6, 1.0))?;
        let id = cells[0].to_string();
        if id.is_empty() {
            return Err(ImportError::Table {
                line,
                problem: "the identifier is empty".into(),
            });
        }
        if id == "*" {
            t.default = Some((temp, std_k, eps));
        } else if let Some(first) = t.line_of.get(&id) {
            return Err(ImportError::Table {
                line,
                problem: format!("`{id}` is listed again (first on line {first})"),
            });
        } else {
            t.line_of.insert(id.clone(), line);
            t.by_id.insert(id, (temp, std_k, eps));
        }
    }
    Ok(t)
}

fn err(at: impl Into<String>, problem: impl Into<String>) -> ImportError {
    ImportError::Model {
        at: at.into(),
        problem: problem.into(),
    }
}

fn units_to_m(units: Option<&str>) -> Result<f64, ImportError> {
    Ok(match units.unwrap_or("Meters") {
        "Meters" => 1.0,
        "Millimeters" => 0.001,
        "Centimeters" => 0.01,
        "Feet" => 0.3048,
        "Inches" => 0.0254,
        u => {
            return Err(err(
                "units",
                format!("unknown units `{u}` (Meters, Millimeters, Centimeters, Feet or Inches)"),
            ));
        }
    })
}

fn polygon(v: &Value, at: &str, scale: f64) -> Result<Vec<[f64; 3]>, ImportError> {
    if v.get("type").and_then(Value::as_str) != Some("Face3D") {
        return Err(err(at, "expected a Face3D geometry"));
    }
    if v.get("holes")
        .and_then(Value::as_array)
        .is_some_and(|h| !h.is_empty())
    {
        return Err(err(
            at,
            "a face with holes is not read: split it into faces without holes in Honeybee",
        ));
    }
    let b = v.get("boundary").and_then(Value::as_array).ok_or_else(|| {
        err(
            format!("{at}.boundary"),
            "expected a list of [x, y, z] points",
        )
    })?;
    b.iter()
        .enumerate()
        .map(|(i, p)| {
            let c: Option<Vec<f64>> = p
                .as_array()
                .filter(|a| a.len() == 3)
                .map(|a| a.iter().filter_map(Value::as_f64).collect());
            match c {
                Some(c) if c.len() == 3 => Ok([c[0] * scale, c[1] * scale, c[2] * scale]),
                _ => Err(err(
                    format!("{at}.boundary[{i}]"),
                    "expected [x, y, z] numbers",
                )),
            }
        })
        .collect()
}

/// Honeybee's default model tolerance (m): faces may be this far from planar.
const DEFAULT_TOLERANCE_M: f64 = 0.01;

/// `p` projected onto `plane` (its own best fit when `None`) when every vertex lies within `tol`
/// of it, as Honeybee's tolerance allows; refused, naming `at`, when one lies farther. Returns
/// the points and the plane.
fn flatten(
    p: Vec<[f64; 3]>,
    plane: Option<&PlaneFrame>,
    tol: f64,
    at: &str,
) -> Result<(Vec<[f64; 3]>, Option<PlaneFrame>), ImportError> {
    let pts: Vec<Point3<f64>> = p.iter().map(|c| Point3::new(c[0], c[1], c[2])).collect();
    let Some(frame) = plane.cloned().or_else(|| PlaneFrame::of_polygon(&pts)) else {
        // Degenerate: the scene's own checks name it.
        return Ok((p, None));
    };
    let worst = pts
        .iter()
        .map(|q| frame.signed_distance(q).abs())
        .fold(0.0, f64::max);
    if worst > tol {
        return Err(err(
            at,
            format!(
                "a vertex lies {:.1} mm off the {}plane, more than the model's tolerance of {:.1} mm: make it planar in Honeybee",
                worst * 1e3,
                if plane.is_some() {
                    "parent face's "
                } else {
                    "face's "
                },
                tol * 1e3
            ),
        ));
    }
    let flat = pts
        .iter()
        .map(|q| {
            let r = q - frame.normal.into_inner() * frame.signed_distance(q);
            [r.x, r.y, r.z]
        })
        .collect();
    Ok((flat, Some(frame)))
}

/// What a Honeybee object's temperature comes from.
struct Lookup<'a> {
    table: Option<&'a Temperatures>,
    used: HashSet<String>,
    missing: Vec<String>,
}

impl Lookup<'_> {
    /// (°C, ± K, emissivity) for `ident`: the table's row, else mrtmap's user_data, else the
    /// table's default; `None` (noted as missing) without any.
    fn get(&mut self, ident: &str, obj: &Value) -> Option<(f64, Option<f64>, f64)> {
        let data = obj.get("user_data").and_then(|u| u.get("mrtmap"));
        let own = data
            .and_then(|d| d.get("temperature_c"))
            .and_then(Value::as_f64);
        let own_std = data
            .and_then(|d| d.get("temperature_std_k"))
            .and_then(Value::as_f64);
        let own_eps = data
            .and_then(|d| d.get("emissivity"))
            .and_then(Value::as_f64);
        if let Some(&(t, s, e)) = self.table.and_then(|t| t.by_id.get(ident)) {
            self.used.insert(ident.to_string());
            return Some((t, s, e.unwrap_or(1.0)));
        }
        if let Some(t) = own {
            return Some((t, own_std, own_eps.unwrap_or(1.0)));
        }
        if let Some((t, s, e)) = self.table.and_then(|t| t.default) {
            return Some((t, s, e.unwrap_or(1.0)));
        }
        self.missing.push(ident.to_string());
        None
    }
}

/// What [`read`] made of a model.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadModel {
    /// The scene (not yet validated: `RadiantScene::new` checks it).
    pub scene: SceneFile,
    /// The room's identifier.
    pub room: String,
    /// Indoor shades that are not mrtmap's furniture, left out (the engine needs closed furniture).
    pub shades_left_out: usize,
}

fn ident(v: &Value, at: &str) -> Result<String, ImportError> {
    v.get("identifier")
        .and_then(Value::as_str)
        .map(str::to_string)
        .ok_or_else(|| err(at, "has no identifier"))
}

/// The scene id an mrtmap export kept in `user_data["mrtmap"]["id"]` (Honeybee's identifier
/// may have had to change it: "wall east" becomes "wall_east").
fn own_id(obj: &Value) -> Option<String> {
    obj.get("user_data")?
        .get("mrtmap")?
        .get("id")?
        .as_str()
        .filter(|s| !s.is_empty())
        .map(str::to_string)
}

/// One face of room `k` as a surface (`None` when it has no temperature: `look` notes it).
fn read_face(
    f: &Value,
    at: &str,
    (scale, tol): (f64, f64),
    look: &mut Lookup<'_>,
) -> Result<Option<SurfaceFile>, ImportError> {
    let id = ident(f, at)?;
    let kind = match f.get("face_type").and_then(Value::as_str) {
        Some("Floor") => "floor",
        Some("RoofCeiling") => "ceiling",
        Some("Wall") => "wall",
        _ => "other",
    };
    let g_at = format!("{at}.geometry");
    let raw = polygon(f.get("geometry").unwrap_or(&Value::Null), &g_at, scale)?;
    let (poly, plane) = flatten(raw, None, tol, &g_at)?;
    let data = f.get("user_data").and_then(|u| u.get("mrtmap"));
    let mut features = Vec::new();
    for (key, label) in [("apertures", "window"), ("doors", "door")] {
        for (j, sub) in f
            .get(key)
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .enumerate()
        {
            let sat = format!("{at}.{key}[{j}]");
            let sid = ident(sub, &sat)?;
            let s_at = format!("{sat}.geometry");
            let raw = polygon(sub.get("geometry").unwrap_or(&Value::Null), &s_at, scale)?;
            let (sp, _) = flatten(raw, plane.as_ref(), tol, &s_at)?;
            // A Honeybee door with glass is a glazed door (the sun comes through it).
            let glass_door = key == "doors" && sub.get("is_glass") == Some(&Value::Bool(true));
            let label = sub
                .get("user_data")
                .and_then(|u| u.get("mrtmap"))
                .and_then(|d| d.get("label"))
                .and_then(Value::as_str)
                .unwrap_or(if glass_door { "glazed door" } else { label });
            if let Some((t, s, e)) = look.get(&sid, sub) {
                let (st, ss) = surface_of(sub);
                features.push(FeatureFile {
                    id: own_id(sub).unwrap_or(sid),
                    label: label.to_string(),
                    polygon: sp,
                    temperature_c: t,
                    emissivity: e,
                    temperature_std_k: s,
                    surface_temperature_c: st,
                    surface_temperature_std_k: ss,
                });
            }
        }
    }
    if let Some(extra) = data
        .and_then(|d| d.get("features"))
        .and_then(Value::as_array)
    {
        for (j, e) in extra.iter().enumerate() {
            let parsed: Result<FeatureFile, _> = serde_json::from_value(e.clone());
            features.push(parsed.map_err(|x| {
                err(
                    format!("{at}.user_data.mrtmap.features[{j}]"),
                    x.to_string(),
                )
            })?);
        }
    }
    let label = data
        .and_then(|d| d.get("label"))
        .and_then(Value::as_str)
        .or_else(|| f.get("display_name").and_then(Value::as_str))
        .unwrap_or(kind)
        .to_string();
    let raster = data
        .and_then(|d| d.get("raster"))
        .and_then(|r| serde_json::from_value(r.clone()).ok());
    Ok(look.get(&id, f).map(|(t, s, e)| SurfaceFile {
        id: own_id(f).unwrap_or(id),
        kind: kind.to_string(),
        label,
        polygon: poly,
        temperature_c: t,
        emissivity: e,
        temperature_std_k: s,
        surface_temperature_c: surface_of(f).0,
        surface_temperature_std_k: surface_of(f).1,
        observed_fraction: data
            .and_then(|d| d.get("observed_fraction"))
            .and_then(Value::as_f64),
        features,
        raster,
    }))
}

/// A piece of furniture read back from mrtmap's shades: its triangles and its first shade.
struct ShadeGroup<'a> {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    first: &'a Value,
}

/// The room's furniture from the shades mrtmap wrote (grouped by the furniture's id), and how
/// many other shades were left out.
fn read_furniture(
    r: &Value,
    k: usize,
    scale: f64,
    look: &mut Lookup<'_>,
) -> Result<(Vec<OccluderFile>, usize), ImportError> {
    let mut furniture: BTreeMap<String, ShadeGroup<'_>> = BTreeMap::new();
    let mut shades_left_out = 0;
    for (i, sh) in r
        .get("indoor_shades")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .enumerate()
    {
        let data = sh.get("user_data").and_then(|u| u.get("mrtmap"));
        let Some(fid) = data
            .and_then(|d| d.get("furniture"))
            .and_then(Value::as_str)
        else {
            shades_left_out += 1;
            continue;
        };
        let p = polygon(
            sh.get("geometry").unwrap_or(&Value::Null),
            &format!("rooms[{k}].indoor_shades[{i}].geometry"),
            scale,
        )?;
        let e = furniture.entry(fid.to_string()).or_insert(ShadeGroup {
            vertices: Vec::new(),
            triangles: Vec::new(),
            first: sh,
        });
        let base = e.vertices.len();
        e.vertices.extend(p.iter().copied());
        for j in 1..p.len().saturating_sub(1) {
            e.triangles.push([base, base + j, base + j + 1]);
        }
    }
    let mut occluders = Vec::new();
    for (
        fid,
        ShadeGroup {
            vertices,
            triangles,
            first: sh,
        },
    ) in furniture
    {
        let data = sh.get("user_data").and_then(|u| u.get("mrtmap"));
        let label = data
            .and_then(|d| d.get("label"))
            .and_then(Value::as_str)
            .unwrap_or("furniture");
        let box_: Option<BoxFile> = data
            .and_then(|d| d.get("box"))
            .and_then(|b| serde_json::from_value(b.clone()).ok());
        if let Some((t, _, e)) = look.get(&fid, sh) {
            occluders.push(OccluderFile {
                id: fid,
                label: label.to_string(),
                temperature_c: t,
                emissivity: e,
                vertices: box_.is_none().then_some(vertices),
                triangles: box_.is_none().then_some(triangles),
                box_,
            });
        }
    }
    Ok((occluders, shades_left_out))
}

/// A Honeybee model's room (the one named `room`, or the model's only room) as a scene, with
/// temperatures from `table` (by identifier) or from the model's `user_data["mrtmap"]`.
pub fn read(
    text: &str,
    room: Option<&str>,
    table: Option<&Temperatures>,
) -> Result<ReadModel, ImportError> {
    let model: Value = serde_json::from_str(text)
        .map_err(|e| err(format!("line {}", e.line()), format!("not JSON: {e}")))?;
    if model.get("type").and_then(Value::as_str) != Some("Model") {
        return Err(err(
            "type",
            "this is not a Honeybee model (its `type` is not `Model`)",
        ));
    }
    let scale = units_to_m(model.get("units").and_then(Value::as_str))?;
    let tol = model
        .get("tolerance")
        .and_then(Value::as_f64)
        .filter(|t| t.is_finite() && *t > 0.0)
        .map_or(DEFAULT_TOLERANCE_M, |t| (t * scale).min(0.05));
    let rooms = model
        .get("rooms")
        .and_then(Value::as_array)
        .filter(|r| !r.is_empty())
        .ok_or_else(|| err("rooms", "the model has no rooms"))?;
    let names: Vec<String> = rooms
        .iter()
        .map(|r| {
            r.get("identifier")
                .and_then(Value::as_str)
                .unwrap_or("?")
                .to_string()
        })
        .collect();
    let k = match room {
        Some(want) => names.iter().position(|n| n == want).ok_or_else(|| {
            err(
                "rooms",
                format!(
                    "no room `{want}`; the model's rooms are {}",
                    names.join(", ")
                ),
            )
        })?,
        None if rooms.len() == 1 => 0,
        None => {
            return Err(err(
                "rooms",
                format!(
                    "the model has {} rooms ({}); choose one with --room",
                    rooms.len(),
                    names.join(", ")
                ),
            ));
        }
    };
    let r = &rooms[k];
    let mut look = Lookup {
        table,
        used: HashSet::new(),
        missing: Vec::new(),
    };
    let faces = r
        .get("faces")
        .and_then(Value::as_array)
        .ok_or_else(|| err(format!("rooms[{k}].faces"), "the room has no faces"))?;
    let mut surfaces = Vec::new();
    for (i, f) in faces.iter().enumerate() {
        let at = format!("rooms[{k}].faces[{i}]");
        surfaces.extend(read_face(f, &at, (scale, tol), &mut look)?);
    }
    let (occluders, shades_left_out) = read_furniture(r, k, scale, &mut look)?;
    if !look.missing.is_empty() {
        let n = look.missing.len();
        let some: Vec<&str> = look.missing.iter().take(8).map(String::as_str).collect();
        return Err(err(
            format!("rooms[{k}]"),
            format!(
                "{n} object(s) have no temperature ({}{}): list them in the temperatures table by identifier, or give a `*` row",
                some.join(", "),
                if n > 8 { ", …" } else { "" }
            ),
        ));
    }
    if let Some(t) = table {
        let unknown: Vec<&String> = t
            .by_id
            .keys()
            .filter(|id| !look.used.contains(*id))
            .collect();
        if let Some(u) = unknown.first() {
            return Err(ImportError::Table {
                line: t.line_of.get(*u).copied().unwrap_or(0),
                problem: format!(
                    "`{u}` is not a face, aperture, door or furniture of room `{}`: check the identifier",
                    names[k]
                ),
            });
        }
    }
    let rdata = r.get("user_data").and_then(|u| u.get("mrtmap"));
    Ok(ReadModel {
        scene: SceneFile {
            format: "mrtmap-scene/1".into(),
            up: Some([0.0, 0.0, 1.0]),
            world_from_room: rdata
                .and_then(|d| d.get("world_from_room"))
                .and_then(|w| serde_json::from_value(w.clone()).ok()),
            temperature_level_std_k: rdata
                .and_then(|d| d.get("temperature_level_std_k"))
                .and_then(Value::as_f64),
            temperatures: rdata
                .and_then(|d| d.get("temperatures"))
                .and_then(|w| serde_json::from_value(w.clone()).ok()),
            surfaces,
            occluders,
        },
        room: names[k].clone(),
        shades_left_out,
    })
}
