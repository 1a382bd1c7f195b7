//! The whole run on a recording, one function per stage, each in its own folder of `out` and
//! reused while its inputs have not changed (see [`crate::cache`]):
//!
//! ```text
//!  recording ──fuse──► fuse/ (cloud.ply, fusion.json, poses.txt)
//!            ──segment──► segment/ (scene.json, segment.json, segments.ply)
//!            ──map──► map-H.HHm/ per height (mrt_grid.csv, mrt_map.png/.svg, summary.json)
//! ```
//!
//! Every file's path comes from [`crate::layout`] ([`RunLayout`] and its stage folders).
//!
//! A new stage goes here: a `*_stage` function taking what it needs and returning its outcome,
//! called in order by [`run`], with its files in its own folder.

use std::path::Path;

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_io::{
    Recording, RecordingFile, RecordingWarning, Trajectory, read_cloud_ply, write_atomic,
    write_cloud_ply,
};
use mrtmap_radiation::{GridSpec, RadiantScene};
use mrtmap_scan::FusedFrame;
use mrtmap_scan::segment::{MaskInput, SegmentParams, TextureInput, segment_textured_until};
/// What segmentation reports, and the label votes (mrtmap-scan's).
pub use mrtmap_scan::segment::{SegmentReport, Votes};
use mrtmap_scan::{FuseParams, FusionReport, SkipReason, refined_poses};
use mrtmap_track::{TrackParams, TrackReport};

use crate::cache::{Fingerprint, Stage, StageOutcome, read_json, run_or_reuse, write_json};
use crate::comfort::{ComfortSummary, comfort_title, make_comfort_maps};
use crate::error::{Error, Result};
use crate::layout::{FuseDir, RunLayout, SegmentDir, TrackDir};
use crate::level::{Level, LevelInputs};
use crate::maps::{Mark, MarkAt, Summary, make_map};
use crate::progress::Progress;
use crate::settings::{PointEntry, PointFrame, Project, Quantity, TrackMode};

/// The tracked trajectory without the poses that jump away from their neighbours' motion and
/// back (issue 54: the frame after a lost one was written 54 cm off); the report counts them and
/// its accuracy is of the trajectory written.
fn without_outliers(
    traj: Trajectory,
    mut report: TrackReport,
    truth: Option<&Trajectory>,
) -> (Trajectory, TrackReport) {
    let (clean, check) = mrtmap_scan::pose_check::drop_outlier_poses(&traj);
    if check.dropped == 0 && check.left_out == 0 {
        return (traj, report);
    }
    report.outliers_dropped = check.dropped + check.left_out;
    if let Some(t) = truth {
        report.accuracy = mrtmap_track::trajectory_error(&clean, t);
    }
    (clean, report)
}

/// Tracks `rec`'s colour and depth frames into `out`: trajectory.txt (world_from_depth, TUM) and
/// track.json (what was done; with the recording's groundtruth.txt, the trajectory error).
pub fn track_into(
    rec: &Recording,
    params: &TrackParams,
    out: &Path,
    progress: &dyn Progress,
) -> Result<(Trajectory, TrackReport)> {
    progress.begin("tracking the camera (colour + depth)");
    let (traj, report) = mrtmap_track::track_until(
        rec,
        params,
        &|d, t| progress.advance(d as u64, t as u64),
        &|| progress.stopped(),
    )
    .map_err(|e| Error::source(&rec.dir, e.to_string()))?
    .ok_or(Error::Stopped { stage: "tracking" })?;
    let (traj, report) = without_outliers(traj, report, rec.groundtruth.as_ref());
    std::fs::create_dir_all(out).map_err(|e| mrtmap_io::FileError::io(out, e))?;
    let dir = TrackDir::new(out);
    write_atomic(
        &dir.trajectory_txt(),
        traj.to_tum(&format!(
            "mrtmap track of {}: world_from_depth at the colour frames' times (the first frame's depth camera is the world)",
            rec.dir.display()
        ))
        .as_bytes(),
    )?;
    write_json(&dir.track_json(), &report)?;
    Ok((traj, report))
}

/// Fuses `rec` into `out`: cloud.ply, fusion.json and poses.txt (the refined trajectory).
pub fn fuse_into(
    rec: &Recording,
    params: &FuseParams,
    out: &Path,
    progress: &dyn Progress,
) -> Result<FusionReport> {
    progress.begin("fusing thermal frames");
    let fused = mrtmap_scan::fuse_until(rec, params, &|d, t| progress.advance(d, t), &|| {
        progress.stopped()
    })
    .ok_or(Error::Stopped { stage: "fusion" })?;
    if let Some(problem) = nothing_fused(&fused.report) {
        return Err(Error::source(&rec.dir, problem));
    }
    write_fused(rec, params, &fused, out)?;
    Ok(fused.report)
}

