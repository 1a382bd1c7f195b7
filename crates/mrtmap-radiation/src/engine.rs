//! View factors from a point and the mean radiant temperature there, by two engines.
//!
//! - **Exact**: each polygon's solid angle (Van Oosterom–Strackee), each feature's view factor
//!   subtracted from its host's (the seed paper's Algorithm 1). Valid when every surface is fully
//!   visible from the point: no occluders, and no surface hiding another. The second condition is
//!   checked: seen from inside a closed room the solid angles tile the sphere exactly once, so a sum
//!   above 1 means some surface hides another (a non-convex room seen from this point).
//! - **Monte Carlo**: rays in N directions against a BVH of every triangle (surfaces and
//!   occluders); a hit on a surface is assigned to the feature whose polygon contains the hit
//!   point, else to the surface. The directions come in R independent replicates (R random
//!   rotations of a Fibonacci lattice, or R batches of uniform random directions); standard errors
//!   are the spread between replicates over √R, an honest estimate for either direction set.

use mrtmap_geometry::nalgebra::{Point3, Vector3};
use mrtmap_geometry::polygon::point_in_polygon_fast;
use mrtmap_geometry::sampling::{self, DirectionSet};
use mrtmap_geometry::{RayCaster, sphere_view_factor};
use mrtmap_physics::{
    MeanRadiant, PhysicsError, RadiantSource, Temperature, mean_radiant_temperature,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::bounds::RoomBounds;
use crate::scene::{RadiantScene, SurfaceKind, UnseenShare};

/// Tolerance on Σ F above 1 before the exact engine declares that surfaces hide each other.
pub const EXACT_OVERLAP_TOLERANCE: f64 = 1e-6;

/// What a view factor belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PatchKind {
    /// A surface net of its features.
    Surface,
    /// A feature on a surface.
    Feature,
    /// An occluder.
    Occluder,
}

/// A radiating element as seen from points: a surface (net of its features), a feature or an
/// occluder, with its temperature.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Patch {
    /// The element's id.
    pub id: String,
    /// Its label.
    pub label: String,
    /// Surface, feature or occluder.
    pub kind: PatchKind,
    /// For surfaces, the surface kind.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface_kind: Option<SurfaceKind>,
    /// For features, the host surface's id.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub host: Option<String>,
    /// Radiant temperature.
    pub temperature: Temperature,
    /// Emissivity.
    pub emissivity: f64,
    /// Temperature uncertainty (K, 0 when unknown).
    pub temperature_std_k: f64,
}

/// The patches of a scene, in a fixed order: each surface followed by its features, then the
/// occluders.
pub fn patches(scene: &RadiantScene) -> Vec<Patch> {
    let mut out = Vec::new();
    for s in &scene.surfaces {
        out.push(Patch {
            id: s.id.clone(),
            label: s.label.clone(),
            kind: PatchKind::Surface,
            surface_kind: Some(s.kind),
            host: None,
            temperature: s.temperature,
            emissivity: s.emissivity,
            temperature_std_k: s.temperature_std_k.unwrap_or(0.0),
        });
        for f in &s.features {
            out.push(Patch {
                id: f.id.clone(),
                label: f.label.clone(),
                kind: PatchKind::Feature,
                surface_kind: None,
                host: Some(s.id.clone()),
                temperature: f.temperature,
                emissivity: f.emissivity,
                temperature_std_k: f.temperature_std_k.unwrap_or(0.0),
            });
        }
    }
    for o in &scene.occluders {
        out.push(Patch {
            id: o.id.clone(),
            label: o.label.clone(),
            kind: PatchKind::Occluder,
            surface_kind: None,
            host: None,
            temperature: o.temperature,
            emissivity: o.emissivity,
            temperature_std_k: 0.0,
        });
    }
    out
}

/// Monte Carlo settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct MonteCarlo {
    /// Rays per point (rounded up to a multiple of `replicates`).
    pub rays: usize,
    /// Seed; each point draws from its own stream of it, so results do not depend on threading.
    pub seed: u64,
    /// Direction set.
    pub directions: DirectionSet,
    /// Independent replicates used for the standard errors (≥ 2).
    pub replicates: usize,
}

impl Default for MonteCarlo {
    fn default() -> Self {
        Self {
            rays: 20_000,
            seed: 1,
            directions: DirectionSet::Fibonacci,
            replicates: 8,
        }
    }
}

/// Which engine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "engine")]
pub enum Method {
    /// Exact solid angles (no occluders).
    Exact,
    /// Monte Carlo ray tracing.
    MonteCarlo(MonteCarlo),
    /// Exact where it is valid, Monte Carlo elsewhere: scenes with occluders, and points from
    /// which one surface hides another (non-convex rooms).
    Auto(MonteCarlo),
}

