//! What a user sets: `project.toml` (every key optional) and the view-factor settings shared by
//! `run`, `map` and `mrt`. Flags are merged into a [`Project`] once, by the CLI; everything after
//! that reads typed values.

use std::path::Path;

use mrtmap_geometry::sampling::DirectionSet;
use mrtmap_physics::Posture;
use mrtmap_radiation::{Facing, Method, MonteCarlo, MrtEngine, RadiantScene};
use mrtmap_scan::FuseParams;
use mrtmap_scan::clock::ClockOffset;
use mrtmap_scan::segment::SegmentParams;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// The documented example, shown by `mrtmap run --help`.
pub const PROJECT_EXAMPLE: &str = r#"# project.toml: every key is optional (defaults shown); flags override them.
[map]
grid = [20, 20]           # nodes across and along the floor's bounding rectangle
heights_m = [1.1]         # one map per height above the floor (1.1 m seated head, 1.7 m standing)
margin_m = 0.1            # distance kept from the walls
quantities = ["mrt"]      # also: mrt_seated, mrt_standing, mrt_sun, asymmetry, operative, pmv, ppd (a
                          # person, with [comfort]; mrt_sun with [sun]); the person's maps are at
                          # the body centre's height

[[points]]                # named points (e.g. globe locations), metres, in the room frame:
name = "A"                # x, y along the floor from the origin corner, z above the floor
xyz = [1.2, 0.8, 1.1]
# frame = "scan"          # or in the scan's world frame (the frame of trajectory.txt)

[room]
# origin_corner = 1       # the floor corner at the origin (numbered on the report's map); by
                          # default the start of the longest wall with the room in x, y >= 0

[air]
temperature_c = 21.0      # for the report's operative temperature and globe comparisons
speed_m_s = 0.1

[comfort]                 # a person, for the person's maps and points (ISO 7730, Fanger's PMV)
posture = "seated"        # seated (body centre 0.6 m) | standing (1.0 m)
# facing_deg = 90.0       # which way the person faces (0 = +x, 90 = +y); unset: any way (averaged)
# air_temperature_c = 22  # default: [air] temperature_c; needed for operative, pmv, ppd
# air_temperature_profile = [[0.1, 21.0], [1.7, 23.0]]  # [height m, °C] for stratified air
# air_speed_m_s = 0.1     # default: [air] speed_m_s
relative_humidity_pct = 50.0
met = 1.2                 # metabolic rate (1.2: seated office work)
clo = 0.7                 # clothing insulation

[fuse]
voxel_m = 0.03
icp = true                # refine poses by ICP against the map (as the seed paper)
sync_tolerance_ms = 20.0  # thermal frame ↔ nearest depth frame (at least 0.55 of the depth frames' interval)
time_offset = "auto"      # added to the thermal stamps: auto (rig.toml's [thermal] time_offset_s, else
                          # estimated from the scan) | estimate | off | milliseconds, e.g. "-70"
depth_stride = 0          # every N-th depth pixel; 0: about one per thermal pixel
self_calibrate = true     # remove each frame's offset (FFC, drift) and the vignetting, from overlaps

[track]
mode = "auto"             # the built-in RGB-D tracker: auto (when the recording has no poses),
                          # always (re-track even when it has them), never
loop_closure = true
use_imu = true            # predict each frame's rotation from imu.txt's gyro when there is one
fast_threshold = 12       # FAST corner threshold (grey levels); lower finds more on weak texture

[segment]
feature_threshold_k = 0.3 # a texel differing from its surface's background by more is a feature
feature_min_area_m2 = 0.04
raster_m = 0.15           # each surface's temperature raster (texel, m); 0: one temperature per surface
masks = true              # label features by the recording's instance masks when it has masks.txt
texture = true            # cast the thermal frames onto the room model: glass and other surfaces the
                          # depth camera did not see take the thermal camera's temperatures

[mrt]
method = "auto"           # auto | exact | montecarlo
rays = 20000              # Monte Carlo rays per point
seed = 1
directions = "fibonacci"  # fibonacci | random
replicates = 8            # independent ray sets the standard error comes from
placement_std_m = 0.01    # how well a point is placed relative to the walls (m, 1σ); adds the MRT's gradient × it to the MRT's ± (not a person's or a plane's); 0: leave out

[emissivity]              # long-wave emissivities: by label from docs/scene-format.md's table (window
                          # 0.84, painted wall 0.93, ...) unless given here; they turn the camera's
                          # radiant temperatures into surface temperatures and contact readings into
                          # what the camera should read (the MRT itself needs none)
std = 0.02                # the standard uncertainty of each emissivity
# by_label = { window = 0.88, radiator = 0.2 }  # labels containing the key (longest key first)
# by_id = { "wall-3" = 0.90 }                   # one surface or feature, by its id in scene.json

[sun]                     # the sun through the windows (SolarCal), for mrt_sun and validate; unset: none
# altitude_deg = 30.0     # the sun in the room's frame: degrees above the horizon,
# azimuth_deg = 0.0       # and from +x towards +y
# date_time = "2026-01-15T10:30:00Z"  # or: a UTC time and a place (NOAA's sun position)
# latitude_deg = 52.5     # north positive
# longitude_deg = 13.4    # east positive
# north_deg = 0.0         # compass bearing of the room's +y axis (0: +y north, +x east)
# epw = "site.epw"        # with date_time: an EnergyPlus weather file gives the place and that
                          # hour's direct normal irradiance (local standard time, hour ending)
# dni_w_m2 = 700.0        # direct normal irradiance outside (needed with a sun)
# transmittance = 0.6     # the windows' total solar transmittance with shades (needed with a sun)
floor_reflectance = 0.6   # the floor's short-wave reflectance
asw = 0.7                 # the person's short-wave absorptivity

[export]
formats = []              # also write the room to export/room.EXT: "hbjson", "gbxml", "gltf", "rad"
# max_points = 200000     # thermal-cloud points in the glTF (evenly thinned); 0: leave the cloud out
"#;

/// `[map]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapSection {
    /// Grid nodes across and along the floor's bounding rectangle.
    pub grid: [usize; 2],
    /// One map per height above the floor (m).
    pub heights_m: Vec<f64>,
    /// Distance kept from the walls (m).
    pub margin_m: f64,
    /// What to map: the sphere's MRT at each height, and a person's quantities.
    pub quantities: Vec<Quantity>,
}

impl Default for MapSection {
    fn default() -> Self {
        Self {
            grid: [20, 20],
            heights_m: vec![1.1],
            margin_m: 0.1,
            quantities: vec![Quantity::Mrt],
        }
    }
}

/// What a map can show (`[map] quantities`, `--quantity`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
#[value(rename_all = "snake_case")]
pub enum Quantity {
    /// The MRT of a small sphere at each map height (ISO 7726).
    Mrt,
    /// The MRT of a seated person (body centre 0.6 m), facing as `[comfort]` says.
    MrtSeated,
    /// The MRT of a standing person (body centre 1.0 m).
    MrtStanding,
    /// The MRT of `[comfort]`'s person with SolarCal's ΔMRT of `[sun]` added (facing the sun
    /// when `[comfort] facing_deg` is unset).
    MrtSun,
    /// The worst radiant temperature asymmetry (K) at the abdomen of `[comfort]`'s posture.
    Asymmetry,
    /// Operative temperature (ISO 7726) of `[comfort]`'s person.
    Operative,
    /// Predicted mean vote (ISO 7730).
    Pmv,
    /// Predicted percentage dissatisfied (ISO 7730).
    Ppd,
}

