//! Tracking while the scan is recorded (`mrtmap live` on a recording without poses): the
//! frames are placed by the same [`Tracker`] as [`super::track`]'s, a few at a time as the
//! recording grows.
//!
//! A colour frame is placed once the depth list has passed its time by the sync tolerance (its
//! nearest depth frame is then listed). Loops are closed as keyframes are added, but the pose
//! graph is optimised only by the full run's tracking at the end: a pose given out live is not
//! moved afterwards.

use mrtmap_geometry::nalgebra::Isometry3;
use mrtmap_io::Recording;
use rayon::prelude::*;

use super::frames::FrameReader;
use super::{FRAME_CHUNK, TrackError, TrackParams, Tracker, renormalised};

/// Problems kept (the first ones).
const MAX_PROBLEMS: usize = 10;

/// The tracker fed as a recording grows.
pub struct LiveTracker {
    tracker: Tracker,
    reader: FrameReader,
    next: usize,
    /// Colour frames that could not be read, in words (the first few).
    problems: Vec<String>,
}

impl LiveTracker {
    /// A tracker for `rec`'s rig: it needs a colour camera and at least one colour frame.
    pub fn new(rec: &Recording, params: &TrackParams) -> Result<Self, TrackError> {
        let tracker = Tracker::new(rec, params)?;
        let reader = FrameReader::new(params, tracker.cams);
        Ok(LiveTracker {
            tracker,
            reader,
            next: 0,
            problems: Vec::new(),
        })
    }

    /// Places every colour frame of `rec` the depth list has passed; returns the poses of those
    /// placed (world_from_depth at the colour frame's time; the first placed frame's depth camera
    /// is the world, as [`super::track`] writes them).
    pub fn advance(&mut self, rec: &Recording) -> Vec<(f64, Isometry3<f64>)> {
        let Some(depth_end) = rec.depth.last().map(|e| e.t) else {
            return Vec::new();
        };
        let tol = self.tracker.params.sync_tolerance_s;
        let ready = rec.rgb[self.next.min(rec.rgb.len())..]
            .iter()
            .take_while(|e| e.t + tol <= depth_end)
            .count();
        let (start, end) = (self.next, self.next + ready);
        self.next = end;
        let d = self.tracker.cams.colour_from_depth;
        let mut out = Vec::new();
        for lo in (start..end).step_by(FRAME_CHUNK) {
            let hi = (lo + FRAME_CHUNK).min(end);
            let feats: Vec<_> = (lo..hi)
                .into_par_iter()
                .map(|i| self.reader.read(rec, i))
                .collect();
            for (i, f) in (lo..hi).zip(feats) {
                match f {
                    Ok(f) => self.tracker.step(rec, i, f),
                    Err(e) => {
                        if self.problems.len() < MAX_PROBLEMS {
                            self.problems.push(e.to_string());
                        }
                        continue;
                    }
                }
                if let Some(Some(p)) = self.tracker.poses.get(i) {
                    out.push((rec.rgb[i].t, renormalised(&(d.inverse() * p * d))));
                }
            }
        }
        out
    }

    /// Colour frames taken so far (placed or not).
    pub fn taken(&self) -> usize {
        self.next
    }

    /// Colour frames that could not be read, in words (the first few).
    pub fn problems(&self) -> &[String] {
        &self.problems
    }
}
