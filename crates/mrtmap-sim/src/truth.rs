//! Exact truth for a simulated scan: MRT at the room's validation points and on the 20×20 grid at
//! 1.1 m, and the room's scene in world coordinates.
//!
//! The MRT comes from the room's fine model (walls with a gradient cut into 5 cm strips): by exact
//! solid angles when the room is convex and has no furniture, otherwise by Monte Carlo ray tracing
//! with many Fibonacci rays, whose standard error is written beside each value.

use mrtmap_geometry::nalgebra::{Isometry3, Point3};
use mrtmap_io::PoseFile;
use mrtmap_radiation::{GridSpec, MapFrame, Method, MrtEngine, MrtField, SceneFile};
use serde::{Deserialize, Serialize};

use crate::room::Room;

/// The `format` of truth.json.
pub const TRUTH_FORMAT: &str = "mrtmap-truth/1";

/// MRT at a named point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthPoint {
    /// Name (A…D).
    pub name: String,
    /// Room frame (z up, floor at 0).
    pub xyz_room: [f64; 3],
    /// World frame (the recording's).
    pub xyz_world: [f64; 3],
    /// Mean radiant temperature (°C).
    pub mrt_c: f64,
    /// Its standard error (0 when exact).
    pub std_error_k: f64,
}

/// MRT on a grid node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthNode {
    /// Column.
    pub i: usize,
    /// Row.
    pub j: usize,
    /// Room frame.
    pub xyz_room: [f64; 3],
    /// World frame.
    pub xyz_world: [f64; 3],
    /// MRT (°C), absent inside furniture.
    pub mrt_c: Option<f64>,
    /// Standard error (K).
    pub std_error_k: Option<f64>,
}

/// The grid truth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthGrid {
    /// Nodes along x (room frame).
    pub nx: usize,
    /// Nodes along y.
    pub ny: usize,
    /// Height above the floor (m).
    pub height_m: f64,
    /// Margin from the walls (m).
    pub margin_m: f64,
    /// Nodes inside the floor plan.
    pub nodes: Vec<TruthNode>,
}

/// truth.json.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Truth {
    /// "mrtmap-truth/1".
    pub format: String,
    /// Room name.
    pub room: String,
    /// Air temperature (°C).
    pub air_temperature_c: f64,
    /// p_in_world = world_from_room · p_in_room.
    pub world_from_room: PoseFile,
    /// Up in the world frame.
    pub up_world: [f64; 3],
    /// "exact" or "montecarlo".
    pub method: String,
    /// How late the recording's thermal frames are stamped (s): thermal.txt's time minus the
    /// exposure's.
    #[serde(default)]
    pub thermal_lag_s: f64,
    /// The simulated microbolometer's time constant τ (s): a pixel reads the scene's radiance
    /// weighted by exp(−age/τ), whose centroid lies τ before the exposure's nominal time. The
    /// offset that places the frames best is therefore −(`thermal_lag_s` + this), what a reader
    /// that estimates the clock offset should find.
    #[serde(default)]
    pub thermal_time_constant_s: f64,
    /// Rays per point for Monte Carlo.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rays: Option<usize>,
    /// Validation points.
    pub points: Vec<TruthPoint>,
    /// The grid.
    pub grid: TruthGrid,
    /// The room as a scene in world coordinates, each surface whole at its radiant-average
    /// temperature (what segmentation should recover).
    pub scene: SceneFile,
    /// The sun through the windows (`mrtmap simulate --sun`): SolarCal's ΔMRT of a seated person
    /// facing the sun at each grid node. The recording does not show it (a long-wave camera
    /// cannot see the beam).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sun: Option<TruthSun>,
    /// The thermal camera's true pose in the depth camera's frame, when it differs from
    /// rig.toml's (`mrtmap simulate --extrinsic-error-mm/--extrinsic-error-deg`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub true_depth_from_thermal: Option<PoseFile>,
}