impl Quantity {
    /// Its name in files ("mrt_seated").
    pub fn name(self) -> &'static str {
        match self {
            Self::Mrt => "mrt",
            Self::MrtSeated => "mrt_seated",
            Self::MrtStanding => "mrt_standing",
            Self::MrtSun => "mrt_sun",
            Self::Asymmetry => "asymmetry",
            Self::Operative => "operative",
            Self::Pmv => "pmv",
            Self::Ppd => "ppd",
        }
    }

    /// The person's quantities among `qs` (all but the sphere's MRT, which every map run draws).
    pub fn person(qs: &[Quantity]) -> Vec<Quantity> {
        qs.iter().copied().filter(|q| *q != Quantity::Mrt).collect()
    }

    /// Whether it needs the air (temperature, humidity…): operative temperature, PMV and PPD.
    pub fn needs_air(self) -> bool {
        matches!(self, Self::Operative | Self::Pmv | Self::Ppd)
    }
}

/// `[comfort]`: the person whose comfort the person's maps and points describe.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ComfortSection {
    /// Seated or standing.
    pub posture: Posture,
    /// Which way the person faces (degrees from +x towards +y); `None`: any way (averaged).
    pub facing_deg: Option<f64>,
    /// Air temperature (°C); default `[air] temperature_c`.
    pub air_temperature_c: Option<f64>,
    /// Air temperature by height, `[height m, °C]` pairs (linear between, constant beyond).
    pub air_temperature_profile: Vec<[f64; 2]>,
    /// Air speed (m/s); default `[air] speed_m_s`.
    pub air_speed_m_s: Option<f64>,
    /// Relative humidity (%).
    pub relative_humidity_pct: f64,
    /// Metabolic rate (met).
    pub met: f64,
    /// Clothing insulation (clo).
    pub clo: f64,
}

impl Default for ComfortSection {
    fn default() -> Self {
        Self {
            posture: Posture::Seated,
            facing_deg: None,
            air_temperature_c: None,
            air_temperature_profile: Vec::new(),
            air_speed_m_s: None,
            relative_humidity_pct: 50.0,
            met: 1.2,
            clo: 0.7,
        }
    }
}

impl ComfortSection {
    /// Which way the person faces.
    pub fn facing(&self) -> Facing {
        self.facing_deg.map_or(Facing::Any, Facing::Azimuth)
    }

    /// The air temperature (°C) at `height_m` above the floor: the profile, else the one value
    /// here, else `[air]`'s; `None` when none is given.
    pub fn air_at(&self, air: &AirSection, height_m: f64) -> Option<f64> {
        let p = &self.air_temperature_profile;
        if let (Some(first), Some(last)) = (p.first(), p.last()) {
            if height_m <= first[0] {
                return Some(first[1]);
            }
            if height_m >= last[0] {
                return Some(last[1]);
            }
            return p.windows(2).find_map(|w| {
                let ([h0, t0], [h1, t1]) = (w[0], w[1]);
                (height_m >= h0 && height_m <= h1)
                    .then(|| t0 + (t1 - t0) * (height_m - h0) / (h1 - h0).max(1e-12))
            });
        }
        self.air_temperature_c.or(air.temperature_c)
    }

    /// The air speed (m/s).
    pub fn air_speed(&self, air: &AirSection) -> f64 {
        self.air_speed_m_s.unwrap_or(air.speed_m_s)
    }

    /// Checks ranges, and that the air is given when `quantities` need it.
    pub fn check(&self, air: &AirSection, quantities: &[Quantity]) -> Result<()> {
        let bad = |key: &str, v: f64, allowed: &str| {
            Error::setting(
                format!("[comfort] {key} = {v}"),
                format!("is outside {allowed}"),
            )
        };
        if !(0.0..=100.0).contains(&self.relative_humidity_pct) {
            return Err(bad(
                "relative_humidity_pct",
                self.relative_humidity_pct,
                "0…100 %",
            ));
        }
        if !(0.5..=5.0).contains(&self.met) {
            return Err(bad("met", self.met, "0.5…5 met"));
        }
        if !(0.0..=3.0).contains(&self.clo) {
            return Err(bad("clo", self.clo, "0…3 clo"));
        }
        let v = self.air_speed(air);
        if !(0.0..=5.0).contains(&v) {
            return Err(bad("air_speed_m_s", v, "0…5 m/s"));
        }
        if let Some(f) = self.facing_deg
            && !f.is_finite()
        {
            return Err(bad("facing_deg", f, "finite degrees"));
        }
        // Air a room's occupants breathe: a typo (500 for 50, °F for °C) is refused, not mapped.
        let airs = [
            ("[air] temperature_c", air.temperature_c),
            ("[comfort] air_temperature_c", self.air_temperature_c),
        ]
        .into_iter()
        .filter_map(|(k, v)| v.map(|v| (k, v)))
        .chain(
            self.air_temperature_profile
                .iter()
                .map(|h| ("[comfort] air_temperature_profile", h[1])),
        );
        for (key, t) in airs {
            if !(AIR_RANGE_C.0..=AIR_RANGE_C.1).contains(&t) {
                return Err(Error::setting(
                    format!("{key} = {t}"),
                    format!(
                        "is outside {}…{} °C, the air of a room people occupy (in °C, not °F)",
                        AIR_RANGE_C.0, AIR_RANGE_C.1
                    ),
                ));
            }
        }
        let p = &self.air_temperature_profile;
        if p.windows(2).any(|w| w[1][0] <= w[0][0]) || p.iter().flatten().any(|x| !x.is_finite()) {
            return Err(Error::setting(
                "[comfort] air_temperature_profile",
                "must list [height m, °C] pairs with heights increasing",
            ));
        }
        if quantities.iter().any(|q| q.needs_air()) && self.air_at(air, 1.0).is_none() {
            return Err(Error::setting(
                "[map] quantities",
                "include operative, pmv or ppd, which need the air temperature: set [comfort] air_temperature_c (or [air] temperature_c, --air-c)",
            ));
        }
        Ok(())
    }
}

/// The error for `mrt_sun` asked for without `[sun]`.
pub fn no_sun_error() -> Error {
    Error::setting(
        "mrt_sun",
        "needs the sun: give [sun] in project.toml (--config) with altitude_deg and azimuth_deg (or date_time, latitude_deg, longitude_deg), dni_w_m2 and transmittance",
    )
}

/// The air temperatures accepted (°C): a room people occupy.
pub const AIR_RANGE_C: (f64, f64) = (-30.0, 60.0);

/// The frame a point is given in: one choice for `--frame` and `[[points]] frame`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum PointFrame {
    /// The room frame: x, y along the floor from the origin corner, z above the floor.
    #[default]
    Room,
    /// The scan's world frame (the frame of trajectory.txt).
    Scan,
}

/// `[[points]]`: a named point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointEntry {
    /// Name.
    pub name: String,
    /// Position (m).
    pub xyz: [f64; 3],
    /// The frame of `xyz`.
    #[serde(default, skip_serializing_if = "is_room")]
    pub frame: PointFrame,
}

fn is_room(f: &PointFrame) -> bool {
    *f == PointFrame::Room
}

/// `[room]`: the room frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RoomSection {
    /// The floor corner at the origin (1-based, as numbered on the report's map); `None` for the
    /// rule (the start of the longest wall with the room at x, y ≥ 0).
    pub origin_corner: Option<usize>,
}

impl RoomSection {
    /// Settings that need no cloud: corners are numbered from 1.
    pub fn check(&self) -> Result<()> {
        if self.origin_corner == Some(0) {
            return Err(Error::setting(
                "--origin-corner 0 ([room] origin_corner)".to_string(),
                "is not a corner: corners are numbered from 1, as on the report's map; leave it out for the default",
            ));
        }
        Ok(())
    }
}

