//! Loop closure: the newest keyframe joined to older ones it sees again, as pose-graph edges.
//!
//! 1. Candidates: keyframes at least the minimum separation back in the sequence whose estimated
//!    pose lies within the loop radius and looks nearly the same way; the nearest few.
//! 2. Each candidate matched over the whole image (no prediction) and posed by RANSAC and
//!    Gauss–Newton, as a frame against its reference.
//! 3. A pose with enough inliers is a loop: an edge from the candidate to the new keyframe,
//!    weighted by its information.

use mrtmap_geometry::pose_graph::Edge;

use super::matching::match_features;
use super::pose::{Seen, estimate};
use super::{Cameras, Keyframe, TrackParams, TrackReport, rotation_deg};

/// A loop candidate must look within this angle (degrees) of the new keyframe's direction.
const MAX_TURN_DEG: f64 = 35.0;

/// The nearest this many candidates are tried.
const CANDIDATES: usize = 2;

/// RANSAC's seed for a loop to keyframe `id` is this plus `id` (a frame placed against a keyframe
/// is seeded by its own index): a fixed seed keeps results deterministic.
const SEED_BASE: u64 = 0x100;

/// Tries to join the newest keyframe to older ones nearby; adds accepted loops as edges.
pub(super) fn close_loops(
    kfs: &mut [Keyframe],
    edges: &mut Vec<Edge>,
    cams: &Cameras,
    p: &TrackParams,
    report: &mut TrackReport,
) {
    let Some((new, older)) = kfs.split_last() else {
        return;
    };
    let id = older.len();
    if id < p.loop_min_separation {
        return;
    }
    // Candidates: far enough back in the sequence, near in space and looking the same way.
    let mut cands: Vec<(f64, usize)> = older[..id - p.loop_min_separation]
        .iter()
        .enumerate()
        .filter_map(|(k, o)| {
            let rel = o.pose.inverse() * new.pose;
            let d = rel.translation.vector.norm();
            (d < p.loop_radius_m && rotation_deg(&rel) < MAX_TURN_DEG).then_some((d, k))
        })
        .collect();
    cands.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(_, k) in cands.iter().take(CANDIDATES) {
        report.loops_tried += 1;
        let o = &older[k];
        let m = match_features(&o.feats, &o.xyz, &new.feats, None, &cams.colour, p);
        let Some(fd) = estimate(
            &o.xyz,
            Seen {
                norm: &new.feats.norm,
                xyz: &new.xyz,
            },
            &m,
            None,
            cams.colour.fx,
            p,
            SEED_BASE + id as u64,
        ) else {
            continue;
        };
        if fd.inliers < p.loop_min_inliers {
            continue;
        }
        report.loops_accepted += 1;
        edges.push(Edge {
            from: k as i64,
            to: id as i64,
            measured: fd.pose.inverse(),
            information: fd.information,
        });
    }
}
