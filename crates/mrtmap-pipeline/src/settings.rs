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
quantities = ["mrt"]      # also: mrt_seated, mrt_standing, asymmetry, operative, pmv, ppd (a person,
                          # with [comfort]); the person's maps are at the body centre's height

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
    #[test]
    fn too_many_rays_are_refused_naming_the_flag() {
        let mut m = MrtSection::default();
        m.rays = MAX_RAYS;
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
}