/// `[air]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AirSection {
    /// Air temperature (°C).
    pub temperature_c: Option<f64>,
    /// Air speed (m/s).
    pub speed_m_s: f64,
}

impl Default for AirSection {
    fn default() -> Self {
        Self {
            temperature_c: None,
            speed_m_s: 0.1,
        }
    }
}

/// When the built-in tracker runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TrackMode {
    /// When the recording has no trajectory.txt.
    #[default]
    Auto,
    /// Always, replacing the recording's poses.
    Always,
    /// Never (a recording without poses is refused).
    Never,
}

/// `[track]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackSection {
    /// When the tracker runs.
    pub mode: TrackMode,
    /// Look for loop closures.
    pub loop_closure: bool,
    /// Predict each frame's rotation from the recording's gyro (imu.txt) where it has one.
    pub use_imu: bool,
    /// FAST corner threshold (grey levels).
    pub fast_threshold: u8,
}

impl Default for TrackSection {
    fn default() -> Self {
        let t = mrtmap_track::TrackParams::default();
        Self {
            mode: TrackMode::Auto,
            loop_closure: t.loop_closure,
            use_imu: t.use_imu,
            fast_threshold: t.fast_threshold,
        }
    }
}

impl TrackSection {
    /// The tracker's parameters.
    pub fn params(&self) -> mrtmap_track::TrackParams {
        mrtmap_track::TrackParams {
            loop_closure: self.loop_closure,
            use_imu: self.use_imu,
            fast_threshold: self.fast_threshold,
            ..Default::default()
        }
    }
}

/// `[fuse]`, and the flags of `mrtmap fuse` (the doc comments are their `--help`, the defaults
/// those of [`Default`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, clap::Args)]
#[serde(default, deny_unknown_fields)]
pub struct FuseSection {
    /// Voxel size (m).
    #[arg(long = "voxel-m", default_value_t = 0.03)]
    pub voxel_m: f64,
    /// Refine poses by point-to-plane ICP against the map built so far (on or off).
    #[arg(long, default_value = "on", value_name = "on|off", action = clap::ArgAction::Set,
          value_parser = crate::parse::parse_on_off)]
    pub icp: bool,
    /// Largest time between a thermal frame and the depth frame it takes (ms); at least 0.55 of
    /// the depth frames' interval is used, so every thermal frame finds one at any depth rate.
    #[arg(long = "sync-tolerance-ms", default_value_t = 20.0)]
    pub sync_tolerance_ms: f64,
    /// Use every N-th depth pixel in each direction; 0: about one depth point per thermal pixel
    /// (the cameras' focal lengths' ratio, rounded: 3 for a 640×480 D435 beside a Lepton).
    #[arg(long, default_value_t = 0)]
    pub depth_stride: u32,
    /// Radiometric self-calibration (on or off): estimate and remove each frame's offset
    /// (flat-field corrections, drift) and the vignetting from the frames' overlaps.
    #[arg(long, default_value = "on", value_name = "on|off", action = clap::ArgAction::Set,
          value_parser = crate::parse::parse_on_off)]
    pub self_calibrate: bool,
    /// What to add to the thermal stamps to put them on the depth camera's clock: auto (rig.toml's
    /// `[thermal] time_offset_s`, else estimated from the scan), estimate, off, or milliseconds
    /// (-70: frames stamped 70 ms after their exposure).
    #[arg(long, default_value = "auto", allow_hyphen_values = true)]
    pub time_offset: String,
}

/// The thermal clock's setting from its text: auto, estimate, off, or milliseconds.
pub fn parse_time_offset(text: &str) -> Result<ClockOffset> {
    let refuse = || {
        Error::setting(
            format!("time offset '{text}' (--time-offset, [fuse] time_offset)"),
            "is not auto, estimate, off or a number of milliseconds between -1000 and 1000",
        )
    };
    match text.trim() {
        "auto" => Ok(ClockOffset::Auto),
        "estimate" => Ok(ClockOffset::Estimate),
        "off" => Ok(ClockOffset::Off),
        other => {
            let ms: f64 = other
                .trim_end_matches("ms")
                .trim()
                .parse()
                .map_err(|_| refuse())?;
            if ms.is_finite() && ms.abs() <= 1000.0 {
                Ok(ClockOffset::Fixed(ms / 1000.0))
            } else {
                Err(refuse())
            }
        }
    }
}

impl Default for FuseSection {
    fn default() -> Self {
        Self {
            voxel_m: 0.03,
            icp: true,
            sync_tolerance_ms: 20.0,
            depth_stride: 0,
            self_calibrate: true,
            time_offset: "auto".into(),
        }
    }
}

impl FuseSection {
    /// The fusion's parameters, after checking the ranges.
    pub fn params(&self) -> Result<FuseParams> {
        if !(self.voxel_m > 0.001 && self.voxel_m <= 1.0) {
            return Err(Error::setting(
                format!("voxel size {} m (--voxel-m, [fuse] voxel_m)", self.voxel_m),
                "is outside 0.001…1 m",
            ));
        }
        if !(self.sync_tolerance_ms > 0.0 && self.sync_tolerance_ms <= 1000.0) {
            return Err(Error::setting(
                format!(
                    "sync tolerance {} ms (--sync-tolerance-ms, [fuse] sync_tolerance_ms)",
                    self.sync_tolerance_ms
                ),
                "is outside 0…1000 ms",
            ));
        }
        let mut p = FuseParams {
            voxel_m: self.voxel_m,
            sync_tolerance_s: self.sync_tolerance_ms / 1000.0,
            ..FuseParams::default()
        };
        p.icp.enabled = self.icp;
        p.depth.stride = self.depth_stride;
        p.radiometric.enabled = self.self_calibrate;
        p.clock = parse_time_offset(&self.time_offset)?;
        Ok(p)
    }
}

/// `[segment]`, and the flags of `mrtmap segment` (the doc comments are their `--help`, the
/// defaults those of [`Default`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, clap::Args)]
#[serde(default, deny_unknown_fields)]
pub struct SegmentSection {
    /// A texel belongs to a feature when it differs from its surface's background by more (K).
    #[arg(long, default_value_t = 0.3)]
    pub feature_threshold_k: f64,
    /// Smallest feature (m²).
    #[arg(long = "feature-min-area-m2", default_value_t = 0.04)]
    pub feature_min_area_m2: f64,
    /// Texel of each surface's temperature raster in scene.json (m), so that a stratified wall
    /// radiates as it is; 0 for one temperature per surface.
    #[arg(long = "raster-m", default_value_t = 0.15)]
    pub raster_m: f64,
    /// Label features by the recording's instance masks when it has them.
    #[arg(skip = true)]
    pub masks: bool,
    /// Cast the fused thermal frames onto the room model found, so that what the depth camera
    /// did not see (glass, dark or shiny surfaces, dropouts) takes the thermal camera's
    /// temperatures.
    #[arg(skip = true)]
    pub texture: bool,
}

impl Default for SegmentSection {
    fn default() -> Self {
        Self {
            feature_threshold_k: 0.3,
            feature_min_area_m2: 0.04,
            raster_m: 0.15,
            masks: true,
            texture: true,
        }
    }
}

impl SegmentSection {
    /// Settings that need no cloud: the raster's texel.
    pub fn check(&self) -> Result<()> {
        let r = self.raster_m;
        if !(r == 0.0 || (r.is_finite() && (0.03..=2.0).contains(&r))) {
            return Err(Error::setting(
                format!("--raster-m {r} ([segment] raster_m)"),
                "must be 0 (no raster) or between 0.03 and 2 m",
            ));
        }
        Ok(())
    }

