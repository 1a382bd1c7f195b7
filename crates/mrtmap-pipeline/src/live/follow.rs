//! Following a recording folder while a recorder writes it.
//!
//! The recorder's contract (docs/recording-format.md, "Recording live"): rig.toml (and
//! references.csv, if any) exist from the start; the lists grow by appended lines; each line's
//! file is written before the line. So, at each poll:
//!
//! 1. Each list is read from where the last poll stopped, up to its last complete line: a line
//!    still being written is left for the next poll.
//! 2. A frame line is taken once its file is whole (a PNG up to its end chunk, another format
//!    when its size has not changed since the last poll). A file that has not appeared after
//!    [`MISSING_WAIT_S`] is skipped with a warning naming the list, the line and the file; the
//!    lines after it wait meanwhile, so the stream stays in order.
//! 3. A line that goes back in time, or that cannot be read, is skipped with a warning naming the
//!    list and the line; the stream goes on.
//!
//! The thermal stamps are moved onto the depth clock by the rig's offset (or the project's given
//! one) as they are taken; the finished recording is read again from disk by the final run.

use std::collections::VecDeque;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

use mrtmap_io::{
    LineSkip, ListLine, Recording, RecordingFile, SkippedLine, StreamEntry, StreamLines, Trajectory,
};

/// How long a listed file may take to appear before its line is skipped (s).
pub(crate) const MISSING_WAIT_S: f64 = 2.0;

/// Warnings kept (the first ones; the count goes on).
const MAX_WARNINGS: usize = 50;

/// Which list: a file of the recording layout.
type List = RecordingFile;

/// A line waiting for its file.
struct Pending {
    line: usize,
    t: f64,
    path: PathBuf,
    since: Instant,
    size: Option<u64>,
}

/// One list being followed.
struct Tail {
    list: List,
    /// Bytes read so far.
    offset: u64,
    /// The list's rules (mrtmap-io's, as the batch reader's), fed every line read so far.
    rules: StreamLines,
    pending: VecDeque<Pending>,
    /// Lines read so far (trajectory.txt).
    pose_lines: usize,
    /// The last pose's time (trajectory.txt).
    last_t: f64,
}

/// A thermal frame taken: its index in the recording and when its file was written.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Taken {
    pub(crate) index: usize,
    pub(crate) written: SystemTime,
}

/// A recording folder followed as it grows.
pub(crate) struct Follower {
    /// The recording as taken so far (thermal stamps on the depth clock).
    pub(crate) rec: Recording,
    tails: Vec<Tail>,
    thermal_offset_s: f64,
    /// What was skipped and why, in words (the first [`MAX_WARNINGS`]).
    pub(crate) warnings: Vec<String>,
    /// How many warnings there were in all.
    pub(crate) warning_count: usize,
    /// When a list last grew.
    pub(crate) last_growth: Instant,
    /// The thermal frames taken at the last poll, with when each was written.
    pub(crate) taken: Vec<Taken>,
    /// trajectory.txt is not read (the poses are tracked live instead).
    pub(crate) ignore_trajectory: bool,
}

/// Whether a file is whole: a PNG up to its end chunk; another format once its size stands.
fn whole(path: &Path, size_before: Option<u64>) -> (bool, Option<u64>) {
    let Ok(meta) = std::fs::metadata(path) else {
        return (false, None);
    };
    let size = meta.len();
    let is_png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if is_png {
        let ok = size >= 12
            && File::open(path)
                .and_then(|mut f| {
                    f.seek(SeekFrom::End(-12))?;
                    let mut b = [0u8; 12];
                    f.read_exact(&mut b)?;
                    Ok(&b[4..8] == b"IEND")
                })
                .unwrap_or(false);
        return (ok, Some(size));
    }
    (size > 0 && size_before == Some(size), Some(size))
}

