//! The room as triangles with a temperature at every vertex: what the report's 3D view draws and
//! what the glTF export writes. Surfaces are their temperature rasters texel by texel where they
//! have one, else their outline with the features cut out; features lie 2 mm in front of their
//! host (so a rastered host's texels never show through); furniture is its triangles.

use mrtmap_geometry::nalgebra::{Point3, Unit, Vector3};
use mrtmap_geometry::polygon::{area_3d, centroid, newell_normal, triangulate_with_holes};
use mrtmap_radiation::{RadiantScene, RoomBounds, Surface};

/// How far a feature is drawn in front of its host surface (m).
pub const FEATURE_LIFT_M: f64 = 0.002;

/// What a part of the room is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PartRole {
    /// A surface of the envelope (its kind: floor, ceiling, wall, other).
    Surface,
    /// A feature on a surface (window, light, painting …).
    Feature,
    /// Furniture (an occluder).
    Furniture,
}

impl PartRole {
    /// "surface", "feature" or "furniture".
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Surface => "surface",
            Self::Feature => "feature",
            Self::Furniture => "furniture",
        }
    }
}

/// One named part of the room as triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshPart {
    /// The scene's id.
    pub id: String,
    /// The semantic label.
    pub label: String,
    /// Surface, feature or furniture.
    pub role: PartRole,
    /// floor, ceiling, wall or other for a surface; the host's id for a feature; "" otherwise.
    pub detail: String,
    /// Its radiant temperature (°C): the scene's value (a rastered surface's texels vary about it).
    pub temperature_c: f64,
    /// Its temperature's standard uncertainty (K), when the scene states one.
    pub temperature_std_k: Option<f64>,
    /// Area (m²): a surface's whole outline, features included.
    pub area_m2: f64,
    /// Its emissivity.
    pub emissivity: f64,
    /// Its true surface temperature (°C) and ± (K), when the scene gives one.
    pub surface_temperature: Option<(f64, f64)>,
    /// Share of it observed, when the scene states it.
    pub observed_fraction: Option<f64>,
    /// Vertices in the scene's frame (m).
    pub positions: Vec<[f64; 3]>,
    /// Temperature at each vertex (°C).
    pub vertex_temperature_c: Vec<f64>,
    /// Triangles, counter-clockwise seen from outside the room (a surface's, a feature's) or from
    /// outside the furniture.
    pub triangles: Vec<[u32; 3]>,
}

/// A surface's normal pointing out of the room: away from the floor outline for walls, down for
/// the floor, up for the ceiling (a point 5 cm along it must lie outside the room's bounds); for a
/// scene without a floor, away from the centroid of all surfaces.
pub fn outward_normal(scene: &RadiantScene, surface: &Surface) -> Unit<Vector3<f64>> {
    let n = surface.frame.normal;
    let c = centroid(&surface.polygon);
    let outward = match RoomBounds::of_scene(scene) {
        Some(b) => b.locate(&(c + 0.05 * n.into_inner())).is_some(),
        None => {
            let all: Vec<Point3<f64>> = scene
                .surfaces
                .iter()
                .flat_map(|s| s.polygon.iter().copied())
                .collect();
            n.dot(&(c - centroid(&all))) >= 0.0
        }
    };
    if outward { n } else { -n }
}

/// A polygon's vertices in the order that makes its normal `outward` (right-hand rule).
pub fn oriented(polygon: &[Point3<f64>], outward: &Unit<Vector3<f64>>) -> Vec<Point3<f64>> {
    let mut p = polygon.to_vec();
    if newell_normal(&p).dot(outward) < 0.0 {
        p.reverse();
    }
    p
}

