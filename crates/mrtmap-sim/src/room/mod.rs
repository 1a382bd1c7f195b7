//! Room descriptions (TOML) and their conversion to radiant scenes.
//!
//! A room is a floor plan (a simple polygon, metres) extruded to a height, with a temperature per
//! wall, floor and ceiling (walls optionally with a vertical gradient), features on any surface,
//! furniture boxes, the air temperature and named validation points. Coordinates are the room
//! frame: z up, the floor at z = 0. Wall `i` runs from `floor_plan[i]` to `floor_plan[i + 1]`.

pub mod grey;

use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Vector3};
use mrtmap_geometry::polygon::{self, Containment};
use mrtmap_radiation::{
    FeatureFile, OccluderFile, RadiantScene, SCENE_FORMAT, SceneError, SceneFile, SurfaceFile,
};
use serde::{Deserialize, Serialize};

/// Largest height of a strip when a wall with a gradient is cut into uniform strips (m).
pub const GRADIENT_STRIP_M: f64 = 0.05;

/// Surface temperatures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TemperaturesFile {
    /// Floor (°C).
    pub floor_c: f64,
    /// Ceiling (°C).
    pub ceiling_c: f64,
    /// Every wall unless overridden (°C, at mid-height).
    pub walls_c: f64,
    /// Vertical gradient of every wall unless overridden (K/m, positive = warmer up).
    #[serde(default)]
    pub wall_gradient_k_per_m: f64,
    /// The floor's emissivity (unset: 1 in black rooms, drawn in grey ones).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub floor_emissivity: Option<f64>,
    /// The ceiling's emissivity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ceiling_emissivity: Option<f64>,
    /// Every wall's emissivity unless overridden.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub walls_emissivity: Option<f64>,
}

/// A per-wall override.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WallFile {
    /// Wall index (edge of the floor plan).
    pub index: usize,
    /// Temperature at mid-height (°C).
    #[serde(default)]
    pub temperature_c: Option<f64>,
    /// Vertical gradient (K/m).
    #[serde(default)]
    pub gradient_k_per_m: Option<f64>,
    /// Label (default "wall").
    #[serde(default)]
    pub label: Option<String>,
    /// Emissivity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emissivity: Option<f64>,
}

/// A feature: a rectangle or polygon on a surface with its own temperature.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeatureSpec {
    /// "floor", "ceiling" or "wall N".
    pub on: String,
    /// Semantic label (window, recessed light, painting, radiator, door…).
    pub label: String,
    /// Temperature (°C).
    pub temperature_c: f64,
    /// On a wall [s, z, width, height] (s along the wall from its start, z above the floor); on the
    /// floor or ceiling [x, y, width, depth] in plan coordinates.
    #[serde(default)]
    pub rect: Option<[f64; 4]>,
    /// Or a polygon in the same 2D coordinates.
    #[serde(default)]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// Emissivity (unset: 1 in black rooms; glass 0.84 and others drawn in grey ones).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emissivity: Option<f64>,
}

/// A furniture box (an occluder with a temperature).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FurnitureSpec {
    /// Label.
    pub label: String,
    /// Lower corner (room frame).
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
    /// Temperature (°C).
    pub temperature_c: f64,
}

/// A named validation point (where a globe thermometer would stand).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointSpec {
    /// Name (A, B…).
    pub name: String,
    /// Plan position (m).
    pub xy: [f64; 2],
    /// Height above the floor (m).
    #[serde(default = "head_height")]
    pub height_m: f64,
}

fn head_height() -> f64 {
    1.1
}

/// A room description as written in TOML.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoomFile {
    /// Name.
    pub name: String,
    /// What it is.
    #[serde(default)]
    pub description: String,
    /// Floor-to-ceiling height (m).
    pub height_m: f64,
    /// Air temperature (°C).
    pub air_temperature_c: f64,
    /// Floor plan vertices (m), either winding.
    pub floor_plan: Vec<[f64; 2]>,
    /// Surface temperatures.
    pub temperatures: TemperaturesFile,
    /// Per-wall overrides.
    #[serde(default)]
    pub walls: Vec<WallFile>,
    /// Features.
    #[serde(default)]
    pub features: Vec<FeatureSpec>,
    /// Furniture.
    #[serde(default)]
    pub furniture: Vec<FurnitureSpec>,
    /// Validation points.
    #[serde(default)]
    pub points: Vec<PointSpec>,
    /// Every surface's and feature's emissivity, as the simulator drew them (written into a
    /// recording's room.toml, so that the room read back is the one simulated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emissivities: Option<EmissivitiesFile>,
}

