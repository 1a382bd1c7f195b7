//! Settings resolved once, for every front end: the defaults, then project.toml (or Python's
//! `config=` dict), then the flags. A flag is an override of one project.toml key (`--rays` is
//! `mrt.rays`); a flag not given leaves the file's value. Steps:
//!
//! 1. The base: [`Project::default`], or project.toml read by [`Project::load`] (its errors name
//!    the file and line), or a project a front end built (Python's dict).
//! 2. The overrides, in the order given: each is set at its key in the base written out as TOML
//!    and the whole read back, so that a flag is checked exactly as the same key in the file would
//!    be; an error names the flag and its value.
//! 3. Named points (`--mark`) replace the file's point of the same name.
//! 4. [`Project::check`]: what can be checked before any stage runs.

use std::path::Path;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::settings::{DirectionChoice, MethodChoice, PointEntry, Project};

/// One flag: a project.toml key (`"mrt.rays"`) and its value, named by the flag that gave it.
#[derive(Clone, Debug, PartialEq)]
struct Override {
    key: String,
    flag: String,
    value: std::result::Result<toml::Value, String>,
}

/// Flags over project.toml: build with [`Overrides::set`] for each flag given, then
/// [`Project::resolve`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Overrides {
    items: Vec<Override>,
    points: Vec<PointEntry>,
}

impl Overrides {
    /// No overrides: the file's settings (or the defaults) as they are.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets `key` (project.toml's, dotted: `"map.grid"`) to `value`, given by `flag` (`"--grid"`,
    /// or Python's keyword).
    pub fn set<T: Serialize + ?Sized>(&mut self, key: &str, flag: &str, value: &T) -> &mut Self {
        self.items.push(Override {
            key: key.to_string(),
            flag: flag.to_string(),
            value: toml::Value::try_from(value).map_err(|e| e.to_string()),
        });
        self
    }

    /// [`Overrides::set`] when the flag was given (`Some`).
    pub fn set_some<T: Serialize>(
        &mut self,
        key: &str,
        flag: &str,
        value: Option<&T>,
    ) -> &mut Self {
        if let Some(v) = value {
            self.set(key, flag, v);
        }
        self
    }

    /// A named point (`--mark NAME=X,Y,Z`): it replaces the file's point of that name.
    pub fn point(&mut self, p: PointEntry) -> &mut Self {
        self.points.push(p);
        self
    }

    /// Whether no flag was given.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty() && self.points.is_empty()
    }

    /// `base` with the overrides applied (not yet checked: see [`Project::resolve`]).
    pub fn apply(&self, base: Project) -> Result<Project> {
        let mut p = base;
        for o in &self.items {
            let value = o.value.clone().map_err(|e| {
                Error::setting(
                    o.flag.clone(),
                    format!("cannot be written as the setting `{}`: {e}", o.key),
                )
            })?;
            let mut table = toml::Table::try_from(&p).map_err(|e| {
                Error::setting("the settings", format!("cannot be written as TOML: {e}"))
            })?;
            set_key(&mut table, &o.key, value.clone());
            p = toml::Value::Table(table)
                .try_into()
                .map_err(|e: toml::de::Error| {
                    Error::setting(
                        format!("{} {value}", o.flag),
                        format!(
                            "is refused as [{}] {}: {}",
                            section(&o.key),
                            leaf(&o.key),
                            e.message().trim()
                        ),
                    )
                })?;
        }
        for q in &self.points {
            p.points.retain(|x| x.name != q.name);
            p.points.push(q.clone());
        }
        Ok(p)
    }
}

fn section(key: &str) -> &str {
    key.rsplit_once('.').map_or("", |(s, _)| s)
}

fn leaf(key: &str) -> &str {
    key.rsplit_once('.').map_or(key, |(_, l)| l)
}