fn arr(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// Appends triangles `tris` over `pts` to `part` at temperature `t_c`, wound to face `outward`.
fn push_triangles(
    part: &mut MeshPart,
    pts: &[Point3<f64>],
    tris: &[[usize; 3]],
    t_c: &dyn Fn(usize) -> f64,
    outward: &Vector3<f64>,
) {
    let base = part.positions.len() as u32;
    part.positions.extend(pts.iter().map(arr));
    part.vertex_temperature_c.extend((0..pts.len()).map(t_c));
    for t in tris {
        let n = (pts[t[1]] - pts[t[0]]).cross(&(pts[t[2]] - pts[t[0]]));
        let (a, b, c) = (t[0] as u32, t[1] as u32, t[2] as u32);
        part.triangles.push(if n.dot(outward) >= 0.0 {
            [base + a, base + b, base + c]
        } else {
            [base + a, base + c, base + b]
        });
    }
}

fn fan(n: usize) -> Vec<[usize; 3]> {
    (1..n.saturating_sub(1)).map(|i| [0, i, i + 1]).collect()
}

fn surface_part(scene: &RadiantScene, s: &Surface) -> MeshPart {
    let out = outward_normal(scene, s);
    let mut part = MeshPart {
        id: s.id.clone(),
        label: s.label.clone(),
        role: PartRole::Surface,
        detail: s.kind.as_str().to_string(),
        temperature_c: s.temperature.celsius(),
        temperature_std_k: s.temperature_std_k,
        area_m2: area_3d(&s.polygon),
        emissivity: s.emissivity,
        surface_temperature: s.surface_temperature.map(|(t, e)| (t.celsius(), e)),
        observed_fraction: s.observed_fraction,
        positions: Vec::new(),
        vertex_temperature_c: Vec::new(),
        triangles: Vec::new(),
    };
    let t_surface = s.temperature.celsius();
    if let Some(r) = &s.raster {
        for texel in &r.texels {
            let t = r.file.temperature_c[texel.index].unwrap_or(t_surface);
            push_triangles(
                &mut part,
                &texel.polygon,
                &fan(texel.polygon.len()),
                &|_| t,
                &out,
            );
        }
        return part;
    }
    let (pts, tris) = outline_triangles(s);
    push_triangles(&mut part, &pts, &tris, &|_| t_surface, &out);
    part
}

/// A surface's outline with its features cut out, as triangles over points in its plane (the
/// whole outline when the features cannot be cut out of it); wound either way.
pub fn outline_triangles(s: &Surface) -> (Vec<Point3<f64>>, Vec<[usize; 3]>) {
    let holes: Vec<_> = s.features.iter().map(|f| f.polygon_2d.clone()).collect();
    let (tris, holes) = match triangulate_with_holes(&s.polygon_2d, &holes) {
        Ok(t) => (t, holes),
        Err(_) => (
            mrtmap_geometry::polygon::triangulate(&s.polygon_2d)
                .unwrap_or_else(|_| fan(s.polygon.len())),
            Vec::new(),
        ),
    };
    let pts = s
        .polygon_2d
        .iter()
        .chain(holes.iter().flatten())
        .map(|q| s.frame.to_3d(q))
        .collect();
    (pts, tris)
}

/// The room as named parts: surfaces, then each surface's features, then furniture.
pub fn scene_mesh(scene: &RadiantScene) -> Vec<MeshPart> {
    let mut parts: Vec<MeshPart> = scene
        .surfaces
        .iter()
        .map(|s| surface_part(scene, s))
        .collect();
    for s in &scene.surfaces {
        let out = outward_normal(scene, s);
        let lift = -FEATURE_LIFT_M * out.into_inner();
        for f in &s.features {
            let pts: Vec<Point3<f64>> = f.polygon.iter().map(|p| p + lift).collect();
            let tris = mrtmap_geometry::polygon::triangulate(&f.polygon_2d)
                .unwrap_or_else(|_| fan(pts.len()));
            let t = f.temperature.celsius();
            let mut part = MeshPart {
                id: f.id.clone(),
                label: f.label.clone(),
                role: PartRole::Feature,
                detail: s.id.clone(),
                temperature_c: t,
                temperature_std_k: f.temperature_std_k,
                area_m2: area_3d(&f.polygon),
                emissivity: f.emissivity,
                surface_temperature: f.surface_temperature.map(|(t, e)| (t.celsius(), e)),
                observed_fraction: None,
                positions: Vec::new(),
                vertex_temperature_c: Vec::new(),
                triangles: Vec::new(),
            };
            push_triangles(&mut part, &pts, &tris, &|_| t, &out);
            parts.push(part);
        }
    }
    for o in &scene.occluders {
        let t = o.temperature.celsius();
        let tris = o.triangles();
        let mut part = MeshPart {
            id: o.id.clone(),
            label: o.label.clone(),
            role: PartRole::Furniture,
            detail: String::new(),
            temperature_c: t,
            temperature_std_k: None,
            emissivity: o.emissivity,
            surface_temperature: None,
            area_m2: tris
                .iter()
                .map(|t| 0.5 * (t[1] - t[0]).cross(&(t[2] - t[0])).norm())
                .sum(),
            observed_fraction: None,
            positions: Vec::new(),
            vertex_temperature_c: Vec::new(),
            triangles: Vec::new(),
        };
        let centre = centroid(&tris.iter().flatten().copied().collect::<Vec<_>>());
        for tri in &tris {
            let c = centroid(tri);
            push_triangles(&mut part, tri, &[[0, 1, 2]], &|_| t, &(c - centre));
        }
        parts.push(part);
    }
    parts
}

/// The range of temperatures a colour scale spans (°C): the values' own, widened about its middle to
/// 1 K at least (a uniform room still gets a scale); 20…21 °C for no values.
pub fn colour_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
        (a.min(t), b.max(t))
    });
    if !lo.is_finite() {
        return (20.0, 21.0);
    }
    if hi - lo < 1.0 {
        let m = 0.5 * (lo + hi);
        return (m - 0.5, m + 0.5);
    }
    (lo, hi)
}

/// The colour of `t_c` on the maps' palette (blue cold → red warm) over `lo…hi` (°C).
/// Colour of an MRT grid cell at `t_c` on `lo…hi`: viridis, a palette of its own, so that a
/// grid cell is never read on the surfaces' scale (issue 54: a 20.6 °C MRT cell drawn pink-red
/// beside a 20.9 °C wall drawn pale yellow, one palette on two scales).
pub fn grid_rgb(t_c: f64, lo: f64, hi: f64) -> [u8; 3] {
    let t = if hi > lo { (t_c - lo) / (hi - lo) } else { 0.5 };
    let g = colorgrad::preset::viridis();
    let c = colorgrad::Gradient::at(&g, t.clamp(0.0, 1.0) as f32).to_rgba8();
    [c[0], c[1], c[2]]
}

pub fn temperature_rgb(t_c: f64, lo: f64, hi: f64) -> [u8; 3] {
    let t = if hi > lo { (t_c - lo) / (hi - lo) } else { 0.5 };
    let c = crate::map::palette(t);
    [c.0, c.1, c.2]
}