impl Follower {
    /// Starts following `dir`, whose rig.toml must be readable.
    pub(crate) fn new(dir: &Path, thermal_offset_s: Option<f64>) -> crate::Result<Self> {
        let rig = mrtmap_io::Rig::read(&RecordingFile::Rig.path_in(dir))?;
        let offset = thermal_offset_s
            .or(rig.thermal_time_offset_s)
            .unwrap_or(0.0);
        let tails = [
            List::Depth,
            List::Thermal,
            List::Rgb,
            List::Masks,
            List::Trajectory,
        ]
        .into_iter()
        .map(|list| Tail {
            list,
            offset: 0,
            rules: StreamLines::new(),
            pose_lines: 0,
            pending: VecDeque::new(),
            last_t: f64::NEG_INFINITY,
        })
        .collect();
        Ok(Follower {
            rec: Recording {
                dir: dir.to_path_buf(),
                rig,
                depth: Vec::new(),
                thermal: Vec::new(),
                rgb: Vec::new(),
                masks: Vec::new(),
                trajectory: Trajectory::default(),
                groundtruth: None,
                imu: Vec::new(),
                warnings: Vec::new(),
            },
            tails,
            thermal_offset_s: offset,
            warnings: Vec::new(),
            warning_count: 0,
            last_growth: Instant::now(),
            taken: Vec::new(),
            ignore_trajectory: false,
        })
    }

    /// Thermal frames listed so far (taken, or waiting for their file).
    pub(crate) fn thermal_received(&self) -> usize {
        self.rec.thermal.len()
            + self
                .tails
                .iter()
                .find(|t| t.list == List::Thermal)
                .map_or(0, |t| t.pending.len())
    }

    fn warn(&mut self, w: String) {
        self.warning_count += 1;
        if self.warnings.len() < MAX_WARNINGS {
            self.warnings.push(w);
        }
    }

    /// Reads what the lists gained since the last poll; returns whether anything was taken.
    pub(crate) fn poll(&mut self) -> bool {
        self.taken.clear();
        let mut grew = false;
        for k in 0..self.tails.len() {
            grew |= self.read_new_lines(k);
            self.take_pending(k);
        }
        if grew {
            self.last_growth = Instant::now();
        }
        grew
    }

    /// Reads the complete lines appended to list `k` since the last poll.
    fn read_new_lines(&mut self, k: usize) -> bool {
        let list = self.tails[k].list;
        let path = list.path_in(&self.rec.dir);
        let Ok(mut f) = File::open(&path) else {
            return false;
        };
        let mut bytes = Vec::new();
        if f.seek(SeekFrom::Start(self.tails[k].offset)).is_err()
            || f.read_to_end(&mut bytes).is_err()
        {
            return false;
        }
        let Some(end) = bytes.iter().rposition(|&b| b == b'\n') else {
            return false;
        };
        self.tails[k].offset += end as u64 + 1;
        let text = String::from_utf8_lossy(&bytes[..=end]).into_owned();
        for raw in text.lines() {
            if list == List::Trajectory {
                // The byte-order mark and comment rules are the stream lists' (and
                // Trajectory::parse's, which reads each line).
                self.tails[k].pose_lines += 1;
                let n = self.tails[k].pose_lines;
                let raw = if n == 1 {
                    raw.strip_prefix('\u{feff}').unwrap_or(raw)
                } else {
                    raw
                };
                let s = raw.trim();
                if !s.is_empty() && !s.starts_with('#') && !self.ignore_trajectory {
                    self.take_pose(k, n, s, &path);
                }
                continue;
            }
            match self.tails[k].rules.next_line(raw) {
                ListLine::Nothing => {}
                ListLine::Skipped(skip) => self.skip(list, &skip),
                ListLine::Entry(e) => self.tails[k].pending.push_back(Pending {
                    line: e.line,
                    t: e.t,
                    path: e.path,
                    since: Instant::now(),
                    size: None,
                }),
            }
        }
        true
    }

    /// A line left out, in the batch reader's words.
    fn skip(&mut self, list: List, skip: &SkippedLine) {
        self.warn(format!(
            "{} line {}: {}: skipped",
            list.name(),
            skip.line,
            skip.why
        ));
    }

