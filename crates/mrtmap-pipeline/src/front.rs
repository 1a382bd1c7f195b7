//! The front door: one type a front end (the CLI, the Python binding, the live page) holds. It
//! carries the resolved settings ([`crate::resolve`]), whether to redo stages, how a recording in
//! another format is read, and where progress goes; each of its methods is one whole command, whose
//! result the front end prints or returns.
//!
//! ```no_run
//! use mrtmap_pipeline::{Overrides, Pipeline, Project};
//! # fn main() -> Result<(), mrtmap_pipeline::Error> {
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
use mrtmap_scan::segment::SegmentReport;
use mrtmap_track::TrackReport;

use crate::coverage::Coverage;
use crate::error::{Error, Result};
use crate::layout::TrackDir;
use crate::maps::{GridSpec, Mark, SceneMaps};
use crate::points::{PointAnswers, PointQuery};
use crate::progress::{Progress, Silent};
use crate::report::RunDone;
use crate::run::SegmentJob;
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
    /// The voxel size fused at (m).
    pub voxel_m: f64,
}

impl FuseDone {
    /// What `mrtmap fuse` prints (the warnings apart): the conversion, the frames fused, the clock,
    /// the poses dropped, the frames skipped, the depth points, ICP, the files written in `out`.
    pub fn lines(&self, recording: &Path, out: &Path) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(c) = &self.prepared.conversion {
            lines.extend(c.lines());
        } else if self.prepared.reused {
            lines.push(format!(
                "using {} (converted earlier from {})",
                self.prepared.dir.display(),
                recording.display()
            ));
        }
        let r = &self.report;
        lines.push(format!(
            "fused {} of {} thermal frames into {} voxels of {} m in {:.1} s ({:.0} frames/s)",
            r.used_frames,
            r.thermal_frames,
            r.voxels,
            self.voxel_m,
            r.timing_s.total,
            r.frames_per_second
        ));
        lines.push(format!("  {}", r.clock.describe()));
        for line in r.pose_check.jump_lines() {
            lines.push(format!("  warning: {line}"));
        }
        if r.pose_check.dropped > 0 {
            lines.push(format!(
                "  dropped {} of {} poses that jumped away from their neighbours' motion and back (the largest {:.2} m)",
                r.pose_check.dropped,
                r.pose_check.poses,
                r.pose_check
                    .examples
                    .iter()
                    .fold(0.0f64, |m, d| m.max(d.off_m))
            ));
        }
        for (why, n) in &r.skipped {
            lines.push(format!("  skipped {n} frames: {why}"));
        }
        for p in &r.problems {
            lines.push(format!("  problem: {p}"));
        }
        let o = &r.observations;
        lines.push(format!(
            "  depth points: {} kept, {} outside the thermal view, {} hidden from it, {} grazing, {} on strong thermal edges",
            o.kept, o.outside, o.occluded, o.grazing, o.edge
        ));
        if r.icp.enabled {
            lines.push(format!(
                "  ICP: {} of {} refinements accepted (mean fitness {:.2}, inlier RMSE {:.1} mm); final correction {:.1} cm, {:.2}°",
                r.icp.accepted,
                r.icp.attempted,
                r.icp.mean_fitness,
                r.icp.mean_inlier_rmse_m * 1e3,
                r.icp.final_correction_m * 100.0,
                r.icp.final_correction_deg
            ));
            for (why, n) in &r.icp.rejected {
                lines.push(format!("    rejected {n}: {why}"));
            }
        }
        lines.push(format!(
            "wrote cloud.ply, fusion.json, poses.txt in {}",
            out.display()
        ));
        lines
    }
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

impl TrackDone {
    /// What `mrtmap track` prints (the warnings apart): frames tracked, corners and inliers, the
    /// error against groundtruth.txt when there is one, the trajectory written in `out`.
    pub fn lines(&self, out: &Path) -> Vec<String> {
        let r = &self.report;
        let mut lines = vec![
            format!(
                "tracked {} of {} colour frames in {:.1} s: {} keyframes, {} loop closures accepted of {} tried, {} frames lost, {} found again, {} placed by depth alone",
                r.tracked,
                r.frames,
                r.seconds,
                r.keyframes,
                r.loops_accepted,
                r.loops_tried,
                r.lost,
                r.relocalised,
                r.depth_only
            ),
            format!(
                "  {:.0} corners per frame, {:.0} inliers per tracked frame, reprojection {:.2} px; {} frames without depth near in time; {}",
                r.mean_corners,
                r.mean_inliers,
                r.mean_reprojection_px,
                r.unsynced,
                if r.gyro_samples > 0 {
                    format!(
                        "rotation predicted from {} gyro samples (imu.txt)",
                        r.gyro_samples
                    )
                } else {
                    "no gyro: constant-velocity prediction".to_string()
                }
            ),
        ];
        if let Some(e) = r.accuracy {
            lines.push(format!(
                "  against groundtruth.txt ({} poses): ATE RMSE {:.1} mm (max {:.1} mm), {:.2}° after alignment; frame to frame {:.2} mm, {:.3}°; over {:.2} s: {:.1} mm, {:.2}° (RMSE)",
                e.poses,
                e.ate_rmse_m * 1000.0,
                e.ate_max_m * 1000.0,
                e.ate_rotation_rmse_deg,
                e.rpe_translation_rmse_m * 1000.0,
                e.rpe_rotation_rmse_deg,
                e.drift_span_s,
                e.drift_translation_rmse_m * 1000.0,
                e.drift_rotation_rmse_deg
            ));
        }
        lines.push(format!(
            "wrote {} poses to {}",
            self.trajectory.len(),
            TrackDir::new(out).trajectory_txt().display()
        ));
        lines
    }
}

