//! MRT on a horizontal grid over the floor: grid nodes in the map frame ([`MapFrame`]), and the
//! computed field.

use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_geometry::polygon::{Containment, point_in_polygon};
use mrtmap_physics::Temperature;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::bounds::RoomBounds;
use crate::engine::{MrtEngine, MrtError, PointMrt};
use crate::map_frame::{FieldError, MapFrame};

/// Grid settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GridSpec {
    /// Nodes along u.
    pub nx: usize,
    /// Nodes along v.
    pub ny: usize,
    /// Height above the floor (m); 1.1 m is seated head height.
    pub height_m: f64,
    /// Distance kept from the floor outline (m).
    pub margin_m: f64,
}

/// The most nodes a grid may have (a 2000 × 2000 map).
pub const MAX_GRID_NODES: usize = 4_000_000;

impl GridSpec {
    /// Refuses a grid without nodes or with more than [`MAX_GRID_NODES`], and a height or margin
    /// that is not a number or a negative margin: what can be checked before the room is known.
    pub fn check(&self) -> Result<(), FieldError> {
        let nodes = self.nx.saturating_mul(self.ny);
        if self.nx == 0 || self.ny == 0 || nodes > MAX_GRID_NODES {
            return Err(FieldError::BadGrid(format!(
                "{}×{} nodes (at least 1×1, at most {MAX_GRID_NODES} in all)",
                self.nx, self.ny
            )));
        }
        if !(self.height_m.is_finite() && self.margin_m.is_finite() && self.margin_m >= 0.0) {
            return Err(FieldError::BadGrid(format!(
                "height {} m, margin {} m (the margin is a distance from the walls: 0 or more)",
                self.height_m, self.margin_m
            )));
        }
        Ok(())
    }
}

impl Default for GridSpec {
    fn default() -> Self {
        Self {
            nx: 20,
            ny: 20,
            height_m: 1.1,
            margin_m: 0.1,
        }
    }
}

/// One grid node.
#[derive(Clone, Debug, PartialEq)]
pub struct GridNode {
    /// Column (along u).
    pub i: usize,
    /// Row (along v).
    pub j: usize,
    /// Map coordinates.
    pub uv: Point2<f64>,
    /// 3D point (scene frame).
    pub point: Point3<f64>,
    /// The MRT there, or why not.
    pub result: Result<PointMrt, MrtError>,
}

/// Summary of a field: extremes and mean with where they are.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FieldSummary {
    /// Nodes computed.
    pub nodes: usize,
    /// Nodes skipped (inside occluders or failed).
    pub skipped: usize,
    /// Lowest MRT (°C) and its node.
    pub min: Extreme,
    /// Highest MRT (°C) and its node.
    pub max: Extreme,
    /// Mean MRT over the nodes (°C).
    pub mean_c: f64,
    /// Largest standard error (K).
    pub max_std_error_k: f64,
    /// The largest of each of the standard error's parts over the nodes (K).
    #[serde(default)]
    pub max_std_error_parts: StdErrorParts,
    /// The unseen patches whose being unseen matters most for the map (at most
    /// [`UNSEEN_LISTED`]), largest first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unseen_patches: Vec<UnseenImpact>,
}

/// A standard error's parts (K), which combine in quadrature into the total.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StdErrorParts {
    /// Monte Carlo sampling of the view factors.
    pub sampling_k: f64,
    /// The surfaces' temperatures (their random error).
    pub temperatures_k: f64,
    /// Where the point lies relative to the surfaces.
    pub placement_k: f64,
    /// Areas the scan never saw.
    pub unseen_k: f64,
    /// The camera's absolute level.
    pub level_k: f64,
}

impl StdErrorParts {
    /// The parts of `r`.
    pub fn of(r: &PointMrt) -> Self {
        Self {
            sampling_k: r.sampling_std_error_k,
            temperatures_k: r.temperature_std_error_k,
            placement_k: r.placement_std_error_k,
            unseen_k: r.unseen_std_error_k,
            level_k: r.level_std_error_k,
        }
    }

