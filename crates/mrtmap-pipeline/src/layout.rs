//! Where a run's files go: [`RunLayout`] names every file `mrtmap run` writes and reads in its
//! output folder, and each stage's folder is a type of its own ([`TrackDir`], [`FuseDir`],
//! [`SegmentDir`], [`MapDir`], [`ComfortDir`]), which the commands that run one stage
//! (`mrtmap track`, `fuse`, `segment`, `map`) write too. [`DemoLayout`] is `mrtmap demo`'s folder.
//! No other module spells these names. For people, the same tree is in docs/run-folder.md (a test
//! keeps the two alike).
//!
//! ```text
//! OUT/
//!   report.html             the report: maps, tables, the room in 3D; one file, nothing linked
//!   run.json                the source, each stage's time and reuse, the warnings, the settings
//!   .mrtmap-made            the entries mrtmap wrote here (a later run writes only into those)
//!   recording/              a bag, MCAP file or database converted (docs/recording.md)
//!   recording.stage.json    the conversion's fingerprint (a recording folder is read where it is)
//!   track/                  the built-in tracker, when the recording has no poses
//!     trajectory.txt        world_from_depth at the colour frames' times (TUM)
//!     track.json            what the tracker did; with groundtruth.txt, its error
//!   fuse/
//!     cloud.ply             the thermal cloud (temperature_c and temperature_std per point)
//!     fusion.json           fusion's report: frames used and skipped, clock, ICP, self-calibration
//!     poses.txt             the refined pose of each fused thermal frame's depth frame (TUM)
//!     frames.json           the fused frames, for texturing the room model
//!   segment/
//!     scene.json            the radiant scene (docs/scene-format.md)
//!     segment.json          segmentation's report: surfaces, features, furniture, warnings
//!     segments.ply          the cloud with each point's surface_id and feature_id
//!     level.json            the temperatures' absolute level, from the reference readings
//!   map-1.10m/              one per height, named by RunLayout::map_dir_name
//!     mrt_grid.csv          MRT and its ± parts at each node of the grid
//!     mrt_map.png           the heatmap with contours
//!     mrt_map.svg           the same, as vectors
//!     summary.json          the map's figures and its marked points
//!   comfort/                a person's comfort maps, when [map] quantities ask for them
//!     comfort.json          the figures, the floor by ISO 7730 category, the marked points
//!     pmv.png               per quantity (here pmv): the map as PNG, SVG and grid CSV
//!     pmv.svg
//!     pmv.csv
//!   export/                 the room for other tools, as [export] formats asks
//!     room.hbjson           per format: room.hbjson, room.xml, room.glb, room.rad
//!   validation.csv          `mrtmap validate --map OUT`: each globe against the map
//!   validation.json         the same rows, which the report's 3D view shows
//! ```
//!
//! Each stage folder also holds `stage.json`, the fingerprint of its inputs and settings that
//! lets a later run reuse it ([`crate::cache`]).
//!
//! ```text
//! mrtmap-demo/              DemoLayout
//!   simulate.json           the simulation's fingerprint
//!   recording/              the simulated scan, with truth.json (the exact MRT)
//!   run/                    a run folder, as above
//!   demo.json               ours, a globe's reading and the truth at each point; the grid's error
//! ```

use std::path::{Path, PathBuf};

use crate::settings::ExportFormat;
use crate::settings::Quantity;

/// Each stage folder's fingerprint (see [`crate::cache::Stage`]).
const STAGE_JSON: &str = "stage.json";

/// `dir/stage.json`.
pub(crate) fn stage_json_in(dir: &Path) -> PathBuf {
    dir.join(STAGE_JSON)
}

/// A run's output folder (`mrtmap run … --out OUT`): the path of each file in it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunLayout {
    root: PathBuf,
}