impl Method {
    /// Short name.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Exact => "exact",
            Method::MonteCarlo(_) => "montecarlo",
            Method::Auto(_) => "auto",
        }
    }

    /// The method in a few words, for a map's subtitle.
    pub fn brief(&self) -> String {
        match self {
            Method::Exact => "exact view factors".to_string(),
            Method::Auto(_) => {
                "exact view factors (Monte Carlo where surfaces hide each other)".to_string()
            }
            Method::MonteCarlo(mc) => format!("Monte Carlo view factors ({} rays)", mc.rays),
        }
    }

    /// The method for people; `engine` names the ray caster of a Monte Carlo method.
    pub fn describe(&self, engine: Option<&str>) -> String {
        match self {
            Method::Exact => "exact view factors (solid angles)".to_string(),
            Method::Auto(mc) => format!(
                "exact view factors (solid angles), Monte Carlo ({} rays) where surfaces hide each other",
                mc.rays
            ),
            Method::MonteCarlo(mc) => format!(
                "Monte Carlo view factors ({} rays per point, {} directions in {} replicates, seed {}{})",
                mc.rays,
                mc.directions.describe(),
                mc.replicates,
                mc.seed,
                engine.map(|e| format!(", {e}")).unwrap_or_default()
            ),
        }
    }
}

/// ΣF may differ from 1 by this much before a point counts as not enclosed (1 % of the view).
pub const ENCLOSURE_TOLERANCE: f64 = 0.01;

/// Why an MRT could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MrtError {
    /// Exact view factors asked for a scene with occluders.
    #[error(
        "the scene has furniture ({count} piece(s) as occluders; first: '{first}'), which exact solid angles cannot see: use the Monte Carlo method (--method montecarlo, or auto)"
    )]
    OccludersNeedRayTracing {
        /// How many.
        count: usize,
        /// The first one's id.
        first: String,
    },
    /// Surfaces hide each other from the point.
    #[error(
        "point {point:?}: the surfaces' solid angles sum to {sum:.6} of the sphere (> 1), so some surface hides another from here (the room is not convex from this point): use the Monte Carlo method"
    )]
    SurfacesHidden {
        /// The point.
        point: [f64; 3],
        /// Σ F.
        sum: f64,
    },
    /// A person centred at the point would reach through the floor or the ceiling.
    #[error(
        "a {posture} person centred at ({:.2}, {:.2}, {:.2}) would have their {part} {where_}: a {posture} person's body centre is {centre_m:.2} m above their feet and {head_m:.2} m under their crown; place the centre at {centre_m:.2} m above the floor (or give a posture that fits)",
        point[0], point[1], point[2]
    )]
    PersonDoesNotFit {
        /// The body centre.
        point: [f64; 3],
        /// "seated" or "standing".
        posture: &'static str,
        /// "feet" or "head".
        part: &'static str,
        /// Where that part would be.
        where_: String,
        /// Body centre above the feet (m).
        centre_m: f64,
        /// Crown above the body centre (m).
        head_m: f64,
    },
    /// A scene in true surface temperatures whose radiosities could not be solved.
    #[error("the scene's surface temperatures could not be turned into radiosities: {0}")]
    EnclosureSolve(String),
    /// A scene in true surface temperatures of grey elements handed to the engine unsolved.
    #[error(
        "the scene gives true surface temperatures of grey elements, whose radiosities must be solved before an MRT (mrtmap_radiation::enclosure::engine)"
    )]
    UnsolvedSurfaceTemperatures,
    /// The point is not in the room.
    #[error("point ({:.2}, {:.2}, {:.2}) is {where_}: the room spans {room}", point[0], point[1], point[2])]
    OutsideRoom {
        /// The point.
        point: [f64; 3],
        /// Where it is.
        where_: String,
        /// Where the room is.
        room: String,
    },
    /// The scene does not enclose the point: part of the sphere around it sees nothing.
    #[error(
        "point ({:.2}, {:.2}, {:.2}): the scene's surfaces cover only {:.1} % of the view around it (ΣF = {sum:.4}); a room must be closed (is a wall, the ceiling or the floor missing?). To compute it anyway, allow open scenes (--allow-open)",
        point[0], point[1], point[2], sum * 100.0
    )]
    NotEnclosed {
        /// The point.
        point: [f64; 3],
        /// Σ F.
        sum: f64,
    },
    /// A query that needs the room's floor (up and the horizontal axes) on a scene without one.
    #[error("{what} needs a scene with a floor (it gives up and the horizontal axes)")]
    NeedsFloor {
        /// What was asked.
        what: &'static str,
    },
    /// A person centred at the point would pass through furniture (a seated person's legs
    /// through a desk).
    #[error(
        "a {posture} person centred at ({:.2}, {:.2}, {:.2}) would pass through the furniture '{id}' at {at_m:.2} m above their feet: a {posture} person's body reaches from {centre_m:.2} m below the centre to {head_m:.2} m above it; place the centre clear of it",
        point[0], point[1], point[2]
    )]
    PersonThroughOccluder {
        /// The body centre.
        point: [f64; 3],
        /// "seated" or "standing".
        posture: &'static str,
        /// The occluder.
        id: String,
        /// Where the body meets it, above the floor (m).
        at_m: f64,
        /// Body centre above the feet (m).
        centre_m: f64,
        /// Crown above the body centre (m).
        head_m: f64,
    },
    /// The point lies inside an occluder.
    #[error("point ({:.2}, {:.2}, {:.2}) lies inside the furniture '{id}'", point[0], point[1], point[2])]
    InsideOccluder {
        /// The point.
        point: [f64; 3],
        /// The occluder.
        id: String,
    },
    /// Too few rays for the replicates.
    #[error("{rays} rays cannot make {replicates} replicates: use at least {min} rays")]
    TooFewRays {
        /// Rays asked for.
        rays: usize,
        /// Replicates.
        replicates: usize,
        /// Minimum.
        min: usize,
    },
    /// The comfort formula failed (e.g. nothing seen).
    #[error("point {point:?}: {source}")]
    Physics {
        /// The point.
        point: [f64; 3],
        /// Why.
        source: PhysicsError,
    },
}