    /// Each part with its name for people, in order.
    pub fn named(&self) -> [(&'static str, f64); 5] {
        [
            ("sampling", self.sampling_k),
            ("surface temperatures", self.temperatures_k),
            ("placement", self.placement_k),
            ("unseen areas", self.unseen_k),
            ("camera level", self.level_k),
        ]
    }

    /// The larger of each part.
    pub fn max(self, o: Self) -> Self {
        Self {
            sampling_k: self.sampling_k.max(o.sampling_k),
            temperatures_k: self.temperatures_k.max(o.temperatures_k),
            placement_k: self.placement_k.max(o.placement_k),
            unseen_k: self.unseen_k.max(o.unseen_k),
            level_k: self.level_k.max(o.level_k),
        }
    }
}

/// A value at a place.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Extreme {
    /// MRT (°C).
    pub mrt_c: f64,
    /// Scene coordinates.
    pub xyz: [f64; 3],
    /// Map coordinates.
    pub uv: [f64; 2],
}

/// A grid laid over a floor: node coordinates along u and v, and the nodes inside the outline.
#[derive(Clone, Debug, PartialEq)]
pub struct GridLayout {
    /// Node coordinates along u.
    pub u: Vec<f64>,
    /// Node coordinates along v.
    pub v: Vec<f64>,
    /// (i, j, map coordinates) of the nodes inside the floor outline, row-major (j then i).
    pub places: Vec<(usize, usize, Point2<f64>)>,
}

/// MRT over a grid.
pub struct MrtField {
    /// The frame.
    pub frame: MapFrame,
    /// The grid.
    pub spec: GridSpec,
    /// Node coordinates along u.
    pub u: Vec<f64>,
    /// Node coordinates along v.
    pub v: Vec<f64>,
    /// Nodes inside the floor outline (row-major: j then i).
    pub nodes: Vec<GridNode>,
    /// The scene's unseen patches by what their being unseen does to the map, largest first.
    pub unseen: Vec<UnseenImpact>,
}

/// What one unseen patch of a surface does to a map: the largest part of a node's standard error
/// it makes, and where.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UnseenImpact {
    /// The surface's id.
    pub surface_id: String,
    /// The patch (index into the surface raster's `unseen`).
    pub patch: usize,
    /// Its area (m²).
    pub area_m2: f64,
    /// Its centroid (scene frame).
    pub centre: [f64; 3],
    /// The temperatures seen around it (°C).
    pub range_c: [f64; 2],
    /// The largest part of a node's standard error it makes (K).
    pub max_std_error_k: f64,
    /// That node (scene frame).
    pub at: [f64; 3],
}

/// How many unseen patches a map's summary lists.
pub const UNSEEN_LISTED: usize = 10;

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    if n == 1 {
        return vec![(a + b) / 2.0];
    }
    (0..n)
        .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
        .collect()
}

impl MrtField {
    /// The grid of `spec` over `frame`: node coordinates along u and v, and the nodes inside the
    /// floor outline (i, j, map coordinates), checked against the room when `bounds` are known.
    pub fn layout(
        frame: &MapFrame,
        spec: &GridSpec,
        bounds: Option<&RoomBounds>,
    ) -> Result<GridLayout, FieldError> {
        spec.check()?;
        if let Some(b) = bounds {
            b.check_height(spec.height_m)?;
        }
        let (lo, hi) = frame.floor_bounds();
        let m = spec.margin_m;
        if hi.x - lo.x <= 2.0 * m || hi.y - lo.y <= 2.0 * m {
            return Err(FieldError::BadGrid(format!(
                "a margin of {m} m leaves no floor to map"
            )));
        }
        let u = linspace(lo.x + m, hi.x - m, spec.nx);
        let v = linspace(lo.y + m, hi.y - m, spec.ny);
        // Nodes keep at least half the margin from the outline: a scanned floor is not an exact
        // rectangle, and the outermost nodes of its bounding box may lie a few mm beyond the margin.
        let tol = 0.5 * m;
        let mut places = Vec::new();
        for (j, &vv) in v.iter().enumerate() {
            for (i, &uu) in u.iter().enumerate() {
                let uv = Point2::new(uu, vv);
                if point_in_polygon(&uv, &frame.floor_uv, tol) == Containment::Inside {
                    places.push((i, j, uv));
                }
            }
        }
        Ok(GridLayout { u, v, places })
    }

    /// Computes the field on `spec` (in parallel; results do not depend on the thread count).
    pub fn compute(
        engine: &MrtEngine<'_>,
        frame: MapFrame,
        spec: GridSpec,
    ) -> Result<Self, FieldError> {
        match Self::compute_until(engine, frame, spec, &|| false)? {
            Some(f) => Ok(f),
            // `stop` never says so.
            None => unreachable!("a map that is never asked to stop stopped"),
        }
    }