impl RunLayout {
    /// The run folder at `root`.
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self { root: root.into() }
    }

    /// The run folder itself.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The path of a run's file inside any run folder, `/`-separated on every platform, as the
    /// report and each map of [`crate::RunOutcome`] (its `csv`) give it: `RunLayout::name_in_run(|r|
    /// r.mrt_grid_csv(1.1))` is `map-1.10m/mrt_grid.csv`.
    pub fn name_in_run(file: impl FnOnce(&RunLayout) -> PathBuf) -> String {
        file(&RunLayout::new(""))
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join("/")
    }

    /// `report.html`.
    pub fn report_html(&self) -> PathBuf {
        self.root.join("report.html")
    }

    /// `run.json`.
    pub fn run_json(&self) -> PathBuf {
        self.root.join("run.json")
    }

    /// `recording/`: a source that is not a folder, converted (also in `mrtmap fuse`'s folder).
    pub fn recording_dir(&self) -> PathBuf {
        self.root.join("recording")
    }

    /// `recording.stage.json`: the conversion's fingerprint.
    pub fn recording_stage_json(&self) -> PathBuf {
        self.root.join("recording.stage.json")
    }

    /// The track stage's folder.
    pub fn track(&self) -> TrackDir {
        TrackDir::new(self.track_dir())
    }

    /// `track/`.
    pub fn track_dir(&self) -> PathBuf {
        self.root.join("track")
    }

    /// `track/trajectory.txt`.
    pub fn trajectory_txt(&self) -> PathBuf {
        self.track().trajectory_txt()
    }

    /// `track/track.json`.
    pub fn track_json(&self) -> PathBuf {
        self.track().track_json()
    }

    /// The fuse stage's folder.
    pub fn fuse(&self) -> FuseDir {
        FuseDir::new(self.fuse_dir())
    }

    /// `fuse/`.
    pub fn fuse_dir(&self) -> PathBuf {
        self.root.join("fuse")
    }

    /// `fuse/cloud.ply`.
    pub fn cloud_ply(&self) -> PathBuf {
        self.fuse().cloud_ply()
    }

    /// `fuse/fusion.json`.
    pub fn fusion_json(&self) -> PathBuf {
        self.fuse().fusion_json()
    }

    /// `fuse/poses.txt`.
    pub fn poses_txt(&self) -> PathBuf {
        self.fuse().poses_txt()
    }

    /// `fuse/frames.json`.
    pub fn frames_json(&self) -> PathBuf {
        self.fuse().frames_json()
    }

    /// The segment stage's folder.
    pub fn segment(&self) -> SegmentDir {
        SegmentDir::new(self.segment_dir())
    }

    /// `segment/`.
    pub fn segment_dir(&self) -> PathBuf {
        self.root.join("segment")
    }

    /// `segment/scene.json`.
    pub fn scene_json(&self) -> PathBuf {
        self.segment().scene_json()
    }

    /// `segment/segment.json`.
    pub fn segment_json(&self) -> PathBuf {
        self.segment().segment_json()
    }

    /// `segment/segments.ply`.
    pub fn segments_ply(&self) -> PathBuf {
        self.segment().segments_ply()
    }

    /// `segment/level.json`.
    pub fn level_json(&self) -> PathBuf {
        self.segment().level_json()
    }

    /// The name of the map folder at `height_m`: `map-1.10m` (centimetres, so heights a
    /// centimetre apart have folders of their own).
    pub fn map_dir_name(height_m: f64) -> String {
        format!("map-{height_m:.2}m")
    }

    /// The map stage's folder at `height_m`.
    pub fn map(&self, height_m: f64) -> MapDir {
        MapDir::new(self.map_dir(height_m))
    }

    /// `map-H.HHm/`.
    pub fn map_dir(&self, height_m: f64) -> PathBuf {
        self.root.join(Self::map_dir_name(height_m))
    }

    /// `map-H.HHm/mrt_grid.csv`.
    pub fn mrt_grid_csv(&self, height_m: f64) -> PathBuf {
        self.map(height_m).mrt_grid_csv()
    }

    /// `map-H.HHm/mrt_map.png`.
    pub fn mrt_map_png(&self, height_m: f64) -> PathBuf {
        self.map(height_m).mrt_map_png()
    }

    /// `map-H.HHm/mrt_map.svg`.
    pub fn mrt_map_svg(&self, height_m: f64) -> PathBuf {
        self.map(height_m).mrt_map_svg()
    }

    /// `map-H.HHm/summary.json`.
    pub fn summary_json(&self, height_m: f64) -> PathBuf {
        self.map(height_m).summary_json()
    }

    /// The comfort stage's folder.
    pub fn comfort(&self) -> ComfortDir {
        ComfortDir::new(self.comfort_dir())
    }

    /// `comfort/`.
    pub fn comfort_dir(&self) -> PathBuf {
        self.root.join("comfort")
    }

    /// `comfort/comfort.json`.
    pub fn comfort_json(&self) -> PathBuf {
        self.comfort().comfort_json()
    }

    /// `comfort/<quantity>.png`.
    pub fn comfort_png(&self, q: Quantity) -> PathBuf {
        self.comfort().png(q)
    }

    /// `comfort/<quantity>.svg`.
    pub fn comfort_svg(&self, q: Quantity) -> PathBuf {
        self.comfort().svg(q)
    }

    /// `comfort/<quantity>.csv`.
    pub fn comfort_csv(&self, q: Quantity) -> PathBuf {
        self.comfort().csv(q)
    }

    /// `export/`.
    pub fn export_dir(&self) -> PathBuf {
        self.root.join("export")
    }

    /// `export/room.<extension>`: the room in `format`.
    pub fn export_file(&self, format: ExportFormat) -> PathBuf {
        self.export_dir()
            .join(format!("room.{}", format.extension()))
    }

    /// `validation.csv` (`mrtmap validate`).
    pub fn validation_csv(&self) -> PathBuf {
        self.root.join("validation.csv")
    }

    /// `validation.json` (`mrtmap validate`; the report shows its globes).
    pub fn validation_json(&self) -> PathBuf {
        self.root.join("validation.json")
    }

    /// `.mrtmap-made`: the entries mrtmap wrote here, which a later run may write again
    /// ([`mrtmap_io::claim_dir`]).
    pub fn made_list(&self) -> PathBuf {
        self.root.join(mrtmap_io::MADE)
    }

    /// The entries a run with maps at `heights_m` may write at the top of its folder: what it
    /// claims there ([`mrtmap_io::claim_dir`]) before writing.
    pub fn top_names(heights_m: &[f64]) -> Vec<String> {
        let l = RunLayout::new("");
        let mut paths = vec![
            l.report_html(),
            l.run_json(),
            l.recording_dir(),
            l.recording_stage_json(),
            l.track_dir(),
            l.fuse_dir(),
            l.segment_dir(),
            l.comfort_dir(),
            l.export_dir(),
            l.validation_csv(),
            l.validation_json(),
        ];
        paths.extend(heights_m.iter().map(|&h| l.map_dir(h)));
        paths
            .iter()
            .filter_map(|p| p.components().next())
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect()
    }
}