    /// The segmentation's parameters, with the room frame's origin corner.
    pub fn params(&self, room: &RoomSection) -> SegmentParams {
        SegmentParams {
            feature_threshold_k: self.feature_threshold_k,
            feature_min_area_m2: self.feature_min_area_m2,
            raster_m: self.raster_m,
            origin_corner: room.origin_corner,
            ..SegmentParams::default()
        }
    }
}

/// How view factors are computed: one choice for flags (`--method`) and `[mrt] method`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum MethodChoice {
    /// Exact solid angles where valid; Monte Carlo with occluders or where surfaces hide each
    /// other (non-convex rooms).
    #[default]
    Auto,
    /// Exact solid angles (Van Oosterom–Strackee), features subtracted from their host.
    Exact,
    /// Monte Carlo ray tracing against a BVH (handles occluders and non-convex rooms).
    Montecarlo,
}

/// Monte Carlo direction sets: one choice for `--directions` and `[mrt] directions`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum DirectionChoice {
    /// Randomly rotated spherical Fibonacci lattices (converges faster).
    #[default]
    Fibonacci,
    /// Independent uniform random directions.
    Random,
}

impl From<DirectionChoice> for DirectionSet {
    fn from(d: DirectionChoice) -> Self {
        match d {
            DirectionChoice::Fibonacci => DirectionSet::Fibonacci,
            DirectionChoice::Random => DirectionSet::Random,
        }
    }
}

/// `[mrt]`, and the flags of `map` and `mrt`: the view-factor method. One definition for both:
/// the doc comments are the flags' `--help`, the defaults those of [`Default`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, clap::Args)]
#[serde(default, deny_unknown_fields)]
pub struct MrtSection {
    /// View-factor method: exact solid angles where valid and Monte Carlo with occluders or where
    /// surfaces hide each other (auto), exact solid angles only (exact), or Monte Carlo ray
    /// tracing (montecarlo).
    #[arg(long, value_enum, default_value_t = MethodChoice::Auto)]
    pub method: MethodChoice,
    /// Monte Carlo: rays per point.
    #[arg(long, default_value_t = MonteCarlo::default().rays)]
    pub rays: usize,
    /// Monte Carlo: random seed (results are reproducible from it).
    #[arg(long, default_value_t = MonteCarlo::default().seed)]
    pub seed: u64,
    /// Monte Carlo: direction set (randomly rotated spherical Fibonacci lattices converge faster
    /// than independent random directions).
    #[arg(long, value_enum, default_value_t = DirectionChoice::Fibonacci)]
    pub directions: DirectionChoice,
    /// Monte Carlo: independent replicates the standard errors come from.
    #[arg(long, default_value_t = MonteCarlo::default().replicates)]
    pub replicates: usize,
    /// Answer at points the scene does not enclose (a missing wall, floor or ceiling leaves part
    /// of the view empty: ΣF short of 1) instead of refusing them; ΣF is printed with each point.
    #[arg(long)]
    pub allow_open: bool,
    /// How well a point is placed relative to the room's surfaces (m, one standard deviation): the
    /// MRT's gradient times it joins the MRT's ± (near a cold window it dominates; not yet a
    /// person's or a plane's); 0 leaves it out.
    #[arg(long, default_value_t = 0.01)]
    pub placement_std_m: f64,
}

impl Default for MrtSection {
    fn default() -> Self {
        let mc = MonteCarlo::default();
        Self {
            method: MethodChoice::Auto,
            rays: mc.rays,
            seed: mc.seed,
            directions: DirectionChoice::Fibonacci,
            replicates: mc.replicates,
            allow_open: false,
            placement_std_m: 0.01,
        }
    }
}

impl MrtSection {
    /// The method for `scene`: `auto` is Monte Carlo when the scene has occluders (exact solid
    /// angles cannot see them), else exact with Monte Carlo where surfaces hide each other.
    pub fn method(&self, scene: &RadiantScene) -> Result<Method> {
        self.check()?;
        let mc = MonteCarlo {
            rays: self.rays,
            seed: self.seed,
            directions: self.directions.into(),
            replicates: self.replicates,
        };
        Ok(match self.method {
            MethodChoice::Exact => Method::Exact,
            MethodChoice::Montecarlo => Method::MonteCarlo(mc),
            MethodChoice::Auto if scene.occluders.is_empty() => Method::Auto(mc),
            MethodChoice::Auto => Method::MonteCarlo(mc),
        })
    }

    /// Settings that need no scene: the placement uncertainty and the ray count (checked before a
    /// run's fusion, not after it).
    pub fn check(&self) -> Result<()> {
        if self.rays == 0 {
            return Err(Error::setting(
                "--rays 0 ([mrt] rays)",
                "is too few: at least 1 ray per point is needed",
            ));
        }
        if self.method != MethodChoice::Exact && self.replicates < 2 {
            return Err(Error::setting(
                format!("--replicates {} ([mrt] replicates)", self.replicates),
                "is too few: the standard error needs at least 2 independent replicates",
            ));
        }
        if self.rays > MAX_RAYS {
            return Err(Error::setting(
                format!("--rays {} ([mrt] rays)", self.rays),
                format!(
                    "is more than the {MAX_RAYS} rays per point allowed (each ray holds about 42 bytes while a point is answered: 1e8 rays took 4.2 GB); 20000 give about ±0.01 K"
                ),
            ));
        }
        if !(self.placement_std_m.is_finite() && (0.0..=1.0).contains(&self.placement_std_m)) {
            return Err(Error::setting(
                format!(
                    "--placement-std-m {} ([mrt] placement_std_m)",
                    self.placement_std_m
                ),
                "must be between 0 and 1 m",
            ));
        }
        Ok(())
    }

    /// The engine for `scene` with these settings (its method, and whether open scenes are
    /// answered).
    pub fn engine<'a>(&self, scene: &'a RadiantScene) -> Result<MrtEngine<'a>> {
        self.check()?;
        Ok(MrtEngine::new(scene, self.method(scene)?)?
            .allow_open(self.allow_open)
            .with_placement_std(self.placement_std_m))
    }
}

/// The most Monte Carlo rays per point a setting may ask for: 10 million (about 420 MB while a
/// point is answered); issue 54 found 2e9 running out of memory and 1e15 aborting Python.
pub const MAX_RAYS: usize = 10_000_000;

/// A project: everything `mrtmap run` needs besides the recording.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Project {
    /// Maps.
    pub map: MapSection,
    /// Named points.
    pub points: Vec<PointEntry>,
    /// Air.
    pub air: AirSection,
    /// Fusion.
    pub fuse: FuseSection,
    /// The built-in tracker.
    pub track: TrackSection,
    /// Segmentation.
    pub segment: SegmentSection,
    /// The room frame.
    pub room: RoomSection,
    /// The person for comfort maps and points.
    pub comfort: ComfortSection,
    /// Contact-thermometer readings of surface points (besides the recording's references.csv).
    pub references: Vec<crate::level::Reference>,
    /// View factors.
    pub mrt: MrtSection,
    /// Exports of the measured room (`export/` of the run's output).
    pub export: crate::export::ExportSection,
    /// Emissivities.
    pub emissivity: EmissivitySection,
    /// The sun through the windows (SolarCal), for `mrt_sun` maps and `validate`.
    pub sun: SunSection,
}

