//! The room's own frame: z up, the floor at z = 0, the origin at a floor corner, x along a wall,
//! the room in x ≥ 0, y ≥ 0: coordinates a person can find with a tape measure.
//!
//! The rule, applied to the floor outline (corners counter-clockwise seen from above, wall k from
//! corner k to corner k + 1):
//!
//! 1. A wall qualifies when, measured from its starting corner with x along it and y = up × x
//!    (into the room), every corner lies at x ≥ 0 and y ≥ 0 (within 5 cm).
//! 2. Of those, the longest wall gives x. Walls within 2 % of the longest count as equally long;
//!    among them, the one carrying the most feature area (windows, radiators: usually the
//!    exterior wall) wins, then the colder one.
//! 3. The origin is that wall's starting corner, on the floor.
//!
//! Corners are numbered 1… counter-clockwise from the automatic origin, wall k running from
//! corner k to corner k + 1, so the numbers a report shows stay the same when a person picks
//! another corner as the origin (`origin_corner`). The rule depends only on the room's shape and
//! temperatures, not on where the scan started, so two scans of one room get the same frame up to
//! the room's own symmetry.

use mrtmap_geometry::nalgebra::{
    Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3,
};
use serde::{Deserialize, Serialize};

/// Walls within this fraction of the longest count as equally long.
const LENGTH_TIE: f64 = 0.02;
/// A corner this far on the wrong side of an axis still counts as inside the quadrant (m).
const QUADRANT_TOLERANCE_M: f64 = 0.05;

/// One wall as the rule sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallFacts {
    /// Length along the floor (m).
    pub length_m: f64,
    /// Area of the features on it (m²).
    pub feature_area_m2: f64,
    /// Its background temperature (K).
    pub temperature_k: f64,
}

/// The room frame chosen, and how.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoomFrame {
    /// p_in_world = world_from_room · p_in_room.
    #[serde(skip)]
    pub world_from_room: Isometry3<f64>,
    /// Index of the floor corner at the origin (into the outline as given).
    pub origin_index: usize,
    /// Index of the corner numbered 1 (the automatic origin).
    pub first_index: usize,
    /// Corner number (1-based) of the origin.
    pub origin_corner: usize,
    /// Whether a person chose the origin (else the rule did).
    pub chosen: bool,
    /// Corners on the wrong side of an axis, when a chosen origin puts part of the room at x < 0
    /// or y < 0.
    pub outside_quadrant: usize,
}