/// The emissivities a simulation used, in order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EmissivitiesFile {
    /// By surface: floor, ceiling, walls 0… (in the plan's counter-clockwise order).
    pub surfaces: Vec<f64>,
    /// By feature, in the file's order.
    pub features: Vec<f64>,
}

/// Why a room description is invalid.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RoomError {
    /// TOML syntax or shape.
    #[error("{0}")]
    Toml(String),
    /// A rule broken.
    #[error("{0}")]
    Invalid(String),
    /// The scene built from it is invalid.
    #[error("the room makes an invalid scene: {0}")]
    Scene(#[from] SceneError),
}

/// Which surface of the room.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SurfaceRef {
    /// The floor.
    Floor,
    /// The ceiling.
    Ceiling,
    /// Wall `i`.
    Wall(usize),
}

/// A feature placed in 3D.
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedFeature {
    /// Id ("window-1"…).
    pub id: String,
    /// Label.
    pub label: String,
    /// Host surface.
    pub on: SurfaceRef,
    /// Polygon in the host's 2D coordinates (see [`Room::surface_frame`]).
    pub polygon_2d: Vec<Point2<f64>>,
    /// Temperature (°C).
    pub temperature_c: f64,
}

/// A validated room.
#[derive(Clone, Debug, PartialEq)]
pub struct Room {
    /// The description it came from.
    pub file: RoomFile,
    /// Floor plan, counter-clockwise seen from above.
    pub plan: Vec<Point2<f64>>,
    /// Whether the plan is convex.
    pub convex: bool,
    /// Wall temperatures at mid-height (°C) and gradients (K/m), by wall index.
    pub walls: Vec<(f64, f64, String)>,
    /// Features placed on their surfaces.
    pub features: Vec<PlacedFeature>,
    /// Each wall's emissivity as the file gives it, by wall index.
    pub wall_emissivity: Vec<Option<f64>>,
    /// Emissivities and irradiances, once [`Room::with_surfaces`] has set them (none: black).
    pub grey: Option<grey::Grey>,
}

fn finite(name: &str, v: f64) -> Result<f64, RoomError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(RoomError::Invalid(format!("{name} is not a finite number")))
    }
}

/// The floor plan, counter-clockwise seen from above, and whether the file's was reversed.
fn floor_plan(file: &RoomFile) -> Result<(Vec<Point2<f64>>, bool), RoomError> {
    let inv = RoomError::Invalid;
    if file.floor_plan.len() < 3 {
        return Err(inv("floor_plan needs at least 3 vertices".into()));
    }
    let mut plan: Vec<Point2<f64>> = file
        .floor_plan
        .iter()
        .map(|p| Point2::new(p[0], p[1]))
        .collect();
    if plan.iter().any(|p| !p.x.is_finite() || !p.y.is_finite()) {
        return Err(inv("floor_plan has a coordinate that is not finite".into()));
    }
    polygon::check_simple(&plan, 1e-6)
        .map_err(|e| inv(format!("floor_plan is not a simple polygon ({e:?})")))?;
    let reversed = polygon::signed_area(&plan) < 0.0;
    if reversed {
        plan.reverse();
    }
    Ok((plan, reversed))
}

/// The plan edge of the file's wall `i`: after reversing, file wall i is plan edge n−2−i.
fn plan_wall(i: usize, n: usize, reversed: bool) -> usize {
    if reversed { (2 * n - 2 - i) % n } else { i }
}

