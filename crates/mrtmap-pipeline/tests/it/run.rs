use std::path::Path;
use std::sync::Mutex;

use mrtmap_pipeline::run::run;
use mrtmap_pipeline::settings::{PointEntry, PointFrame};
use mrtmap_pipeline::{Progress, Project};
use mrtmap_sim::{NoiseLevel, SimConfig, preset, simulate};

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
    let first = run(&rec, &out, &p, false, &log).unwrap();
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
    let again = run(&rec, &out, &p, false, &mrtmap_pipeline::Silent).unwrap();
    assert!(again.stages.iter().all(|s| s.skipped), "{:?}", again.stages);
    assert_eq!(
        again.maps[0].summary.marks[0].mrt_c,
        first.maps[0].summary.marks[0].mrt_c
    );
    // A new map height runs only that map.
    p.map.heights_m.push(1.7);
    let more = run(&rec, &out, &p, false, &mrtmap_pipeline::Silent).unwrap();
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
        false,
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