/// Why a fusion that made no voxel made none, and what to check; `None` when it made some. Such
/// a fusion is refused here, naming the frames' fate, rather than later as a room with no floor
/// or walls (which blamed the scan for thermal stamps in milliseconds or a rig in millimetres).
fn nothing_fused(r: &FusionReport) -> Option<String> {
    if r.voxels > 0 {
        return None;
    }
    if r.thermal_frames == 0 || r.depth_frames == 0 {
        let list = if r.thermal_frames == 0 {
            RecordingFile::Thermal
        } else {
            RecordingFile::Depth
        };
        return Some(format!(
            "{list} lists no frames, so there is nothing to fuse: list the frames recorded (docs/recording.md)"
        ));
    }
    let fate = {
        let skipped: Vec<String> = r
            .skipped
            .iter()
            .map(|(why, n)| format!("{n} {why}"))
            .collect();
        format!(
            "{} of {} thermal frames fused{}{}",
            r.used_frames,
            r.thermal_frames,
            if skipped.is_empty() {
                String::new()
            } else {
                format!(" ({})", skipped.join(", "))
            },
            r.problems
                .first()
                .map(|p| format!("; the first: {p}"))
                .unwrap_or_default()
        )
    };
    Some(format!(
        "fusion placed no thermal pixel on any depth point: {fate}. Check that thermal.txt's and depth.txt's timestamps are seconds on one clock, that rig.toml's [thermal] intrinsics match its images, and that depth_from_thermal is in metres"
    ))
}

/// Writes a fusion into `out`: cloud.ply, fusion.json, poses.txt and frames.json.
pub(crate) fn write_fused(
    rec: &Recording,
    params: &FuseParams,
    fused: &mrtmap_scan::Fused,
    out: &Path,
) -> Result<()> {
    let comment = format!(
        "mrtmap thermal cloud of {}\ntemperature_c: radiant (T^4) weighted average of the observations; temperature_std in K\nvoxel {} m, ICP {}",
        rec.dir.display(),
        params.voxel_m,
        if params.icp.enabled { "on" } else { "off" }
    );
    let dir = FuseDir::new(out);
    write_cloud_ply(&dir.cloud_ply(), &fused.cloud, &comment, &[])?;
    write_json(&dir.fusion_json(), &fused.report)?;
    let traj = fused.trajectory();
    write_atomic(
        &dir.poses_txt(),
        traj.to_tum("world_from_depth of each fused thermal frame's depth frame, after ICP")
            .as_bytes(),
    )?;
    write_json(&dir.frames_json(), &fused.frames)?;
    Ok(())
}

/// What `mrtmap segment` is given: a fusion's folder and where to write, with the recording to
/// texture from, the masks to label by, the settings and the contact readings.
#[derive(Clone, Debug)]
pub struct SegmentJob<'a> {
    /// The output folder of a fusion (cloud.ply, poses.txt).
    pub fused: &'a Path,
    /// A recording with instance masks (masks.txt) to label the features by.
    pub masks: Option<&'a Path>,
    /// The recording that was fused, whose thermal frames texture the room model (the masks'
    /// recording when not given); its masks, references.csv and camera accuracy are used as
    /// `run` uses them.
    pub recording: Option<&'a Path>,
    /// The settings (`[segment]`, `[room]`, `[emissivity]`, `[[references]]`, `[mrt]`).
    pub project: &'a Project,
    /// Contact readings (a references.csv besides the recording's).
    pub references: Option<&'a Path>,
    /// Where scene.json, segments.ply and segment.json go.
    pub out: &'a Path,
}

/// Segments a fusion's folder as [`SegmentJob`] says, after checking its inputs; one call for
/// `mrtmap segment`. With the recording given, its inputs are gathered as the segment stage of
/// `run` gathers them, so the two give the same scene.
pub fn segment_folder(job: &SegmentJob<'_>) -> Result<SegmentReport> {
    if !FuseDir::new(job.fused).cloud_ply().exists() {
        return Err(Error::source(
            job.fused,
            "no cloud.ply here: give the output folder of `mrtmap fuse`",
        ));
    }
    let masks = match job.masks {
        Some(dir) => {
            let r = Recording::open(dir)?;
            if r.masks.is_empty() {
                return Err(Error::source(dir, "no masks listed (masks.txt)"));
            }
            Some(r)
        }
        None => None,
    };
    let recording = match (job.recording, masks) {
        (Some(dir), _) => Some(Recording::open(dir)?),
        (None, m) => m,
    };
    let p = job.project;
    let use_masks = job.masks.is_some()
        || (p.segment.masks && recording.as_ref().is_some_and(|r| !r.masks.is_empty()));
    let inputs = SegmentInputs {
        recording: recording.as_ref(),
        masks: use_masks,
        texture: p.segment.texture && recording.is_some(),
    };
    let level = LevelInputs::gathered(recording.as_ref(), job.references, p)?;
    segment_into(
        job.fused,
        &inputs,
        &p.segment.params(&p.room),
        &level,
        job.out,
    )
}

