//! Semantic labels for thermal features: a majority vote of detector labels over frames (the seed
//! paper's rule), or, without masks, simple documented rules.
//!
//! # Votes
//! For each mask frame, the feature's cloud points are projected into the colour camera at the
//! frame's pose; a point counts when the depth frame nearest in time confirms it is visible (its
//! depth within 5 cm + 3 % of the image's). If at least 10 points are visible and one instance
//! covers at least half of them, that instance's label gets the frame's vote. The label with the
//! most votes wins; its share of the votes is reported, and a tie or a share under 0.6 is flagged.
//!
//! # Rules (no masks, or no votes)
//! | where | sign | label |
//! |---|---|---|
//! | ceiling | warmer, under 1.5 m² | recessed light |
//! | ceiling | warmer, 1.5 m² or more | radiant panel |
//! | wall | colder by more than 2 K | window |
//! | wall | warmer by more than 8 K | radiator |
//! | anything else | | unlabelled |

use std::collections::BTreeMap;

use super::MaskInput;
use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3};
use mrtmap_io::masks::{labels_path, read_mask_labels};
use mrtmap_io::{Image16, Recording, read_image16};
use mrtmap_radiation::SurfaceKind;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Share of the votes under which a majority is flagged as weak.
pub const WEAK_MAJORITY: f64 = 0.6;

/// The votes a feature got.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Votes {
    /// Votes per label.
    pub votes: BTreeMap<String, usize>,
    /// The winning label's share of the votes.
    pub share: f64,
    /// Whether the top two labels tie.
    pub tie: bool,
    /// Whether the share is under [`WEAK_MAJORITY`].
    pub weak: bool,
}

impl Votes {
    fn from_counts(votes: &BTreeMap<String, usize>) -> Option<(String, Votes)> {
        let total: usize = votes.values().sum();
        let mut ranked: Vec<(&String, &usize)> = votes.iter().collect();
        ranked.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        let (top, n) = ranked.first().map(|(l, n)| ((*l).clone(), **n))?;
        let tie = ranked.get(1).is_some_and(|x| *x.1 == n);
        let share = n as f64 / total.max(1) as f64;
        Some((
            top,
            Votes {
                share,
                tie,
                weak: share < WEAK_MAJORITY,
                votes: votes.clone(),
            },
        ))
    }
}

/// The rule label of a feature.
pub fn rule_label(host: SurfaceKind, contrast_k: f64, area_m2: f64) -> &'static str {
    match host {
        SurfaceKind::Ceiling if contrast_k > 0.0 => {
            if area_m2 < 1.5 {
                "recessed light"
            } else {
                "radiant panel"
            }
        }
        SurfaceKind::Wall if contrast_k < -2.0 => "window",
        SurfaceKind::Wall if contrast_k > 8.0 => "radiator",
        _ => mrtmap_radiation::UNLABELLED,
    }
}

/// What the masks gave.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MaskSummary {
    /// Mask frames listed.
    pub frames: usize,
    /// Frames that could be used (pose, depth and images found).
    pub frames_used: usize,
    /// Votes cast.
    pub votes: usize,
    /// Problems (first few).
    pub problems: Vec<String>,
}

/// One mask frame's view: the colour (mask) camera and where it was, the depth frame nearest in
/// time and where that was.
struct MaskView<'a> {
    rec: &'a Recording,
    cam: PinholeCamera,
    cam_from_world: Isometry3<f64>,
    depth: Image16,
    depth_from_world: Isometry3<f64>,
    mask: Image16,
}

impl MaskView<'_> {
    /// The mask instance most of a feature's visible points fall on (half of them at least, of
    /// ten visible at least); a point counts as visible when the depth frame sees it.
    fn instance(&self, pts: &[Point3<f64>]) -> Option<u16> {
        let depth_cam = &self.rec.rig.depth;
        let mut counts: BTreeMap<u16, usize> = BTreeMap::new();
        let mut visible = 0usize;
        for p in pts {
            let q = self.depth_from_world * p;
            let Some(px) = depth_cam.project(&q).filter(|px| depth_cam.contains(px)) else {
                continue;
            };
            let raw = self.depth.get(px.x.round() as u32, px.y.round() as u32);
            let z = raw as f64 / self.rec.rig.depth_scale;
            if raw == 0 || (z - q.z).abs() > 0.05 + 0.03 * q.z {
                continue;
            }
            let Some(pc) = self
                .cam
                .project(&(self.cam_from_world * p))
                .filter(|pc: &Point2<f64>| self.cam.contains(pc))
            else {
                continue;
            };
            visible += 1;
            let id = self.mask.get(pc.x.round() as u32, pc.y.round() as u32);
            if id > 0 {
                *counts.entry(id).or_default() += 1;
            }
        }
        let (id, n) = counts.iter().max_by_key(|(_, n)| **n)?;
        (visible >= 10 && 2 * n >= visible).then_some(*id)
    }
}

/// The depth frame within 50 ms of `t` nearest to it.
fn nearest_depth(rec: &Recording, t: f64) -> Option<usize> {
    let k = rec.depth.partition_point(|d| d.t < t);
    [k.checked_sub(1), (k < rec.depth.len()).then_some(k)]
        .into_iter()
        .flatten()
        .min_by(|&a, &b| {
            (rec.depth[a].t - t)
                .abs()
                .total_cmp(&(rec.depth[b].t - t).abs())
        })
        .filter(|&d| (rec.depth[d].t - t).abs() <= 0.05)
}