/// The track stage's folder (`track/` of a run, or `mrtmap track --out`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TrackDir {
    dir: PathBuf,
}

impl TrackDir {
    /// The folder at `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// `trajectory.txt`: world_from_depth at the colour frames' times (TUM).
    pub fn trajectory_txt(&self) -> PathBuf {
        mrtmap_io::RecordingFile::Trajectory.path_in(&self.dir)
    }

    /// `track.json`: what the tracker did.
    pub fn track_json(&self) -> PathBuf {
        self.dir.join("track.json")
    }

    /// `stage.json`.
    pub fn stage_json(&self) -> PathBuf {
        stage_json_in(&self.dir)
    }

    /// What the stage must leave for a later run to reuse it.
    pub fn outputs(&self) -> Vec<PathBuf> {
        vec![self.trajectory_txt(), self.track_json()]
    }
}

/// The fuse stage's folder (`fuse/` of a run, or `mrtmap fuse --out`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FuseDir {
    dir: PathBuf,
}

impl FuseDir {
    /// The folder at `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// `cloud.ply`: the thermal cloud.
    pub fn cloud_ply(&self) -> PathBuf {
        self.dir.join("cloud.ply")
    }

    /// `fusion.json`: fusion's report.
    pub fn fusion_json(&self) -> PathBuf {
        self.dir.join("fusion.json")
    }

    /// `poses.txt`: the refined trajectory (TUM).
    pub fn poses_txt(&self) -> PathBuf {
        self.dir.join("poses.txt")
    }

    /// `frames.json`: the fused frames.
    pub fn frames_json(&self) -> PathBuf {
        self.dir.join("frames.json")
    }

    /// `stage.json`.
    pub fn stage_json(&self) -> PathBuf {
        stage_json_in(&self.dir)
    }

    /// What the stage must leave for a later run to reuse it.
    pub fn outputs(&self) -> Vec<PathBuf> {
        vec![
            self.cloud_ply(),
            self.fusion_json(),
            self.poses_txt(),
            self.frames_json(),
        ]
    }
}