/// `[sun]`: the sun outside and the glazing, for SolarCal's ΔMRT on a person (the `mrt_sun` map,
/// operative temperature and PMV/PPD with the sun, and `mrtmap validate`'s globes in the beam).
/// The sun is given either by `altitude_deg` and `azimuth_deg` in the room's frame, or by
/// `date_time` (UTC) with `latitude_deg`, `longitude_deg` and `north_deg`; a sun below the
/// horizon at that time is refused (no beam: leave `[sun]` out for a night-time map).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SunSection {
    /// Solar altitude (degrees above the horizon, 0…90).
    pub altitude_deg: Option<f64>,
    /// Solar azimuth in the room's frame (degrees from +x towards +y).
    pub azimuth_deg: Option<f64>,
    /// The moment, ISO 8601 in UTC ("2026-01-15T10:30:00Z").
    pub date_time: Option<String>,
    /// Latitude (degrees, north positive), with `date_time`.
    pub latitude_deg: Option<f64>,
    /// Longitude (degrees, east positive), with `date_time`.
    pub longitude_deg: Option<f64>,
    /// The compass bearing of the room's +y axis (degrees; 0: +y north, +x east), with
    /// `date_time`.
    pub north_deg: f64,
    /// An EnergyPlus weather file (EPW), with `date_time`: its LOCATION gives the latitude and
    /// longitude (unless given) and its hour holding `date_time` (local standard time, hour ending)
    /// the direct normal irradiance (unless `dni_w_m2` is given). A relative path is from the
    /// folder mrtmap runs in.
    pub epw: Option<String>,
    /// Direct normal irradiance outside (W/m²); needed with a sun.
    pub dni_w_m2: Option<f64>,
    /// The windows' total solar transmittance with their shades (0…1); needed with a sun.
    pub transmittance: Option<f64>,
    /// The floor's short-wave reflectance (0…1).
    pub floor_reflectance: f64,
    /// The person's short-wave absorptivity (0…1).
    pub asw: f64,
}

impl Default for SunSection {
    fn default() -> Self {
        Self {
            altitude_deg: None,
            azimuth_deg: None,
            date_time: None,
            latitude_deg: None,
            longitude_deg: None,
            north_deg: 0.0,
            epw: None,
            dni_w_m2: None,
            transmittance: None,
            floor_reflectance: mrtmap_physics::DEFAULT_FLOOR_REFLECTANCE,
            asw: mrtmap_physics::DEFAULT_ASW,
        }
    }
}

impl SunSection {
    /// Whether any key places a sun (so that `query` gives one or an error).
    pub fn is_given(&self) -> bool {
        self.altitude_deg.is_some()
            || self.azimuth_deg.is_some()
            || self.date_time.is_some()
            || self.latitude_deg.is_some()
            || self.longitude_deg.is_some()
            || self.epw.is_some()
            || self.dni_w_m2.is_some()
            || self.transmittance.is_some()
    }

    /// The sun's altitude and room azimuth at `when` (`date_time`), at the place the keys (or the
    /// EPW file) give, and the EPW file's hour when one is given.
    fn sun_at_time(&self, when: &str) -> Result<(f64, f64, Option<EpwHour>)> {
        let time = parse_utc(when).ok_or_else(|| {
            Error::setting(
                format!("[sun] date_time = \"{when}\""),
                "is not an ISO 8601 UTC time like \"2026-01-15T10:30:00Z\"",
            )
        })?;
        let epw = match &self.epw {
            Some(path) => Some(epw_at(Path::new(path), &time)?),
            None => None,
        };
        let lat_given = self.latitude_deg.or(epw.map(|w| w.latitude_deg));
        let lon_given = self.longitude_deg.or(epw.map(|w| w.longitude_deg));
        let need = |key: &str, v: Option<f64>| {
            v.ok_or_else(|| {
                Error::setting(
                    "[sun] date_time",
                    format!("needs [sun] {key} to place the sun"),
                )
            })
        };
        let lat = sun_within(
            "latitude_deg",
            need("latitude_deg", lat_given)?,
            -90.0,
            90.0,
            "-90…90°",
        )?;
        let lon = sun_within(
            "longitude_deg",
            need("longitude_deg", lon_given)?,
            -180.0,
            180.0,
            "-180…180° (east positive)",
        )?;
        let north = sun_within("north_deg", self.north_deg, -360.0, 360.0, "-360…360°")?;
        let pos = mrtmap_physics::sun_position(&time, lat, lon)
            .map_err(|e| Error::setting(format!("[sun] date_time = \"{when}\""), e.to_string()))?;
        if pos.altitude_deg <= 0.0 {
            return Err(Error::setting(
                format!("[sun] date_time = \"{when}\""),
                format!(
                    "puts the sun {:.1}° below the horizon at {lat}°, {lon}°: no beam (leave [sun] out for a map without the sun)",
                    -pos.altitude_deg
                ),
            ));
        }
        Ok((
            pos.altitude_deg,
            mrtmap_physics::room_azimuth_deg(pos.azimuth_deg, north),
            epw,
        ))
    }

    /// Checks every key (the same as [`SunSection::query`] without its answer).
    pub fn check(&self) -> Result<()> {
        self.query().map(|_| ())
    }

    /// The sun in the room's frame with the glazing and the person's absorptivity; `None` when
    /// `[sun]` places no sun. Errors name the key.
    pub fn query(&self) -> Result<Option<crate::points::SunQuery>> {
        if !self.is_given() {
            return Ok(None);
        }
        let bad = |key: &str, v: f64, allowed: &str| {
            Error::setting(
                format!("[sun] {key} = {v}"),
                format!("is outside {allowed}"),
            )
        };
        let within = |key: &str, v: f64, lo: f64, hi: f64, allowed: &str| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(v)
            } else {
                Err(bad(key, v, allowed))
            }
        };
        if self.epw.is_some() && self.date_time.is_none() {
            return Err(Error::setting(
                "[sun] epw",
                "needs [sun] date_time (UTC) to pick its hour",
            ));
        }
        let mut epw: Option<EpwHour> = None;
        let (altitude, azimuth) = match (
            self.altitude_deg,
            self.azimuth_deg,
            self.date_time.as_deref(),
        ) {
            (Some(alt), Some(az), None) => {
                let alt = within(
                    "altitude_deg",
                    alt,
                    0.0,
                    90.0,
                    "0…90° (a sun above the horizon)",
                )?;
                let az = within("azimuth_deg", az, -360.0, 360.0, "-360…360°")?;
                (alt, az.rem_euclid(360.0))
            }
            (None, None, Some(when)) => {
                let (alt, az, w) = self.sun_at_time(when)?;
                epw = w;
                (alt, az)
            }
            (_, _, Some(_)) => {
                return Err(Error::setting(
                    "[sun] date_time",
                    "is given with altitude_deg or azimuth_deg: place the sun one way, not both",
                ));
            }
            (None, None, None) => {
                return Err(Error::setting(
                    "[sun]",
                    "places no sun: give altitude_deg and azimuth_deg, or date_time with latitude_deg and longitude_deg",
                ));
            }
            (Some(_), None, None) | (None, Some(_), None) => {
                return Err(Error::setting(
                    "[sun] altitude_deg and azimuth_deg",
                    "go together: give both",
                ));
            }
        };
        let dni = self.dni_w_m2.or(epw.map(|w| w.dni_w_m2)).ok_or_else(|| {
            Error::setting(
                "[sun] dni_w_m2",
                "is needed with a sun: the direct normal irradiance outside (W/m²)",
            )
        })?;
        let dni = within(
            "dni_w_m2",
            dni,
            0.0,
            mrtmap_physics::MAX_DNI_W_M2,
            "0…1500 W/m²",
        )?;
        let tau = self.transmittance.ok_or_else(|| {
            Error::setting(
                "[sun] transmittance",
                "is needed with a sun: the windows' total solar transmittance (0…1)",
            )
        })?;
        let tau = within("transmittance", tau, 0.0, 1.0, "0…1")?;
        let floor = within("floor_reflectance", self.floor_reflectance, 0.0, 1.0, "0…1")?;
        let asw = within("asw", self.asw, 0.0, 1.0, "0…1")?;
        let mut q = crate::points::SunQuery::new(altitude, azimuth, dni, tau);
        q.floor_reflectance = floor;
        q.asw = asw;
        Ok(Some(q))
    }
}