/// Each wall's temperature at mid-height, gradient and label, by plan edge.
fn wall_settings(
    file: &RoomFile,
    n: usize,
    reversed: bool,
) -> Result<Vec<(f64, f64, String)>, RoomError> {
    let t = &file.temperatures;
    for (name, v) in [
        ("floor_c", t.floor_c),
        ("ceiling_c", t.ceiling_c),
        ("walls_c", t.walls_c),
        ("wall_gradient_k_per_m", t.wall_gradient_k_per_m),
    ] {
        finite(name, v)?;
    }
    let mut walls: Vec<(f64, f64, String)> =
        vec![(t.walls_c, t.wall_gradient_k_per_m, "wall".to_string()); n];
    for w in &file.walls {
        if w.index >= n {
            return Err(RoomError::Invalid(format!(
                "[[walls]] index {} does not exist (the plan has {n} walls, 0…{})",
                w.index,
                n - 1
            )));
        }
        let e = &mut walls[plan_wall(w.index, n, reversed)];
        if let Some(v) = w.temperature_c {
            e.0 = finite("wall temperature_c", v)?;
        }
        if let Some(g) = w.gradient_k_per_m {
            e.1 = finite("wall gradient_k_per_m", g)?;
        }
        if let Some(l) = &w.label {
            e.2 = l.clone();
        }
    }
    Ok(walls)
}

/// The surface a feature is on (`k`-th feature, for messages).
fn feature_surface(
    f: &FeatureSpec,
    k: usize,
    n: usize,
    reversed: bool,
) -> Result<SurfaceRef, RoomError> {
    Ok(match f.on.trim() {
        "floor" => SurfaceRef::Floor,
        "ceiling" => SurfaceRef::Ceiling,
        s => {
            let idx = s
                .strip_prefix("wall")
                .and_then(|x| x.trim().parse::<usize>().ok())
                .filter(|i| *i < n)
                .ok_or_else(|| {
                    RoomError::Invalid(format!(
                        "feature {} ('{}'): on = '{}' is not floor, ceiling or wall 0…{}",
                        k + 1,
                        f.label,
                        f.on,
                        n - 1
                    ))
                })?;
            SurfaceRef::Wall(plan_wall(idx, n, reversed))
        }
    })
}

/// A feature's outline on its surface, from `rect` or `polygon`.
fn feature_outline(f: &FeatureSpec, k: usize) -> Result<Vec<Point2<f64>>, RoomError> {
    match (&f.rect, &f.polygon) {
        (Some(r), None) => {
            if r.iter().any(|x| !x.is_finite()) || r[2] <= 0.0 || r[3] <= 0.0 {
                return Err(RoomError::Invalid(format!(
                    "feature {} ('{}'): rect {:?} needs a positive width and height",
                    k + 1,
                    f.label,
                    r
                )));
            }
            Ok(vec![
                Point2::new(r[0], r[1]),
                Point2::new(r[0] + r[2], r[1]),
                Point2::new(r[0] + r[2], r[1] + r[3]),
                Point2::new(r[0], r[1] + r[3]),
            ])
        }
        (None, Some(p)) => Ok(p.iter().map(|q| Point2::new(q[0], q[1])).collect()),
        _ => Err(RoomError::Invalid(format!(
            "feature {} ('{}'): give either rect or polygon",
            k + 1,
            f.label
        ))),
    }
}

/// The features placed on their surfaces, with ids from their labels.
fn place_features(
    file: &RoomFile,
    plan: &[Point2<f64>],
    reversed: bool,
) -> Result<Vec<PlacedFeature>, RoomError> {
    let n = plan.len();
    let mut counts = std::collections::HashMap::<String, usize>::new();
    let mut features = Vec::new();
    for (k, f) in file.features.iter().enumerate() {
        let on = feature_surface(f, k, n, reversed)?;
        let poly = feature_outline(f, k)?;
        // Walls with a reversed plan run the other way: mirror s.
        let poly = match on {
            SurfaceRef::Wall(i) if reversed => {
                let len = (plan[(i + 1) % n] - plan[i]).norm();
                poly.iter().map(|q| Point2::new(len - q.x, q.y)).collect()
            }
            _ => poly,
        };
        finite("feature temperature_c", f.temperature_c)?;
        let slug = mrtmap_radiation::slug(&f.label);
        let c = counts.entry(slug.clone()).or_default();
        *c += 1;
        features.push(PlacedFeature {
            id: format!("{slug}-{c}"),
            label: f.label.clone(),
            on,
            polygon_2d: poly,
            temperature_c: f.temperature_c,
        });
    }
    Ok(features)
}