/// Sets the dotted `key` in `table`, making the sections on the way.
fn set_key(table: &mut toml::Table, key: &str, value: toml::Value) {
    match key.split_once('.') {
        None => {
            table.insert(key.to_string(), value);
        }
        Some((head, rest)) => {
            let sub = table
                .entry(head.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            if !sub.is_table() {
                *sub = toml::Value::Table(toml::Table::new());
            }
            if let toml::Value::Table(t) = sub {
                set_key(t, rest, value);
            }
        }
    }
}

impl Project {
    /// The settings of a run: the defaults, then `file` (project.toml) when given, then the
    /// `flags`; checked.
    pub fn resolve(file: Option<&Path>, flags: &Overrides) -> Result<Self> {
        let base = match file {
            Some(f) => Self::load(f)?,
            None => Self::default(),
        };
        Self::resolve_over(base, flags)
    }

    /// [`Project::resolve`] over a project a front end built (Python's `config=` dict).
    pub fn resolve_over(base: Self, flags: &Overrides) -> Result<Self> {
        let p = flags.apply(base)?;
        p.check()?;
        Ok(p)
    }
}

/// `[mrt]`'s flags (`map`, `mrt`): each overrides its key of project.toml when given.
#[derive(Clone, Debug, Default, PartialEq, clap::Args)]
pub struct MrtFlags {
    /// View-factor method: exact solid angles where valid and Monte Carlo with occluders or where
    /// surfaces hide each other (auto), exact solid angles only (exact), or Monte Carlo ray
    /// tracing (montecarlo). Default: [mrt] method, else auto.
    #[arg(long, value_enum)]
    pub method: Option<MethodChoice>,
    /// Monte Carlo: rays per point. Default: [mrt] rays, else 20000.
    #[arg(long)]
    pub rays: Option<usize>,
    /// Monte Carlo: random seed (results are reproducible from it). Default: [mrt] seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Monte Carlo: direction set (randomly rotated spherical Fibonacci lattices converge faster
    /// than independent random directions). Default: [mrt] directions, else fibonacci.
    #[arg(long, value_enum)]
    pub directions: Option<DirectionChoice>,
    /// Monte Carlo: independent replicates the standard errors come from. Default: [mrt]
    /// replicates, else 8.
    #[arg(long)]
    pub replicates: Option<usize>,
    /// Answer at points the scene does not enclose (a missing wall, floor or ceiling leaves part
    /// of the view empty: ΣF short of 1) instead of refusing them; ΣF is printed with each point.
    #[arg(long)]
    pub allow_open: bool,
    /// How well a point is placed relative to the room's surfaces (m, one standard deviation): the
    /// MRT's gradient times it joins the MRT's ± (near a cold window it dominates; not yet a
    /// person's or a plane's); 0 leaves it out. Default: [mrt] placement_std_m, else 0.01.
    #[arg(long)]
    pub placement_std_m: Option<f64>,
}

impl MrtFlags {
    /// The flags given, as overrides.
    pub fn add_to(&self, o: &mut Overrides) {
        o.set_some("mrt.method", "--method", self.method.as_ref())
            .set_some("mrt.rays", "--rays", self.rays.as_ref())
            .set_some("mrt.seed", "--seed", self.seed.as_ref())
            .set_some("mrt.directions", "--directions", self.directions.as_ref())
            .set_some("mrt.replicates", "--replicates", self.replicates.as_ref())
            .set_some(
                "mrt.placement_std_m",
                "--placement-std-m",
                self.placement_std_m.as_ref(),
            );
        if self.allow_open {
            o.set("mrt.allow_open", "--allow-open", &true);
        }
    }

    /// `[mrt]` with these flags over the defaults (commands without a project.toml).
    pub fn section(&self) -> Result<crate::MrtSection> {
        let mut o = Overrides::new();
        self.add_to(&mut o);
        Ok(o.apply(Project::default())?.mrt)
    }
}

/// `[fuse]`'s flags (`run`, `fuse`, `coverage`): each overrides its key of project.toml when
/// given; the defaults are [`crate::settings::FuseSection`]'s.
#[derive(Clone, Debug, Default, PartialEq, clap::Args)]
pub struct FuseFlags {
    /// Voxel size (m) ([fuse] voxel_m).
    #[arg(long = "voxel-m")]
    pub voxel_m: Option<f64>,
    /// Refine poses by point-to-plane ICP against the map built so far ([fuse] icp).
    #[arg(long, value_name = "on|off", value_parser = crate::parse::parse_on_off)]
    pub icp: Option<bool>,
    /// Largest time between a thermal frame and the depth frame it takes (ms); at least 0.55 of
    /// the depth frames' interval is used, so every thermal frame finds one at any depth rate
    /// ([fuse] sync_tolerance_ms).
    #[arg(long = "sync-tolerance-ms")]
    pub sync_tolerance_ms: Option<f64>,
    /// Use every N-th depth pixel in each direction; 0: about one depth point per thermal pixel
    /// (the cameras' focal lengths' ratio, rounded: 3 for a 640×480 D435 beside a Lepton)
    /// ([fuse] depth_stride).
    #[arg(long)]
    pub depth_stride: Option<u32>,
    /// Radiometric self-calibration: estimate and remove each frame's offset (flat-field
    /// corrections, drift) and the vignetting from the frames' overlaps ([fuse] self_calibrate).
    #[arg(long, value_name = "on|off", value_parser = crate::parse::parse_on_off)]
    pub self_calibrate: Option<bool>,
    /// What to add to the thermal stamps to put them on the depth camera's clock: auto (rig.toml's
    /// `[thermal] time_offset_s`, else estimated from the scan), estimate, off, or milliseconds
    /// (-70: frames stamped 70 ms after their exposure) ([fuse] time_offset).
    #[arg(long, allow_hyphen_values = true)]
    pub time_offset: Option<String>,
}

impl FuseFlags {
    /// The flags given, as overrides.
    pub fn add_to(&self, o: &mut Overrides) {
        o.set_some("fuse.voxel_m", "--voxel-m", self.voxel_m.as_ref())
            .set_some("fuse.icp", "--icp", self.icp.as_ref())
            .set_some(
                "fuse.sync_tolerance_ms",
                "--sync-tolerance-ms",
                self.sync_tolerance_ms.as_ref(),
            )
            .set_some(
                "fuse.depth_stride",
                "--depth-stride",
                self.depth_stride.as_ref(),
            )
            .set_some(
                "fuse.self_calibrate",
                "--self-calibrate",
                self.self_calibrate.as_ref(),
            )
            .set_some(
                "fuse.time_offset",
                "--time-offset",
                self.time_offset.as_ref(),
            );
    }
}

/// `[segment]`'s flags (`run`, `segment`): each overrides its key of project.toml when given;
/// the defaults are [`crate::settings::SegmentSection`]'s.
#[derive(Clone, Debug, Default, PartialEq, clap::Args)]
pub struct SegmentFlags {
    /// A texel belongs to a feature when it differs from its surface's background by more (K)
    /// ([segment] feature_threshold_k).
    #[arg(long)]
    pub feature_threshold_k: Option<f64>,
    /// Smallest feature (m²) ([segment] feature_min_area_m2).
    #[arg(long = "feature-min-area-m2")]
    pub feature_min_area_m2: Option<f64>,
    /// Texel of each surface's temperature raster in scene.json (m), so that a stratified wall
    /// radiates as it is; 0 for one temperature per surface ([segment] raster_m).
    #[arg(long = "raster-m")]
    pub raster_m: Option<f64>,
    /// Do not label features by the recording's instance masks ([segment] masks = false).
    #[arg(long)]
    pub no_masks: bool,
}

impl SegmentFlags {
    /// The flags given, as overrides.
    pub fn add_to(&self, o: &mut Overrides) {
        o.set_some(
            "segment.feature_threshold_k",
            "--feature-threshold-k",
            self.feature_threshold_k.as_ref(),
        )
        .set_some(
            "segment.feature_min_area_m2",
            "--feature-min-area-m2",
            self.feature_min_area_m2.as_ref(),
        )
        .set_some("segment.raster_m", "--raster-m", self.raster_m.as_ref())
        .set_some(
            "segment.masks",
            "--no-masks",
            self.no_masks.then_some(&false),
        );
    }
}

/// `[track]`'s flags (`run`, `track`): each overrides its key of project.toml when given; the
/// defaults are [`crate::settings::TrackSection`]'s.
#[derive(Clone, Debug, Default, PartialEq, clap::Args)]
pub struct TrackFlags {
    /// Do not look for loop closures ([track] loop_closure = false).
    #[arg(long)]
    pub no_loops: bool,
    /// Leave the recording's gyro (imu.txt) out of the prediction ([track] use_imu = false).
    #[arg(long)]
    pub no_imu: bool,
    /// FAST corner threshold (grey levels); lower finds more corners on weak texture ([track]
    /// fast_threshold).
    #[arg(long)]
    pub fast_threshold: Option<u8>,
}

impl TrackFlags {
    /// The flags given, as overrides.
    pub fn add_to(&self, o: &mut Overrides) {
        o.set_some(
            "track.loop_closure",
            "--no-loops",
            self.no_loops.then_some(&false),
        )
        .set_some("track.use_imu", "--no-imu", self.no_imu.then_some(&false))
        .set_some(
            "track.fast_threshold",
            "--fast-threshold",
            self.fast_threshold.as_ref(),
        );
    }
}

#[cfg(test)]
mod tests {
    use serde_json::Value;

    use super::*;

    /// Every key of every section, each away from its default (the sun both by angle and by
    /// time: parsed, not checked).
    const EVERY_KEY: &str = r#"
[map]
grid = [7, 5]
heights_m = [0.6, 1.7]
margin_m = 0.25
quantities = ["mrt", "pmv"]
[[points]]
name = "desk"
xyz = [1.0, 2.0, 1.1]
frame = "scan"
[air]
temperature_c = 23.5
speed_m_s = 0.3
[fuse]
voxel_m = 0.05
icp = false
sync_tolerance_ms = 35.0
depth_stride = 3
self_calibrate = false
time_offset = "off"
[track]
mode = "always"
loop_closure = false
use_imu = false
fast_threshold = 20
[segment]
feature_threshold_k = 0.5
feature_min_area_m2 = 0.1
raster_m = 0.3
masks = false
texture = false
[room]
origin_corner = 2
[comfort]
posture = "standing"
facing_deg = 90.0
air_temperature_c = 22.0
air_temperature_profile = [[0.1, 21.0], [1.7, 23.0]]
air_speed_m_s = 0.2
relative_humidity_pct = 40.0
met = 1.4
clo = 1.0
[[references]]
label = "window"
xyz = [4.2, 1.8, 1.5]
temperature_c = 11.5
std_k = 0.1
frame = "scan"
emissivity = 0.84
[mrt]
method = "montecarlo"
rays = 2000
seed = 7
directions = "random"
replicates = 4
allow_open = true
placement_std_m = 0.02
[export]
formats = ["hbjson", "rad"]
max_points = 5000
[emissivity]
std = 0.05
by_label = { window = 0.8 }
by_id = { "wall-1" = 0.9 }
[sun]
altitude_deg = 30.0
azimuth_deg = 10.0
date_time = "2026-01-15T10:30:00Z"
latitude_deg = 40.7
longitude_deg = -74.0
north_deg = 15.0
epw = "weather.epw"
dni_w_m2 = 700.0
transmittance = 0.6
floor_reflectance = 0.3
asw = 0.5
"#;

    /// (dotted key, value) of every leaf of `v` (arrays and maps of ids are leaves).
    fn leaves(v: &Value, prefix: &str, out: &mut Vec<(String, Value)>) {
        match v {
            Value::Object(m) if !prefix.ends_with("by_label") && !prefix.ends_with("by_id") => {
                for (k, x) in m {
                    let key = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    leaves(x, &key, out);
                }
            }
            _ => out.push((prefix.to_string(), v.clone())),
        }
    }

    fn keys_of(p: &Project) -> Vec<(String, Value)> {
        let mut out = Vec::new();
        leaves(&serde_json::to_value(p).unwrap(), "", &mut out);
        out
    }

    #[test]
    fn every_key_resolves_default_then_file_then_flag() {
        let defaults = Project::default();
        let file = Project::parse(EVERY_KEY).unwrap();
        let default_keys = keys_of(&defaults);
        let file_keys = keys_of(&file);
        // The fixture holds every key there is (a new key must join it), each away from its
        // default: the file wins over the defaults everywhere.
        for (key, d) in &default_keys {
            let f = file_keys.iter().find(|(k, _)| k == key);
            let f = f.unwrap_or_else(|| panic!("EVERY_KEY lacks `{key}`"));
            assert_ne!(&f.1, d, "EVERY_KEY sets `{key}` to its default");
        }
        // A flag wins over the file: each key set back to its default by a flag.
        for (key, d) in default_keys
            .iter()
            .filter(|(k, d)| !d.is_null() && k != "points" && k != "references")
        {
            let mut o = Overrides::new();
            o.set(key, "--flag", d);
            let got = keys_of(&o.apply(file.clone()).unwrap());
            for ((k, g), (_, f)) in got.iter().zip(&file_keys) {
                let want = if k == key { d } else { f };
                assert_eq!(g, want, "after a flag for `{key}`, `{k}`");
            }
        }
        // Keys without a default: a flag sets them over the defaults.
        for (key, f) in file_keys
            .iter()
            .filter(|(k, _)| default_keys.iter().any(|(d, v)| d == k && v.is_null()))
        {
            let mut o = Overrides::new();
            o.set(key, "--flag", f);
            let got = keys_of(&o.apply(Project::default()).unwrap());
            let g = &got.iter().find(|(k, _)| k == key).unwrap().1;
            assert_eq!(g, f, "`{key}`");
        }
    }

    #[test]
    fn no_flag_leaves_the_file_as_it_is() {
        let file = Project::parse(EVERY_KEY).unwrap();
        assert_eq!(Overrides::new().apply(file.clone()).unwrap(), file);
        let mut o = Overrides::new();
        MrtFlags::default().add_to(&mut o);
        assert!(o.is_empty());
        assert_eq!(o.apply(file.clone()).unwrap().mrt, file.mrt);
    }

    #[test]
    fn the_mrt_flags_override_only_what_they_give() {
        let file = Project::parse("[mrt]\nmethod = \"montecarlo\"\nrays = 2000\n").unwrap();
        let mut o = Overrides::new();
        MrtFlags {
            seed: Some(9),
            ..MrtFlags::default()
        }
        .add_to(&mut o);
        let p = Project::resolve_over(file, &o).unwrap();
        assert_eq!(p.mrt.method, MethodChoice::Montecarlo);
        assert_eq!((p.mrt.rays, p.mrt.seed), (2000, 9));
    }

    #[test]
    fn a_bad_flag_is_named_with_its_value() {
        let mut o = Overrides::new();
        o.set("map.margin_m", "--margin-m", &"wide");
        let e = o.apply(Project::default()).unwrap_err().to_string();
        assert!(
            e.contains("--margin-m") && e.contains("wide") && e.contains("[map] margin_m"),
            "{e}"
        );
        // Checked as the file's key is: a flag out of range is refused by the same check.
        let mut o = Overrides::new();
        o.set("mrt.rays", "--rays", &0usize);
        let e = Project::resolve(None, &o).unwrap_err().to_string();
        assert!(e.contains("--rays 0"), "{e}");
    }

    #[test]
    fn a_mark_replaces_the_files_point_of_its_name() {
        let file = Project::parse(EVERY_KEY).unwrap();
        let mut o = Overrides::new();
        o.point(PointEntry {
            name: "desk".into(),
            xyz: [2.0, 2.0, 1.1],
            frame: crate::settings::PointFrame::Room,
        });
        let p = o.apply(file).unwrap();
        assert_eq!(p.points.len(), 1);
        assert_eq!(p.points[0].xyz, [2.0, 2.0, 1.1]);
    }
}
