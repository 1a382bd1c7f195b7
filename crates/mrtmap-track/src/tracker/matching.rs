//! Matching a frame's corners to a keyframe's by their BRIEF descriptors.
//!
//! 1. Candidates: with a predicted pose, the current corners within the search radius of where
//!    each reference corner's 3D point projects (guided); else every current corner.
//! 2. Each reference corner's best candidate by Hamming distance, kept when it is within the
//!    largest distance and clearly better than the second best (Lowe's ratio).
//! 3. Mutual: of the reference corners that chose one current corner, only the nearest in
//!    descriptor distance keeps it.

use std::collections::BTreeMap;

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Isometry3, Point3};

use super::TrackParams;
use super::features::Features;

/// Hamming distance between two 256-bit descriptors.
fn hamming(a: &[u64; 4], b: &[u64; 4]) -> u32 {
    (a[0] ^ b[0]).count_ones()
        + (a[1] ^ b[1]).count_ones()
        + (a[2] ^ b[2]).count_ones()
        + (a[3] ^ b[3]).count_ones()
}

/// Matches (reference index, current index): guided by `predicted` (current_from_reference) when
/// given, otherwise over the whole image; mutual best with a ratio test.
pub(super) fn match_features(
    r: &Features,
    r_xyz: &[Option<Point3<f64>>],
    c: &Features,
    predicted: Option<&Isometry3<f64>>,
    cam: &PinholeCamera,
    p: &TrackParams,
) -> Vec<(usize, usize)> {
    let best_for = |i: usize, cands: &mut dyn Iterator<Item = usize>| -> Option<usize> {
        let (mut b, mut bd, mut sd) = (usize::MAX, u32::MAX, u32::MAX);
        for j in cands {
            let d = hamming(&r.desc[i], &c.desc[j]);
            if d < bd {
                (sd, bd, b) = (bd, d, j);
            } else if d < sd {
                sd = d;
            }
        }
        (bd <= p.max_hamming && (bd as f64) < p.ratio * sd as f64).then_some(b)
    };
    let r2 = p.search_radius_px * p.search_radius_px;
    let forward: Vec<Option<usize>> = (0..r.desc.len())
        .map(|i| match predicted {
            Some(t) => {
                let x = r_xyz[i]?;
                let px = cam.project(&(t * x))?;
                let mut near = (0..c.px.len()).filter(|&j| (c.px[j] - px).norm_squared() < r2);
                best_for(i, &mut near)
            }
            None => best_for(i, &mut (0..c.desc.len())),
        })
        .collect();
    // Mutual: the current corner's best among the reference corners that chose it.
    let mut chosen: BTreeMap<usize, (u32, usize)> = BTreeMap::new();
    for (i, j) in forward.iter().enumerate() {
        if let Some(j) = *j {
            let d = hamming(&r.desc[i], &c.desc[j]);
            let e = chosen.entry(j).or_insert((d, i));
            if d < e.0 {
                *e = (d, i);
            }
        }
    }
    chosen.into_iter().map(|(j, (_, i))| (i, j)).collect()
}
