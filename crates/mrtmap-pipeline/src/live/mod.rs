//! `mrtmap live`: the room filling in while the scan is recorded, and when it is enough.
//!
//! 1. A [`follow::Follower`] reads the recording folder as the recorder appends to it.
//! 2. [`mrtmap_scan::LiveFusion`] fuses each thermal frame once the depth list and the
//!    trajectory have passed it (the coverage check's coarse settings: 5 cm voxels, no ICP), so a
//!    frame is fused within a poll of being written.
//! 3. Every [`LiveOptions::refresh_s`] a snapshot of the fusion goes to a second thread that runs
//!    the coverage check's coarse pipeline on it (segmentation with texturing, the temperatures'
//!    level, a 10 × 10 map at 1.1 m with its ±) and judges it as `mrtmap coverage` does.
//! 4. [`LiveState`] (`/state.json`) is sent out at least every [`STATE_EVERY_S`]; the advice is
//!    worded from the camera's pose at that moment. A new 3D view page follows each refresh.
//! 5. When the recording has not grown for `exit_when_idle_s`, or on a stop request, the whole run
//!    is made into `out` by [`crate::Pipeline::run`], exactly as `mrtmap run` makes it.

mod follow;
pub(crate) mod replay;

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

use mrtmap_geometry::nalgebra::Isometry3;
use mrtmap_io::{Recording, RecordingFile, Trajectory};
use mrtmap_radiation::RadiantScene;
use mrtmap_scan::{Fused, LiveFusion};
use serde::Serialize;

use crate::advice::Advice;
use crate::coverage::{Coverage, coarse, judge};
use crate::error::{Error, Result};
use crate::layout::RunLayout;
use crate::maps::{GridSpec, make_map};
use crate::run::{MapResult, RunOutcome, SegmentInputs, segment_into, write_fused};
use crate::settings::Project;

/// How often the folder is read (s).
const POLL_S: f64 = 0.1;

/// The state is sent at least this often (s).
pub(crate) const STATE_EVERY_S: f64 = 1.0;

/// Thermal frames a refresh textures the room model from at most, and mask frames it labels
/// features by (evenly spread over the scan): each is read at each refresh, and the scan grows.
const TEXTURE_FRAMES: usize = 60;

/// Where the poses come from is decided once this much of the scan's depth frames is listed (s).
const DECIDE_POSES_AFTER_S: f64 = 1.0;

/// Frame latencies kept for the state's median.
const LATENCIES_KEPT: usize = 300;

/// What `mrtmap live` is asked.
#[derive(Clone, Debug)]
pub(crate) struct LiveOptions {
    /// The map's target (K, 2σ).
    pub target_k: f64,
    /// Stop following once the recording has not grown for this long (s).
    pub exit_when_idle_s: Option<f64>,
    /// The room model and the map are refreshed this often at most (s).
    pub refresh_s: f64,
}

impl Default for LiveOptions {
    fn default() -> Self {
        LiveOptions {
            target_k: 0.2,
            exit_when_idle_s: None,
            refresh_s: 2.0,
        }
    }
}

/// One surface's share seen so far.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceSeen {
    /// Its id (segment.json's).
    pub id: String,
    /// Its name for people in the room.
    pub name: String,
    /// Share seen (with depth or by texturing).
    pub seen: f64,
    /// Never seen: placed at the floor's edge.
    pub inferred: bool,
}

/// The camera's pose now (the trajectory's last pose).
#[derive(Clone, Debug, Serialize)]
pub struct CameraNow {
    /// Its time (s).
    pub t: f64,
    /// Its position in the scan's frame (m).
    pub position: [f64; 3],
    /// Its orientation in the scan's frame (x, y, z, w).
    pub rotation_xyzw: [f64; 4],
    /// Its position in the room's frame (m), once the room is put together.
    pub position_room: Option<[f64; 3]>,
}

/// Where `mrtmap live` is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub enum LivePhase {
    /// Following the recording as it grows.
    #[default]
    #[serde(rename = "following")]
    Following,
    /// Making the full run on the finished recording.
    #[serde(rename = "final run")]
    FinalRun,
    /// The full run is written.
    #[serde(rename = "done")]
    Done,
    /// The full run failed.
    #[serde(rename = "failed")]
    Failed,
}