    /// One trajectory line.
    fn take_pose(&mut self, k: usize, n: usize, s: &str, path: &Path) {
        match Trajectory::parse(s, path) {
            Ok(one) if one.stamps.len() == 1 => {
                let t = one.stamps[0];
                let traj = &mut self.rec.trajectory;
                match traj.stamps.last() {
                    Some(&last) if t < last => self.warn(format!(
                        "trajectory.txt line {n}: its time {t:.6} goes back before the line above ({last:.6}): skipped"
                    )),
                    Some(&last) if t == last => {}
                    _ => {
                        traj.stamps.push(t);
                        traj.poses.push(one.poses[0]);
                        self.tails[k].last_t = t;
                    }
                }
            }
            Ok(_) => {}
            Err(e) => self.warn(format!("trajectory.txt line {n}: {}: skipped", e.kind)),
        }
    }

    /// Takes the lines of list `k` whose files are whole, in order.
    fn take_pending(&mut self, k: usize) {
        let list = self.tails[k].list;
        while let Some(head) = self.tails[k].pending.front_mut() {
            let file = self.rec.dir.join(&head.path);
            let (ok, size) = whole(&file, head.size);
            head.size = size;
            if !ok {
                if head.since.elapsed().as_secs_f64() < MISSING_WAIT_S {
                    return;
                }
                let (line, p) = (head.line, head.path.clone());
                self.tails[k].pending.pop_front();
                let what = if size.is_some() {
                    "is still incomplete"
                } else {
                    "has not appeared"
                };
                let why = LineSkip::Missing(p);
                self.warn(format!(
                    "{} line {line}: {why} (it {what} after {MISSING_WAIT_S} s): skipped",
                    list.name()
                ));
                continue;
            }
            let Some(head) = self.tails[k].pending.pop_front() else {
                return;
            };
            let mut entry = StreamEntry {
                t: head.t,
                path: head.path,
                line: head.line,
            };
            match list {
                List::Depth => self.rec.depth.push(entry),
                List::Thermal => {
                    entry.t += self.thermal_offset_s;
                    let written = std::fs::metadata(&file)
                        .and_then(|m| m.modified())
                        .unwrap_or_else(|_| SystemTime::now());
                    self.taken.push(Taken {
                        index: self.rec.thermal.len(),
                        written,
                    });
                    self.rec.thermal.push(entry);
                }
                List::Rgb => self.rec.rgb.push(entry),
                List::Masks => self.rec.masks.push(entry),
                _ => {}
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::io::Write;

    use super::*;

    const RIG: &str = "[depth]\nwidth = 8\nheight = 6\nfx = 5.0\nfy = 5.0\ncx = 3.5\ncy = 2.5\ndepth_scale = 1000.0\n\n[thermal]\nwidth = 4\nheight = 3\nfx = 2.0\nfy = 2.0\ncx = 1.5\ncy = 1.0\nencoding = \"centikelvin\"\n\n[thermal.depth_from_thermal]\ntranslation = [0.0, 0.0, 0.0]\nrotation_xyzw = [0.0, 0.0, 0.0, 1.0]\n";

    fn append(dir: &Path, list: &str, text: &str) {
        let mut f = OpenOptions::new()
            .create(true)
            .append(true)
            .open(dir.join(list))
            .unwrap();
        f.write_all(text.as_bytes()).unwrap();
    }

    fn png(dir: &Path, rel: &str) {
        let p = dir.join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_pixel(4, 3, image::Luma([29315]))
            .save(&p)
            .unwrap();
    }

    use std::fs::OpenOptions;

    /// A list that starts with a byte-order mark (a Windows editor's) gives its first line to
    /// live as to `run` (live dropped it as "expected 'timestamp path'": issue 61).
    #[test]
    fn a_byte_order_mark_is_read_past_as_the_batch_reader_does() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        std::fs::write(dir.join("rig.toml"), RIG).unwrap();
        let mut f = Follower::new(dir, None).unwrap();
        png(dir, "thermal/0.png");
        png(dir, "thermal/1.png");
        let text = "\u{feff}10.0 thermal/0.png\n10.1 thermal/1.png\n";
        append(dir, "thermal.txt", text);
        f.poll();
        assert!(f.warnings.is_empty(), "{:?}", f.warnings);
        let batch = mrtmap_io::parse_stream_list(text, Path::new("thermal.txt")).unwrap();
        assert_eq!(f.rec.thermal.len(), batch.len());
        for (a, b) in f.rec.thermal.iter().zip(&batch) {
            assert_eq!((a.line, &a.path), (b.line, &b.path));
        }
    }

    /// The same damaged lists, read by `run`'s reader (Recording::open) and followed live, give
    /// the same frames (issue 61): a byte-order mark, a repeated line, a line back in time, one
    /// that is not "timestamp path", a timestamp that is not a number and a file that never
    /// appears, in a list of 40 frames, fed to live in two pieces cut mid-line.
    #[test]
    fn live_and_run_take_the_same_frames_from_the_same_damaged_lists() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        std::fs::write(dir.join("rig.toml"), RIG).unwrap();
        let mut thermal = String::from("\u{feff}# t path\n");
        let mut depth = String::new();
        let mut poses = String::new();
        for i in 0..40 {
            let t = 10.0 + 0.1 * f64::from(i);
            if i != 17 {
                png(dir, &format!("thermal/{i}.png"));
            }
            png(dir, &format!("depth/{i}.png"));
            thermal.push_str(&format!("{t:.3} thermal/{i}.png\n"));
            depth.push_str(&format!("{t:.3} depth/{i}.png\n"));
            poses.push_str(&format!("{t:.3} 0 0 0 0 0 0 1\n"));
            match i {
                5 => thermal.push_str(&format!("{t:.3} thermal/{i}.png\n")),
                9 => thermal.push_str("10.1 thermal/1.png\n"),
                12 => thermal.push_str("garbage\n"),
                30 => thermal.push_str("ten thermal/3.png\n"),
                _ => {}
            }
        }
        std::fs::write(dir.join("depth.txt"), &depth).unwrap();
        std::fs::write(dir.join("trajectory.txt"), &poses).unwrap();
        std::fs::write(dir.join("thermal.txt"), &thermal).unwrap();
        let batch = Recording::open(dir).unwrap();
        std::fs::remove_file(dir.join("thermal.txt")).unwrap();

        let mut f = Follower::new(dir, None).unwrap();
        let cut = thermal.len() / 2 + 3;
        let cut = (cut..).find(|&c| thermal.is_char_boundary(c)).unwrap();
        append(dir, "thermal.txt", &thermal[..cut]);
        f.poll();
        append(dir, "thermal.txt", &thermal[cut..]);
        f.poll();
        std::thread::sleep(std::time::Duration::from_secs_f64(MISSING_WAIT_S + 0.1));
        f.poll();
        let frames = |v: &[StreamEntry]| -> Vec<(usize, PathBuf, i64)> {
            v.iter()
                .map(|e| (e.line, e.path.clone(), (e.t * 1e6).round() as i64))
                .collect()
        };
        assert_eq!(batch.thermal.len(), 39, "40 frames, one never written");
        assert_eq!(frames(&f.rec.thermal), frames(&batch.thermal));
        assert_eq!(frames(&f.rec.depth), frames(&batch.depth));
        // Both name the five lines left out: batch in its warnings, live one by one.
        let skipped = batch
            .warnings
            .iter()
            .find_map(|w| match w {
                mrtmap_io::RecordingWarning::SkippedLines { list, count, .. } => {
                    Some((*list, *count))
                }
                _ => None,
            })
            .unwrap();
        assert_eq!(skipped, ("thermal.txt", 4));
        assert!(
            batch.warnings.iter().any(|w| matches!(
                w,
                mrtmap_io::RecordingWarning::RepeatedLines { count: 1, .. }
            )),
            "{:?}",
            batch.warnings
        );
        assert_eq!(f.warning_count, 5, "{:?}", f.warnings);
    }

    /// A line still being written is left for the next poll; a file that has not appeared holds
    /// its list for MISSING_WAIT_S, then is skipped with a warning naming the line and the file;
    /// a line that goes back in time is skipped and named; the stream goes on after each.
    #[test]
    fn half_lines_wait_and_bad_lines_are_named_and_skipped() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        std::fs::write(dir.join("rig.toml"), RIG).unwrap();
        let mut f = Follower::new(dir, None).unwrap();
        png(dir, "thermal/0.png");
        append(
            dir,
            "thermal.txt",
            "# header\n10.0 thermal/0.png\n10.1 ther",
        );
        f.poll();
        assert_eq!(f.rec.thermal.len(), 1);
        assert_eq!(f.taken.len(), 1);
        png(dir, "thermal/1.png");
        append(dir, "thermal.txt", "mal/1.png\n");
        f.poll();
        assert_eq!(f.rec.thermal.len(), 2, "the completed line is taken");
        assert_eq!(f.rec.thermal[1].line, 3);
        // A file that never appears, then a good frame behind it.
        png(dir, "thermal/3.png");
        append(
            dir,
            "thermal.txt",
            "10.2 thermal/2.png\n10.3 thermal/3.png\n",
        );
        f.poll();
        assert_eq!(f.rec.thermal.len(), 2, "the list waits for line 4's file");
        assert_eq!(f.thermal_received(), 4);
        std::thread::sleep(std::time::Duration::from_secs_f64(MISSING_WAIT_S + 0.1));
        f.poll();
        assert_eq!(f.rec.thermal.len(), 3);
        assert!((f.rec.thermal[2].t - 10.3).abs() < 1e-12);
        assert_eq!(f.warnings.len(), 1, "{:?}", f.warnings);
        assert!(
            f.warnings[0].contains(
                "thermal.txt line 4: its file thermal/2.png is not there (it has not appeared"
            ),
            "{}",
            f.warnings[0]
        );
        // Back in time, and a line that is not 'timestamp path'.
        png(dir, "thermal/4.png");
        append(
            dir,
            "thermal.txt",
            "9.0 thermal/0.png\nnonsense\n10.4 thermal/4.png\n",
        );
        f.poll();
        assert_eq!(f.rec.thermal.len(), 4);
        assert!(
            f.warnings[1].contains("thermal.txt line 6: its time 9.000000 goes back"),
            "{}",
            f.warnings[1]
        );
        assert!(
            f.warnings[2].contains("thermal.txt line 7: expected 'timestamp path'"),
            "{}",
            f.warnings[2]
        );
        // Poses: a half line waits, a pose back in time is named.
        append(
            dir,
            "trajectory.txt",
            "10.0 0 0 0 0 0 0 1\n10.1 0 0 0 0 0 0 1\n10.05 0 0 0 0 0 0 1\n10.2 0 0",
        );
        f.poll();
        assert_eq!(f.rec.trajectory.len(), 2);
        assert!(
            f.warnings[3].contains("trajectory.txt line 3: its time 10.050000 goes back"),
            "{}",
            f.warnings[3]
        );
        append(dir, "trajectory.txt", " 0 0 0 0 1\n");
        f.poll();
        assert_eq!(f.rec.trajectory.len(), 3);
        assert_eq!(f.warning_count, 4);
    }

    /// A PNG is taken only once it is whole (its end chunk written).
    #[test]
    fn a_frame_is_taken_once_its_file_is_whole() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        std::fs::write(dir.join("rig.toml"), RIG).unwrap();
        let mut f = Follower::new(dir, Some(0.05)).unwrap();
        png(dir, "depth/full.png");
        let bytes = std::fs::read(dir.join("depth/full.png")).unwrap();
        std::fs::write(dir.join("depth/0.png"), &bytes[..bytes.len() - 12]).unwrap();
        append(dir, "depth.txt", "1.0 depth/0.png\n");
        f.poll();
        assert!(
            f.rec.depth.is_empty(),
            "a PNG without its end is waited for"
        );
        std::fs::write(dir.join("depth/0.png"), &bytes).unwrap();
        f.poll();
        assert_eq!(f.rec.depth.len(), 1);
        // The thermal stamps are moved onto the depth clock by the offset given.
        png(dir, "thermal/0.png");
        append(dir, "thermal.txt", "2.0 thermal/0.png\n");
        f.poll();
        assert!((f.rec.thermal[0].t - 2.05).abs() < 1e-12);
        assert!(f.warnings.is_empty(), "{:?}", f.warnings);
    }
}