/// `v` when finite and within `lo…hi`, else an error naming `[sun] key` and `allowed`.
fn sun_within(key: &str, v: f64, lo: f64, hi: f64, allowed: &str) -> Result<f64> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(Error::setting(
            format!("[sun] {key} = {v}"),
            format!("is outside {allowed}"),
        ))
    }
}

/// What an EPW weather file gives for one hour: its place and the direct normal irradiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EpwHour {
    /// Latitude (degrees, north positive).
    pub latitude_deg: f64,
    /// Longitude (degrees, east positive).
    pub longitude_deg: f64,
    /// Direct normal irradiance (W/m², the file's field 15).
    pub dni_w_m2: f64,
}

/// The hour of the EnergyPlus weather file `path` that holds the instant `time` (UTC): the file's
/// LOCATION line (latitude, longitude, time zone in hours from UTC) and the data row whose month,
/// day and hour (local standard time, hour ending: hour h covers h − 1 to h) hold it, any year
/// (typical-year files mix them). Errors name the file and, for a row, the line.
pub fn epw_at(path: &Path, time: &mrtmap_physics::UtcTime) -> Result<EpwHour> {
    let text = std::fs::read_to_string(path).map_err(|e| mrtmap_io::FileError::io(path, e))?;
    let bad = |line: usize, message: String| Error::Config {
        path: path.to_path_buf(),
        line,
        message,
    };
    let loc = text
        .lines()
        .position(|l| l.starts_with("LOCATION"))
        .ok_or_else(|| bad(1, "no LOCATION line: is it an EPW weather file?".into()))?;
    let cells: Vec<&str> = text.lines().nth(loc).unwrap_or("").split(',').collect();
    let num = |k: usize, what: &str, line: usize| -> Result<f64> {
        cells
            .get(k)
            .and_then(|c| c.trim().parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                bad(
                    line,
                    format!("LOCATION's {what} (field {}) is not a number", k + 1),
                )
            })
    };
    let (lat, lon, tz) = (
        num(6, "latitude", loc + 1)?,
        num(7, "longitude", loc + 1)?,
        num(8, "time zone", loc + 1)?,
    );
    // The local standard time, by whole days and hours from the UTC instant.
    let days_in = |y: i32, m: u32| match m {
        2 if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    };
    let minutes = f64::from(time.hour * 60 + time.minute) + time.second / 60.0 + tz * 60.0;
    let (mut y, mut m, mut d) = (time.year, time.month, time.day as i64);
    let mut day_shift = (minutes / 1440.0).floor() as i64;
    let local_min = minutes - 1440.0 * day_shift as f64;
    while day_shift > 0 {
        d += 1;
        if d > i64::from(days_in(y, m)) {
            d = 1;
            m += 1;
            if m > 12 {
                m = 1;
                y += 1;
            }
        }
        day_shift -= 1;
    }
    while day_shift < 0 {
        d -= 1;
        if d < 1 {
            m = if m == 1 { 12 } else { m - 1 };
            if m == 12 {
                y -= 1;
            }
            d = i64::from(days_in(y, m));
        }
        day_shift += 1;
    }
    let hour = (local_min / 60.0).floor() as i64 + 1;
    for (k, line) in text.lines().enumerate().skip(loc + 1) {
        let c: Vec<&str> = line.split(',').collect();
        if c.len() < 15 {
            continue;
        }
        let int = |i: usize| c[i].trim().parse::<i64>().ok();
        if int(1) == Some(i64::from(m)) && int(2) == Some(d) && int(3) == Some(hour) {
            let dni = c[14]
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| {
                    bad(
                        k + 1,
                        format!(
                            "direct normal irradiance (field 15) '{}' is not a number",
                            c[14].trim()
                        ),
                    )
                })?;
            return Ok(EpwHour {
                latitude_deg: lat,
                longitude_deg: lon,
                dni_w_m2: dni,
            });
        }
    }
    Err(bad(
        0,
        format!(
            "no row for {m:02}-{d:02}, hour {hour} (local standard time, UTC{tz:+}): the file holds no such hour"
        ),
    ))
}

/// An ISO 8601 time in UTC: `YYYY-MM-DDTHH:MM[:SS[.fff]]` with `Z` or `+00:00` (a space for the
/// `T` too); ranges are checked by `sun_position`.
fn parse_utc(s: &str) -> Option<mrtmap_physics::UtcTime> {
    let s = s.trim();
    let body = s
        .strip_suffix('Z')
        .or_else(|| s.strip_suffix('z'))
        .or_else(|| s.strip_suffix("+00:00"))?;
    let (date, time) = body.split_once(['T', 't', ' '])?;
    let mut d = date.split('-');
    let (year, month, day) = (d.next()?, d.next()?, d.next()?);
    if d.next().is_some() || year.len() != 4 || month.len() != 2 || day.len() != 2 {
        return None;
    }
    let mut t = time.split(':');
    let (hour, minute, second) = (t.next()?, t.next()?, t.next().unwrap_or("0"));
    if t.next().is_some() || hour.len() != 2 || minute.len() != 2 {
        return None;
    }
    let second: f64 = second.parse().ok()?;
    second.is_finite().then_some(())?;
    Some(mrtmap_physics::UtcTime {
        year: year.parse().ok()?,
        month: month.parse().ok()?,
        day: day.parse().ok()?,
        hour: hour.parse().ok()?,
        minute: minute.parse().ok()?,
        second,
    })
}

/// `[emissivity]`: the surfaces' long-wave emissivities, where the table's by label are not wanted.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EmissivitySection {
    /// The standard uncertainty of each emissivity.
    pub std: f64,
    /// Emissivity of elements whose label contains the key (case-insensitive; the longest key
    /// that matches wins).
    pub by_label: std::collections::BTreeMap<String, f64>,
    /// Emissivity of one surface or feature, by id.
    pub by_id: std::collections::BTreeMap<String, f64>,
}

impl Default for EmissivitySection {
    fn default() -> Self {
        Self {
            std: mrtmap_radiation::grey::EMISSIVITY_STD,
            by_label: Default::default(),
            by_id: Default::default(),
        }
    }
}

impl EmissivitySection {
    /// Every value is an emissivity (0 < ε ≤ 1), the standard uncertainty within 0…0.5.
    pub fn check(&self) -> Result<()> {
        if !(self.std.is_finite() && (0.0..=0.5).contains(&self.std)) {
            return Err(Error::setting(
                format!("[emissivity] std = {}", self.std),
                "must be between 0 and 0.5",
            ));
        }
        for (table, map) in [("by_label", &self.by_label), ("by_id", &self.by_id)] {
            if let Some((k, v)) = map.iter().find(|(_, v)| !(**v > 0.0 && **v <= 1.0)) {
                return Err(Error::setting(
                    format!("[emissivity] {table}.{k} = {v}"),
                    "is not an emissivity: give a value above 0 and at most 1",
                ));
            }
        }
        Ok(())
    }

