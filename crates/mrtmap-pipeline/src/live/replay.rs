//! A finished recording written again into a folder at its own pace, as a recorder writes one
//! (`mrtmap replay`, `mrtmap simulate --live`): for trying `mrtmap live` without a rig, and for
//! its tests and benchmark.
//!
//! rig.toml and references.csv are written first; then every listed frame, pose and IMU sample
//! in time order, each at its time after the start (divided by the speed): a frame's file is
//! copied before its line is appended, each line in one write.

use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use mrtmap_io::{FileError, Recording, RecordingFile};

use crate::error::{Error, Result};

/// One thing to write: at scan time `t`, `line` into the list `list`, after copying `file`.
struct Event {
    t: f64,
    list: RecordingFile,
    line: String,
    file: Option<PathBuf>,
}

/// What a replay wrote.
#[derive(Clone, Debug, Default)]
pub struct ReplayDone {
    /// Lines appended.
    pub lines: usize,
    /// Files copied.
    pub files: usize,
    /// The scan's length (s).
    pub scan_s: f64,
    /// Seconds the replay took.
    pub secs: f64,
    /// Whether it was stopped before the end.
    pub stopped: bool,
}

fn events(rec: &Recording) -> Vec<Event> {
    let mut ev = Vec::new();
    for (list, entries) in [
        (RecordingFile::Depth, &rec.depth),
        (RecordingFile::Thermal, &rec.thermal),
        (RecordingFile::Rgb, &rec.rgb),
        (RecordingFile::Masks, &rec.masks),
    ] {
        for e in entries {
            ev.push(Event {
                t: e.t,
                list,
                line: format!("{:.6} {}", e.t, e.path.display()),
                file: Some(e.path.clone()),
            });
        }
    }
    for (t, p) in rec.trajectory.stamps.iter().zip(&rec.trajectory.poses) {
        let (v, q) = (p.translation.vector, p.rotation.coords);
        ev.push(Event {
            t: *t,
            list: RecordingFile::Trajectory,
            line: format!(
                "{t:.6} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9}",
                v.x, v.y, v.z, q.x, q.y, q.z, q.w
            ),
            file: None,
        });
    }
    for s in &rec.imu {
        let text = mrtmap_io::imu_text(std::slice::from_ref(s), "");
        let line = text
            .lines()
            .find(|l| !l.starts_with('#'))
            .unwrap_or("")
            .to_string();
        ev.push(Event {
            t: s.t,
            list: RecordingFile::Imu,
            line,
            file: None,
        });
    }
    ev.sort_by(|a, b| a.t.total_cmp(&b.t));
    ev
}

fn copy(from: &Path, to: &Path) -> Result<()> {
    if let Some(d) = to.parent() {
        std::fs::create_dir_all(d).map_err(|e| FileError::io(d, e))?;
    }
    std::fs::copy(from, to).map_err(|e| FileError::io(to, e))?;
    Ok(())
}

/// Writes `from` (a recording folder) into `into` at `speed` times its own pace, until the end or
/// until `stop` is set; `progress(scan seconds written, scan length)` after each second.
pub fn replay(
    from: &Path,
    into: &Path,
    speed: f64,
    stop: &AtomicBool,
    progress: &dyn Fn(f64, f64),
) -> Result<ReplayDone> {
    if !(speed.is_finite() && speed > 0.0 && speed <= 100.0) {
        return Err(Error::setting(
            format!("--speed {speed}"),
            "give the replay's speed as a positive number, at most 100 (1 is the scan's own pace)",
        ));
    }
    let rec = Recording::open(from)?;
    if into.exists()
        && std::fs::read_dir(into)
            .map(|mut d| d.next().is_some())
            .unwrap_or(true)
    {
        return Err(Error::source(
            into,
            "is not empty: a replay writes a new recording, so give a folder that does not exist yet",
        ));
    }
    std::fs::create_dir_all(into).map_err(|e| FileError::io(into, e))?;
    for name in [RecordingFile::Rig, RecordingFile::References].map(RecordingFile::name) {
        if from.join(name).is_file() {
            copy(&from.join(name), &into.join(name))?;
        }
    }
    let ev = events(&rec);
    let (t0, t1) = match (ev.first(), ev.last()) {
        (Some(a), Some(b)) => (a.t, b.t),
        _ => (0.0, 0.0),
    };
    for list in ["depth.txt", "thermal.txt"] {
        std::fs::write(
            into.join(list),
            format!("# replayed from {}\n", from.display()),
        )
        .map_err(|e| FileError::io(&into.join(list), e))?;
    }
    let start = Instant::now();
    let mut done = ReplayDone {
        scan_s: t1 - t0,
        ..ReplayDone::default()
    };
    let mut last_progress = 0.0;
    for e in &ev {
        let due = (e.t - t0) / speed;
        let now = start.elapsed().as_secs_f64();
        if due > now {
            std::thread::sleep(Duration::from_secs_f64(due - now));
        }
        if stop.load(Ordering::Relaxed) {
            done.stopped = true;
            break;
        }
        if let Some(f) = &e.file {
            copy(&from.join(f), &into.join(f))?;
            done.files += 1;
            let labels = mrtmap_io::masks::labels_path(&from.join(f));
            if e.list == RecordingFile::Masks && labels.is_file() {
                copy(&labels, &mrtmap_io::masks::labels_path(&into.join(f)))?;
            }
        }
        let list = e.list.path_in(into);
        let mut out = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&list)
            .map_err(|err| FileError::io(&list, err))?;
        out.write_all(format!("{}\n", e.line).as_bytes())
            .map_err(|err| FileError::io(&list, err))?;
        done.lines += 1;
        if e.t - t0 >= last_progress + 1.0 {
            last_progress = e.t - t0;
            progress(e.t - t0, t1 - t0);
        }
    }
    done.secs = start.elapsed().as_secs_f64();
    Ok(done)
}