impl std::fmt::Display for LivePhase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Following => "following",
            Self::FinalRun => "final run",
            Self::Done => "done",
            Self::Failed => "failed",
        })
    }
}

/// What `mrtmap live` knows now (`GET /state.json`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct LiveState {
    /// Where it is: following, the final run, done or failed (in the JSON "following",
    /// "final run", "done", "failed").
    pub phase: LivePhase,
    /// Where the poses come from: "the recording" (trajectory.txt) or "tracked live" (the
    /// built-in tracker, on a recording without poses).
    pub poses_from: String,
    /// Thermal frames listed (taken or waiting for their file).
    pub frames_received: usize,
    /// Thermal frames fused.
    pub frames_fused: usize,
    /// Thermal frames taken (fused or skipped).
    pub frames_taken: usize,
    /// Scan time between the newest thermal frame listed and the newest taken (s).
    pub behind_s: f64,
    /// Each surface's share seen, at the last refresh.
    pub surfaces: Vec<SurfaceSeen>,
    /// "keep scanning" or "enough for ±0.2 K" (with the target).
    pub verdict: String,
    /// Whether the scan is enough for the target.
    pub good_enough: bool,
    /// Why not, most important first.
    pub reasons: Vec<String>,
    /// The largest standard error of the coarse map (K, 1σ; its ± is twice that), at the last
    /// refresh.
    pub map_max_std_error_k: Option<f64>,
    /// The coarse map's nodes at the last refresh: x, y, z (room frame, m) and MRT (°C).
    pub map_nodes: Vec<[f64; 4]>,
    /// Where to point the camera, from where it is now.
    pub advice: Vec<Advice>,
    /// The camera's pose now.
    pub camera: Option<CameraNow>,
    /// What was skipped and why (lines, frames, files), the first ones.
    pub warnings: Vec<String>,
    /// How many warnings in all.
    pub warning_count: usize,
    /// Seconds from a thermal file written to its frame fused: median of the recent frames.
    pub latency_median_s: Option<f64>,
    /// … and the largest of them.
    pub latency_max_s: Option<f64>,
    /// Refreshes of the room model done.
    pub refreshes: usize,
    /// Seconds the last refresh took.
    pub refresh_took_s: Option<f64>,
    /// Longest time between two refreshes while frames were being fused (s).
    pub refresh_gap_max_s: Option<f64>,
    /// The view page's version (it changes with each refresh).
    pub view_version: usize,
    /// Seconds since following began.
    pub elapsed_s: f64,
    /// The process's resident memory (MB; Linux).
    pub rss_mb: Option<f64>,
}

/// Where `mrtmap live` sends what it knows.
pub trait LiveSink: Sync {
    /// The state now.
    fn state(&self, state: &LiveState);
    /// A new 3D view page (after a refresh).
    fn view(&self, html: String);
}

/// What a refresh made.
struct Refreshed {
    outcome: RunOutcome,
    nodes: Vec<[f64; 4]>,
    view: mrtmap_report::view3d::View3d,
    height_m: f64,
    secs: f64,
}