/// Segments the fusion in `fused` (cloud.ply, poses.txt) into `out`: scene.json, segments.ply,
/// segment.json and level.json. Features are labelled by the masks of `masks` when given; the
/// temperatures are carried to the level the references of `level` fix.
pub fn segment_into(
    fused: &Path,
    inputs: &SegmentInputs<'_>,
    params: &SegmentParams,
    level: &LevelInputs,
    out: &Path,
) -> Result<SegmentReport> {
    segment_into_until(fused, inputs, params, level, out, &|| false)
}

/// [`segment_into`], asking `stop` between segmentation's steps ([`Error::Stopped`] once it says
/// so).
pub(crate) fn segment_into_until(
    fused: &Path,
    inputs: &SegmentInputs<'_>,
    params: &SegmentParams,
    level: &LevelInputs,
    out: &Path,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<SegmentReport> {
    let fused = FuseDir::new(fused);
    let cloud_path = fused.cloud_ply();
    let cloud = read_cloud_ply(&cloud_path)?.cloud;
    let poses = Trajectory::read(&fused.poses_txt())?;
    let masks = inputs.recording.filter(|_| inputs.masks);
    let pose_fn = masks.map(|r| refined_poses(r, &poses));
    let mask_input = masks.zip(pose_fn.as_ref()).map(|(r, f)| MaskInput {
        recording: r,
        world_from_depth: f,
    });
    let frames_path = fused.frames_json();
    let texture_frames: Option<(Vec<FusedFrame>, f64)> = match inputs.recording {
        Some(_) if inputs.texture && frames_path.exists() => {
            let report: FusionReport = read_json(&fused.fusion_json())?;
            Some((read_json(&frames_path)?, report.radiometric.vignetting_k))
        }
        _ => None,
    };
    let texture_input = inputs
        .recording
        .zip(texture_frames.as_ref())
        .map(|(r, (frames, a))| TextureInput {
            recording: r,
            frames,
            vignetting_k: *a,
        });
    let mut seg = segment_textured_until(
        &cloud,
        &poses.poses,
        mask_input.as_ref(),
        texture_input.as_ref(),
        params,
        stop,
    )
    .map_err(|source| Error::Segment {
        cloud: cloud_path.clone(),
        source,
    })?
    .ok_or(Error::Stopped {
        stage: "segmentation",
    })?;
    let found = crate::level::level_segmentation(&mut seg, &cloud, level);
    if stop() {
        return Err(Error::Stopped {
            stage: "segmentation",
        });
    }
    let dir = SegmentDir::new(out);
    write_json(&dir.level_json(), &found)?;
    write_atomic(&dir.scene_json(), (seg.scene.to_json() + "\n").as_bytes())?;
    write_cloud_ply(
        &dir.segments_ply(),
        &cloud,
        "mrtmap segments: surface_id indexes segment.json's surfaces, feature_id its features (-1: none)",
        &[
            ("surface_id", &seg.surface_id),
            ("feature_id", &seg.feature_id),
        ],
    )?;
    write_json(&dir.segment_json(), &seg.report)?;
    Ok(seg.report)
}

/// What segmentation takes from the recording besides the cloud.
#[derive(Clone, Copy, Default)]
pub struct SegmentInputs<'a> {
    /// The recording that was fused.
    pub recording: Option<&'a Recording>,
    /// Label features by its instance masks.
    pub masks: bool,
    /// Cast its thermal frames onto the room model (needs the fusion's frames.json).
    pub texture: bool,
}

/// One map of a run.
#[derive(Clone, Debug)]
pub struct MapResult {
    /// summary.json.
    pub summary: Summary,
    /// mrt_map.png.
    pub png: Vec<u8>,
    /// The grid CSV, relative to the run folder.
    pub csv: String,
}

/// A person's comfort maps: `out/comfort`.
#[derive(Clone, Debug)]
pub struct ComfortResult {
    /// comfort.json.
    pub summary: ComfortSummary,
    /// (quantity, title, PNG) per map.
    pub maps: Vec<(Quantity, String, Vec<u8>)>,
}