/// MRT at one point with its view factors and uncertainty.
#[derive(Clone, Debug, PartialEq)]
pub struct PointMrt {
    /// The point.
    pub point: Point3<f64>,
    /// Mean radiant temperature.
    pub mrt: Temperature,
    /// Total standard error (K): its five parts below combined in quadrature.
    pub std_error_k: f64,
    /// Part of the error from Monte Carlo sampling (0 for exact).
    pub sampling_std_error_k: f64,
    /// Part of the error from the patches' temperature uncertainties.
    pub temperature_std_error_k: f64,
    /// Part of the error from where the point lies relative to the surfaces (see
    /// [`MrtEngine::with_placement_std`]): the MRT's gradient there times the placement's standard
    /// deviation; 0 when no placement uncertainty is set.
    pub placement_std_error_k: f64,
    /// Part of the error from the surfaces' areas the scan never saw (their rasters' unseen
    /// patches): each patch's view factor times its temperature's spread over the range its seen
    /// surroundings allow, patches combined in quadrature.
    pub unseen_std_error_k: f64,
    /// Part of the error from the camera's absolute level (the scene's
    /// `temperature_level_std_k`: a common error of every temperature moves the MRT one to one).
    pub level_std_error_k: f64,
    /// Each unseen patch's part of `unseen_std_error_k` (those the point sees).
    pub unseen_parts: Vec<UnseenPart>,
    /// View factor per patch (order of [`patches`]).
    pub view_factors: Vec<f64>,
    /// Standard error per view factor (0 for exact).
    pub view_factor_std_errors: Vec<f64>,
    /// Σ F: 1 for a closed room; below 1 where rays escape or the scene is open.
    pub view_factor_sum: f64,
    /// Rays traced (0 for exact).
    pub rays: usize,
}

/// One unseen patch's part of a point's standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnseenPart {
    /// The surface (index into the scene's surfaces).
    pub surface: usize,
    /// The patch (index into the surface raster's `unseen`).
    pub patch: usize,
    /// Its part of the standard error (K).
    pub std_error_k: f64,
}

/// What a point sees of the rasters: every patch's temperature (rastered surfaces at their
/// texels' average) and, per unseen patch, the surface patch it lies on and its share.
pub(crate) struct Seen {
    pub(crate) temperatures: Vec<Temperature>,
    /// (surface index, its patch index, the unseen patch's index in the raster, its share).
    pub(crate) unseen: Vec<(usize, usize, usize, UnseenShare)>,
}

enum Owner {
    Surface(usize),
    Occluder(usize),
}

struct Tracer {
    caster: Box<dyn RayCaster>,
    owner: Vec<Owner>,
}

/// A scene made ready for MRT queries with one method: patch list, and for Monte Carlo the BVH.
pub struct MrtEngine<'a> {
    /// The scene as given, or its radiosities when it gives true surface temperatures of grey
    /// elements ([`crate::grey::solve_enclosure`]).
    scene: std::borrow::Cow<'a, RadiantScene>,
    bounds: Option<RoomBounds>,
    /// Answer at points the scene does not enclose (ΣF short of 1) instead of refusing.
    open: bool,
    patches: Vec<Patch>,
    /// Index of each surface's own patch; its features follow it.
    surface_patch: Vec<usize>,
    occluder_patch0: usize,
    method: Method,
    tracer: Option<Tracer>,
    /// Standard deviation (m) of the point's place relative to the room's surfaces.
    placement_std_m: f64,
}

