//! Validation: a [`SceneFile`] checked against every rule of the scene format
//! (docs/scene-format.md) into a [`RadiantScene`], whose errors name the surface, feature or
//! occluder id and the rule broken.
//!
//! 1. The format's version, at least one surface, `up` (finite, non-zero) and `world_from_room`
//!    (a rigid transform).
//! 2. Each surface in order: its id (present, unique across surfaces, features and occluders),
//!    its kind, its polygon (at least 3 finite vertices within [`MAX_COORDINATE_M`], planar
//!    within [`PLANARITY_TOLERANCE_M`], simple in its own plane frame), its temperature,
//!    emissivity and optional values; then each of its features (in the host's plane and
//!    inside it within [`FEATURE_PLANE_TOLERANCE_M`], simple, clear of the features before it);
//!    then its raster ([`Raster::check`]).
//! 3. Each occluder: its id, a box with min below max or a mesh whose triangles name its
//!    vertices, its temperature and emissivity.
//! 4. The common level's uncertainty (0…[`MAX_LEVEL_STD_K`]).
//! 5. A given `up` must point from the floor towards the rest of the room.

use std::collections::HashSet;

use mrtmap_geometry::nalgebra::{Point2, Point3, Unit, Vector3};
use mrtmap_geometry::polygon::{self, NotSimple, PlaneFrame};
use mrtmap_physics::Temperature;

use super::error::SceneError;
use super::file::{FeatureFile, OccluderFile, SCENE_FORMAT, SceneFile, SurfaceFile, point};
use super::limits::{
    FEATURE_PLANE_TOLERANCE_M, MAX_COORDINATE_M, MAX_LEVEL_STD_K, MAX_ROOM_EXTENT_M,
    PLANARITY_TOLERANCE_M, TEMPERATURE_RANGE_C,
};
use super::model::{Feature, Occluder, OccluderShape, RadiantScene, Surface, SurfaceKind};
use super::raster::Raster;

/// The length to which a polygon is checked for being simple (m): an edge shorter than this, or
/// edges closer than this, break the rule.
const SIMPLE_TOLERANCE_M: f64 = 1e-6;

fn check_temperature(element: &'static str, id: &str, c: f64) -> Result<Temperature, SceneError> {
    if !c.is_finite() {
        return Err(SceneError::NotFinite {
            element,
            id: id.into(),
            what: "temperature_c",
        });
    }
    if !(TEMPERATURE_RANGE_C.0..=TEMPERATURE_RANGE_C.1).contains(&c) {
        return Err(SceneError::Temperature {
            element,
            id: id.into(),
            value: c,
        });
    }
    Ok(Temperature::from_celsius(c))
}

fn check_emissivity(element: &'static str, id: &str, e: f64) -> Result<f64, SceneError> {
    if !(e > 0.0 && e <= 1.0) {
        return Err(SceneError::Emissivity {
            element,
            id: id.into(),
            value: e,
        });
    }
    Ok(e)
}

/// An optional true surface temperature with its uncertainty.
fn check_surface_temperature(
    element: &'static str,
    id: &str,
    c: Option<f64>,
    std_k: Option<f64>,
) -> Result<Option<(Temperature, f64)>, SceneError> {
    let Some(c) = c else { return Ok(None) };
    if !(c.is_finite() && (TEMPERATURE_RANGE_C.0..=TEMPERATURE_RANGE_C.1).contains(&c)) {
        return Err(SceneError::BadValue {
            element,
            id: id.into(),
            what: "surface_temperature_c",
            value: c,
            rule: "within −60…200 °C",
        });
    }
    let std_k = check_std(element, id, std_k)?.unwrap_or(0.0);
    Ok(Some((Temperature::from_celsius(c), std_k)))
}

fn check_std(element: &'static str, id: &str, s: Option<f64>) -> Result<Option<f64>, SceneError> {
    match s {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err(SceneError::BadValue {
            element,
            id: id.into(),
            what: "temperature_std_k",
            value: v,
            rule: "a finite value ≥ 0",
        }),
        _ => Ok(s),
    }
}