/// The comfort stage: `out/comfort`, when `[map] quantities` ask for a person's quantities.
fn comfort_stage(
    scene: &RadiantScene,
    run: &RunLayout,
    p: &Project,
    force: bool,
    progress: &dyn Progress,
) -> Result<Option<(StageOutcome, ComfortResult)>> {
    let person = Quantity::person(&p.map.quantities);
    if person.is_empty() {
        return Ok(None);
    }
    let dir = run.comfort();
    let scene_path = run.scene_json();
    let marks: Vec<(String, [f64; 2])> = points_in_room(&p.points, scene, &scene_path)?
        .into_iter()
        .filter_map(|m| match m.at {
            MarkAt::Scene([x, y, _]) => Some((m.name, [x, y])),
            MarkAt::Map(_) => None,
        })
        .collect();
    let fingerprint = Fingerprint::new()
        .file(&scene_path)
        .setting("grid", &p.map.grid)
        .setting("margin_m", &p.map.margin_m)
        .setting("quantities", &person)
        .setting("comfort", &p.comfort)
        .setting("air", &p.air)
        .setting("mrt", &p.mrt)
        .setting("sun", &p.sun)
        .setting("points", &p.points);
    let fingerprint = p
        .named_files()
        .iter()
        .fold(fingerprint, |f, path| f.file_content(path));
    let stage = Stage {
        name: "comfort maps".into(),
        stamp: dir.stage_json(),
        outputs: dir.outputs(&person),
    };
    let mut made = None;
    let outcome = run_or_reuse(&stage, fingerprint, force, || {
        progress.begin("mapping a person's comfort");
        progress.advance(0, 1);
        let engine = p.mrt.engine(scene)?;
        let sun = p.sun.query()?;
        let o = make_comfort_maps(
            &engine,
            scene,
            "the scanned room",
            (p.map.grid, p.map.margin_m),
            &p.comfort,
            &p.air,
            &person,
            sun.as_ref(),
            &marks,
            dir.dir(),
            &|| progress.stopped(),
        )?;
        made = Some(ComfortResult {
            summary: o.summary,
            maps: o.maps,
        });
        Ok(())
    })?;
    let result = match made {
        Some(r) => r,
        None => {
            let summary: ComfortSummary = read_json(&dir.comfort_json())?;
            let maps = person
                .iter()
                .map(|q| {
                    let f = dir.png(*q);
                    let png = std::fs::read(&f).map_err(|e| mrtmap_io::FileError::io(&f, e))?;
                    Ok((*q, comfort_title(*q, &p.comfort), png))
                })
                .collect::<Result<Vec<_>>>()?;
            ComfortResult { summary, maps }
        }
    };
    Ok(Some((outcome, result)))
}

/// A warning per reason fusion skipped thermal frames; an unreadable frame's first problem, which
/// names the file and what is wrong with it (another size, a broken image, a depth or a thermal
/// frame), is said with its count.
fn skip_warnings(fusion: &FusionReport) -> Vec<String> {
    fusion
        .skipped
        .iter()
        .map(|(why, n)| {
            let first = match why {
                SkipReason::UnreadableImage => fusion
                    .problems
                    .first()
                    .map_or(String::new(), |p| format!(" (the first: {p})")),
                _ => String::new(),
            };
            format!("fusion skipped {n} thermal frames: {why}{first}")
        })
        .collect()
}

/// The outcome of a run.
#[derive(Clone, Debug)]
pub struct RunOutcome {
    /// What each stage did.
    pub stages: Vec<StageOutcome>,
    /// The built-in tracker's report, when it ran (the recording had no poses, or
    /// `[track] mode = "always"`).
    pub track: Option<TrackReport>,
    /// The segmented scene.
    pub scene: RadiantScene,
    /// Fusion's report.
    pub fusion: FusionReport,
    /// Segmentation's report.
    pub segment: SegmentReport,
    /// Maps, by height.
    pub maps: Vec<MapResult>,
    /// A person's comfort maps, when `[map] quantities` ask for them.
    pub comfort: Option<ComfortResult>,
    /// The temperatures' absolute level (level.json).
    pub level: Option<Level>,
    /// Warnings gathered over the stages.
    pub warnings: Vec<String>,
}