/// How close to a surface a point may be (m): nearer, it is on the surface.
pub const SURFACE_CLEARANCE_M: f64 = 0.005;

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(
    p: &mrtmap_geometry::nalgebra::Point2<f64>,
    a: &mrtmap_geometry::nalgebra::Point2<f64>,
    b: &mrtmap_geometry::nalgebra::Point2<f64>,
) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared().max(1e-300)).clamp(0.0, 1.0);
    (p - (a + ab * t)).norm()
}

/// Step (m) of the central differences that give the MRT's gradient for the placement term.
const PLACEMENT_STEP_M: f64 = 0.02;

/// Rays per point from which the BVH is built with more care ([`BvhRayCaster::for_many_rays`]):
/// the simulator's truth casts 100,000; a map's default 20,000 keeps the quick build (and its
/// results as they were).
///
/// [`BvhRayCaster::for_many_rays`]: mrtmap_geometry::BvhRayCaster::for_many_rays
#[cfg(not(feature = "embree"))]
const MANY_RAYS: usize = 50_000;

fn caster(tris: &[mrtmap_geometry::Tri], rays: usize) -> Box<dyn RayCaster> {
    #[cfg(feature = "embree")]
    {
        let _ = rays;
        Box::new(mrtmap_geometry::EmbreeRayCaster::new(tris))
    }
    #[cfg(not(feature = "embree"))]
    {
        if rays >= MANY_RAYS {
            Box::new(mrtmap_geometry::BvhRayCaster::for_many_rays(tris))
        } else {
            Box::new(mrtmap_geometry::BvhRayCaster::new(tris))
        }
    }
}

/// A quarter of the rays (at least 64 per replicate), the same directions and replicates.
fn lighter(mc: MonteCarlo) -> MonteCarlo {
    MonteCarlo {
        rays: (mc.rays / 4).max(64 * mc.replicates),
        ..mc
    }
}