/// One mask frame's votes: the label each feature's points fall on, if any; why not when the
/// frame cannot be used.
fn frame_votes(
    rec: &Recording,
    m: &mrtmap_io::StreamEntry,
    world_from_depth: &(dyn Fn(f64) -> Option<Isometry3<f64>> + Sync),
    features: &[Vec<Point3<f64>>],
) -> Result<Vec<Option<String>>, String> {
    let (cam, depth_from_cam) = match rec.rig.rgb {
        Some(r) => (r.camera, r.depth_from_rgb),
        None => (rec.rig.depth, Isometry3::identity()),
    };
    let wd = world_from_depth(m.t)
        .ok_or_else(|| format!("{}: no pose at {:.3} s", m.path.display(), m.t))?;
    let near = nearest_depth(rec, m.t)
        .ok_or_else(|| format!("{}: no depth frame within 50 ms", m.path.display()))?;
    let depth = rec
        .read_depth(&rec.depth[near])
        .map_err(|e| e.to_string())?;
    let wd_depth = world_from_depth(rec.depth[near].t).unwrap_or(wd);
    let png = rec.path_of(m);
    let mask = read_image16(&png).map_err(|e| e.to_string())?;
    mask.check_size(&png, cam.width, cam.height)
        .map_err(|e| e.to_string())?;
    let labels = read_mask_labels(&labels_path(&png)).map_err(|e| e.to_string())?;
    let view = MaskView {
        rec,
        cam,
        cam_from_world: (wd * depth_from_cam).inverse(),
        depth,
        depth_from_world: wd_depth.inverse(),
        mask,
    };
    Ok(features
        .iter()
        .map(|pts| {
            let id = view.instance(pts)?;
            labels.get(&id).map(|l| l.label.clone())
        })
        .collect())
}

/// Votes for every feature (given as its cloud points) from the recording's masks, with
/// `world_from_depth` giving the (refined) pose at any time.
pub fn vote(
    rec: &Recording,
    world_from_depth: &(dyn Fn(f64) -> Option<Isometry3<f64>> + Sync),
    features: &[Vec<Point3<f64>>],
) -> (Vec<Option<(String, Votes)>>, MaskSummary) {
    let mut summary = MaskSummary {
        frames: rec.masks.len(),
        ..Default::default()
    };
    let per_frame: Vec<Result<Vec<Option<String>>, String>> = rec
        .masks
        .par_iter()
        .map(|m| frame_votes(rec, m, world_from_depth, features))
        .collect();
    let mut tallies: Vec<BTreeMap<String, usize>> = vec![BTreeMap::new(); features.len()];
    for r in per_frame {
        match r {
            Ok(votes) => {
                summary.frames_used += 1;
                for (f, v) in votes.into_iter().enumerate() {
                    if let Some(label) = v {
                        *tallies[f].entry(label).or_default() += 1;
                        summary.votes += 1;
                    }
                }
            }
            Err(e) => {
                if summary.problems.len() < 10 {
                    summary.problems.push(e);
                }
            }
        }
    }
    (tallies.iter().map(Votes::from_counts).collect(), summary)
}

/// A label's vote, if masks gave one.
pub(super) type Vote = Option<(String, Votes)>;

/// Labels: one pass over the masks for features and furniture; returns their votes (none without
/// masks) and the masks' summary.
pub(super) fn vote_labels(
    masks: Option<&MaskInput<'_>>,
    features: &[(usize, &crate::segment::features::FoundFeature)],
    furniture: &[crate::segment::furniture::FoundFurniture],
    pos: &[Point3<f64>],
) -> (Vec<Vote>, Vec<Vote>, Option<MaskSummary>) {
    let Some(m) = masks else {
        return (
            vec![None; features.len()],
            vec![None; furniture.len()],
            None,
        );
    };
    let pts: Vec<Vec<Point3<f64>>> = features
        .iter()
        .map(|(_, f)| f.points.iter().map(|&i| pos[i]).collect())
        .chain(
            furniture
                .iter()
                .map(|f| f.points.iter().map(|&i| pos[i]).collect()),
        )
        .collect();
    let (mut voted, summary) = vote(m.recording, m.world_from_depth, &pts);
    let furniture_votes = voted.split_off(features.len());
    (voted, furniture_votes, Some(summary))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn majority_share_ties_and_weak_majorities() {
        let v = |pairs: &[(&str, usize)]| {
            pairs
                .iter()
                .map(|(l, n)| (l.to_string(), *n))
                .collect::<BTreeMap<_, _>>()
        };
        let (l, r) = Votes::from_counts(&v(&[("window", 8), ("mirror", 2)])).unwrap();
        assert_eq!(l, "window");
        assert!((r.share - 0.8).abs() < 1e-12 && !r.tie && !r.weak);
        let (_, r) = Votes::from_counts(&v(&[("lamp", 3), ("recessed light", 3)])).unwrap();
        assert!(r.tie && r.weak);
        let (l, r) = Votes::from_counts(&v(&[("a", 5), ("b", 3), ("c", 2)])).unwrap();
        assert_eq!(l, "a");
        assert!(r.weak && !r.tie, "5 of 10 is a weak majority");
        assert!(Votes::from_counts(&BTreeMap::new()).is_none());
    }

    #[test]
    fn rules_label_without_masks() {
        assert_eq!(
            rule_label(SurfaceKind::Ceiling, 7.0, 0.36),
            "recessed light"
        );
        assert_eq!(rule_label(SurfaceKind::Ceiling, 14.0, 4.3), "radiant panel");
        assert_eq!(rule_label(SurfaceKind::Wall, -7.0, 2.3), "window");
        assert_eq!(rule_label(SurfaceKind::Wall, 25.0, 1.0), "radiator");
        assert_eq!(rule_label(SurfaceKind::Wall, 1.2, 0.6), "unlabelled");
        assert_eq!(rule_label(SurfaceKind::Floor, 3.0, 1.0), "unlabelled");
    }
}