/// The track stage: `out/track`, when the recording has no poses or `[track] mode = "always"`;
/// the recording's trajectory becomes the tracked one (re-tracked: aligned to the recording's own).
fn track_stage(
    rec: &mut Recording,
    run: &RunLayout,
    p: &Project,
    force: bool,
    progress: &dyn Progress,
) -> Result<Option<(StageOutcome, TrackReport)>> {
    let has_poses = !rec.trajectory.is_empty();
    let needed = match p.track.mode {
        TrackMode::Auto => !has_poses,
        TrackMode::Always => true,
        TrackMode::Never => {
            if !has_poses {
                return Err(Error::source(
                    &RecordingFile::Trajectory.path_in(&rec.dir),
                    "the recording has no poses and [track] mode = \"never\": record poses, or set mode = \"auto\" to track the colour and depth frames",
                ));
            }
            false
        }
    };
    if !needed {
        return Ok(None);
    }
    let dir = run.track();
    let fingerprint = [
        RecordingFile::Rig,
        RecordingFile::Depth,
        RecordingFile::Rgb,
        RecordingFile::Imu,
    ]
    .iter()
    .fold(Fingerprint::new(), |f, n| f.file(&n.path_in(&rec.dir)))
    .frames("depth_frames", rec, &rec.depth)
    .frames("rgb_frames", rec, &rec.rgb)
    .setting("track", &p.track);
    let stage = Stage {
        name: "track".into(),
        stamp: dir.stage_json(),
        outputs: dir.outputs(),
    };
    let params = p.track.params();
    let outcome = run_or_reuse(&stage, fingerprint, force, || {
        track_into(rec, &params, dir.dir(), progress).map(|_| ())
    })?;
    let tracked = Trajectory::read(&dir.trajectory_txt())?;
    // Re-tracked (mode = "always"): in the recording's own world frame, the frame of its
    // references.csv and of the project's scan-frame points.
    rec.trajectory = if has_poses {
        mrtmap_track::expressed_in(&tracked, &rec.trajectory).unwrap_or(tracked)
    } else {
        tracked
    };
    Ok(Some((outcome, read_json(&dir.track_json())?)))
}

/// The fuse stage: `out/fuse`.
fn fuse_stage(
    rec: &Recording,
    run: &RunLayout,
    p: &Project,
    force: bool,
    progress: &dyn Progress,
) -> Result<(StageOutcome, FusionReport)> {
    let dir = run.fuse();
    let params = p.fuse.params()?;
    let tracked = run.trajectory_txt();
    let fingerprint = [
        RecordingFile::Rig,
        RecordingFile::Depth,
        RecordingFile::Thermal,
        RecordingFile::Trajectory,
    ]
    .iter()
    .fold(Fingerprint::new(), |f, n| f.file(&n.path_in(&rec.dir)))
    .maybe_file(tracked.exists().then_some(tracked.as_path()))
    .frames("depth_frames", rec, &rec.depth)
    .frames("thermal_frames", rec, &rec.thermal)
    .setting("fuse", &p.fuse);
    let stage = Stage {
        name: "fuse".into(),
        stamp: dir.stage_json(),
        outputs: dir.outputs(),
    };
    let outcome = run_or_reuse(&stage, fingerprint, force, || {
        fuse_into(rec, &params, dir.dir(), progress).map(|_| ())
    })?;
    Ok((outcome, read_json(&dir.fusion_json())?))
}

/// The segment stage: `out/segment`.
fn segment_stage(
    rec: &Recording,
    run: &RunLayout,
    p: &Project,
    force: bool,
    progress: &dyn Progress,
) -> Result<(StageOutcome, SegmentReport)> {
    let fused = run.fuse();
    let dir = run.segment();
    let use_masks = p.segment.masks && !rec.masks.is_empty();
    let fingerprint = Fingerprint::new()
        .file(&fused.cloud_ply())
        .file(&fused.poses_txt())
        .maybe_file(
            Some(fused.frames_json())
                .filter(|f| p.segment.texture && f.exists())
                .as_deref(),
        )
        .maybe_file(
            use_masks
                .then(|| RecordingFile::Masks.path_in(&rec.dir))
                .as_deref(),
        )
        .frames("mask_frames", rec, if use_masks { &rec.masks } else { &[] })
        .setting("segment", &p.segment)
        .setting("room", &p.room)
        .maybe_file(
            Some(RecordingFile::References.path_in(&rec.dir))
                .filter(|f| f.exists())
                .as_deref(),
        )
        .setting("references", &p.references)
        .setting("emissivity", &p.emissivity)
        .setting("mrt", &p.mrt)
        .setting("camera_accuracy_k", &rec.rig.thermal_accuracy_k);
    let stage = Stage {
        name: "segment".into(),
        stamp: dir.stage_json(),
        outputs: dir.outputs(),
    };
    let outcome = run_or_reuse(&stage, fingerprint, force, || {
        progress.begin("segmenting surfaces and features");
        progress.advance(0, 1);
        let inputs = SegmentInputs {
            recording: Some(rec),
            masks: use_masks,
            texture: p.segment.texture,
        };
        let level = LevelInputs::of(rec, p)?;
        segment_into_until(
            fused.dir(),
            &inputs,
            &p.segment.params(&p.room),
            &level,
            dir.dir(),
            &|| progress.stopped(),
        )
        .map(|_| ())
    })?;
    Ok((outcome, read_json(&dir.segment_json())?))
}