fn arr(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

impl<'a> MrtEngine<'a> {
    /// Prepares `scene` for `method`. Exact refuses scenes with occluders.
    /// A scene in true surface temperatures of grey elements is refused: its radiosities must be
    /// solved first ([`crate::enclosure::engine`] does both).
    pub fn new(scene: &'a RadiantScene, method: Method) -> Result<Self, MrtError> {
        if scene.gives_grey_surface_temperatures() {
            return Err(MrtError::UnsolvedSurfaceTemperatures);
        }
        Self::build(std::borrow::Cow::Borrowed(scene), method)
    }

    /// [`MrtEngine::new`] on a scene it keeps.
    pub fn new_owned(scene: RadiantScene, method: Method) -> Result<Self, MrtError> {
        if scene.gives_grey_surface_temperatures() {
            return Err(MrtError::UnsolvedSurfaceTemperatures);
        }
        Self::build(std::borrow::Cow::Owned(scene), method)
    }

    fn build(
        scene_cow: std::borrow::Cow<'a, RadiantScene>,
        method: Method,
    ) -> Result<Self, MrtError> {
        let scene: &RadiantScene = &scene_cow;
        let patches = patches(scene);
        let mut surface_patch = Vec::with_capacity(scene.surfaces.len());
        let mut k = 0;
        for s in &scene.surfaces {
            surface_patch.push(k);
            k += 1 + s.features.len();
        }
        match method {
            Method::Exact => {
                if let Some(o) = scene.occluders.first() {
                    return Err(MrtError::OccludersNeedRayTracing {
                        count: scene.occluders.len(),
                        first: o.id.clone(),
                    });
                }
            }
            Method::MonteCarlo(mc) | Method::Auto(mc) => {
                if mc.replicates < 2 || mc.rays < 2 * mc.replicates {
                    let r = mc.replicates.max(2);
                    return Err(MrtError::TooFewRays {
                        rays: mc.rays,
                        replicates: mc.replicates,
                        min: 2 * r,
                    });
                }
            }
        }
        // Every engine can cast rays: a person's and a plane element's factors are integrated
        // over directions whatever the sphere's method.
        let mut tris = Vec::new();
        let mut owner = Vec::new();
        for (t, si) in scene.surface_triangles() {
            tris.push(t);
            owner.push(Owner::Surface(si));
        }
        for (oi, o) in scene.occluders.iter().enumerate() {
            for t in o.triangles() {
                tris.push(t);
                owner.push(Owner::Occluder(oi));
            }
        }
        let rays = match method {
            Method::Exact => 0,
            Method::MonteCarlo(mc) | Method::Auto(mc) => mc.rays,
        };
        let tracer = Some(Tracer {
            caster: caster(&tris, rays),
            owner,
        });
        let bounds = RoomBounds::of_scene(scene);
        Ok(Self {
            scene: scene_cow,
            bounds,
            open: false,
            patches,
            surface_patch,
            occluder_patch0: k,
            method,
            tracer,
            placement_std_m: 0.0,
        })
    }

    /// Adds to every result's standard error the uncertainty of where the point lies relative to
    /// the room's surfaces, `std_m` (m, one standard deviation in each direction): a globe placed
    /// with a tape measure, or walls a scan placed to about a centimetre. Near a cold window or a
    /// radiator the MRT changes by a tenth of a kelvin per centimetre, so this term, not sampling
    /// or temperatures, dominates there. It is the MRT's gradient (central differences 2 cm either
    /// side on each axis, one-sided where a side is outside the room or in furniture; Monte Carlo
    /// with a quarter of the rays and the same directions on both sides) times `std_m`. Costs six
    /// more evaluations per point (1.5 times the rays of one with Monte Carlo). 0 (the default)
    /// leaves it out.
    pub fn with_placement_std(mut self, std_m: f64) -> Self {
        self.placement_std_m = if std_m.is_finite() {
            std_m.max(0.0)
        } else {
            0.0
        };
        self
    }

    /// The placement uncertainty set by [`Self::with_placement_std`] (m).
    pub fn placement_std(&self) -> f64 {
        self.placement_std_m
    }

    /// The patches, in the order of every result's view factors.
    pub fn patches(&self) -> &[Patch] {
        &self.patches
    }

    /// The method.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The scene.
    pub fn scene(&self) -> &RadiantScene {
        &self.scene
    }

    /// The ray-casting engine's name, for Monte Carlo.
    pub fn ray_engine(&self) -> Option<&'static str> {
        self.tracer.as_ref().map(|t| t.caster.engine())
    }

    /// Answers at points the scene does not enclose (an open scene: ΣF short of 1) instead of
    /// refusing them; the result's `view_factor_sum` says how much is missing.
    pub fn allow_open(mut self, yes: bool) -> Self {
        self.open = yes;
        self
    }

    /// The room's extent, when the scene has a floor.
    pub fn bounds(&self) -> Option<&RoomBounds> {
        self.bounds.as_ref()
    }

    /// Refuses a point outside the room (below the floor, above the ceiling, beyond the walls),
    /// or on one of its surfaces: within [`SURFACE_CLEARANCE_M`] of the floor, the ceiling or a
    /// wall a sphere sees that surface over half its view and has no MRT (a point on a window
    /// gave 16.4 °C by exact view factors and 11.5 °C by rays).
    pub fn check_inside(&self, p: &Point3<f64>) -> Result<(), MrtError> {
        let Some(b) = &self.bounds else {
            return Ok(());
        };
        if let Some(w) = b.locate(p) {
            return Err(MrtError::OutsideRoom {
                point: arr(p),
                where_: w.to_string(),
                room: b.describe(),
            });
        }
        let h = b.frame.height(p);
        let uv = b.frame.uv(p);
        let outline = &b.frame.floor_uv;
        let to_wall = (0..outline.len())
            .map(|i| segment_distance(&uv, &outline[i], &outline[(i + 1) % outline.len()]))
            .fold(f64::INFINITY, f64::min);
        let (d, surface) = [
            (h, "floor"),
            (b.ceiling_m - h, "ceiling"),
            (to_wall, "a wall"),
        ]
        .into_iter()
        .fold((f64::INFINITY, "floor"), |a, x| {
            if x.0.abs() < a.0 { (x.0.abs(), x.1) } else { a }
        });
        if d < SURFACE_CLEARANCE_M {
            return Err(MrtError::OutsideRoom {
                point: arr(p),
                where_: format!(
                    "{:.1} cm from {surface}, on it: a sphere there sees that surface over half its view and has no MRT (keep points at least {:.1} cm from the surfaces)",
                    d * 100.0,
                    SURFACE_CLEARANCE_M * 100.0
                ),
                room: b.describe(),
            });
        }
        Ok(())
    }

    /// MRT at `p`. `stream` selects the point's random stream (use the point's index).
    pub fn at(&self, p: &Point3<f64>, stream: u64) -> Result<PointMrt, MrtError> {
        let mut r = self.at_with(p, stream, self.method)?;
        if self.placement_std_m > 0.0 {
            let g = self.gradient(p, stream);
            r.placement_std_error_k = self.placement_std_m * g.norm();
            r.std_error_k = r.std_error_k.hypot(r.placement_std_error_k);
        }
        Ok(r)
    }

    /// The MRT's gradient at `p` (K/m) by central differences (one-sided where a side is refused,
    /// 0 on an axis where both are), with the lighter ray settings of [`Self::with_placement_std`].
    pub fn gradient(&self, p: &Point3<f64>, stream: u64) -> Vector3<f64> {
        let method = match self.method {
            Method::Exact => Method::Exact,
            Method::MonteCarlo(mc) => Method::MonteCarlo(lighter(mc)),
            Method::Auto(mc) => Method::Auto(lighter(mc)),
        };
        let t = |q: &Point3<f64>| self.at_with(q, stream, method).ok().map(|r| r.mrt.kelvin());
        let h = PLACEMENT_STEP_M;
        let mut centre: Option<Option<f64>> = None;
        let mut g = Vector3::zeros();
        for k in 0..3 {
            let e = Vector3::ith(k, h);
            g[k] = match (t(&(p + e)), t(&(p - e))) {
                (Some(a), Some(b)) => (a - b) / (2.0 * h),
                (a, b) if a.is_some() || b.is_some() => {
                    let Some(c) = *centre.get_or_insert_with(|| t(p)) else {
                        continue;
                    };
                    a.map_or_else(|| b.map_or(0.0, |b| (c - b) / h), |a| (a - c) / h)
                }
                _ => 0.0,
            };
        }
        g
    }

    fn at_with(&self, p: &Point3<f64>, stream: u64, method: Method) -> Result<PointMrt, MrtError> {
        self.check_inside(p)?;
        if let Some(o) = self.scene.occluders.iter().find(|o| o.contains(p)) {
            return Err(MrtError::InsideOccluder {
                point: arr(p),
                id: o.id.clone(),
            });
        }
        let exact = |me: &Self| -> Result<_, MrtError> {
            let f = me.exact_view_factors(p);
            let sum: f64 = f.iter().sum();
            if sum > 1.0 + EXACT_OVERLAP_TOLERANCE {
                return Err(MrtError::SurfacesHidden { point: arr(p), sum });
            }
            let n = f.len();
            Ok((f, vec![0.0; n], 0, Vec::new()))
        };
        let (f, se, rays, replicate_f) = match method {
            Method::Exact => exact(self)?,
            Method::MonteCarlo(mc) => self.monte_carlo(p, &mc, stream),
            Method::Auto(mc) if !self.scene.occluders.is_empty() => {
                self.monte_carlo(p, &mc, stream)
            }
            Method::Auto(mc) => match exact(self) {
                Ok(r) => r,
                Err(_) => self.monte_carlo(p, &mc, stream),
            },
        };
        let sum: f64 = f.iter().sum();
        if !self.open && (sum - 1.0).abs() > ENCLOSURE_TOLERANCE {
            return Err(MrtError::NotEnclosed { point: arr(p), sum });
        }
        let seen = self.seen_temperatures(p, &|_| 1.0);
        let temps = seen.as_ref().map(|s| s.temperatures.as_slice());
        let m = self
            .radiant_of(&f, temps)
            .map_err(|source| MrtError::Physics {
                point: arr(p),
                source,
            })?;
        let sampling = self.sampling_error(&replicate_f, temps);
        let (unseen, unseen_parts) = self.unseen_error(&f, seen.as_ref(), m.temperature);
        let level = self.scene.temperature_level_std_k;
        Ok(PointMrt {
            point: *p,
            mrt: m.temperature,
            std_error_k: sampling
                .hypot(m.std_from_temperatures_k)
                .hypot(unseen)
                .hypot(level),
            sampling_std_error_k: sampling,
            temperature_std_error_k: m.std_from_temperatures_k,
            placement_std_error_k: 0.0,
            unseen_std_error_k: unseen,
            level_std_error_k: level,
            unseen_parts,
            view_factor_sum: f.iter().sum(),
            view_factors: f,
            view_factor_std_errors: se,
            rays,
        })
    }

    /// Each patch's temperature seen from `p` by a receiver of directional weight `weight`: a
    /// surface with a raster radiates at its texels' average weighted by their solid angles (see
    /// `raster`); `None` when the scene has no raster (every patch at its own temperature).
    pub(crate) fn seen_temperatures(
        &self,
        p: &Point3<f64>,
        weight: &dyn Fn(&Vector3<f64>) -> f64,
    ) -> Option<Seen> {
        if self.scene.surfaces.iter().all(|s| s.raster.is_none()) {
            return None;
        }
        let mut t: Vec<Temperature> = self.patches.iter().map(|pa| pa.temperature).collect();
        let mut unseen = Vec::new();
        for (si, s) in self.scene.surfaces.iter().enumerate() {
            if let Some((seen, shares)) = s
                .raster
                .as_ref()
                .and_then(|r| r.seen_with_unseen(p, weight))
            {
                let k = self.surface_patch[si];
                t[k] = seen;
                unseen.extend(shares.into_iter().enumerate().map(|(j, u)| (si, k, j, u)));
            }
        }
        Some(Seen {
            temperatures: t,
            unseen,
        })
    }

    /// The unseen-areas part of a radiant temperature `tr` from factors `f` (K): each unseen
    /// patch's share of its surface's factor, times dTr/dT at its filled temperature, times its
    /// spread over the range allowed; patches in quadrature.
    pub(crate) fn unseen_error(
        &self,
        f: &[f64],
        seen: Option<&Seen>,
        tr: Temperature,
    ) -> (f64, Vec<UnseenPart>) {
        let Some(seen) = seen else {
            return (0.0, Vec::new());
        };
        let total: f64 = self
            .patches
            .iter()
            .zip(f)
            .map(|(pa, &f)| self.scene.radiant_weight(pa.emissivity) * f.max(0.0))
            .sum();
        if seen.unseen.is_empty() || total <= 0.0 {
            return (0.0, Vec::new());
        }
        let tr3 = tr.kelvin().powi(3);
        let parts: Vec<UnseenPart> = seen
            .unseen
            .iter()
            .filter_map(|&(si, k, j, u)| {
                let fj = f[k].max(0.0) * u.share;
                let dtr_dt = self.scene.radiant_weight(self.patches[k].emissivity)
                    * fj
                    * u.filled.kelvin().powi(3)
                    / (tr3 * total);
                let part = dtr_dt * u.std_k;
                (part > 0.0).then_some(UnseenPart {
                    surface: si,
                    patch: j,
                    std_error_k: part,
                })
            })
            .collect();
        let sum = parts.iter().map(|p| p.std_error_k.powi(2)).sum::<f64>();
        (sum.sqrt(), parts)
    }

    /// The radiant temperature of factors `f` per patch: (Σ εFT⁴ / Σ εF)^¼ (normalised, so factors
    /// that sum short of 1, like a person's, weigh what is seen), with the error from the patches'
    /// temperature uncertainties (the camera's level not included). `seen` overrides the patches'
    /// temperatures (rasters).
    pub(crate) fn radiant_of(
        &self,
        f: &[f64],
        seen: Option<&[Temperature]>,
    ) -> Result<MeanRadiant, PhysicsError> {
        let src: Vec<RadiantSource> = self
            .patches
            .iter()
            .enumerate()
            .zip(f)
            .filter(|(_, f)| **f > 0.0)
            .map(|((k, pa), &f)| RadiantSource {
                view_factor: f.min(1.0),
                temperature: seen.map_or(pa.temperature, |s| s[k]),
                emissivity: self.scene.radiant_weight(pa.emissivity),
                temperature_std_k: pa.temperature_std_k,
            })
            .collect();
        mean_radiant_temperature(&src)
    }

    /// The sampling standard error (K) of a radiant temperature from its replicates' factors.
    pub(crate) fn sampling_error(
        &self,
        replicate_f: &[Vec<f64>],
        seen: Option<&[Temperature]>,
    ) -> f64 {
        if replicate_f.len() < 2 {
            return 0.0;
        }
        let vals: Vec<f64> = replicate_f
            .iter()
            .filter_map(|g| self.radiant_of(g, seen).ok())
            .map(|m| m.temperature.kelvin())
            .collect();
        std_error(&vals)
    }

    /// The Monte Carlo settings rays are cast with (the method's, or the defaults for exact).
    pub fn ray_settings(&self) -> MonteCarlo {
        match self.method {
            Method::MonteCarlo(mc) | Method::Auto(mc) => mc,
            Method::Exact => MonteCarlo::default(),
        }
    }

    /// Whether open scenes are answered.
    pub(crate) fn answers_open(&self) -> bool {
        self.open
    }

    /// The patch list.
    pub(crate) fn patch_list(&self) -> &[Patch] {
        &self.patches
    }

    /// Each surface's own patch index (its features follow it).
    pub(crate) fn surface_patches(&self) -> &[usize] {
        &self.surface_patch
    }

    fn exact_view_factors(&self, p: &Point3<f64>) -> Vec<f64> {
        let mut f = vec![0.0; self.patches.len()];
        for (si, s) in self.scene.surfaces.iter().enumerate() {
            let k = self.surface_patch[si];
            let mut net = sphere_view_factor(p, &s.polygon);
            for (fi, feat) in s.features.iter().enumerate() {
                let ff = sphere_view_factor(p, &feat.polygon);
                f[k + 1 + fi] = ff;
                net -= ff;
            }
            f[k] = net.max(0.0);
        }
        f
    }

    /// (pooled view factors, their standard errors, rays traced, per-replicate view factors)
    fn monte_carlo(
        &self,
        p: &Point3<f64>,
        mc: &MonteCarlo,
        stream: u64,
    ) -> (Vec<f64>, Vec<f64>, usize, Vec<Vec<f64>>) {
        let r = self.ray_factors(&self.ray_hits(p, mc, stream), &|_| 1.0);
        (r.factors, r.std_errors, r.rays, r.replicates)
    }

    /// The rays of `mc` cast from `p` on the point's random `stream`: per replicate, each
    /// direction with the patch it hits (none where it escapes an open scene).
    pub(crate) fn ray_hits(&self, p: &Point3<f64>, mc: &MonteCarlo, stream: u64) -> RayHits {
        let Some(tracer) = &self.tracer else {
            return RayHits(Vec::new());
        };
        let mut rng = ChaCha8Rng::seed_from_u64(mc.seed);
        rng.set_stream(stream);
        let per = mc.rays.div_ceil(mc.replicates);
        RayHits(
            (0..mc.replicates)
                .map(|_| {
                    sampling::directions(mc.directions, per, &mut rng)
                        .into_iter()
                        .map(|d| (d, self.trace(tracer, p, &d)))
                        .collect()
                })
                .collect(),
        )
    }

    /// Factors of a receiver whose sensitivity to direction d is `weight(d)` (1 for a sphere;
    /// 4·fp for a person; 4·max(0, n·d) for a plane element), from cast rays:
    /// Fᵢ = (1/N) Σ_{rays hitting i} weight(d).
    pub(crate) fn ray_factors(
        &self,
        hits: &RayHits,
        weight: &dyn Fn(&Vector3<f64>) -> f64,
    ) -> RayFactors {
        let n = self.patches.len();
        let r = hits.0.len();
        let mut reps = Vec::with_capacity(r);
        let (mut total, mut rays) = (0.0, 0usize);
        for rep in &hits.0 {
            let mut sums = vec![0.0f64; n];
            for (d, hit) in rep {
                let w = weight(d);
                total += w;
                if w != 0.0
                    && let Some(k) = hit
                {
                    sums[*k] += w;
                }
            }
            rays += rep.len();
            reps.push(
                sums.iter()
                    .map(|&c| c / rep.len().max(1) as f64)
                    .collect::<Vec<f64>>(),
            );
        }
        let mut f = vec![0.0; n];
        let mut se = vec![0.0; n];
        if r > 0 {
            for k in 0..n {
                let vals: Vec<f64> = reps.iter().map(|g| g[k]).collect();
                f[k] = vals.iter().sum::<f64>() / r as f64;
                se[k] = std_error(&vals);
            }
        }
        RayFactors {
            factors: f,
            std_errors: se,
            rays,
            replicates: reps,
            mean_weight: if rays > 0 { total / rays as f64 } else { 0.0 },
        }
    }

    fn trace(&self, tracer: &Tracer, p: &Point3<f64>, d: &Vector3<f64>) -> Option<usize> {
        let hit = tracer.caster.cast(p, d, f64::INFINITY)?;
        match tracer.owner[hit.triangle as usize] {
            Owner::Occluder(oi) => Some(self.occluder_patch0 + oi),
            Owner::Surface(si) => {
                let s = &self.scene.surfaces[si];
                let k = self.surface_patch[si];
                if !s.features.is_empty() {
                    let q = s.frame.to_2d(&(p + d * hit.t));
                    for (fi, feat) in s.features.iter().enumerate() {
                        let (lo, hi) = feat.bounds_2d;
                        if q.x >= lo.x
                            && q.x <= hi.x
                            && q.y >= lo.y
                            && q.y <= hi.y
                            && point_in_polygon_fast(&q, &feat.polygon_2d)
                        {
                            return Some(k + 1 + fi);
                        }
                    }
                }
                Some(k)
            }
        }
    }
}

/// Cast rays: per replicate, each direction and the patch it hits.
pub(crate) struct RayHits(Vec<Vec<(Vector3<f64>, Option<usize>)>>);

/// Factors integrated over cast rays with a directional weight.
pub(crate) struct RayFactors {
    /// Pooled factor per patch.
    pub factors: Vec<f64>,
    /// Their standard errors.
    pub std_errors: Vec<f64>,
    /// Rays cast.
    pub rays: usize,
    /// Factors per replicate.
    pub replicates: Vec<Vec<f64>>,
    /// The weight averaged over every direction, hit or not: what Σ F would be in a closed room.
    pub mean_weight: f64,
}

/// Standard error of the mean of `vals` (sample standard deviation / √n).
fn std_error(vals: &[f64]) -> f64 {
    let n = vals.len() as f64;
    if vals.len() < 2 {
        return 0.0;
    }
    let mean = vals.iter().sum::<f64>() / n;
    let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (var / n).sqrt()
}