/// The segment stage's folder (`segment/` of a run, or `mrtmap segment --out`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SegmentDir {
    dir: PathBuf,
}

impl SegmentDir {
    /// The folder at `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// `scene.json`: the radiant scene.
    pub fn scene_json(&self) -> PathBuf {
        self.dir.join("scene.json")
    }

    /// `segment.json`: segmentation's report.
    pub fn segment_json(&self) -> PathBuf {
        self.dir.join("segment.json")
    }

    /// `segments.ply`: the cloud with each point's surface and feature.
    pub fn segments_ply(&self) -> PathBuf {
        self.dir.join("segments.ply")
    }

    /// `level.json`: the temperatures' absolute level.
    pub fn level_json(&self) -> PathBuf {
        self.dir.join("level.json")
    }

    /// `stage.json`.
    pub fn stage_json(&self) -> PathBuf {
        stage_json_in(&self.dir)
    }

    /// What the stage must leave for a later run to reuse it.
    pub fn outputs(&self) -> Vec<PathBuf> {
        vec![
            self.scene_json(),
            self.segment_json(),
            self.segments_ply(),
            self.level_json(),
        ]
    }
}

/// A map's folder (`map-H.HHm/` of a run, or `mrtmap map --out`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MapDir {
    dir: PathBuf,
}

impl MapDir {
    /// The folder at `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// `mrt_grid.csv`: MRT and its ± parts at each node.
    pub fn mrt_grid_csv(&self) -> PathBuf {
        self.dir.join("mrt_grid.csv")
    }

    /// `mrt_map.png`: the heatmap.
    pub fn mrt_map_png(&self) -> PathBuf {
        self.dir.join("mrt_map.png")
    }

    /// `mrt_map.svg`: the heatmap as vectors.
    pub fn mrt_map_svg(&self) -> PathBuf {
        self.dir.join("mrt_map.svg")
    }

    /// `summary.json`: the map's figures.
    pub fn summary_json(&self) -> PathBuf {
        self.dir.join("summary.json")
    }

    /// `stage.json`.
    pub fn stage_json(&self) -> PathBuf {
        stage_json_in(&self.dir)
    }

    /// What the stage must leave for a later run to reuse it.
    pub fn outputs(&self) -> Vec<PathBuf> {
        vec![self.summary_json(), self.mrt_map_png(), self.mrt_grid_csv()]
    }
}

/// A person's comfort maps (`comfort/` of a run; `mrtmap map --quantity` writes them beside the
/// MRT map).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ComfortDir {
    dir: PathBuf,
}

impl ComfortDir {
    /// The folder at `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// `comfort.json`: the figures.
    pub fn comfort_json(&self) -> PathBuf {
        self.dir.join("comfort.json")
    }

    /// `<quantity>.png`.
    pub fn png(&self, q: Quantity) -> PathBuf {
        self.dir.join(format!("{}.png", q.name()))
    }

    /// `<quantity>.svg`.
    pub fn svg(&self, q: Quantity) -> PathBuf {
        self.dir.join(format!("{}.svg", q.name()))
    }

    /// `<quantity>.csv`.
    pub fn csv(&self, q: Quantity) -> PathBuf {
        self.dir.join(format!("{}.csv", q.name()))
    }

    /// `stage.json`.
    pub fn stage_json(&self) -> PathBuf {
        stage_json_in(&self.dir)
    }

    /// What the stage must leave for a later run to reuse it: each quantity's PNG and
    /// comfort.json.
    pub fn outputs(&self, quantities: &[Quantity]) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = quantities.iter().map(|q| self.png(*q)).collect();
        files.push(self.comfort_json());
        files
    }
}

/// `mrtmap demo`'s folder: the simulated recording, the run on it and the comparison.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DemoLayout {
    root: PathBuf,
}

