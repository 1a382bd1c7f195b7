//! The front door: one type a front end (the CLI, the Python binding, the live page) holds. It
//! carries the resolved settings ([`crate::resolve`]), whether to redo stages, how a recording in
//! another format is read, and where progress goes; each of its methods is one whole command, whose
//! result the front end prints or returns.
//!
//! ```no_run
//! use mrtmap_pipeline::{Overrides, Pipeline, Project};
//! # fn main() -> mrtmap_pipeline::Result<()> {
//! let project = Project::resolve(None, &Overrides::new())?;
//! let done = Pipeline::new(project).force(false).run("scan".as_ref(), "out".as_ref())?;
//! println!("{}", done.outcome.maps.len());
//! # Ok(())
//! # }
//! ```

use std::path::Path;

use mrtmap_io::{Recording, RecordingWarning, Trajectory};
use mrtmap_radiation::RadiantScene;
use mrtmap_scan::FusionReport;
use mrtmap_track::TrackReport;

use crate::coverage::Coverage;
use crate::error::Result;
use crate::maps::{GridSpec, Mark, SceneMaps};
use crate::points::{PointAnswers, PointQuery};
use crate::progress::{Progress, Silent};
use crate::report::RunDone;
use crate::settings::Project;
use crate::source::{Prepared, SourceOptions};

/// The pipeline as a front end uses it: settings, options, progress; one method per command.
pub struct Pipeline<'p> {
    project: Project,
    force: bool,
    source: SourceOptions,
    progress: &'p dyn Progress,
}

/// What [`Pipeline::fuse`] did: the recording it read (converted or not), what the recording
/// says about itself, and fusion's report.
pub struct FuseDone {
    /// The recording folder fused, and whether it was converted now or earlier.
    pub prepared: Prepared,
    /// The recording's warnings.
    pub warnings: Vec<RecordingWarning>,
    /// Fusion's report (fusion.json).
    pub report: FusionReport,
}

/// What [`Pipeline::track`] did.
pub struct TrackDone {
    /// The recording's warnings.
    pub warnings: Vec<RecordingWarning>,
    /// The trajectory written.
    pub trajectory: Trajectory,
    /// The tracker's report (track.json).
    pub report: TrackReport,
}

impl Pipeline<'static> {
    /// A pipeline with `project`'s settings (see [`Project::resolve`]), reusing unchanged stages,
    /// reporting no progress.
    pub fn new(project: Project) -> Self {
        Self {
            project,
            force: false,
            source: SourceOptions::default(),
            progress: &Silent,
        }
    }
}

impl<'p> Pipeline<'p> {
    /// Redo every stage even when its inputs have not changed.
    pub fn force(mut self, force: bool) -> Self {
        self.force = force;
        self
    }

    /// How a bag, MCAP file or database is read (topics, rig, thermal frames).
    pub fn source(mut self, source: SourceOptions) -> Self {
        self.source = source;
        self
    }

    /// Where progress goes.
    pub fn progress<'q>(self, progress: &'q dyn Progress) -> Pipeline<'q> {
        Pipeline {
            project: self.project,
            force: self.force,
            source: self.source,
            progress,
        }
    }

    /// The settings.
    pub fn project(&self) -> &Project {
        &self.project
    }

    /// `mrtmap run`: the whole pipeline on `recording` into `out` (report.html, run.json, …).
    pub fn run(&self, recording: &Path, out: &Path) -> Result<RunDone> {
        crate::report::run_recording(
            recording,
            out,
            &self.project,
            self.force,
            &self.source,
            self.progress,
        )
    }

    /// `mrtmap fuse`: `recording` (converted into `out/recording` when it is not a folder) fused
    /// into `out` (cloud.ply, fusion.json, poses.txt, frames.json).
    pub fn fuse(&self, recording: &Path, out: &Path) -> Result<FuseDone> {
        let params = self.project.fuse.params()?;
        crate::run::check_out_apart(recording, out)?;
        let prepared = crate::source::prepare(recording, out, &self.source)?;
        let rec = Recording::open(&prepared.dir)?;
        let report = crate::run::fuse_into(&rec, &params, out, self.progress)?;
        Ok(FuseDone {
            prepared,
            warnings: rec.warnings,
            report,
        })
    }

    /// `mrtmap track`: poses for `recording` from its colour and depth, into `out`
    /// (trajectory.txt, track.json).
    pub fn track(&self, recording: &Path, out: &Path) -> Result<TrackDone> {
        crate::run::check_out_apart(recording, out)?;
        let rec = Recording::open(recording)?;
        let (trajectory, report) =
            crate::run::track_into(&rec, &self.project.track.params(), out, self.progress)?;
        Ok(TrackDone {
            warnings: rec.warnings,
            trajectory,
            report,
        })
    }

    /// `mrtmap map`: the MRT map at the first of `[map] heights_m` over `[map] grid`, and the
    /// person's maps `[map] quantities` ask for, of `scene` (named `source` in the outputs), with
    /// `marks`, into `out`.
    pub fn map(
        &self,
        scene: &RadiantScene,
        source: &str,
        marks: &[Mark],
        out: &Path,
    ) -> Result<SceneMaps> {
        let m = &self.project.map;
        let spec = GridSpec {
            nx: m.grid[0],
            ny: m.grid[1],
            height_m: m.heights_m.first().copied().unwrap_or(1.1),
            margin_m: m.margin_m,
        };
        crate::maps::map_scene(scene, source, &self.project, spec, marks, out)
    }

    /// `mrtmap mrt`: the MRT (of a sphere or a person, with the sun when asked) at the query's
    /// points of `scene`, with `[mrt]`'s view factors.
    pub fn mrt(
        &self,
        scene: &RadiantScene,
        source: &str,
        query: &PointQuery,
    ) -> Result<PointAnswers> {
        crate::points::mrt_at_points(scene, source, &self.project.mrt, query)
    }

    /// `mrtmap coverage`: whether `recording` is enough for a map within ±`target_k` (2σ), and
    /// where to scan more; the coarse run goes into `out` (a temporary folder when `None`).
    pub fn coverage(
        &self,
        recording: &Path,
        out: Option<&Path>,
        target_k: f64,
    ) -> Result<Coverage> {
        crate::coverage::coverage_with(
            recording,
            out,
            &self.project,
            &self.source,
            target_k,
            self.progress,
        )
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::Overrides;

    /// The map is made with the project's settings, as resolved: `[map]` and `[mrt]` together.
    #[test]
    fn the_front_doors_map_uses_the_resolved_settings() {
        let project = Project::parse(
            "[map]\ngrid = [5, 4]\nheights_m = [1.7, 0.6]\n[mrt]\nmethod = \"montecarlo\"\nrays = 500\nreplicates = 4\n",
        )
        .unwrap();
        let mut o = Overrides::new();
        o.set("map.grid", "--grid", &[3, 3]);
        let project = Project::resolve_over(project, &o).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let scene = mrtmap_radiation::example_office();
        let maps = Pipeline::new(project)
            .map(&scene, "example", &[], dir.path())
            .unwrap();
        let s = &maps.map.summary.map;
        assert_eq!((s.grid, s.height_m, s.rays), ([3, 3], 1.7, Some(500)));
        assert!(maps.map.method.contains("500 rays"), "{}", maps.map.method);
    }
}