/// The sun outside a simulated room (`mrtmap simulate --sun ALT,AZ --dni W --transmittance T`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimSun {
    /// Solar altitude (degrees above the horizon, 0…90).
    pub altitude_deg: f64,
    /// Solar azimuth in the room's frame (degrees from +x towards +y).
    pub azimuth_deg: f64,
    /// Direct normal irradiance outside (W/m²).
    pub dni_w_m2: f64,
    /// The windows' total solar transmittance (0…1).
    pub transmittance: f64,
}

impl SimSun {
    /// Refuses a sun below the horizon and inputs outside SolarCal's ranges, naming the flag.
    pub fn check(&self) -> Result<(), crate::SimError> {
        let sun = self;
        let range = |what: &str, value: f64, lo: f64, hi: f64, range: &'static str| {
            if value.is_finite() && (lo..=hi).contains(&value) {
                Ok(())
            } else {
                Err(crate::SimError::OutOfRange {
                    what: what.into(),
                    value,
                    range,
                })
            }
        };
        range("--sun altitude", sun.altitude_deg, 0.0, 90.0, "0…90°")?;
        range("--sun azimuth", sun.azimuth_deg, -360.0, 360.0, "-360…360°")?;
        range(
            "--dni",
            sun.dni_w_m2,
            0.0,
            mrtmap_physics::MAX_DNI_W_M2,
            "0…1500 W/m²",
        )?;
        range("--transmittance", sun.transmittance, 0.0, 1.0, "0…1")?;
        Ok(())
    }
}

/// The sun's truth: its inputs and SolarCal on the grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthSun {
    /// The sun and the glazing.
    pub inputs: SimSun,
    /// The person's short-wave absorptivity (SolarCal's default).
    pub asw: f64,
    /// The floor's short-wave reflectance (SolarCal's default).
    pub floor_reflectance: f64,
    /// The person: "seated", facing the sun (SHARP 0).
    pub posture: String,
    /// The body centre's height above the floor (m).
    pub body_centre_m: f64,
    /// One per grid node of [`Truth::grid`], in its order (the grid's x, y).
    pub nodes: Vec<TruthSunNode>,
}

/// SolarCal at one grid node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthSunNode {
    /// Column.
    pub i: usize,
    /// Row.
    pub j: usize,
    /// The body centre in the room frame.
    pub xyz_room: [f64; 3],
    /// Sky-vault view fraction through the windows (traced); absent when the body centre lies
    /// inside furniture (as the values below).
    pub f_svv: Option<f64>,
    /// Fraction of the body in the beam (traced).
    pub f_bes: Option<f64>,
    /// SolarCal's effective radiant field (W/m²).
    pub erf_w_m2: Option<f64>,
    /// SolarCal's ΔMRT (K).
    pub delta_mrt_k: Option<f64>,
    /// Why there is no value ("inside desk").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// SolarCal of a seated person (body centre 0.6 m) facing `sun` at each node of `grid`, with