/// What [`Pipeline::segment`] did: segmentation's report (segment.json).
pub struct SegmentDone {
    /// Segmentation's report.
    pub report: SegmentReport,
}

impl SegmentDone {
    /// What `mrtmap segment` prints: the room, its surfaces and features, the files in `out`.
    pub fn lines(&self, out: &Path) -> Vec<String> {
        let mut lines = crate::run::segment_lines(&self.report);
        lines.push(format!(
            "wrote scene.json, segments.ply, segment.json in {}",
            out.display()
        ));
        lines
    }
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
        mrtmap_io::check_replaceable(out)?;
        let prepared = crate::source::prepare(recording, out, &self.source)?;
        let rec = Recording::open(&prepared.dir)?;
        let report = crate::run::fuse_into(&rec, &params, out, self.progress)?;
        mrtmap_io::record_made(out)?;
        Ok(FuseDone {
            prepared,
            warnings: rec.warnings,
            report,
            voxel_m: self.project.fuse.voxel_m,
        })
    }

    /// `mrtmap track`: poses for `recording` from its colour and depth, into `out`
    /// (trajectory.txt, track.json).
    pub fn track(&self, recording: &Path, out: &Path) -> Result<TrackDone> {
        crate::run::check_out_apart(recording, out)?;
        mrtmap_io::check_replaceable(out)?;
        let rec = Recording::open(recording)?;
        let (trajectory, report) =
            crate::run::track_into(&rec, &self.project.track.params(), out, self.progress)?;
        mrtmap_io::record_made(out)?;
        Ok(TrackDone {
            warnings: rec.warnings,
            trajectory,
            report,
        })
    }

    /// `mrtmap segment`: the fusion in `fused` (cloud.ply, poses.txt) segmented into `out`
    /// (scene.json, segments.ply, segment.json) with `[segment]`, `[room]`, `[emissivity]`,
    /// `[[references]]` and `[mrt]`; the features labelled by the instance masks of the recording
    /// `masks` (or of `recording`, as `run` does), what the cloud missed textured from the
    /// thermal frames of `recording` (the masks' when not given), the temperature level fixed by
    /// the contact readings of the recording's references.csv, `references` and the project's.
    pub fn segment(
        &self,
        fused: &Path,
        masks: Option<&Path>,
        recording: Option<&Path>,
        references: Option<&Path>,
        out: &Path,
    ) -> Result<SegmentDone> {
        mrtmap_io::check_replaceable(out)?;
        let report = crate::run::segment_folder(&SegmentJob {
            fused,
            masks,
            recording,
            project: &self.project,
            references,
            out,
        })?;
        mrtmap_io::record_made(out)?;
        Ok(SegmentDone { report })
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
        if let Some((id, in_scene, want)) = self.project.emissivity.disagrees_with(scene) {
            return Err(Error::setting(
                format!("[emissivity] of {id} = {want}"),
                format!(
                    "differs from the {in_scene} the scene {source} was segmented with: the emissivities are applied where the camera's temperatures become surface temperatures, so segment again with this project (`mrtmap segment --config` or `mrtmap run`)"
                ),
            ));
        }
        mrtmap_io::check_replaceable(out)?;
        let maps = crate::maps::map_scene(scene, source, &self.project, spec, marks, out)?;
        mrtmap_io::record_made(out)?;
        Ok(maps)
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

    /// What [`Pipeline::live`] refuses before it follows anything: a front end calls it before
    /// it opens its page, so that a bad request is not answered with an address first.
    pub fn check_live(
        &self,
        recording: &Path,
        out: &Path,
        target_k: f64,
        exit_when_idle_s: Option<f64>,
    ) -> Result<()> {
        crate::coverage::check_target(target_k)?;
        if let Some(s) = exit_when_idle_s.filter(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(Error::setting(
                format!("--exit-when-idle {s}"),
                "give a positive number of seconds",
            ));
        }
        if !recording.is_dir() {
            return Err(Error::source(
                recording,
                "is not a folder: start the recorder first (live follows the folder it writes), or give the recording's folder",
            ));
        }
        crate::run::check_out_dir(out)?;
        crate::run::check_out_apart(recording, out)?;
        mrtmap_io::check_replaceable(out)?;
        self.project.check_heights_above_floor()
    }

    /// `mrtmap live`: follows `recording` while a recorder writes it, sending what is known to
    /// `sink` (the state at least every second, a 3D view after each refresh, judged against
    /// ±`target_k`), until it has not grown for `exit_when_idle_s` or `stop` is set; then the
    /// whole run into `out`, as [`Pipeline::run`].
    pub fn live(
        &self,
        recording: &Path,
        out: &Path,
        target_k: f64,
        exit_when_idle_s: Option<f64>,
        stop: &std::sync::atomic::AtomicBool,
        sink: &dyn crate::LiveSink,
    ) -> Result<RunDone> {
        self.check_live(recording, out, target_k, exit_when_idle_s)?;
        let opts = crate::live::LiveOptions {
            target_k,
            exit_when_idle_s,
            ..crate::live::LiveOptions::default()
        };
        let final_run = || self.run(recording, out);
        crate::live::live(&self.project, &final_run, recording, out, &opts, stop, sink)
    }

    /// `mrtmap replay`: the finished recording `from` written into the new folder `into` at
    /// `speed` times its own pace, as a recorder writes one, until the end or `stop`;
    /// `progress(scan seconds written, scan length)` about every second of scan.
    pub fn replay(
        from: &Path,
        into: &Path,
        speed: f64,
        stop: &std::sync::atomic::AtomicBool,
        progress: &dyn Fn(f64, f64),
    ) -> Result<crate::ReplayDone> {
        crate::live::replay::replay(from, into, speed, stop, progress)
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