    /// The emissivity of the element `id` labelled `label` (of kind `kind` for a surface).
    pub fn of(&self, id: &str, label: &str, kind: Option<mrtmap_radiation::SurfaceKind>) -> f64 {
        if let Some(e) = self.by_id.get(id) {
            return *e;
        }
        let l = label.to_lowercase();
        self.by_label
            .iter()
            .filter(|(k, _)| l.contains(&k.to_lowercase()))
            .max_by_key(|(k, _)| k.len())
            .map_or_else(
                || mrtmap_radiation::grey::default_emissivity(label, kind),
                |(_, e)| *e,
            )
    }

    /// Sets every surface's, feature's and occluder's emissivity in `scene` and marks its
    /// temperatures as radiant (what the camera read).
    pub fn apply(&self, scene: &mut RadiantScene) {
        for s in &mut scene.surfaces {
            s.emissivity = self.of(&s.id, &s.label, Some(s.kind));
            for f in &mut s.features {
                f.emissivity = self.of(&f.id, &f.label, None);
            }
        }
        for o in &mut scene.occluders {
            o.emissivity = self.of(&o.id, &o.label, None);
        }
        scene.temperatures = Some(mrtmap_radiation::TemperatureKind::Radiant);
    }
}

impl Project {
    /// Reads project.toml; errors name the file and line.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| mrtmap_io::FileError::io(path, e))?;
        Self::parse(&text).map_err(|(line, message)| Error::Config {
            path: path.to_path_buf(),
            line,
            message,
        })
    }

    /// Parses project.toml text; an error gives the 1-based line (0 when unknown) and the message.
    pub fn parse(text: &str) -> std::result::Result<Self, (usize, String)> {
        toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1)
                .unwrap_or(0);
            (line, e.message().to_string())
        })
    }

    /// Checks what can be checked before any stage runs.
    pub fn check(&self) -> Result<()> {
        if self.map.heights_m.is_empty()
            || self
                .map
                .heights_m
                .iter()
                .any(|h| !(h.is_finite() && *h > 0.0))
        {
            return Err(Error::setting(
                format!("map heights {:?} m", self.map.heights_m),
                "must be positive numbers",
            ));
        }
        self.fuse.params()?;
        self.segment.check()?;
        self.room.check()?;
        self.comfort.check(&self.air, &self.map.quantities)?;
        self.mrt.check()?;
        self.emissivity.check()?;
        self.sun.check()?;
        if self.map.quantities.contains(&Quantity::MrtSun) && !self.sun.is_given() {
            return Err(no_sun_error());
        }
        Ok(())
    }

    /// The settings as TOML, for the report.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// Issue 54: a ray count that cannot be answered is refused before anything runs.
    /// An EPW file gives the place and the hour's direct normal irradiance: 11:00 UTC in Berlin
    /// (UTC+1) is in the local hour ending at 13:00.
    #[test]
    fn an_epw_file_gives_the_place_and_the_hour_s_irradiance() {
        let dir = tempfile::tempdir().unwrap();
        let epw = dir.path().join("berlin.epw");
        let row = |h: u32, dni: f64| {
            format!("1989,1,15,{h},60,?9?9?9?9E0,1.0,-2.0,80,101000,0,0,250,150,{dni},60,0,0,0,0\n")
        };
        let text = format!(
            "LOCATION,Berlin,,DEU,IWEC Data,103840,52.47,13.40,1.0,49.0\nDESIGN CONDITIONS,0\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n{}{}",
            row(12, 100.0),
            row(13, 345.0)
        );
        std::fs::write(&epw, text).unwrap();
        let t = parse_utc("2026-01-15T11:00:00Z").unwrap();
        let h = epw_at(&epw, &t).unwrap();
        assert_eq!(
            (h.latitude_deg, h.longitude_deg, h.dni_w_m2),
            (52.47, 13.40, 345.0)
        );
        let sun = SunSection {
            date_time: Some("2026-01-15T11:00:00Z".into()),
            epw: Some(epw.display().to_string()),
            transmittance: Some(0.6),
            ..SunSection::default()
        };
        let q = sun.query().unwrap().unwrap();
        assert_eq!(q.dni_w_m2, 345.0);
        let direct = SunSection {
            epw: None,
            latitude_deg: Some(52.47),
            longitude_deg: Some(13.40),
            dni_w_m2: Some(345.0),
            ..sun.clone()
        };
        let d = direct.query().unwrap().unwrap();
        assert!((d.direction.altitude_deg - q.direction.altitude_deg).abs() < 1e-9);
        // An hour the file does not hold, and an epw without a time, are refused by name.
        let e = epw_at(&epw, &parse_utc("2026-01-16T11:00:00Z").unwrap())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("berlin.epw") && e.contains("01-16, hour 13"),
            "{e}"
        );
        let e = SunSection {
            date_time: None,
            ..sun
        }
        .query()
        .unwrap_err()
        .to_string();
        assert!(e.contains("[sun] epw"), "{e}");
    }

    #[test]
    fn too_many_rays_are_refused_naming_the_flag() {
        let mut m = MrtSection {
            rays: MAX_RAYS,
            ..MrtSection::default()
        };
        assert!(m.check().is_ok());
        m.rays = 1_000_000_000_000_000;
        let e = m.check().unwrap_err().to_string();
        assert!(
            e.contains("--rays 1000000000000000") && e.contains("10000000"),
            "{e}"
        );
        let p = Project {
            mrt: m,
            ..Project::default()
        };
        assert!(p.check().is_err());
    }

    #[test]
    fn the_documented_example_parses_to_the_defaults_plus_its_point() {
        let p = Project::parse(PROJECT_EXAMPLE).unwrap();
        assert_eq!(p.map, MapSection::default());
        assert_eq!(p.fuse, FuseSection::default());
        assert_eq!(p.segment, SegmentSection::default());
        assert_eq!(p.mrt, MrtSection::default());
        assert_eq!(p.track, TrackSection::default());
        assert_eq!(p.export, crate::export::ExportSection::default());
        assert_eq!(p.sun, SunSection::default());
        assert_eq!(p.points.len(), 1);
        assert_eq!(p.air.temperature_c, Some(21.0));
        let (line, msg) = Project::parse("[map]\n\ngird = [1, 2]\n").unwrap_err();
        assert_eq!(line, 3, "unknown keys are refused with their line");
        assert!(msg.contains("gird"), "{msg}");
        assert!(Project::parse("[mrt]\nmethod = \"fast\"\n").is_err());
    }

    #[test]
    fn corner_zero_and_a_wild_raster_are_refused_before_any_stage_runs() {
        let p = Project::parse("[room]\norigin_corner = 0\n").unwrap();
        let e = p.check().unwrap_err().to_string();
        assert!(e.contains("origin_corner") && e.contains("from 1"), "{e}");
        assert!(
            Project::parse("[room]\norigin_corner = 2\n")
                .unwrap()
                .check()
                .is_ok()
        );
        let p = Project::parse("[segment]\nraster_m = 5.0\n").unwrap();
        let e = p.check().unwrap_err().to_string();
        assert!(
            e.contains("raster_m") && e.contains("between 0.03 and 2 m"),
            "{e}"
        );
        assert!(
            Project::parse("[segment]\nraster_m = 0.0\n")
                .unwrap()
                .check()
                .is_ok()
        );
    }

    #[test]
    fn auto_is_monte_carlo_with_occluders_and_too_few_replicates_are_refused() {
        let mut scene = mrtmap_radiation::example_office();
        let s = MrtSection::default();
        assert!(matches!(s.method(&scene).unwrap(), Method::Auto(_)));
        scene.occluders.push(mrtmap_radiation::Occluder {
            id: "desk".into(),
            label: "desk".into(),
            temperature: mrtmap_physics::Temperature::from_celsius(21.0),
            emissivity: 0.95,
            shape: mrtmap_radiation::OccluderShape::Box {
                min: mrtmap_geometry::nalgebra::Point3::new(1.0, 1.0, 0.0),
                max: mrtmap_geometry::nalgebra::Point3::new(2.0, 1.8, 0.75),
            },
        });
        assert!(matches!(s.method(&scene).unwrap(), Method::MonteCarlo(_)));
        let bad = MrtSection { replicates: 0, ..s };
        let e = bad.method(&scene).unwrap_err().to_string();
        assert!(
            e.contains("--replicates 0") && e.contains("at least 2"),
            "{e}"
        );
    }

    #[test]
    fn a_placement_uncertainty_reaches_the_engine_and_a_senseless_one_is_refused() {
        let scene = mrtmap_radiation::example_office();
        let s = MrtSection::default();
        assert_eq!(s.engine(&scene).unwrap().placement_std(), 0.01);
        let p = Project::parse("[mrt]\nplacement_std_m = 0.0\n").unwrap();
        assert_eq!(p.mrt.engine(&scene).unwrap().placement_std(), 0.0);
        // A project's bad value is refused by its check, before any fusion.
        let bad = Project::parse("[mrt]\nplacement_std_m = -0.5\n").unwrap();
        let e = bad.check().unwrap_err().to_string();
        assert!(e.contains("[mrt] placement_std_m"), "{e}");
        for bad in [-0.01, f64::NAN, 2.0] {
            let e = MrtSection {
                placement_std_m: bad,
                ..s
            }
            .engine(&scene)
            .err()
            .unwrap()
            .to_string();
            assert!(
                e.contains("placement_std_m") && e.contains("between 0 and 1 m"),
                "{e}"
            );
        }
    }

    #[test]
    fn the_sun_parses_from_an_angle_or_a_time_and_place() {
        let p = Project::parse(
            "[sun]\naltitude_deg = 30.0\nazimuth_deg = -90.0\ndni_w_m2 = 700\ntransmittance = 0.6\nasw = 0.5\n",
        )
        .unwrap();
        p.check().unwrap();
        let q = p.sun.query().unwrap().unwrap();
        assert_eq!(q.direction.altitude_deg, 30.0);
        assert_eq!(q.direction.azimuth_deg, 270.0);
        assert_eq!((q.dni_w_m2, q.transmittance, q.asw), (700.0, 0.6, 0.5));
        assert_eq!(
            q.floor_reflectance,
            mrtmap_physics::DEFAULT_FLOOR_REFLECTANCE
        );
        assert!(Project::default().sun.query().unwrap().is_none());

        // Berlin, 15 January 2026, 11:00 UTC (about solar noon): the sun due south, about 15°
        // high. With +y pointing north the room's azimuth of south is 270° (−y); with +y pointing
        // east (north_deg 90) +x points south, so the sun is near 0°.
        let text = |north: f64| {
            format!(
                "[sun]\ndate_time = \"2026-01-15T11:00:00Z\"\nlatitude_deg = 52.52\nlongitude_deg = 13.40\nnorth_deg = {north}\ndni_w_m2 = 600\ntransmittance = 0.5\n"
            )
        };
        let q = Project::parse(&text(0.0))
            .unwrap()
            .sun
            .query()
            .unwrap()
            .unwrap();
        let expect = mrtmap_physics::sun_position(
            &mrtmap_physics::UtcTime {
                year: 2026,
                month: 1,
                day: 15,
                hour: 11,
                minute: 0,
                second: 0.0,
            },
            52.52,
            13.40,
        )
        .unwrap();
        assert!((q.direction.altitude_deg - expect.altitude_deg).abs() < 1e-12);
        assert!((10.0..20.0).contains(&q.direction.altitude_deg), "{q:?}");
        assert!((q.direction.azimuth_deg - 270.0).abs() < 5.0, "{q:?}");
        let east = Project::parse(&text(90.0))
            .unwrap()
            .sun
            .query()
            .unwrap()
            .unwrap();
        let e = east.direction.azimuth_deg;
        assert!(!(5.0..=355.0).contains(&e), "{east:?}");
        assert!(
            ((e - q.direction.azimuth_deg).rem_euclid(360.0) - 90.0).abs() < 1e-9,
            "turning the room turns the sun"
        );
    }

    #[test]
    fn a_bad_sun_is_refused_naming_the_key() {
        let base = "altitude_deg = 30.0\nazimuth_deg = 0.0\ndni_w_m2 = 700\ntransmittance = 0.6\n";
        let err = |extra: &str, body: &str| {
            Project::parse(&format!("[sun]\n{body}{extra}"))
                .map_err(|(_, m)| m)
                .and_then(|p| p.check().map_err(|e| e.to_string()))
                .unwrap_err()
        };
        let e = err("", &base.replace("700", "-5"));
        assert!(e.contains("[sun] dni_w_m2 = -5"), "{e}");
        let e = err("", &base.replace("0.6", "1.6"));
        assert!(e.contains("[sun] transmittance = 1.6"), "{e}");
        let e = err("", &base.replace("30.0", "-3.0"));
        assert!(e.contains("[sun] altitude_deg = -3"), "{e}");
        let e = err("asw = 2.0\n", base);
        assert!(e.contains("[sun] asw = 2"), "{e}");
        let e = err("floor_reflectance = -0.1\n", base);
        assert!(e.contains("[sun] floor_reflectance = -0.1"), "{e}");
        let e = err(
            "",
            "altitude_deg = 30.0\nazimuth_deg = 0.0\ntransmittance = 0.6\n",
        );
        assert!(e.contains("[sun] dni_w_m2") && e.contains("needed"), "{e}");
        let e = err(
            "",
            "altitude_deg = 30.0\ndni_w_m2 = 700\ntransmittance = 0.6\n",
        );
        assert!(e.contains("azimuth_deg") && e.contains("both"), "{e}");
        let when =
            "dni_w_m2 = 700\ntransmittance = 0.6\nlatitude_deg = 52.5\nlongitude_deg = 13.4\n";
        let e = err("date_time = \"2026-13-15T10:30:00Z\"\n", when);
        assert!(
            e.contains("[sun] date_time = \"2026-13-15T10:30:00Z\""),
            "{e}"
        );
        let e = err("date_time = \"15.01.2026 10:30\"\n", when);
        assert!(e.contains("ISO 8601"), "{e}");
        // Midnight in Berlin: below the horizon, refused.
        let e = err("date_time = \"2026-01-15T23:00:00Z\"\n", when);
        assert!(e.contains("below the horizon"), "{e}");
        let e = err(
            "date_time = \"2026-01-15T11:00:00Z\"\n",
            "dni_w_m2 = 700\ntransmittance = 0.6\n",
        );
        assert!(e.contains("latitude_deg"), "{e}");
        let e = err("date_time = \"2026-01-15T11:00:00Z\"\n", base);
        assert!(e.contains("not both"), "{e}");
        assert!(Project::parse("[sun]\nsun_altitude = 3\n").is_err());
        // mrt_sun without a sun is refused before anything runs.
        let p = Project::parse("[map]\nquantities = [\"mrt_sun\"]\n").unwrap();
        let e = p.check().unwrap_err().to_string();
        assert!(e.contains("mrt_sun") && e.contains("[sun]"), "{e}");
    }
}