/// f_svv and f_bes traced through the windows of `room`'s fine scene (room frame).
pub fn sun_truth(room: &Room, grid: &TruthGrid, sun: &SimSun) -> Result<TruthSun, crate::SimError> {
    use mrtmap_physics::{
        DEFAULT_ASW, DEFAULT_FLOOR_REFLECTANCE, Posture, SkyAndRoom, SolarInputs, solar_gain_in,
    };
    sun.check()?;
    let fine = room.scene(&Isometry3::identity(), true)?;
    let tracer = mrtmap_radiation::SunTracer::new(&fine);
    let direction = mrtmap_radiation::SunDirection {
        altitude_deg: sun.altitude_deg,
        azimuth_deg: sun.azimuth_deg,
    };
    let posture = Posture::Seated;
    let centre = posture.centre_height_m();
    let sky = SkyAndRoom {
        beam_enters: tracer.beam_enters(&direction),
        ..SkyAndRoom::SOLARCAL
    };
    let nodes = grid
        .nodes
        .iter()
        .map(|n| {
            let p = Point3::new(n.xyz_room[0], n.xyz_room[1], centre);
            if let Some(o) = fine.occluders.iter().find(|o| o.contains(&p)) {
                return Ok(TruthSunNode {
                    i: n.i,
                    j: n.j,
                    xyz_room: arr(&p),
                    f_svv: None,
                    f_bes: None,
                    erf_w_m2: None,
                    delta_mrt_k: None,
                    note: Some(format!("inside {}", o.label)),
                });
            }
            let e = tracer.exposure(&p, posture, &direction);
            let g = solar_gain_in(
                &SolarInputs {
                    altitude_deg: sun.altitude_deg,
                    sharp_deg: 0.0,
                    dni_w_m2: sun.dni_w_m2,
                    transmittance: sun.transmittance,
                    f_svv: e.f_svv,
                    f_bes: e.f_bes,
                    asw: DEFAULT_ASW,
                    posture: posture.into(),
                    floor_reflectance: DEFAULT_FLOOR_REFLECTANCE,
                },
                &sky,
            )
            .map_err(|err| crate::SimError::OutOfRange {
                what: format!("SolarCal at ({:.2}, {:.2}): {err}", p.x, p.y),
                value: f64::NAN,
                range: "SolarCal's ranges",
            })?;
            Ok(TruthSunNode {
                i: n.i,
                j: n.j,
                xyz_room: arr(&p),
                f_svv: Some(e.f_svv),
                f_bes: Some(e.f_bes),
                erf_w_m2: Some(g.erf_w_m2),
                delta_mrt_k: Some(g.delta_mrt_k),
                note: None,
            })
        })
        .collect::<Result<Vec<_>, crate::SimError>>()?;
    Ok(TruthSun {
        inputs: *sun,
        asw: DEFAULT_ASW,
        floor_reflectance: DEFAULT_FLOOR_REFLECTANCE,
        posture: posture.as_str().into(),
        body_centre_m: centre,
        nodes,
    })
}

fn arr(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// Computes the truth of `room` seen in the world frame `world_from_room`.
pub fn compute_truth(
    room: &Room,
    world_from_room: &Isometry3<f64>,
    rays: usize,
    seed: u64,
) -> Result<Truth, crate::SimError> {
    let fine = room.scene(&Isometry3::identity(), true)?;
    let method = room.truth_method(rays, seed, 8);
    let exact = matches!(method, Method::Exact);
    let engine = MrtEngine::new(&fine, method)?;
    let w = |p: &Point3<f64>| arr(&(world_from_room * p));
    let mut points = Vec::new();
    for (k, p) in room.file.points.iter().enumerate() {
        let q = Point3::new(p.xy[0], p.xy[1], p.height_m);
        let r = engine.at(&q, 1_000_000 + k as u64)?;
        points.push(TruthPoint {
            name: p.name.clone(),
            xyz_room: arr(&q),
            xyz_world: w(&q),
            mrt_c: r.mrt.celsius(),
            std_error_k: r.std_error_k,
        });
    }
    let spec = GridSpec::default();
    let frame = MapFrame::of_scene(&fine)?;
    let field = MrtField::compute(&engine, frame, spec)?;
    let nodes = field
        .nodes
        .iter()
        .map(|n| TruthNode {
            i: n.i,
            j: n.j,
            xyz_room: arr(&n.point),
            xyz_world: w(&n.point),
            mrt_c: n.result.as_ref().ok().map(|r| r.mrt.celsius()),
            std_error_k: n.result.as_ref().ok().map(|r| r.std_error_k),
        })
        .collect();
    let up = world_from_room * mrtmap_geometry::nalgebra::Vector3::z();
    Ok(Truth {
        format: TRUTH_FORMAT.into(),
        room: room.file.name.clone(),
        air_temperature_c: room.file.air_temperature_c,
        world_from_room: PoseFile::from_isometry(world_from_room),
        true_depth_from_thermal: None,
        up_world: [up.x, up.y, up.z],
        method: method.name().into(),
        thermal_lag_s: 0.0,
        thermal_time_constant_s: 0.0,
        rays: (!exact).then_some(rays),
        points,
        grid: TruthGrid {
            nx: spec.nx,
            ny: spec.ny,
            height_m: spec.height_m,
            margin_m: spec.margin_m,
            nodes,
        },
        scene: room.scene(world_from_room, false)?.to_file(),
        sun: None,
    })
}
