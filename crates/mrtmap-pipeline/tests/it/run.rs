use std::path::Path;
use std::sync::Mutex;

use mrtmap_pipeline::settings::{PointEntry, PointFrame};
use mrtmap_pipeline::{Pipeline, Progress, Project, RunOutcome};
use mrtmap_sim::{NoiseLevel, SimConfig, preset, simulate};

/// The whole run through the front door, as `mrtmap run` makes it.
fn run(
    rec: &Path,
    out: &Path,
    p: &Project,
    progress: &dyn Progress,
) -> Result<RunOutcome, mrtmap_pipeline::Error> {
    Pipeline::new(p.clone())
        .progress(progress)
        .run(rec, out)
        .map(|done| done.outcome)
}

/// Records what the pipeline says it is doing.
#[derive(Default)]
struct Log(Mutex<Vec<String>>, Mutex<u64>);

impl Progress for Log {
    fn begin(&self, what: &str) {
        self.0.lock().unwrap().push(what.to_string());
    }
    fn advance(&self, _done: u64, _total: u64) {
        *self.1.lock().unwrap() += 1;
    }
}

fn small_scan(dir: &Path) {
    let room = preset("office").unwrap().unwrap();
    // 20 s: the walk has gone around the room (floor, ceiling and every wall seen).
    let mut cfg = SimConfig {
        seconds: 20.0,
        noise: NoiseLevel::None,
        truth_rays: 1000,
        ..SimConfig::default()
    };
    cfg.depth_camera = cfg.depth_camera.scaled(0.25);
    simulate(&room, &cfg, dir, &|_, _| {}).unwrap();
}

#[test]
fn a_run_reports_progress_and_reuses_unchanged_stages() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("scan");
    small_scan(&rec);
    let out = dir.path().join("out");
    let mut p = Project::default();
    p.fuse.depth_stride = 1;
    p.map.grid = [6, 5];
    p.points.push(PointEntry {
        name: "P".into(),
        xyz: [0.0, 0.0, 0.0],
        frame: PointFrame::Scan,
    });
    let log = Log::default();
    let first = run(&rec, &out, &p, &log).unwrap();
    let said = log.0.lock().unwrap().clone();
    assert_eq!(
        said,
        [
            "fusing thermal frames",
            "segmenting surfaces and features",
            "mapping MRT at 1.10 m"
        ]
    );
    assert!(*log.1.lock().unwrap() > 3, "frames advance the progress");
    assert!(first.stages.iter().all(|s| !s.skipped));
    assert_eq!(first.maps.len(), 1);
    assert_eq!(first.maps[0].summary.marks.len(), 1);
    let again = run(&rec, &out, &p, &mrtmap_pipeline::Silent).unwrap();
    assert!(again.stages.iter().all(|s| s.skipped), "{:?}", again.stages);
    assert_eq!(
        again.maps[0].summary.marks[0].mrt_c,
        first.maps[0].summary.marks[0].mrt_c
    );
    // A new map height runs only that map.
    p.map.heights_m.push(1.7);
    let more = run(&rec, &out, &p, &mrtmap_pipeline::Silent).unwrap();
    let skipped: Vec<bool> = more.stages.iter().map(|s| s.skipped).collect();
    assert_eq!(skipped, [true, true, true, false]);
}

#[test]
fn settings_are_checked_before_any_stage_runs() {
    let dir = tempfile::tempdir().unwrap();
    let mut p = Project::default();
    p.fuse.voxel_m = 5.0;
    let e = run(
        &dir.path().join("no-such-scan"),
        &dir.path().join("out"),
        &p,
        &mrtmap_pipeline::Silent,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("voxel size 5 m") && e.contains("0.001…1 m"),
        "{e}"
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn a_recording_without_poses_is_tracked_then_mapped() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("scan");
    let room = preset("office").unwrap().unwrap();
    let mut cfg = SimConfig {
        seconds: 20.0,
        noise: NoiseLevel::None,
        truth_rays: 1000,
        rgb_hz: 15.0,
        poses_in_recording: false,
        ..SimConfig::default()
    };
    cfg.depth_camera = cfg.depth_camera.scaled(0.5);
    simulate(&room, &cfg, &rec, &|_, _| {}).unwrap();
    let out = dir.path().join("out");
    let mut p = Project::default();
    // Refused when tracking is switched off: the recording has no poses.
    p.track.mode = mrtmap_pipeline::settings::TrackMode::Never;
    let err = run(&rec, &out, &p, &mrtmap_pipeline::Silent)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("trajectory.txt") && err.contains("never"),
        "{err}"
    );
    p.track.mode = mrtmap_pipeline::settings::TrackMode::Auto;
    p.fuse.depth_stride = 1;
    p.map.grid = [6, 5];
    let log = Log::default();
    let first = run(&rec, &out, &p, &log).unwrap();
    assert_eq!(first.stages[0].stage, "track");
    assert_eq!(
        log.0.lock().unwrap()[0],
        "tracking the camera (colour + depth)"
    );
    let t = first.track.as_ref().unwrap();
    let e = t.accuracy.unwrap();
    assert!(e.ate_rmse_m < 0.02, "{t:?}");
    assert!(out.join("track").join("trajectory.txt").is_file());
    // The truth's validation points, carried into the tracked world, against the map.
    let tracked = mrtmap_io::Trajectory::read(&out.join("track").join("trajectory.txt")).unwrap();
    let truth_poses = mrtmap_io::Trajectory::read(&rec.join("groundtruth.txt")).unwrap();
    let truth_from_est = mrtmap_track::align(&tracked, &truth_poses).unwrap();
    let truth: mrtmap_sim::Truth =
        serde_json::from_str(&std::fs::read_to_string(rec.join("truth.json")).unwrap()).unwrap();
    for pt in &truth.points {
        let w = truth_from_est.inverse() * mrtmap_geometry::nalgebra::Point3::from(pt.xyz_world);
        p.points.push(PointEntry {
            name: pt.name.clone(),
            xyz: [w.x, w.y, w.z],
            frame: PointFrame::Scan,
        });
    }
    let again = run(&rec, &out, &p, &mrtmap_pipeline::Silent).unwrap();
    // Tracking, fusion and segmentation reused; only the map ran again.
    let skipped: Vec<bool> = again.stages.iter().map(|s| s.skipped).collect();
    assert_eq!(skipped, [true, true, true, false]);
    let marks = &again.maps[0].summary.marks;
    assert_eq!(marks.len(), truth.points.len());
    for (m, pt) in marks.iter().zip(&truth.points) {
        let got = m.mrt_c;
        assert!(
            (got - pt.mrt_c).abs() < 0.2,
            "{}: {got:.3} °C, truth {:.3} °C",
            pt.name,
            pt.mrt_c
        );
    }
}
