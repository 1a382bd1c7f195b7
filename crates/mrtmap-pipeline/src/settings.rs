//! What a user sets: `project.toml` (every key optional) and the view-factor settings shared by
//! `run`, `map` and `mrt`. Flags are merged into a [`Project`] once, by the CLI; everything after
//! that reads typed values.

use std::path::Path;

use mrtmap_geometry::sampling::DirectionSet;
use mrtmap_radiation::{Method, MonteCarlo, MrtEngine, RadiantScene};
use mrtmap_scan::FuseParams;
use mrtmap_scan::segment::SegmentParams;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// The documented example, shown by `mrtmap run --help`.
pub const PROJECT_EXAMPLE: &str = r#"# project.toml: every key is optional (defaults shown); flags override them.
[map]
grid = [20, 20]           # nodes across and along the floor's bounding rectangle
heights_m = [1.1]         # one map per height above the floor (1.1 m seated head, 1.7 m standing)
margin_m = 0.1            # distance kept from the walls

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

[fuse]
voxel_m = 0.03
icp = true                # refine poses by ICP against the map (as the seed paper)
sync_tolerance_ms = 20.0  # thermal frame ↔ nearest depth frame
depth_stride = 2          # every 2nd depth pixel

[segment]
feature_threshold_k = 0.3 # a texel differing from its surface's background by more is a feature
feature_min_area_m2 = 0.04
masks = true              # label features by the recording's instance masks when it has masks.txt

[mrt]
method = "auto"           # auto | exact | montecarlo
rays = 20000              # Monte Carlo rays per point
seed = 1
directions = "fibonacci"  # fibonacci | random
replicates = 8            # independent ray sets the standard error comes from
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
}

impl Default for MapSection {
    fn default() -> Self {
        Self {
            grid: [20, 20],
            heights_m: vec![1.1],
            margin_m: 0.1,
        }
    }
}

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

/// `[fuse]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FuseSection {
    /// Voxel size (m).
    pub voxel_m: f64,
    /// Refine poses by ICP against the map.
    pub icp: bool,
    /// Largest time between a thermal frame and its depth frame (ms).
    pub sync_tolerance_ms: f64,
    /// Every N-th depth pixel in each direction.
    pub depth_stride: u32,
}

impl Default for FuseSection {
    fn default() -> Self {
        Self {
            voxel_m: 0.03,
            icp: true,
            sync_tolerance_ms: 20.0,
            depth_stride: 2,
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
        p.depth.stride = self.depth_stride.max(1);
        Ok(p)
    }
}

/// `[segment]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SegmentSection {
    /// A texel belongs to a feature when it differs from its surface's background by more (K).
    pub feature_threshold_k: f64,
    /// Smallest feature (m²).
    pub feature_min_area_m2: f64,
    /// Label features by the recording's instance masks when it has them.
    pub masks: bool,
}

impl Default for SegmentSection {
    fn default() -> Self {
        Self {
            feature_threshold_k: 0.3,
            feature_min_area_m2: 0.04,
            masks: true,
        }
    }
}

impl SegmentSection {
    /// The segmentation's parameters, with the room frame's origin corner.
    pub fn params(&self, room: &RoomSection) -> SegmentParams {
        SegmentParams {
            feature_threshold_k: self.feature_threshold_k,
            feature_min_area_m2: self.feature_min_area_m2,
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

/// `[mrt]`, and the flags of `map` and `mrt`: the view-factor method.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MrtSection {
    /// Exact, Monte Carlo, or exact where valid.
    pub method: MethodChoice,
    /// Monte Carlo rays per point.
    pub rays: usize,
    /// Monte Carlo seed.
    pub seed: u64,
    /// Monte Carlo direction set.
    pub directions: DirectionChoice,
    /// Independent Monte Carlo replicates the standard errors come from.
    pub replicates: usize,
    /// Answer at points the scene does not enclose (ΣF short of 1: a missing wall, floor or
    /// ceiling) instead of refusing them; the result says how much of the view is missing.
    pub allow_open: bool,
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

    /// The engine for `scene` with these settings (its method, and whether open scenes are
    /// answered).
    pub fn engine<'a>(&self, scene: &'a RadiantScene) -> Result<MrtEngine<'a>> {
        Ok(MrtEngine::new(scene, self.method(scene)?)?.allow_open(self.allow_open))
    }
}

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
    /// Segmentation.
    pub segment: SegmentSection,
    /// The room frame.
    pub room: RoomSection,
    /// View factors.
    pub mrt: MrtSection,
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

    #[test]
    fn the_documented_example_parses_to_the_defaults_plus_its_point() {
        let p = Project::parse(PROJECT_EXAMPLE).unwrap();
        assert_eq!(p.map, MapSection::default());
        assert_eq!(p.fuse, FuseSection::default());
        assert_eq!(p.segment, SegmentSection::default());
        assert_eq!(p.mrt, MrtSection::default());
        assert_eq!(p.points.len(), 1);
        assert_eq!(p.air.temperature_c, Some(21.0));
        let (line, msg) = Project::parse("[map]\n\ngird = [1, 2]\n").unwrap_err();
        assert_eq!(line, 3, "unknown keys are refused with their line");
        assert!(msg.contains("gird"), "{msg}");
        assert!(Project::parse("[mrt]\nmethod = \"fast\"\n").is_err());
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
}