fn check_polygon(
    element: &'static str,
    id: &str,
    poly: &[[f64; 3]],
) -> Result<Vec<Point3<f64>>, SceneError> {
    if poly.len() < 3 {
        return Err(SceneError::TooFewVertices {
            element,
            id: id.into(),
            count: poly.len(),
        });
    }
    if poly.iter().flatten().any(|c| !c.is_finite()) {
        return Err(SceneError::NotFinite {
            element,
            id: id.into(),
            what: "a polygon coordinate",
        });
    }
    if let Some(&value) = poly.iter().flatten().find(|c| c.abs() > MAX_COORDINATE_M) {
        return Err(SceneError::FarCoordinate {
            element,
            id: id.into(),
            value,
        });
    }
    Ok(poly.iter().map(point).collect())
}

fn not_simple(element: &'static str, id: &str, why: NotSimple) -> SceneError {
    let detail = match why {
        NotSimple::TooFewVertices => "fewer than 3 distinct vertices".to_string(),
        NotSimple::ZeroLengthEdge(i) => format!("vertices {} and {} coincide", i, i + 1),
        NotSimple::EdgesIntersect(i, j) => format!("edge {i} intersects edge {j}"),
        NotSimple::ZeroArea => "it encloses no area".to_string(),
    };
    SceneError::NotSimple {
        element,
        id: id.into(),
        detail,
    }
}