/// The frame with its origin at corner `k` and x along wall `k`.
fn frame_at(corners: &[Point3<f64>], k: usize, up: &Vector3<f64>) -> Isometry3<f64> {
    let n = corners.len();
    let along = corners[(k + 1) % n] - corners[k];
    let x = (along - up * up.dot(&along)).normalize();
    let y = up.cross(&x);
    let r = Rotation3::from_basis_unchecked(&[x, y, *up]);
    Isometry3::from_parts(
        Translation3::from(corners[k].coords),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

/// Corners of the outline outside the quadrant x ≥ 0, y ≥ 0 of `world_from_room`.
fn outside(corners: &[Point3<f64>], world_from_room: &Isometry3<f64>) -> usize {
    let room_from_world = world_from_room.inverse();
    corners
        .iter()
        .map(|c| room_from_world * c)
        .filter(|p| p.x < -QUADRANT_TOLERANCE_M || p.y < -QUADRANT_TOLERANCE_M)
        .count()
}

/// The corner the rule picks (index into `corners`).
fn automatic(corners: &[Point3<f64>], walls: &[WallFacts], up: &Vector3<f64>) -> usize {
    let n = corners.len();
    let fits: Vec<usize> = (0..n)
        .filter(|&k| outside(corners, &frame_at(corners, k, up)) == 0)
        .collect();
    // Every outline has a corner whose wall keeps the room in its quadrant unless it is oddly
    // shaped (a spiral); then all walls compete.
    let candidates = if fits.is_empty() {
        (0..n).collect()
    } else {
        fits
    };
    let longest = candidates
        .iter()
        .map(|&k| walls[k].length_m)
        .fold(0.0f64, f64::max);
    let mut tied: Vec<usize> = candidates
        .into_iter()
        .filter(|&k| walls[k].length_m >= (1.0 - LENGTH_TIE) * longest)
        .collect();
    tied.sort_by(|&a, &b| {
        walls[b]
            .feature_area_m2
            .total_cmp(&walls[a].feature_area_m2)
            .then(walls[a].temperature_k.total_cmp(&walls[b].temperature_k))
            .then(walls[b].length_m.total_cmp(&walls[a].length_m))
    });
    tied[0]
}

/// The room frame of a floor outline (`corners` counter-clockwise seen along `up`, wall k from
/// corner k to k + 1, described by `walls`); `origin_corner` (1-based, in the automatic
/// numbering) overrides the rule's origin.
pub fn room_frame(
    corners: &[Point3<f64>],
    walls: &[WallFacts],
    up: &Vector3<f64>,
    origin_corner: Option<usize>,
) -> Result<RoomFrame, usize> {
    let n = corners.len();
    let first = automatic(corners, walls, up);
    let (origin, chosen) = match origin_corner {
        Some(c) if (1..=n).contains(&c) => ((first + c - 1) % n, true),
        Some(_) => return Err(n),
        None => (first, false),
    };
    let world_from_room = frame_at(corners, origin, up);
    Ok(RoomFrame {
        outside_quadrant: outside(corners, &world_from_room),
        world_from_room,
        origin_index: origin,
        first_index: first,
        origin_corner: (origin + n - first) % n + 1,
        chosen,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn facts(corners: &[Point3<f64>]) -> Vec<WallFacts> {
        let n = corners.len();
        (0..n)
            .map(|k| WallFacts {
                length_m: (corners[(k + 1) % n] - corners[k]).norm(),
                feature_area_m2: 0.0,
                temperature_k: 293.0,
            })
            .collect()
    }

    fn pts(xy: &[(f64, f64)]) -> Vec<Point3<f64>> {
        xy.iter().map(|&(x, y)| Point3::new(x, y, 0.0)).collect()
    }

    /// A world frame turned and moved: the rule must give the same room frame in room terms.
    fn moved(p: &[Point3<f64>]) -> (Vec<Point3<f64>>, Isometry3<f64>) {
        let m = Isometry3::new(Vector3::new(3.0, -7.0, 0.0), Vector3::new(0.0, 0.0, 2.1));
        (p.iter().map(|q| m * q).collect(), m)
    }

    #[test]
    fn an_l_shaped_room_lies_in_the_first_quadrant_from_its_longest_wall() {
        // Corners counter-clockwise; the longest wall (6 m) runs along y = 0.
        let c = pts(&[
            (0.0, 0.0),
            (6.0, 0.0),
            (6.0, 3.0),
            (3.0, 3.0),
            (3.0, 5.0),
            (0.0, 5.0),
        ]);
        let f = room_frame(&c, &facts(&c), &Vector3::z(), None).unwrap();
        assert_eq!(f.origin_index, 0);
        assert_eq!(f.outside_quadrant, 0);
        let room_from_world = f.world_from_room.inverse();
        for q in &c {
            let p = room_from_world * q;
            assert!(p.x >= -1e-9 && p.y >= -1e-9 && p.z.abs() < 1e-9, "{p}");
        }
        // The same room in another world frame, its outline starting elsewhere.
        let (m, world_from_old) = moved(&c);
        let mut rotated = m.clone();
        rotated.rotate_left(2);
        let g = room_frame(&rotated, &facts(&rotated), &Vector3::z(), None).unwrap();
        let same = g.world_from_room.inverse() * world_from_old * f.world_from_room;
        assert!(same.translation.vector.norm() < 1e-9 && same.rotation.angle() < 1e-9);
    }

    #[test]
    fn equal_walls_are_told_apart_by_their_windows_then_by_temperature() {
        let c = pts(&[(0.0, 0.0), (4.0, 0.0), (4.0, 3.0), (0.0, 3.0)]);
        let mut w = facts(&c);
        w[2].feature_area_m2 = 2.3; // the window is on the wall from (4,3) to (0,3)
        let f = room_frame(&c, &w, &Vector3::z(), None).unwrap();
        assert_eq!(f.origin_index, 2);
        let mut w = facts(&c);
        w[0].temperature_k = 291.0; // no windows: the colder long wall
        assert_eq!(
            room_frame(&c, &w, &Vector3::z(), None)
                .unwrap()
                .origin_index,
            0
        );
    }

    #[test]
    fn a_chosen_corner_is_numbered_from_the_automatic_origin() {
        let c = pts(&[(0.0, 0.0), (4.0, 0.0), (4.0, 3.0), (0.0, 3.0)]);
        let mut w = facts(&c);
        w[2].feature_area_m2 = 1.0;
        let f = room_frame(&c, &w, &Vector3::z(), Some(2)).unwrap();
        assert_eq!((f.first_index, f.origin_index, f.origin_corner), (2, 3, 2));
        assert!(f.chosen);
        assert!(room_frame(&c, &w, &Vector3::z(), Some(5)).is_err());
        // An L's reflex corner puts part of the room outside the quadrant: counted, not hidden.
        let l = pts(&[
            (0.0, 0.0),
            (6.0, 0.0),
            (6.0, 3.0),
            (3.0, 3.0),
            (3.0, 5.0),
            (0.0, 5.0),
        ]);
        let g = room_frame(&l, &facts(&l), &Vector3::z(), Some(4)).unwrap();
        assert!(g.outside_quadrant > 0);
    }
}