/// The resident memory of this process (MB), where /proc says it.
fn rss_mb() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: f64 = s
        .lines()
        .find(|l| l.starts_with("VmRSS:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    Some(kb / 1024.0)
}

/// The coarse pipeline on a snapshot: the fusion written into `work` as a run's fuse folder,
/// segmented, levelled and mapped; and the 3D view page of it.
fn refresh(rec: &Recording, mut fused: Fused, p: &Project, work: &Path) -> Result<Refreshed> {
    let t0 = Instant::now();
    let run = RunLayout::new(work);
    let keep = mrtmap_report::view3d::evenly_spaced(fused.frames.len(), TEXTURE_FRAMES);
    fused.frames = keep.iter().map(|&i| fused.frames[i]).collect();
    write_fused(rec, &p.fuse.params()?, &fused, run.fuse().dir())?;
    let inputs = SegmentInputs {
        recording: Some(rec),
        masks: p.segment.masks && !rec.masks.is_empty(),
        texture: p.segment.texture,
    };
    let level = crate::level::LevelInputs::of(rec, p)?;
    let segment = segment_into(
        run.fuse().dir(),
        &inputs,
        &p.segment.params(&p.room),
        &level,
        run.segment().dir(),
    )?;
    let scene = RadiantScene::load(&run.scene_json())?;
    let h = p.map.heights_m.first().copied().unwrap_or(1.1);
    let spec = GridSpec {
        nx: p.map.grid[0],
        ny: p.map.grid[1],
        height_m: h,
        margin_m: p.map.margin_m,
    };
    let m = make_map(
        &scene,
        "the scan so far",
        &p.mrt,
        spec,
        &[],
        run.map(h).dir(),
        &|| false,
    )?;
    let outcome = RunOutcome {
        stages: Vec::new(),
        track: None,
        scene,
        fusion: fused.report,
        segment,
        maps: vec![MapResult {
            summary: m.summary,
            png: m.png,
            csv: RunLayout::name_in_run(|r| r.mrt_grid_csv(h)),
        }],
        comfort: None,
        level: crate::cache::read_json(&run.level_json()).ok(),
        warnings: Vec::new(),
    };
    let cloud = crate::export::run_cloud(work, &outcome.scene);
    let view = crate::report::view3d_for_run(work, &outcome, cloud.as_ref());
    Ok(Refreshed {
        nodes: crate::maps::read_grid_nodes(&work.join(&outcome.maps[0].csv))?,
        view,
        height_m: h,
        outcome,
        secs: t0.elapsed().as_secs_f64(),
    })
}

/// The state's part that comes from the last refresh, with the advice from the camera now.
fn judged(
    state: &mut LiveState,
    o: &RunOutcome,
    target_k: f64,
    start: Option<&Isometry3<f64>>,
    camera: Option<&Isometry3<f64>>,
) {
    let c: Coverage = judge(o, target_k, start, camera);
    let namer = crate::advice::Namer::new(&o.scene, start.copied());
    state.surfaces = c
        .surfaces
        .iter()
        .map(|s| SurfaceSeen {
            id: s.id.clone(),
            name: match o.scene.surfaces.iter().find(|x| x.id == s.id) {
                Some(x) if x.kind == mrtmap_radiation::SurfaceKind::Wall => namer.wall(&s.id),
                _ => s.id.clone(),
            },
            seen: 1.0 - s.unseen,
            inferred: s.inferred,
        })
        .collect();
    state.good_enough = c.good_enough;
    state.verdict = if c.good_enough {
        format!("enough for ±{} K", target_k)
    } else {
        "keep scanning".to_string()
    };
    state.reasons = c.reasons;
    state.advice = c.advice;
    let field = o.maps.first().and_then(|m| m.summary.map.field.as_ref());
    state.map_max_std_error_k = field.map(|f| f.max_std_error_k);
}

/// The 3D view page of a refresh: the advice's points numbered as the page lists them, and the
/// camera.
fn view_page(r: &Refreshed, traj: &Trajectory, target_k: f64) -> String {
    use mrtmap_report::view3d::ViewMark;
    let c = judge(&r.outcome, target_k, traj.poses.first(), traj.poses.last());
    let mut marks: Vec<ViewMark> = c
        .advice
        .iter()
        .enumerate()
        .map(|(k, a)| ViewMark {
            text: format!("{}", k + 1),
            xyz: a.point,
            kind: "point",
        })
        .collect();
    if let Some(at) = camera_now(traj, Some(&r.outcome.scene)).and_then(|c| c.position_room) {
        marks.push(ViewMark {
            text: "camera".into(),
            xyz: at,
            kind: "globe",
        });
    }
    mrtmap_report::view3d_page(&r.view, &marks, &[r.height_m])
}

/// The camera's pose now, in the state's words.
fn camera_now(traj: &Trajectory, scene: Option<&RadiantScene>) -> Option<CameraNow> {
    let (t, p) = (traj.stamps.last()?, traj.poses.last()?);
    let q = p.rotation.coords;
    let room = scene
        .and_then(|s| s.world_from_room)
        .map(|w| (w.inverse() * p).translation.vector.into());
    Some(CameraNow {
        t: *t,
        position: p.translation.vector.into(),
        rotation_xyzw: [q.x, q.y, q.z, q.w],
        position_room: room,
    })
}

/// Follows `recording` as it is written, sending what is known to `sink`, until it stops growing
/// for `opts.exit_when_idle_s` or `stop` is set; then makes the whole run into `out` by
/// `final_run` (as `mrtmap run`, with `project`) and returns it.
pub(crate) fn live(
    project: &Project,
    final_run: &dyn Fn() -> Result<crate::report::RunDone>,
    recording: &Path,
    out: &Path,
    opts: &LiveOptions,
    stop: &AtomicBool,
    sink: &dyn LiveSink,
) -> Result<crate::report::RunDone> {
    check_live_out(recording, out)?;
    // Held while following, so that a second `live` (or `run`) into the same folder is refused
    // now; given back just before the final run, which takes it again.
    let lock = crate::lock::OutLock::take(out)?;
    let p = coarse(project);
    let params = p.fuse.params()?;
    let fixed_offset = match params.clock {
        mrtmap_scan::clock::ClockOffset::Fixed(o) => Some(o),
        mrtmap_scan::clock::ClockOffset::Off => Some(0.0),
        _ => None,
    };
    let mut follower = follow::Follower::new(recording, fixed_offset)?;
    let work = tempfile::tempdir()
        .map_err(|e| mrtmap_io::FileError::io(Path::new("a temporary folder"), e))?;
    let mut fusion = LiveFusion::new(&params);
    // Where the poses come from is decided once a second of depth frames is listed:
    // trajectory.txt when it exists then, else the built-in tracker (a recorder may create
    // trajectory.txt after rig.toml and its first frames; deciding at the start tracked a
    // recording that had poses, and kept the tracker's keyframes: about 2.4 MB a second of scan).
    let can_track =
        follower.rec.rig.rgb.is_some() && p.track.mode != crate::settings::TrackMode::Never;
    let mut track_live: Option<bool> = None;
    let mut tracker: Option<mrtmap_track::LiveTracker> = None;
    let t0 = Instant::now();
    let mut state = LiveState {
        phase: LivePhase::Following,
        poses_from: "not known yet".into(),
        verdict: "keep scanning".into(),
        ..LiveState::default()
    };
    let mut latency = Latency::default();
    let mut r = Refresher::new(work.path());
    let mut last_state = Instant::now() - Duration::from_secs(10);
    loop {
        let round = Instant::now();
        follower.poll();
        let listed_s = match (follower.rec.depth.first(), follower.rec.depth.last()) {
            (Some(a), Some(b)) => b.t - a.t,
            _ => 0.0,
        };
        if track_live.is_none() && listed_s >= DECIDE_POSES_AFTER_S {
            let has_poses = RecordingFile::Trajectory.path_in(recording).exists();
            // A rig with a colour camera whose recording lists no colour frame has nothing to
            // track: it was shown as "tracked live" while nothing fused.
            let tracked = can_track && !has_poses && !follower.rec.rgb.is_empty();
            follower.ignore_trajectory = tracked;
            state.poses_from = if tracked {
                "tracked live"
            } else if has_poses {
                "the recording"
            } else {
                "none: the recording has no trajectory.txt and no colour frames to track"
            }
            .into();
            track_live = Some(tracked);
        }
        if track_live == Some(true) {
            track_more(&mut tracker, &mut follower.rec, &p);
        }
        latency.written(&follower.taken);
        latency.fused(&fusion.advance(&follower.rec).taken);
        r.collect(&mut state, sink, &follower.rec.trajectory, opts.target_k);
        r.start_when_due(&mut state, &follower.rec, &fusion, &p, opts.refresh_s);
        let idle = opts
            .exit_when_idle_s
            .is_some_and(|s| follower.last_growth.elapsed().as_secs_f64() > s);
        let stopping = idle || stop.load(Ordering::Relaxed);
        if stopping || last_state.elapsed().as_secs_f64() >= STATE_EVERY_S - POLL_S / 2.0 {
            last_state = Instant::now();
            update_state(&mut state, &follower, &fusion, &latency, &r, opts);
            state.elapsed_s = t0.elapsed().as_secs_f64();
            state.rss_mb = rss_mb();
            sink.state(&state);
        }
        if stopping {
            break;
        }
        let spent = round.elapsed().as_secs_f64();
        std::thread::sleep(Duration::from_secs_f64((POLL_S - spent).max(0.005)));
    }
    r.finish();
    state.phase = LivePhase::FinalRun;
    sink.state(&state);
    drop(lock);
    let done = final_run();
    state.phase = if done.is_ok() {
        LivePhase::Done
    } else {
        LivePhase::Failed
    };
    sink.state(&state);
    done
}

/// From a thermal file written to its frame fused: the recent frames' times.
#[derive(Default)]
struct Latency {
    /// Frames taken by the follower, not yet by fusion: their index and when written.
    waiting: VecDeque<(usize, SystemTime)>,
    /// The recent frames' latencies (s).
    recent: VecDeque<f64>,
}

impl Latency {
    fn written(&mut self, taken: &[follow::Taken]) {
        self.waiting
            .extend(taken.iter().map(|t| (t.index, t.written)));
    }

    fn fused(&mut self, taken: &[usize]) {
        let now = SystemTime::now();
        for i in taken {
            while let Some(&(k, w)) = self.waiting.front() {
                if k > *i {
                    break;
                }
                self.waiting.pop_front();
                if k == *i {
                    self.recent
                        .push_back(now.duration_since(w).map_or(0.0, |d| d.as_secs_f64()));
                    if self.recent.len() > LATENCIES_KEPT {
                        self.recent.pop_front();
                    }
                }
            }
        }
    }

    /// The median and the largest of the recent latencies.
    fn median_max(&self) -> (Option<f64>, Option<f64>) {
        let mut l: Vec<f64> = self.recent.iter().copied().collect();
        l.sort_by(f64::total_cmp);
        (l.get(l.len() / 2).copied(), l.last().copied())
    }
}

/// The refreshes: the one running on its thread, the last one done, and why the last failed.
struct Refresher {
    /// Snapshots to the refresh thread (one thread for every refresh: a thread started per
    /// refresh got memory of its own from the allocator each time, and the process grew by about
    /// 7 MB a refresh over the 343 s scan).
    jobs: Sender<Job>,
    done: Receiver<Result<Refreshed>>,
    busy: bool,
    worker: Option<JoinHandle<()>>,
    last: Option<RunOutcome>,
    started: Instant,
    fused_at: usize,
    problem: Option<String>,
}

impl Refresher {
    /// Takes a finished refresh: the state's counts, the map's nodes and a new view page.
    fn collect(
        &mut self,
        state: &mut LiveState,
        sink: &dyn LiveSink,
        traj: &Trajectory,
        target_k: f64,
    ) {
        let Ok(result) = self.done.try_recv() else {
            if self.busy && self.worker.as_ref().is_some_and(JoinHandle::is_finished) {
                self.busy = false;
                self.problem = Some("the refresh stopped unexpectedly".into());
            }
            return;
        };
        self.busy = false;
        match result {
            Ok(r) => {
                state.refreshes += 1;
                state.refresh_took_s = Some(r.secs);
                state.view_version += 1;
                sink.view(view_page(&r, traj, target_k));
                state.map_nodes = r.nodes;
                self.last = Some(r.outcome);
                self.problem = None;
            }
            Err(e) => self.problem = Some(missing_in_words(&e, traj.poses.last())),
        }
    }

    /// Starts a refresh on a snapshot when none runs, one is due and frames were fused since.
    fn start_when_due(
        &mut self,
        state: &mut LiveState,
        rec: &Recording,
        fusion: &LiveFusion,
        p: &Project,
        every_s: f64,
    ) {
        let gap = self.started.elapsed().as_secs_f64();
        if self.busy || gap < every_s || fusion.fused() <= self.fused_at || fusion.fused() < 10 {
            return;
        }
        if state.refreshes > 0 {
            state.refresh_gap_max_s = Some(state.refresh_gap_max_s.unwrap_or(0.0).max(gap));
        }
        self.started = Instant::now();
        self.fused_at = fusion.fused();
        let mut rec = rec.clone();
        let keep = mrtmap_report::view3d::evenly_spaced(rec.masks.len(), TEXTURE_FRAMES);
        rec.masks = keep.iter().map(|&i| rec.masks[i].clone()).collect();
        self.busy = self.jobs.send((rec, fusion.snapshot(), p.clone())).is_ok();
    }

    /// A refresher whose thread writes into `work`.
    fn new(work: &Path) -> Self {
        let (jobs, inbox) = channel::<Job>();
        let (outbox, done) = channel();
        let dir = work.to_path_buf();
        let worker = std::thread::spawn(move || {
            for (rec, snap, p) in inbox {
                if outbox.send(refresh(&rec, snap, &p, &dir)).is_err() {
                    return;
                }
            }
        });
        Refresher {
            jobs,
            done,
            busy: false,
            worker: Some(worker),
            last: None,
            started: Instant::now(),
            fused_at: 0,
            problem: None,
        }
    }

    /// Waits for the refresh running, then ends the thread.
    fn finish(mut self) {
        let (jobs, _) = channel();
        drop(std::mem::replace(&mut self.jobs, jobs));
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
    }
}

/// A refresh's inputs: the recording so far, the fusion's snapshot and the coarse settings.
type Job = (Recording, Fused, Project);

/// Places the colour frames the depth list has passed and appends their poses to the trajectory
/// (the tracker starts at the first colour frame).
fn track_more(tracker: &mut Option<mrtmap_track::LiveTracker>, rec: &mut Recording, p: &Project) {
    if tracker.is_none() && !rec.rgb.is_empty() {
        *tracker = mrtmap_track::LiveTracker::new(rec, &p.track.params()).ok();
    }
    let Some(t) = tracker.as_mut() else {
        return;
    };
    for (t, pose) in t.advance(rec) {
        if rec.trajectory.stamps.last().is_none_or(|&l| t > l) {
            rec.trajectory.stamps.push(t);
            rec.trajectory.poses.push(pose);
        }
    }
}

/// The state from the follower, the fusion and the last refresh.
fn update_state(
    state: &mut LiveState,
    follower: &follow::Follower,
    fusion: &LiveFusion,
    latency: &Latency,
    r: &Refresher,
    opts: &LiveOptions,
) {
    let (last, refresh_problem) = (r.last.as_ref(), &r.problem);
    let rec = &follower.rec;
    state.frames_received = follower.thermal_received();
    state.frames_fused = fusion.fused();
    state.frames_taken = fusion.taken();
    state.behind_s = match (rec.thermal.last(), fusion.taken().checked_sub(1)) {
        (Some(newest), Some(k)) => (newest.t - rec.thermal[k].t).max(0.0),
        (Some(newest), None) => newest.t - rec.thermal[0].t,
        _ => 0.0,
    };
    (state.latency_median_s, state.latency_max_s) = latency.median_max();
    let camera = rec.trajectory.poses.last();
    let start = rec.trajectory.poses.first();
    state.camera = camera_now(&rec.trajectory, last.map(|o| &o.scene));
    if let Some(o) = last {
        judged(state, o, opts.target_k, start, camera);
    }
    state.warnings = follower.warnings.clone();
    let problems = &fusion_problems(fusion);
    state.warnings.extend(problems.iter().cloned());
    state.warning_count = follower.warning_count + problems.len();
    if let Some(why) = refresh_problem {
        state.good_enough = false;
        state.verdict = "keep scanning".into();
        state.reasons = vec![format!("the room is not put together yet: {why}")];
        // Advice about a room model that is not there would contradict the reason.
        state.advice.clear();
    } else if last.is_none() {
        state.reasons = vec!["the room is not put together yet: keep scanning".into()];
    }
}

/// Why the room could not be put together yet, in words for the person holding the rig: what to
/// look at, and where the gap is from where the camera is now (no file paths, no coordinates of
/// the scan's frame).
fn missing_in_words(e: &Error, camera: Option<&Isometry3<f64>>) -> String {
    use mrtmap_scan::segment::SegmentError as S;
    let Error::Segment { source, .. } = e else {
        return "keep scanning the room slowly, floor, walls and ceiling".into();
    };
    match source {
        S::NoPoses => "no camera poses yet: keep the camera moving slowly".into(),
        S::NoFloor => "no floor seen yet: tilt the camera down to the floor".into(),
        S::NoCeiling => "no ceiling seen yet: tilt the camera up to the ceiling".into(),
        S::NoWalls => {
            "no wall seen from floor to ceiling yet: look at the walls up to the ceiling".into()
        }
        S::OpenOutline {
            from, to, length_m, ..
        } => {
            let gap = mrtmap_geometry::nalgebra::Point3::new(
                0.5 * (from[0] + to[0]),
                0.5 * (from[1] + to[1]),
                0.5 * (from[2] + to[2]),
            );
            let (where_, turn) = camera.map_or(("somewhere", "look around"), |c| {
                // The camera's right (+x) and forward (+z), in the scan's frame.
                let d = gap - c.translation.vector;
                let (right, ahead) = (
                    d.coords
                        .dot(&(c.rotation * mrtmap_geometry::nalgebra::Vector3::x())),
                    d.coords
                        .dot(&(c.rotation * mrtmap_geometry::nalgebra::Vector3::z())),
                );
                let bearing = right.atan2(ahead).to_degrees();
                match bearing {
                    b if b.abs() <= 45.0 => ("ahead of you", "scan ahead"),
                    b if b.abs() >= 135.0 => ("behind you", "turn around"),
                    b if b > 0.0 => ("to your right", "turn right"),
                    _ => ("to your left", "turn left"),
                }
            });
            format!(
                "the walls are not joined {where_} (about {length_m:.1} m not seen): {turn} and scan that part of the room"
            )
        }
        _ => "keep scanning the room slowly, floor, walls and ceiling".into(),
    }
}

/// The frames fusion could not read, in words.
fn fusion_problems(fusion: &LiveFusion) -> Vec<String> {
    fusion
        .problems()
        .iter()
        .map(|p| format!("fusion skipped a frame: {p}"))
        .collect()
}

/// The folder a live run's final outputs go to, checked before following begins.
pub(crate) fn check_live_out(recording: &Path, out: &Path) -> Result<PathBuf> {
    crate::run::check_out_dir(out)?;
    crate::run::check_out_apart(recording, out)?;
    // The final run writes in place: a folder of the user's is refused now, not after the scan.
    mrtmap_io::check_replaceable(out)?;
    if !RecordingFile::Rig.path_in(recording).is_file() {
        return Err(Error::source(
            &RecordingFile::Rig.path_in(recording),
            "is missing: a recording followed live must have its rig.toml from the start (the recorder writes it first)",
        ));
    }
    Ok(out.to_path_buf())
}

#[cfg(test)]
mod tests {
    use mrtmap_geometry::nalgebra::{Translation3, UnitQuaternion, Vector3};
    use mrtmap_scan::segment::SegmentError;

    use super::*;

    /// Issue 64: before the room closes, the reason says in words what is missing and where,
    /// from the camera now: no file path, no coordinates of the scan's frame (it was "cannot
    /// segment …/fuse/cloud.ply: the room's outline does not close: from (1.88, 1.71, 0.64) …").
    #[test]
    fn what_is_missing_is_said_in_words_from_where_the_camera_is() {
        let open = |from: [f64; 3], to: [f64; 3]| Error::Segment {
            cloud: PathBuf::from("/tmp/live-xyz/fuse/cloud.ply"),
            source: SegmentError::OpenOutline {
                from,
                to,
                length_m: 1.2,
            },
        };
        // A camera at the origin looking along +z, its right +x.
        let camera = Isometry3::identity();
        let said = |e: &Error| missing_in_words(e, Some(&camera));
        let behind = said(&open([-0.5, 0.0, -3.0], [0.5, 0.0, -3.0]));
        assert!(
            behind.contains("behind you") && behind.contains("turn around"),
            "{behind}"
        );
        assert!(!behind.contains('/') && !behind.contains("-3") && !behind.contains("frame"));
        assert!(said(&open([2.0, 0.0, -0.5], [2.0, 0.0, 0.5])).contains("to your right"));
        assert!(said(&open([-2.0, 0.0, -0.5], [-2.0, 0.0, 0.5])).contains("to your left"));
        assert!(said(&open([-0.5, 0.0, 3.0], [0.5, 0.0, 3.0])).contains("ahead of you"));
        // The camera turned half a turn: what was ahead is behind.
        let turned = Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI),
        );
        assert!(
            missing_in_words(&open([-0.5, 0.0, 3.0], [0.5, 0.0, 3.0]), Some(&turned))
                .contains("behind you")
        );
        let floor = Error::Segment {
            cloud: PathBuf::from("/tmp/x/cloud.ply"),
            source: SegmentError::NoFloor,
        };
        assert_eq!(
            said(&floor),
            "no floor seen yet: tilt the camera down to the floor"
        );
    }
}