/// Furniture boxes with min below max, and points inside the room.
fn check_furniture_and_points(file: &RoomFile, plan: &[Point2<f64>]) -> Result<(), RoomError> {
    for (k, b) in file.furniture.iter().enumerate() {
        if (0..3).any(|i| !(b.min[i].is_finite() && b.max[i].is_finite() && b.min[i] < b.max[i])) {
            return Err(RoomError::Invalid(format!(
                "furniture {} ('{}'): min {:?} must be below max {:?}",
                k + 1,
                b.label,
                b.min,
                b.max
            )));
        }
        finite("furniture temperature_c", b.temperature_c)?;
    }
    for p in &file.points {
        let q = Point2::new(p.xy[0], p.xy[1]);
        if polygon::point_in_polygon(&q, plan, 1e-3) != Containment::Inside
            || !(0.0..file.height_m).contains(&p.height_m)
        {
            return Err(RoomError::Invalid(format!(
                "point {} at {:?}, {} m is not inside the room",
                p.name, p.xy, p.height_m
            )));
        }
    }
    Ok(())
}

impl Room {
    /// Parses and validates TOML text.
    pub fn from_toml(text: &str) -> Result<Self, RoomError> {
        let file: RoomFile = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            RoomError::Toml(match line {
                Some(l) => format!("line {l}: {}", e.message()),
                None => e.message().to_string(),
            })
        })?;
        Self::new(file)
    }

    /// Validates a room description.
    pub fn new(file: RoomFile) -> Result<Self, RoomError> {
        finite("height_m", file.height_m)?;
        if !(1.5..=20.0).contains(&file.height_m) {
            return Err(RoomError::Invalid(format!(
                "height_m {} is outside 1.5…20 m",
                file.height_m
            )));
        }
        finite("air_temperature_c", file.air_temperature_c)?;
        let (plan, reversed) = floor_plan(&file)?;
        let n = plan.len();
        let convex = (0..n).all(|i| {
            let (a, b, c) = (plan[i], plan[(i + 1) % n], plan[(i + 2) % n]);
            (b - a).perp(&(c - b)) >= -1e-12
        });
        let walls = wall_settings(&file, n, reversed)?;
        let features = place_features(&file, &plan, reversed)?;
        check_furniture_and_points(&file, &plan)?;
        let mut wall_emissivity = vec![None; n];
        for w in &file.walls {
            wall_emissivity[plan_wall(w.index, n, reversed)] = w.emissivity;
        }
        let t = &file.temperatures;
        for (what, e) in [
            ("floor_emissivity", t.floor_emissivity),
            ("ceiling_emissivity", t.ceiling_emissivity),
            ("walls_emissivity", t.walls_emissivity),
        ]
        .into_iter()
        .chain(
            file.walls
                .iter()
                .map(|w| ("a wall's emissivity", w.emissivity)),
        )
        .chain(
            file.features
                .iter()
                .map(|f| ("a feature's emissivity", f.emissivity)),
        )
        .chain(file.emissivities.iter().flat_map(|e| {
            e.surfaces
                .iter()
                .chain(&e.features)
                .map(|v| ("[emissivities]", Some(*v)))
        })) {
            if let Some(e) = e
                && !(e > 0.0 && e <= 1.0)
            {
                return Err(RoomError::Invalid(format!(
                    "{what} {e} is outside 0 < ε ≤ 1"
                )));
            }
        }
        if let Some(e) = &file.emissivities
            && (e.surfaces.len() != n + 2 || e.features.len() != features.len())
        {
            return Err(RoomError::Invalid(format!(
                "[emissivities] gives {} surfaces and {} features; the room has {} and {}",
                e.surfaces.len(),
                e.features.len(),
                n + 2,
                features.len()
            )));
        }
        let room = Self {
            file,
            plan,
            convex,
            walls,
            features,
            wall_emissivity,
            grey: None,
        };
        // Validate the geometry through the scene rules (features inside hosts, no overlaps…).
        room.scene(&Isometry3::identity(), false)?;
        Ok(room)
    }

    /// Number of walls.
    pub fn wall_count(&self) -> usize {
        self.plan.len()
    }

    /// Height.
    pub fn height(&self) -> f64 {
        self.file.height_m
    }

    /// A surface's 2D frame: origin, first axis, second axis (room frame). Walls: s along the wall
    /// from its start, z up. Floor and ceiling: plan x, y.
    pub fn surface_frame(&self, s: SurfaceRef) -> (Point3<f64>, Vector3<f64>, Vector3<f64>) {
        match s {
            SurfaceRef::Floor => (Point3::origin(), Vector3::x(), Vector3::y()),
            SurfaceRef::Ceiling => (
                Point3::new(0.0, 0.0, self.height()),
                Vector3::x(),
                Vector3::y(),
            ),
            SurfaceRef::Wall(i) => {
                let (a, b) = (self.plan[i], self.plan[(i + 1) % self.plan.len()]);
                let d = (b - a).normalize();
                (
                    Point3::new(a.x, a.y, 0.0),
                    Vector3::new(d.x, d.y, 0.0),
                    Vector3::z(),
                )
            }
        }
    }

    /// 3D point of 2D coordinates on a surface.
    pub fn on_surface(&self, s: SurfaceRef, q: &Point2<f64>) -> Point3<f64> {
        let (o, u, v) = self.surface_frame(s);
        o + u * q.x + v * q.y
    }

    /// A surface's polygon in its 2D coordinates.
    pub fn surface_polygon_2d(&self, s: SurfaceRef) -> Vec<Point2<f64>> {
        match s {
            SurfaceRef::Floor | SurfaceRef::Ceiling => self.plan.clone(),
            SurfaceRef::Wall(i) => {
                let len = (self.plan[(i + 1) % self.plan.len()] - self.plan[i]).norm();
                let h = self.height();
                vec![
                    Point2::new(0.0, 0.0),
                    Point2::new(len, 0.0),
                    Point2::new(len, h),
                    Point2::new(0.0, h),
                ]
            }
        }
    }

    /// Inward unit normal of a surface.
    pub fn inward_normal(&self, s: SurfaceRef) -> Vector3<f64> {
        match s {
            SurfaceRef::Floor => Vector3::z(),
            SurfaceRef::Ceiling => -Vector3::z(),
            SurfaceRef::Wall(i) => {
                let (a, b) = (self.plan[i], self.plan[(i + 1) % self.plan.len()]);
                let d = (b - a).normalize();
                Vector3::new(-d.y, d.x, 0.0) // left of a counter-clockwise edge
            }
        }
    }

    /// Temperature (°C) of a point on a surface, features excluded (walls include the gradient).
    pub fn background_temperature_c(&self, s: SurfaceRef, z: f64) -> f64 {
        match s {
            SurfaceRef::Floor => self.file.temperatures.floor_c,
            SurfaceRef::Ceiling => self.file.temperatures.ceiling_c,
            SurfaceRef::Wall(i) => {
                let (t, g, _) = &self.walls[i];
                t + g * (z - self.height() / 2.0)
            }
        }
    }

    /// The room with its surfaces black or grey (the room file's emissivities where it gives them;
    /// see [`grey::Grey::emissivities`]) and, grey, its radiosities solved.
    pub fn with_surfaces(
        mut self,
        surfaces: grey::Surfaces,
        seed: u64,
        rays: usize,
    ) -> Result<Self, crate::SimError> {
        let g = grey::Grey::emissivities(&self, surfaces, seed);
        self.grey = g.is_grey().then_some(g);
        grey::solve(&mut self, rays, seed)?;
        Ok(self)
    }

    /// The room as written into a recording: its file with the emissivities simulated.
    pub fn file_as_simulated(&self) -> RoomFile {
        let mut f = self.file.clone();
        if let Some(g) = &self.grey {
            f.emissivities = Some(EmissivitiesFile {
                surfaces: g.surface_emissivity.clone(),
                features: g.feature_emissivity.clone(),
            });
        }
        f
    }

    /// The view factors its truth is computed with: exact solid angles when the room is convex
    /// and has no furniture, else `rays` Fibonacci rays per point in `replicates` sets.
    pub fn truth_method(
        &self,
        rays: usize,
        seed: u64,
        replicates: usize,
    ) -> mrtmap_radiation::Method {
        if self.convex && self.file.furniture.is_empty() {
            mrtmap_radiation::Method::Exact
        } else {
            mrtmap_radiation::Method::MonteCarlo(mrtmap_radiation::MonteCarlo {
                rays,
                seed,
                directions: mrtmap_geometry::sampling::DirectionSet::Fibonacci,
                replicates,
            })
        }
    }

    /// Whether any surface is grey.
    pub fn is_grey(&self) -> bool {
        self.grey.is_some()
    }

    /// The index of a surface in [`Room::surfaces`].
    pub fn surface_index(&self, s: SurfaceRef) -> usize {
        match s {
            SurfaceRef::Floor => 0,
            SurfaceRef::Ceiling => 1,
            SurfaceRef::Wall(i) => 2 + i,
        }
    }

    /// A surface's emissivity (1 in a black room).
    pub fn emissivity(&self, s: SurfaceRef) -> f64 {
        self.grey
            .as_ref()
            .map_or(1.0, |g| g.surface_emissivity[self.surface_index(s)])
    }

    /// Feature `k`'s emissivity.
    pub fn feature_emissivity(&self, k: usize) -> f64 {
        self.grey.as_ref().map_or(1.0, |g| g.feature_emissivity[k])
    }

    fn surface_irradiance_k(&self, s: SurfaceRef) -> Option<f64> {
        self.grey
            .as_ref()
            .and_then(|g| g.surface_irradiance_k.get(self.surface_index(s)).copied())
    }

    fn feature_irradiance_k(&self, k: usize) -> Option<f64> {
        self.grey
            .as_ref()
            .and_then(|g| g.feature_irradiance_k.get(k).copied())
    }

    /// The radiant temperature (°C: what the camera reads, what the MRT uses) of a surface's
    /// background at height `z`: its own temperature in a black room.
    pub fn background_radiant_c(&self, s: SurfaceRef, z: f64) -> f64 {
        grey::radiant_c(
            self.background_temperature_c(s, z),
            self.emissivity(s),
            self.surface_irradiance_k(s),
        )
    }

    /// Feature `k`'s radiant temperature (°C).
    pub fn feature_radiant_c(&self, k: usize) -> f64 {
        grey::radiant_c(
            self.features[k].temperature_c,
            self.feature_emissivity(k),
            self.feature_irradiance_k(k),
        )
    }

    /// The radiant (T⁴ area-average) temperature of a surface's background as the camera reads
    /// it (°C): [`Room::surface_radiant_temperature_c`] in a black room.
    pub fn surface_apparent_c(&self, s: SurfaceRef) -> f64 {
        grey::radiant_c(
            self.surface_radiant_temperature_c(s),
            self.emissivity(s),
            self.surface_irradiance_k(s),
        )
    }

    /// All surfaces in a fixed order: floor, ceiling, walls 0….
    pub fn surfaces(&self) -> Vec<SurfaceRef> {
        (0..2 + self.wall_count()).map(Self::surface_at).collect()
    }

    /// Surface `index` of [`Room::surfaces`] without making the list (the renderers ask per
    /// pixel): the floor, the ceiling, then the walls in order.
    pub fn surface_at(index: usize) -> SurfaceRef {
        match index {
            0 => SurfaceRef::Floor,
            1 => SurfaceRef::Ceiling,
            i => SurfaceRef::Wall(i - 2),
        }
    }

    /// Id of a surface in scenes.
    pub fn surface_id(&self, s: SurfaceRef) -> String {
        match s {
            SurfaceRef::Floor => "floor".into(),
            SurfaceRef::Ceiling => "ceiling".into(),
            SurfaceRef::Wall(i) => format!("wall-{i}"),
        }
    }

    /// The radiant scene of the room in the frame `world_from_room`.
    ///
    /// With `strips` false, each surface is whole at its radiant-average temperature (features
    /// excluded; a gradient wall's temperature is the T⁴ area average of its background), the form a
    /// scan's segmentation should recover. With `strips` true, walls with a gradient are cut into
    /// horizontal strips of at most [`GRADIENT_STRIP_M`] with features clipped to them: the model
    /// the truth MRT is computed from. Furniture becomes box occluders in the room frame and
    /// triangle meshes otherwise.
    pub fn scene(
        &self,
        world_from_room: &Isometry3<f64>,
        strips: bool,
    ) -> Result<RadiantScene, SceneError> {
        let mut surfaces = Vec::new();
        for s in self.surfaces() {
            surfaces.extend(self.surface_files(s, world_from_room, strips));
        }
        let up = world_from_room * Vector3::z();
        RadiantScene::new(&SceneFile {
            format: SCENE_FORMAT.into(),
            up: Some([up.x, up.y, up.z]),
            world_from_room: None,
            temperature_level_std_k: None,
            temperatures: self
                .is_grey()
                .then_some(mrtmap_radiation::TemperatureKind::Radiant),
            surfaces,
            occluders: self.occluder_files(world_from_room),
        })
    }

    /// Height bands a surface is cut into: one for the whole surface, or strips of
    /// [`GRADIENT_STRIP_M`] on a stratified wall when `strips` is asked for.
    fn bands(&self, s: SurfaceRef, strips: bool) -> Vec<(f64, f64)> {
        let h = self.height();
        let gradient = matches!(s, SurfaceRef::Wall(i) if self.walls[i].1 != 0.0);
        if strips && gradient {
            let k = (h / GRADIENT_STRIP_M).ceil() as usize;
            (0..k)
                .map(|j| (h * j as f64 / k as f64, h * (j + 1) as f64 / k as f64))
                .collect()
        } else {
            vec![(f64::NEG_INFINITY, f64::INFINITY)]
        }
    }

    /// A surface as scene entries in the world frame: whole, or one per height band.
    fn surface_files(
        &self,
        s: SurfaceRef,
        world_from_room: &Isometry3<f64>,
        strips: bool,
    ) -> Vec<SurfaceFile> {
        let w = |p: Point3<f64>| {
            let q = world_from_room * p;
            [q.x, q.y, q.z]
        };
        let id = self.surface_id(s);
        let (kind, label) = match s {
            SurfaceRef::Floor => ("floor", "floor".to_string()),
            SurfaceRef::Ceiling => ("ceiling", "ceiling".to_string()),
            SurfaceRef::Wall(i) => ("wall", self.walls[i].2.clone()),
        };
        let poly2 = self.surface_polygon_2d(s);
        let feats: Vec<(usize, &PlacedFeature)> = self
            .features
            .iter()
            .enumerate()
            .filter(|(_, f)| f.on == s)
            .collect();
        let bands = self.bands(s, strips);
        let grey = self.is_grey();
        let whole = bands.len() == 1;
        let clip = |p: &[Point2<f64>], z0, z1| {
            if whole {
                p.to_vec()
            } else {
                clip_band(p, z0, z1)
            }
        };
        let name = |base: &str, bi: usize| {
            if whole {
                base.to_string()
            } else {
                format!("{base}#{bi}")
            }
        };
        let mut out = Vec::new();
        for (bi, &(z0, z1)) in bands.iter().enumerate() {
            let (temperature_c, true_c) = if whole {
                (
                    self.surface_apparent_c(s),
                    self.surface_radiant_temperature_c(s),
                )
            } else {
                (
                    self.background_radiant_c(s, (z0 + z1) / 2.0),
                    self.background_temperature_c(s, (z0 + z1) / 2.0),
                )
            };
            let mut features = Vec::new();
            for &(k, f) in &feats {
                let fp = clip(&f.polygon_2d, z0, z1);
                if fp.len() < 3 || polygon::signed_area(&fp).abs() < 1e-9 {
                    continue;
                }
                features.push(FeatureFile {
                    id: name(&f.id, bi),
                    label: f.label.clone(),
                    polygon: fp.iter().map(|q| w(self.on_surface(s, q))).collect(),
                    temperature_c: self.feature_radiant_c(k),
                    emissivity: self.feature_emissivity(k),
                    temperature_std_k: None,
                    surface_temperature_c: grey.then_some(f.temperature_c),
                    surface_temperature_std_k: None,
                });
            }
            out.push(SurfaceFile {
                id: name(&id, bi),
                kind: kind.into(),
                label: label.clone(),
                polygon: clip(&poly2, z0, z1)
                    .iter()
                    .map(|q| w(self.on_surface(s, q)))
                    .collect(),
                temperature_c,
                emissivity: self.emissivity(s),
                temperature_std_k: None,
                surface_temperature_c: grey.then_some(true_c),
                surface_temperature_std_k: None,
                observed_fraction: None,
                features,
                raster: None,
            });
        }
        out
    }

    /// The furniture as occluders in the world frame: boxes while the frame is axis-aligned with
    /// the room's, else meshes.
    fn occluder_files(&self, world_from_room: &Isometry3<f64>) -> Vec<OccluderFile> {
        let w = |p: Point3<f64>| {
            let q = world_from_room * p;
            [q.x, q.y, q.z]
        };
        let axis_aligned = world_from_room.rotation.angle() < 1e-12;
        self.file
            .furniture
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let corners =
                    mrtmap_geometry::box_corners(&Point3::from(b.min), &Point3::from(b.max));
                let slug = mrtmap_radiation::slug(&b.label);
                let (box_, vertices, triangles) = if axis_aligned {
                    let (lo, hi) = (w(corners[0]), w(corners[7]));
                    (
                        Some(mrtmap_radiation::BoxFile { min: lo, max: hi }),
                        None,
                        None,
                    )
                } else {
                    (
                        None,
                        Some(corners.iter().map(|c| w(*c)).collect()),
                        Some(mrtmap_geometry::BOX_TRIANGLES.to_vec()),
                    )
                };
                OccluderFile {
                    id: format!("{slug}-{}", k + 1),
                    label: b.label.clone(),
                    temperature_c: b.temperature_c,
                    emissivity: 1.0,
                    box_,
                    vertices,
                    triangles,
                }
            })
            .collect()
    }

    /// Radiant (T⁴ area-average) temperature of a surface's background (features excluded), °C.
    pub fn surface_radiant_temperature_c(&self, s: SurfaceRef) -> f64 {
        let gradient = matches!(s, SurfaceRef::Wall(i) if self.walls[i].1 != 0.0);
        if !gradient {
            return self.background_temperature_c(s, 0.0);
        }
        // Integrate T⁴ over the background area in thin bands.
        let h = self.height();
        let poly = self.surface_polygon_2d(s);
        let feats: Vec<&PlacedFeature> = self.features.iter().filter(|f| f.on == s).collect();
        let k = 2000;
        let (mut a, mut a4) = (0.0, 0.0);
        for j in 0..k {
            let (z0, z1) = (h * j as f64 / k as f64, h * (j + 1) as f64 / k as f64);
            let area = polygon::signed_area(&clip_band(&poly, z0, z1)).abs()
                - feats
                    .iter()
                    .map(|f| polygon::signed_area(&clip_band(&f.polygon_2d, z0, z1)).abs())
                    .sum::<f64>();
            let t =
                self.background_temperature_c(s, (z0 + z1) / 2.0) + mrtmap_physics::ZERO_CELSIUS_K;
            a += area;
            a4 += area * t.powi(4);
        }
        (a4 / a).powf(0.25) - mrtmap_physics::ZERO_CELSIUS_K
    }
}