/// The project's points in the scene's (room) frame: points given in the scan's frame are carried
/// through the scene's `world_from_room`.
pub fn points_in_room(
    points: &[PointEntry],
    scene: &RadiantScene,
    scene_path: &Path,
) -> Result<Vec<Mark>> {
    points
        .iter()
        .map(|pt| {
            let xyz = match pt.frame {
                PointFrame::Room => pt.xyz,
                PointFrame::Scan => {
                    let Some(world_from_room) = scene.world_from_room else {
                        return Err(Error::source(
                            scene_path,
                            format!(
                                "point {} is given in the scan's frame, but the scene has no world_from_room to carry it into the room's frame",
                                pt.name
                            ),
                        ));
                    };
                    let q = world_from_room.inverse() * Point3::from(pt.xyz);
                    [q.x, q.y, q.z]
                }
            };
            Ok(Mark {
                name: pt.name.clone(),
                at: MarkAt::Scene(xyz),
            })
        })
        .collect()
}

/// The map stage at one height: `out/map-H.HHm`.
fn map_stage(
    scene: &RadiantScene,
    run: &RunLayout,
    p: &Project,
    height_m: f64,
    force: bool,
    progress: &dyn Progress,
) -> Result<(StageOutcome, MapResult)> {
    let dir = run.map(height_m);
    let scene_path = run.scene_json();
    let spec = GridSpec {
        nx: p.map.grid[0],
        ny: p.map.grid[1],
        height_m,
        margin_m: p.map.margin_m,
    };
    let marks = points_in_room(&p.points, scene, &scene_path)?;
    // This map's own settings only: adding another height leaves it unchanged.
    let fingerprint = Fingerprint::new()
        .file(&scene_path)
        .setting("grid", &p.map.grid)
        .setting("margin_m", &p.map.margin_m)
        .setting("mrt", &p.mrt)
        .setting("points", &p.points)
        .setting("height", &height_m);
    let stage = Stage {
        name: format!("map at {height_m:.2} m"),
        stamp: dir.stage_json(),
        outputs: dir.outputs(),
    };
    let mut made = None;
    let outcome = run_or_reuse(&stage, fingerprint, force, || {
        progress.begin(&format!("mapping MRT at {height_m:.2} m"));
        progress.advance(0, 1);
        made = Some(make_map(
            scene,
            "the scanned room",
            &p.mrt,
            spec,
            &marks,
            dir.dir(),
            &|| progress.stopped(),
        )?);
        Ok(())
    })?;
    let (summary, png) = match made {
        Some(m) => (m.summary, m.png),
        None => (
            read_json(&dir.summary_json())?,
            std::fs::read(dir.mrt_map_png())
                .map_err(|e| mrtmap_io::FileError::io(&dir.mrt_map_png(), e))?,
        ),
    };
    let csv = RunLayout::name_in_run(|r| r.mrt_grid_csv(height_m));
    Ok((outcome, MapResult { summary, png, csv }))
}

/// Refuses what makes no sense in the scanned room before any map is computed: a map height
/// outside it, a point outside it, settings the MRT engine refuses.
fn check_requests(scene: &RadiantScene, scene_path: &Path, p: &Project) -> Result<()> {
    let engine = p.mrt.engine(scene)?;
    let Some(bounds) = engine.bounds() else {
        return Ok(());
    };
    for &h in &p.map.heights_m {
        bounds.check_height(h)?;
    }
    for m in points_in_room(&p.points, scene, scene_path)? {
        if let MarkAt::Scene(xyz) = m.at {
            engine
                .check_inside(&Point3::from(xyz))
                .map_err(|source| Error::Point {
                    name: m.name.clone(),
                    source,
                })?;
        }
    }
    Ok(())
}

/// Refuses an output path that is a file, before anything runs (it is created when missing).
pub fn check_out_dir(out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(Error::source(
            out,
            "is a file, but the output must be a folder (created when missing): choose another --out",
        ));
    }
    Ok(())
}

/// Refuses an output folder that is the recording folder itself: the outputs would be written
/// among its frames and lists (and a later run would read them as the recording's).
pub fn check_out_apart(recording: &Path, out: &Path) -> Result<()> {
    if let (Ok(a), Ok(b)) = (recording.canonicalize(), out.canonicalize())
        && a == b
    {
        return Err(Error::source(
            out,
            "is the recording folder itself, so the outputs would be written among its frames: choose another --out (such as a folder beside it)",
        ));
    }
    Ok(())
}

/// `Err(Stopped)` when `progress` asks the run to stop before `stage`.
fn go_on(progress: &dyn Progress, stage: &'static str) -> Result<()> {
    if progress.stopped() {
        return Err(Error::Stopped { stage });
    }
    Ok(())
}