fn bounds(poly: &[Point2<f64>]) -> (Point2<f64>, Point2<f64>) {
    let mut lo = Point2::new(f64::INFINITY, f64::INFINITY);
    let mut hi = Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
    for p in poly {
        lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    (lo, hi)
}

/// Ids seen so far: each must be present and unique across surfaces, features and occluders.
#[derive(Default)]
struct Ids(HashSet<String>);

impl Ids {
    fn claim(&mut self, id: &str, element: String) -> Result<(), SceneError> {
        if id.is_empty() {
            return Err(SceneError::EmptyId { element });
        }
        if !self.0.insert(id.to_string()) {
            return Err(SceneError::DuplicateId { id: id.into() });
        }
        Ok(())
    }
}

/// `up`, when given: a finite, non-zero vector.
fn check_up(up: Option<[f64; 3]>) -> Result<Option<Unit<Vector3<f64>>>, SceneError> {
    let Some(u) = up else {
        return Ok(None);
    };
    let v = Vector3::new(u[0], u[1], u[2]);
    if !v.iter().all(|c| c.is_finite()) {
        return Err(SceneError::BadUp { value: u });
    }
    Ok(Some(
        Unit::try_new(v, 1e-9).ok_or(SceneError::BadUp { value: u })?,
    ))
}

/// A feature of the surface `host` (its frame and 2D outline), checked against the features
/// already accepted on it.
fn check_feature(
    f: &FeatureFile,
    host: &str,
    frame: &PlaneFrame,
    host_2d: &[Point2<f64>],
    others: &[Feature],
) -> Result<Feature, SceneError> {
    let fpoly = check_polygon("feature", &f.id, &f.polygon)?;
    let off = fpoly
        .iter()
        .map(|p| frame.signed_distance(p).abs())
        .fold(0.0, f64::max);
    if off > FEATURE_PLANE_TOLERANCE_M {
        return Err(SceneError::FeatureOffPlane {
            id: f.id.clone(),
            host: host.into(),
            distance_mm: off * 1e3,
        });
    }
    let f2: Vec<Point2<f64>> = fpoly.iter().map(|p| frame.to_2d(p)).collect();
    polygon::check_simple(&f2, SIMPLE_TOLERANCE_M).map_err(|e| not_simple("feature", &f.id, e))?;
    if !polygon::polygon_inside(&f2, host_2d, FEATURE_PLANE_TOLERANCE_M) {
        return Err(SceneError::FeatureOutsideHost {
            id: f.id.clone(),
            host: host.into(),
        });
    }
    if let Some(other) = others
        .iter()
        .find(|o| polygon::polygons_overlap(&o.polygon_2d, &f2, FEATURE_PLANE_TOLERANCE_M))
    {
        return Err(SceneError::FeaturesOverlap {
            a: other.id.clone(),
            b: f.id.clone(),
            host: host.into(),
        });
    }
    Ok(Feature {
        id: f.id.clone(),
        label: f.label.clone(),
        polygon: fpoly,
        temperature: check_temperature("feature", &f.id, f.temperature_c)?,
        emissivity: check_emissivity("feature", &f.id, f.emissivity)?,
        temperature_std_k: check_std("feature", &f.id, f.temperature_std_k)?,
        surface_temperature: check_surface_temperature(
            "feature",
            &f.id,
            f.surface_temperature_c,
            f.surface_temperature_std_k,
        )?,
        bounds_2d: bounds(&f2),
        polygon_2d: f2,
    })
}

/// A surface (the `si`-th) with its features.
fn check_surface(s: &SurfaceFile, si: usize, ids: &mut Ids) -> Result<Surface, SceneError> {
    ids.claim(&s.id, format!("surface {}", si + 1))?;
    let kind = SurfaceKind::parse(&s.kind).ok_or_else(|| SceneError::UnknownKind {
        id: s.id.clone(),
        kind: s.kind.clone(),
    })?;
    let poly = check_polygon("surface", &s.id, &s.polygon)?;
    let dev = polygon::planarity_deviation(&poly);
    if dev > PLANARITY_TOLERANCE_M {
        return Err(SceneError::NonPlanar {
            element: "surface",
            id: s.id.clone(),
            deviation_mm: dev * 1e3,
        });
    }
    let frame = PlaneFrame::of_polygon(&poly)
        .ok_or_else(|| not_simple("surface", &s.id, NotSimple::ZeroArea))?;
    let poly2: Vec<Point2<f64>> = poly.iter().map(|p| frame.to_2d(p)).collect();
    polygon::check_simple(&poly2, SIMPLE_TOLERANCE_M)
        .map_err(|e| not_simple("surface", &s.id, e))?;
    let temperature = check_temperature("surface", &s.id, s.temperature_c)?;
    let emissivity = check_emissivity("surface", &s.id, s.emissivity)?;
    let temperature_std_k = check_std("surface", &s.id, s.temperature_std_k)?;
    let surface_temperature = check_surface_temperature(
        "surface",
        &s.id,
        s.surface_temperature_c,
        s.surface_temperature_std_k,
    )?;
    if let Some(f) = s.observed_fraction
        && !(0.0..=1.0).contains(&f)
    {
        return Err(SceneError::BadValue {
            element: "surface",
            id: s.id.clone(),
            what: "observed_fraction",
            value: f,
            rule: "between 0 and 1",
        });
    }
    let mut features: Vec<Feature> = Vec::with_capacity(s.features.len());
    for (fi, f) in s.features.iter().enumerate() {
        ids.claim(&f.id, format!("feature {} of surface '{}'", fi + 1, s.id))?;
        features.push(check_feature(f, &s.id, &frame, &poly2, &features)?);
    }
    let raster = s
        .raster
        .as_ref()
        .map(|r| Raster::check(r, &s.id, &poly, &frame.normal))
        .transpose()?;
    Ok(Surface {
        id: s.id.clone(),
        kind,
        label: s.label.clone(),
        polygon: poly,
        temperature,
        emissivity,
        temperature_std_k,
        surface_temperature,
        observed_fraction: s.observed_fraction,
        raster,
        features,
        frame,
        polygon_2d: poly2,
    })
}

/// An occluder's shape: a box with min below max, or a mesh whose triangles name its vertices.
fn check_shape(o: &OccluderFile) -> Result<OccluderShape, SceneError> {
    let bad = |detail: String| SceneError::BadOccluder {
        id: o.id.clone(),
        detail,
    };
    let far = |cs: &mut dyn Iterator<Item = &f64>| -> Result<(), SceneError> {
        for &value in cs {
            if value.abs() > MAX_COORDINATE_M {
                return Err(SceneError::FarCoordinate {
                    element: "occluder",
                    id: o.id.clone(),
                    value,
                });
            }
        }
        Ok(())
    };
    match (&o.box_, &o.vertices, &o.triangles) {
        (Some(b), None, None) => {
            if b.min.iter().chain(b.max.iter()).any(|c| !c.is_finite()) {
                return Err(bad("box corners must be finite".into()));
            }
            far(&mut b.min.iter().chain(b.max.iter()))?;
            if (0..3).any(|i| b.min[i] >= b.max[i]) {
                return Err(bad(format!(
                    "box min {:?} is not below max {:?} on every axis",
                    b.min, b.max
                )));
            }
            Ok(OccluderShape::Box {
                min: point(&b.min),
                max: point(&b.max),
            })
        }
        (None, Some(v), Some(t)) => {
            if v.iter().flatten().any(|c| !c.is_finite()) {
                return Err(bad("mesh vertices must be finite".into()));
            }
            far(&mut v.iter().flatten())?;
            if t.is_empty() {
                return Err(bad("mesh has no triangles".into()));
            }
            if let Some((k, tri)) = t
                .iter()
                .enumerate()
                .find(|(_, tri)| tri.iter().any(|&i| i >= v.len()))
            {
                return Err(bad(format!(
                    "triangle {k} {tri:?} refers to a vertex beyond the {} given",
                    v.len()
                )));
            }
            Ok(OccluderShape::Mesh {
                vertices: v.iter().map(point).collect(),
                triangles: t.clone(),
            })
        }
        _ => Err(bad(
            "give either `box` or both `vertices` and `triangles`".into()
        )),
    }
}

/// Refuses surfaces spanning more than [`MAX_ROOM_EXTENT_M`], naming the unit they were likely
/// written in (issue 54: a scene in millimetres mapped a 4.2 km room without a word).
fn check_extent(surfaces: &[Surface]) -> Result<(), SceneError> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in surfaces.iter().flat_map(|s| s.polygon.iter()) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent_m = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    if extent_m <= MAX_ROOM_EXTENT_M {
        return Ok(());
    }
    let hint = [(1000.0, "millimetres"), (100.0, "centimetres")]
        .iter()
        .find(|(per_m, _)| (1.0..=MAX_ROOM_EXTENT_M).contains(&(extent_m / per_m)))
        .map_or(String::new(), |(per_m, unit)| {
            format!(
                "; in {unit} it would span {:.2} m: were its coordinates written in {unit}? Divide them by {per_m:.0}",
                extent_m / per_m
            )
        });
    Err(SceneError::TooLarge {
        extent_m,
        max_m: MAX_ROOM_EXTENT_M,
        hint,
    })
}

