//! What a user sets: `project.toml` (every key optional), one section per file, and the
//! view-factor settings shared by `run`, `map` and `mrt`. Flags and files meet once, in
//! `resolve` ([`crate::Overrides`]); everything after that reads typed values.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

mod comfort;
mod emissivity;
pub(crate) mod export;
mod map;
pub(crate) mod mrt;
mod references;
mod scan;
pub(crate) mod sun;

pub use comfort::{AirSection, ComfortSection};
pub use emissivity::EmissivitySection;
pub(crate) use export::ExportFormat;
pub use export::ExportSection;
pub use map::{MapSection, PointEntry, PointFrame, Quantity, RoomSection};
pub(crate) use mrt::MrtSection;
pub use mrt::{DirectionChoice, MethodChoice};
pub use references::Reference;
pub use scan::{FuseSection, SegmentSection, TrackMode, TrackSection};
pub use sun::SunSection;

pub(crate) use comfort::*;

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

[sun]                     # the sun through the glazing (SolarCal), for mrt_sun and validate; unset: none
# altitude_deg = 30.0     # the sun in the room's frame: degrees above the horizon,
# azimuth_deg = 0.0       # and from +x towards +y
# date_time = "2026-01-15T10:30:00Z"  # or: a UTC time and a place (NOAA's sun position)
# latitude_deg = 52.5     # north positive
# longitude_deg = 13.4    # east positive
# north_deg = 0.0         # compass bearing of the room's +y axis (0: +y north, +x east)
# epw = "site.epw"        # with date_time: an EnergyPlus weather file gives the place and that
                          # hour's direct normal and diffuse irradiance (local standard time, hour
                          # ending); a relative path is from this file's folder
# dni_w_m2 = 700.0        # direct normal irradiance outside (needed with a sun)
# transmittance = 0.6     # the windows' total solar transmittance with shades (needed with a sun)
floor_reflectance = 0.6   # the floor's short-wave reflectance
asw = 0.7                 # the person's short-wave absorptivity

[export]
formats = []              # also write the room to export/room.EXT: "hbjson", "gbxml", "gltf", "rad"
# max_points = 200000     # thermal-cloud points in the glTF (evenly thinned); 0: leave the cloud out
"#;

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
    pub references: Vec<Reference>,
    /// View factors.
    pub mrt: MrtSection,
    /// Exports of the measured room (`export/` of the run's output).
    pub export: ExportSection,
    /// Emissivities.
    pub emissivity: EmissivitySection,
    /// The sun through the windows (SolarCal), for `mrt_sun` maps and `validate`.
    pub sun: SunSection,
}