/// Runs fuse → segment → maps on the recording folder `recording` into `out`.
pub fn run(
    recording: &Path,
    out: &Path,
    p: &Project,
    force: bool,
    progress: &dyn Progress,
) -> Result<RunOutcome> {
    p.check()?;
    check_out_dir(out)?;
    check_out_apart(recording, out)?;
    let mut rec = Recording::open(recording)?;
    // The contact readings are read again after segmentation; a bad row is refused now, not
    // after fusion's seconds.
    let references = RecordingFile::References.path_in(&rec.dir);
    if references.exists() {
        crate::settings::Reference::read_csv(&references)?;
    }
    let layout = RunLayout::new(out);
    let on_depth_clock = |w: &RecordingWarning| {
        // The recording's count was of the stamps as recorded; on the depth clock they may have
        // poses (fusion says).
        matches!(w, RecordingWarning::ThermalWithoutPose { .. })
    };
    let mut recording_warnings: Vec<RecordingWarning> = rec
        .warnings
        .iter()
        .filter(|w| **w != RecordingWarning::NoTrajectory)
        .cloned()
        .collect();
    go_on(progress, "tracking")?;
    let tracked = track_stage(&mut rec, &layout, p, force, progress)?;
    go_on(progress, "fusion")?;
    let (fused, fusion) = fuse_stage(&rec, &layout, p, force, progress)?;
    if fusion.clock.offset_s != 0.0 && !fusion.skipped.contains_key(&SkipReason::NoPose) {
        recording_warnings.retain(|w| !on_depth_clock(w));
    }
    let mut warnings: Vec<String> = recording_warnings
        .iter()
        .map(|w| format!("recording: {w}"))
        .collect();
    if let Some((_, t)) = &tracked {
        warnings.extend(t.warnings());
    }
    warnings.extend(skip_warnings(&fusion));
    if fusion.clock.weak && fusion.clock.source == mrtmap_scan::clock::OffsetSource::Estimated {
        warnings.push(format!("fusion: {}", fusion.clock.describe()));
    }
    for line in fusion.pose_check.jump_lines() {
        warnings.push(format!("fusion: {line}"));
    }
    if fusion.pose_check.dropped > 0 {
        warnings.push(format!(
            "fusion dropped {} of {} poses that jumped away from their neighbours' motion and back (the pose source relocalising or losing track); the trajectory is interpolated across them",
            fusion.pose_check.dropped, fusion.pose_check.poses
        ));
    }
    go_on(progress, "segmentation")?;
    let (segmented, segment) = segment_stage(&rec, &layout, p, force, progress)?;
    warnings.extend(
        segment
            .warnings
            .iter()
            .map(|w| format!("segmentation: {w}")),
    );
    let scene_path = layout.scene_json();
    let scene = RadiantScene::load(&scene_path)?;
    check_requests(&scene, &scene_path, p)?;
    let (track_outcome, track) = tracked.unzip();
    let mut stages: Vec<StageOutcome> = track_outcome.into_iter().collect();
    stages.extend([fused, segmented]);
    let mut maps = Vec::new();
    for &h in &p.map.heights_m {
        go_on(progress, "a map")?;
        let (st, m) = map_stage(&scene, &layout, p, h, force, progress)?;
        stages.push(st);
        maps.push(m);
    }
    let level: Option<Level> = read_json(&layout.level_json()).ok();
    go_on(progress, "the comfort maps")?;
    let comfort = match comfort_stage(&scene, &layout, p, force, progress)? {
        Some((st, c)) => {
            stages.push(st);
            Some(c)
        }
        None => None,
    };
    if p.sun.is_given() && !mrtmap_radiation::SunTracer::new(&scene).has_windows() {
        warnings.push(format!("sun: {}", crate::points::NO_GLAZING));
    }
    Ok(RunOutcome {
        stages,
        track,
        scene,
        fusion,
        segment,
        maps,
        comfort,
        level,
        warnings,
    })
}

impl RunOutcome {
    /// What `run` and `demo` print: the tracker's figures, each stage, the frames fused and the
    /// clock, each map, the warnings and where the report is (`out`, after `secs`), in lines.
    pub fn lines(&self, out: &Path, secs: f64) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(t) = &self.track {
            lines.push(format!(
                "poses from the built-in tracker (track/trajectory.txt): {} of {} colour frames, {} keyframes, {} loop closures{}",
                t.tracked,
                t.frames,
                t.keyframes,
                t.loops_accepted,
                t.accuracy
                    .map(|e| format!(
                        "; against groundtruth.txt ATE {:.1} mm, drift over {:.1} s {:.1} mm, {:.2}°",
                        e.ate_rmse_m * 1000.0,
                        e.drift_span_s,
                        e.drift_translation_rmse_m * 1000.0,
                        e.drift_rotation_rmse_deg
                    ))
                    .unwrap_or_default()
            ));
        }
        lines.extend(crate::cache::stage_lines(&self.stages));
        lines.push(format!(
            "{} of {} thermal frames fused; {}",
            self.fusion.used_frames,
            self.fusion.thermal_frames,
            self.fusion.clock.describe()
        ));
        for m in &self.maps {
            lines.extend(m.summary.lines());
        }
        for w in &self.warnings {
            lines.push(format!("warning: {w}"));
        }
        lines.push(format!(
            "done in {secs:.1} s; report: {}",
            RunLayout::new(out).report_html().display()
        ));
        lines
    }
}