/// Clips a 2D polygon to the band y ∈ [y0, y1] (Sutherland–Hodgman against two half-planes).
fn clip_band(poly: &[Point2<f64>], y0: f64, y1: f64) -> Vec<Point2<f64>> {
    use mrtmap_geometry::shape2d::clip_half_plane;
    let lower = clip_half_plane(poly, |p| p.y - y0);
    if lower.is_empty() {
        return lower;
    }
    let mut both = clip_half_plane(&lower, |p| y1 - p.y);
    both.dedup_by(|a, b| (*a - *b).norm() < 1e-12);
    if both.len() > 1 && (both[0] - both[both.len() - 1]).norm() < 1e-12 {
        both.pop();
    }
    both
}

/// The documented presets: (name, TOML text).
pub const PRESETS: [(&str, &str); 3] = [
    ("office", include_str!("../../rooms/office.toml")),
    ("l-shaped", include_str!("../../rooms/l-shaped.toml")),
    (
        "radiant-ceiling",
        include_str!("../../rooms/radiant-ceiling.toml"),
    ),
];

/// A preset room by name.
pub fn preset(name: &str) -> Option<Result<Room, RoomError>> {
    PRESETS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| Room::from_toml(t))
}

/// Whether a feature's label names glass: glazing of every kind and mirrors
/// ([`mrtmap_radiation::ElementKind::is_glass`]). Near-infrared light passes through (or is
/// mirrored by) them, so an active-stereo depth camera gets no depth there; a thermal camera sees
/// the pane itself, which is opaque at 8–14 µm.
pub fn is_glass(label: &str) -> bool {
    mrtmap_radiation::ElementKind::of_label(label).is_glass()
}