impl DemoLayout {
    /// The demo folder at `root`.
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self { root: root.into() }
    }

    /// The demo folder itself.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// `simulate.json`: the simulation's fingerprint.
    pub fn simulate_json(&self) -> PathBuf {
        self.root.join("simulate.json")
    }

    /// `recording/`: the simulated scan.
    pub fn recording_dir(&self) -> PathBuf {
        self.root.join("recording")
    }

    /// `recording/truth.json`: the simulation's exact truth.
    pub fn truth_json(&self) -> PathBuf {
        self.recording_dir().join("truth.json")
    }

    /// `run/`: the run on the recording.
    pub fn run(&self) -> RunLayout {
        RunLayout::new(self.root.join("run"))
    }

    /// `demo.json`: ours and a globe's reading against the truth.
    pub fn demo_json(&self) -> PathBuf {
        self.root.join("demo.json")
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// The names the docs give (docs/run-folder.md, the module doc above) and the README's
    /// `map-1.10m` are the ones the methods give.
    #[test]
    fn the_methods_give_the_documented_names() {
        let r = RunLayout::new("OUT");
        let named = |p: PathBuf| {
            p.strip_prefix("OUT")
                .unwrap()
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect::<Vec<_>>()
                .join("/")
        };
        let cases = [
            (r.report_html(), "report.html"),
            (r.run_json(), "run.json"),
            (r.recording_dir(), "recording"),
            (r.recording_stage_json(), "recording.stage.json"),
            (r.trajectory_txt(), "track/trajectory.txt"),
            (r.track_json(), "track/track.json"),
            (r.track().stage_json(), "track/stage.json"),
            (r.cloud_ply(), "fuse/cloud.ply"),
            (r.fusion_json(), "fuse/fusion.json"),
            (r.poses_txt(), "fuse/poses.txt"),
            (r.frames_json(), "fuse/frames.json"),
            (r.fuse().stage_json(), "fuse/stage.json"),
            (r.scene_json(), "segment/scene.json"),
            (r.segment_json(), "segment/segment.json"),
            (r.segments_ply(), "segment/segments.ply"),
            (r.level_json(), "segment/level.json"),
            (r.mrt_grid_csv(1.1), "map-1.10m/mrt_grid.csv"),
            (r.mrt_map_png(1.1), "map-1.10m/mrt_map.png"),
            (r.mrt_map_svg(1.1), "map-1.10m/mrt_map.svg"),
            (r.summary_json(1.1), "map-1.10m/summary.json"),
            (r.map(0.6).stage_json(), "map-0.60m/stage.json"),
            (r.comfort_json(), "comfort/comfort.json"),
            (r.comfort_png(Quantity::Pmv), "comfort/pmv.png"),
            (r.comfort_svg(Quantity::Pmv), "comfort/pmv.svg"),
            (r.comfort_csv(Quantity::Pmv), "comfort/pmv.csv"),
            (r.export_file(ExportFormat::Gltf), "export/room.glb"),
            (r.validation_csv(), "validation.csv"),
            (r.validation_json(), "validation.json"),
        ];
        let doc = include_str!("../../../docs/run-folder.md");
        for (path, name) in cases {
            assert_eq!(named(path), name);
            let file = name.rsplit('/').next().unwrap();
            assert!(
                doc.contains(file),
                "docs/run-folder.md does not name {file}"
            );
        }
        assert_eq!(
            RunLayout::name_in_run(|r| r.mrt_grid_csv(1.7)),
            "map-1.70m/mrt_grid.csv"
        );
        assert_eq!(
            RunLayout::name_in_run(|r| r.comfort_csv(Quantity::MrtSeated)),
            "comfort/mrt_seated.csv"
        );
        let d = DemoLayout::new("mrtmap-demo");
        assert_eq!(
            d.truth_json(),
            Path::new("mrtmap-demo/recording/truth.json")
        );
        assert_eq!(
            d.run().report_html(),
            Path::new("mrtmap-demo/run/report.html")
        );
        assert_eq!(d.demo_json(), Path::new("mrtmap-demo/demo.json"));
        assert_eq!(d.simulate_json(), Path::new("mrtmap-demo/simulate.json"));
    }

    /// docs/run-folder.md shows the module doc's trees, line for line.
    #[test]
    fn the_docs_show_the_module_docs_trees() {
        let trees = |text: &str, prefix: &str| -> Vec<String> {
            let mut out = Vec::new();
            let mut inside = false;
            for line in text.lines() {
                let Some(l) = line.strip_prefix(prefix) else {
                    continue;
                };
                if l.starts_with("```") {
                    inside = !inside;
                } else if inside {
                    out.push(l.trim_end().to_string());
                }
            }
            out
        };
        let module = trees(include_str!("layout.rs"), "//! ");
        let doc = trees(include_str!("../../../docs/run-folder.md"), "");
        assert!(!module.is_empty());
        assert_eq!(module, doc);
    }
}