/// A label's vote share, in words.
fn votes_text(v: Option<&Votes>) -> String {
    v.map(|v| {
        format!(
            ", {:.0} % of {} votes",
            v.share * 100.0,
            v.votes.values().sum::<usize>()
        )
    })
    .unwrap_or_default()
}

/// What segmentation found, in lines (what `mrtmap segment` prints): the room, its surfaces with
/// their temperatures and coverage, the features with their labels and votes, the furniture, and
/// the warnings.
pub fn segment_lines(r: &SegmentReport) -> Vec<String> {
    let mut lines = Vec::new();
    lines.push(format!(
        "room: {} walls, {:.2} m high; {:.0} % of the cloud on no surface (furniture, clutter)",
        r.surfaces.len() - 2,
        r.height_m,
        r.unassigned_fraction * 100.0
    ));
    for s in &r.surfaces {
        lines.push(format!(
            "  {:<8} {:>6.2} m²  {}  ({:.0} % observed)",
            s.id,
            s.area_m2,
            s.temperature_c
                .map_or("not observed".to_string(), |t| format!(
                    "{t:6.2} °C ± {} K",
                    mrtmap_report::numbers::uncertainty(s.temperature_std_k, 2)
                )),
            s.observed_fraction * 100.0
        ));
    }
    for f in &r.features {
        lines.push(format!(
            "  {:<18} on {:<8} {:6.2} °C ({:+.1} K), {:.2} m², label by {}{}",
            f.id,
            f.host,
            f.temperature_c,
            f.contrast_k,
            f.area_m2,
            f.label_source,
            votes_text(f.votes.as_ref())
        ));
    }
    for f in &r.furniture {
        lines.push(format!(
            "  {:<18} furniture {:.2} × {:.2} × {:.2} m, {:6.2} °C, label by {}{}",
            f.id,
            f.size_m[0],
            f.size_m[1],
            f.size_m[2],
            f.temperature_c,
            f.label_source,
            votes_text(f.votes.as_ref())
        ));
    }
    lines.extend(r.warnings.iter().map(|w| format!("  warning: {w}")));
    lines
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// Issue 54: the built-in tracker wrote a pose 54 cm off its neighbours (the frame after a
    /// lost one); it is left out of trajectory.txt and counted.
    #[test]
    fn a_tracked_pose_that_jumps_and_comes_back_is_not_written() {
        use mrtmap_geometry::nalgebra::{Isometry3, Translation3, UnitQuaternion};
        let stamps: Vec<f64> = (0..90).map(|k| f64::from(k) / 30.0).collect();
        let poses: Vec<Isometry3<f64>> = stamps
            .iter()
            .map(|&t| {
                Isometry3::from_parts(
                    Translation3::new(0.5 * t, 0.0, 1.4),
                    UnitQuaternion::from_euler_angles(0.0, 0.0, 0.5 * t),
                )
            })
            .collect();
        let truth = Trajectory {
            stamps: stamps.clone(),
            poses: poses.clone(),
        };
        let mut tracked = truth.clone();
        tracked.poses[40].translation.vector.y += 0.54;
        let (out, report) = without_outliers(tracked, TrackReport::default(), Some(&truth));
        assert_eq!((out.stamps.len(), report.outliers_dropped), (89, 1));
        assert!(!out.stamps.contains(&stamps[40]));
        assert!(report.accuracy.unwrap().ate_rmse_m < 1e-9);
        assert!(report.warnings()[0].contains("1 tracked pose(s) left out"));
        // A clean track is written as it is.
        let (out, report) = without_outliers(truth.clone(), TrackReport::default(), None);
        assert_eq!((out.stamps.len(), report.outliers_dropped), (90, 0));
    }

    /// Issue 54: "fusion skipped 1 thermal frames: an image could not be read" named no file.
    #[test]
    fn an_unreadable_frame_is_named_in_the_runs_warning() {
        let mut f = FusionReport::default();
        f.skipped.insert(SkipReason::UnreadableImage, 1);
        f.skipped.insert(SkipReason::NoPose, 2);
        f.problems
            .push("scan/thermal/000003.png: image is 5×3 pixels but the rig says 4×3".into());
        let w = skip_warnings(&f);
        assert_eq!(
            w,
            vec![
                "fusion skipped 2 thermal frames: no pose at the frame time".to_string(),
                "fusion skipped 1 thermal frames: an image could not be read (the first: scan/thermal/000003.png: image is 5×3 pixels but the rig says 4×3)".to_string(),
            ]
        );
    }
}