    /// [`MrtField::compute`], asking `stop` before each node: `Ok(None)` once it says so (a
    /// person pressed Ctrl-C).
    pub fn compute_until(
        engine: &MrtEngine<'_>,
        frame: MapFrame,
        spec: GridSpec,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<Option<Self>, FieldError> {
        let GridLayout { u, v, places } = Self::layout(&frame, &spec, engine.bounds())?;
        let nx = spec.nx;
        let nodes = places
            .into_par_iter()
            .map(|(i, j, uv)| {
                if stop() {
                    return None;
                }
                let point = frame.point(&uv, spec.height_m);
                let result = engine.at(&point, (j * nx + i) as u64);
                Some(GridNode {
                    i,
                    j,
                    uv,
                    point,
                    result,
                })
            })
            .collect::<Option<Vec<GridNode>>>();
        let Some(nodes) = nodes else {
            return Ok(None);
        };
        let unseen = unseen_impacts(engine, &nodes);
        Ok(Some(Self {
            frame,
            spec,
            u,
            v,
            nodes,
            unseen,
        }))
    }

    /// Extremes and mean, and the unseen patches that matter most; `None` when no node was
    /// computed.
    pub fn summary(&self) -> Option<FieldSummary> {
        let ok: Vec<(&GridNode, &PointMrt)> = self
            .nodes
            .iter()
            .filter_map(|n| n.result.as_ref().ok().map(|r| (n, r)))
            .collect();
        if ok.is_empty() {
            return None;
        }
        let ext = |(n, r): &(&GridNode, &PointMrt)| Extreme {
            mrt_c: r.mrt.celsius(),
            xyz: [n.point.x, n.point.y, n.point.z],
            uv: [n.uv.x, n.uv.y],
        };
        let key = |x: &&(&GridNode, &PointMrt)| x.1.mrt.kelvin();
        let min = ok.iter().min_by(|a, b| key(a).total_cmp(&key(b)))?;
        let max = ok.iter().max_by(|a, b| key(a).total_cmp(&key(b)))?;
        Some(FieldSummary {
            nodes: ok.len(),
            skipped: self.nodes.len() - ok.len(),
            min: ext(min),
            max: ext(max),
            mean_c: ok.iter().map(|x| x.1.mrt.celsius()).sum::<f64>() / ok.len() as f64,
            max_std_error_k: ok.iter().map(|x| x.1.std_error_k).fold(0.0, f64::max),
            max_std_error_parts: ok
                .iter()
                .map(|x| StdErrorParts::of(x.1))
                .fold(StdErrorParts::default(), StdErrorParts::max),
            unseen_patches: self.unseen.iter().take(UNSEEN_LISTED).cloned().collect(),
        })
    }

    /// The MRT at node (i, j), if computed.
    pub fn value(&self, i: usize, j: usize) -> Option<Temperature> {
        self.nodes
            .iter()
            .find(|n| n.i == i && n.j == j)
            .and_then(|n| n.result.as_ref().ok())
            .map(|r| r.mrt)
    }
}

/// Each unseen patch's largest part of a node's standard error over `nodes`, largest first.
fn unseen_impacts(engine: &MrtEngine<'_>, nodes: &[GridNode]) -> Vec<UnseenImpact> {
    let mut best: std::collections::BTreeMap<(usize, usize), (f64, Point3<f64>)> =
        std::collections::BTreeMap::new();
    for n in nodes {
        let Ok(r) = &n.result else { continue };
        for part in &r.unseen_parts {
            let e = best
                .entry((part.surface, part.patch))
                .or_insert((0.0, n.point));
            if part.std_error_k > e.0 {
                *e = (part.std_error_k, n.point);
            }
        }
    }
    let scene = engine.scene();
    let mut out: Vec<UnseenImpact> = best
        .into_iter()
        .filter_map(|((si, j), (k, at))| {
            let s = scene.surfaces.get(si)?;
            let raster = s.raster.as_ref()?;
            let (area_m2, centre) = raster.unseen_extent(j)?;
            Some(UnseenImpact {
                surface_id: s.id.clone(),
                patch: j,
                area_m2,
                centre: [centre.x, centre.y, centre.z],
                range_c: raster.file.unseen.get(j)?.range_c,
                max_std_error_k: k,
                at: [at.x, at.y, at.z],
            })
        })
        .collect();
    out.sort_by(|a, b| b.max_std_error_k.total_cmp(&a.max_std_error_k));
    out
}