impl Project {
    /// Reads project.toml; errors name the file and line.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| mrtmap_io::FileError::io(path, e))?;
        let mut p = Self::parse(&text).map_err(|(line, message)| Error::Config {
            path: path.to_path_buf(),
            line,
            message,
        })?;
        // A file the project names by a relative path is found beside the project.toml.
        if let (Some(epw), Some(dir)) = (&mut p.sun.epw, path.parent())
            && Path::new(epw.as_str()).is_relative()
        {
            *epw = dir.join(epw.as_str()).display().to_string();
        }
        Ok(p)
    }

    /// The files the settings name (the weather file): inputs of the stages that read them, so
    /// that replacing one behind the same path re-runs those stages.
    pub fn named_files(&self) -> Vec<std::path::PathBuf> {
        self.sun.epw.iter().map(std::path::PathBuf::from).collect()
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

    /// Refuses map heights at or below the floor before a run, when the room and its ceiling are
    /// not known yet (`map` and `mrt` check heights against the room itself, naming its ceiling).
    pub fn check_heights_above_floor(&self) -> Result<()> {
        if let Some(h) = self.map.heights_m.iter().find(|h| **h <= 0.0) {
            return Err(Error::setting(
                format!("a map {h:.2} m above the floor ([map] heights_m, --height)"),
                "is not in the room: give a height above the floor (1.1 m is seated head height, 1.7 m standing)",
            ));
        }
        Ok(())
    }

    /// Checks what can be checked before any stage runs.
    pub fn check(&self) -> Result<()> {
        if self.map.heights_m.is_empty() {
            return Err(Error::setting(
                "[map] heights_m = []",
                "asks for no map: give at least one height above the floor (1.1 m seated head, 1.7 m standing)",
            ));
        }
        if self.map.heights_m.iter().any(|h| !h.is_finite()) {
            return Err(Error::setting(
                format!("map heights {:?} m", self.map.heights_m),
                "must be numbers (metres above the floor)",
            ));
        }
        for &h in &self.map.heights_m {
            mrtmap_radiation::GridSpec {
                nx: self.map.grid[0],
                ny: self.map.grid[1],
                height_m: h,
                margin_m: self.map.margin_m,
            }
            .check()
            .map_err(|e| {
                Error::setting(
                    format!(
                        "[map] grid = {:?}, margin_m = {} (--grid, --margin-m)",
                        self.map.grid, self.map.margin_m
                    ),
                    format!("is refused: {e}"),
                )
            })?;
        }
        self.fuse.params()?;
        self.segment.check()?;
        self.room.check()?;
        self.comfort.check(&self.air, &self.map.quantities)?;
        self.mrt.check()?;
        self.emissivity.check()?;
        self.sun.check()?;
        for r in &self.references {
            r.check().map_err(|b| {
                Error::setting(
                    format!("[[references]] \"{}\" {} = {}", r.label, b.key, b.value),
                    format!("is outside {}", b.allowed),
                )
            })?;
        }
        if let Some(p) = self
            .points
            .iter()
            .find(|p| p.xyz.iter().any(|v| !v.is_finite()))
        {
            return Err(Error::setting(
                format!("[[points]] \"{}\" xyz = {:?}", p.name, p.xyz),
                "is not a place: give three numbers in metres",
            ));
        }
        // Two points of one name were both printed as that name: which is which?
        let mut names = std::collections::HashSet::new();
        if let Some(p) = self.points.iter().find(|p| !names.insert(p.name.as_str())) {
            return Err(Error::setting(
                format!("[[points]] name = \"{}\"", p.name),
                "is given to two points: name each point once (--mark too)",
            ));
        }
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
    use mrtmap_radiation::Method;

    /// Issue 54: a ray count that cannot be answered is refused before anything runs.
    #[test]
    fn too_many_rays_are_refused_naming_the_flag() {
        use super::mrt::MAX_RAYS;
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
        assert_eq!(p.export, ExportSection::default());
        assert_eq!(p.sun, SunSection::default());
        assert_eq!(p.points.len(), 1);
        assert_eq!(p.air.temperature_c, Some(21.0));
        let (line, msg) = Project::parse("[map]\n\ngird = [1, 2]\n").unwrap_err();
        assert_eq!(line, 3, "unknown keys are refused with their line");
        assert!(msg.contains("gird"), "{msg}");
        assert!(Project::parse("[mrt]\nmethod = \"fast\"\n").is_err());
    }

    /// Issue 54: a grid without nodes or a negative margin was refused only after fusion and
    /// segmentation (7 s into a 20 s scan's run).
    #[test]
    fn a_bad_grid_is_refused_before_any_stage_runs() {
        for (toml, says) in [
            ("[map]\ngrid = [0, 5]\n", "0×5 nodes"),
            ("[map]\ngrid = [100000, 100000]\n", "at most 4000000"),
            ("[map]\nmargin_m = -1.0\n", "margin -1 m"),
        ] {
            let e = Project::parse(toml)
                .unwrap()
                .check()
                .unwrap_err()
                .to_string();
            assert!(e.contains("[map] grid") && e.contains(says), "{e}");
        }
        let huge = Project::parse("[map]\ngrid = [18446744073709551615, 2]\n");
        if let Ok(p) = huge {
            assert!(p.check().is_err());
        }
        let twice = "[[points]]\nname = \"A\"\nxyz = [1.0, 1.0, 1.1]\n[[points]]\nname = \"A\"\nxyz = [2.0, 1.0, 1.1]\n";
        let e = Project::parse(twice)
            .unwrap()
            .check()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("name = \"A\"") && e.contains("two points"),
            "{e}"
        );
        // An air speed is named where it was given ([air] was named as [comfort]'s key).
        let e = Project::parse("[air]\nspeed_m_s = -1.0\n")
            .unwrap()
            .check()
            .unwrap_err()
            .to_string();
        assert!(e.contains("[air] speed_m_s = -1"), "{e}");
        // Three values (the third was ignored) and one are refused, with the line.
        for toml in ["[map]\ngrid = [20, 20, 20]\n", "[map]\ngrid = [20]\n"] {
            let (line, e) = Project::parse(toml).unwrap_err();
            assert!(line == 2 && e.contains("where it takes two"), "{line}: {e}");
        }
        assert_eq!(
            Project::parse("[map]\ngrid = [8, 6]\n").unwrap().map.grid,
            [8, 6]
        );
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