impl RadiantScene {
    /// Validates a scene file against every rule of the spec.
    pub fn new(file: &SceneFile) -> Result<Self, SceneError> {
        if file.format != SCENE_FORMAT {
            return Err(SceneError::Format {
                found: file.format.clone(),
            });
        }
        if file.surfaces.is_empty() {
            return Err(SceneError::NoSurfaces);
        }
        let up_given = check_up(file.up)?;
        let world_from_room = match file.world_from_room {
            None => None,
            Some(p) => Some(
                p.to_isometry()
                    .ok_or(SceneError::BadWorldFromRoom { value: p })?,
            ),
        };
        let mut ids = Ids::default();
        let surfaces = file
            .surfaces
            .iter()
            .enumerate()
            .map(|(si, s)| check_surface(s, si, &mut ids))
            .collect::<Result<Vec<_>, _>>()?;
        check_extent(&surfaces)?;
        let mut occluders = Vec::with_capacity(file.occluders.len());
        for (oi, o) in file.occluders.iter().enumerate() {
            ids.claim(&o.id, format!("occluder {}", oi + 1))?;
            occluders.push(Occluder {
                id: o.id.clone(),
                label: o.label.clone(),
                shape: check_shape(o)?,
                temperature: check_temperature("occluder", &o.id, o.temperature_c)?,
                emissivity: check_emissivity("occluder", &o.id, o.emissivity)?,
            });
        }
        let level = file.temperature_level_std_k.unwrap_or(0.0);
        if !(level.is_finite() && (0.0..=MAX_LEVEL_STD_K).contains(&level)) {
            return Err(SceneError::LevelStd { value: level });
        }
        let scene = Self {
            up_given,
            world_from_room,
            temperature_level_std_k: level,
            temperatures: file.temperatures,
            surfaces,
            occluders,
        };
        scene.check_up_direction()?;
        Ok(scene)
    }

    /// A given `up` must point from the floor towards the rest of the room.
    fn check_up_direction(&self) -> Result<(), SceneError> {
        let (Some(up), Some(floor)) = (self.up_given, self.floor()) else {
            return Ok(());
        };
        let others: Vec<Point3<f64>> = self
            .surfaces
            .iter()
            .filter(|s| !std::ptr::eq(*s, floor))
            .flat_map(|s| s.polygon.iter().copied())
            .collect();
        if others.is_empty() {
            return Ok(());
        }
        let rise = up.dot(&(polygon::centroid(&others) - polygon::centroid(&floor.polygon)));
        if rise < 0.0 {
            return Err(SceneError::UpOutOfRoom {
                value: [up.x, up.y, up.z],
                floor: floor.id.clone(),
            });
        }
        Ok(())
    }
}
