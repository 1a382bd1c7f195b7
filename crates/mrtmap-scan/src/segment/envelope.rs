//! The room's envelope from a thermal cloud: up, planes, their classes, and the loop of walls
//! whose consecutive intersections are the room's corners (the seed paper's Algorithm 1, "retrieve
//! surface plane and corners").

use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Unit, Vector2, Vector3};
use mrtmap_geometry::plane::{Plane, RansacParams, intersect_three, ransac_plane};
use mrtmap_geometry::polygon::{centroid, signed_area};
use mrtmap_geometry::shape2d::line_intersection;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::{SegmentError, SegmentParams};

/// What a plane is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlaneClass {
    /// The floor.
    Floor,
    /// The ceiling.
    Ceiling,
    /// A wall of the envelope.
    Wall,
    /// Horizontal, not floor or ceiling (a table top…).
    OtherHorizontal,
    /// Vertical but not a wall (too short, or not on the outline).
    OtherVertical,
    /// Neither horizontal nor vertical.
    Slanted,
}

/// A plane found in the cloud.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FoundPlane {
    /// The plane (normal into the room for envelope planes).
    pub plane: Plane,
    /// Its inliers (indices into the cloud).
    #[serde(skip)]
    pub inliers: Vec<usize>,
    /// Number of inliers.
    pub points: usize,
    /// Class.
    pub class: PlaneClass,
}

/// The envelope: up, floor, ceiling and the walls in order around the room, with corners.
#[derive(Clone, Debug)]
pub struct Envelope {
    /// Up (unit).
    pub up: Unit<Vector3<f64>>,
    /// Index of the floor in `planes`.
    pub floor: usize,
    /// Index of the ceiling.
    pub ceiling: usize,
    /// Walls in order around the room (counter-clockwise seen from above).
    pub walls: Vec<usize>,
    /// Corners at the floor: corner k is where wall k−1 meets wall k.
    pub floor_corners: Vec<Point3<f64>>,
    /// Corners at the ceiling.
    pub ceiling_corners: Vec<Point3<f64>>,
    /// All planes found.
    pub planes: Vec<FoundPlane>,
    /// The horizontal frame (origin on the floor, normal up).
    pub frame: PlaneFrame,
}

/// Up from the camera poses: the mean of the cameras' "up" (−y in OpenCV's convention) over the
/// walk. Tilt sweeps cancel over a walk that looks all around.
pub fn up_from_poses(world_from_camera: &[Isometry3<f64>]) -> Option<Unit<Vector3<f64>>> {
    let s = world_from_camera
        .iter()
        .fold(Vector3::zeros(), |a, p| a - p.rotation * Vector3::y());
    Unit::try_new(s, 1e-9)
}

fn percentile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// The mean of the cloud's points `idx`.
fn mean_of(points: &[Point3<f64>], idx: &[usize]) -> Point3<f64> {
    let sum = idx
        .iter()
        .fold(Vector3::zeros(), |a, &i| a + points[i].coords);
    Point3::from(sum / idx.len().max(1) as f64)
}

/// Finds planes by repeated RANSAC, merging near-coplanar ones.
pub fn find_planes(
    points: &[Point3<f64>],
    normals: &[Vector3<f64>],
    p: &SegmentParams,
) -> Vec<FoundPlane> {
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let mut remaining: Vec<usize> = (0..points.len()).collect();
    let min_points = p.min_plane_points.max(points.len() / 400);
    let mut found: Vec<(Plane, Vec<usize>)> = Vec::new();
    let ransac = RansacParams {
        distance_m: p.plane_distance_m,
        normal_deg: p.plane_normal_deg,
        ..RansacParams::default()
    };
    for _ in 0..p.max_planes {
        let Some((pl, inl)) = ransac_plane(points, normals, &remaining, &ransac, &mut rng) else {
            break;
        };
        if inl.len() < min_points {
            break;
        }
        let mut taken = vec![false; points.len()];
        for &i in &inl {
            taken[i] = true;
        }
        remaining.retain(|&i| !taken[i]);
        found.push((pl, inl));
    }
    // Merge planes that are the same surface split in two.
    let mut merged: Vec<(Plane, Vec<usize>)> = Vec::new();
    for (pl, inl) in found {
        let same = merged.iter_mut().find(|(m, _)| {
            m.normal.dot(&pl.normal).abs() > p.merge_deg.to_radians().cos() && {
                m.distance(&mean_of(points, &inl)).abs() < p.merge_distance_m
            }
        });
        match same {
            Some((m, mi)) => {
                mi.extend(inl);
                let pts: Vec<Point3<f64>> = mi.iter().map(|&i| points[i]).collect();
                if let Some(f) = Plane::fit(&pts) {
                    *m = if f.normal.dot(&m.normal) < 0.0 {
                        f.flipped()
                    } else {
                        f
                    };
                }
            }
            None => merged.push((pl, inl)),
        }
    }
    merged
        .into_iter()
        .map(|(plane, inliers)| FoundPlane {
            plane,
            points: inliers.len(),
            inliers,
            class: PlaneClass::Slanted,
        })
        .collect()
}

/// Height of a point along `up`.
fn height(pt: &Point3<f64>, up: &Vector3<f64>) -> f64 {
    up.dot(&pt.coords)
}

/// Floor and ceiling, and up refined from the floor's normal.
struct Caps {
    floor: usize,
    ceiling: usize,
    up: Unit<Vector3<f64>>,
    h_floor: f64,
    h_ceiling: f64,
}

/// Floor and ceiling: the lowest and highest large horizontal planes; up from the floor's normal,
/// oriented like the cameras' up. Classifies the horizontal planes and orients the floor's normal
/// up and the ceiling's down.
fn floor_and_ceiling(
    points: &[Point3<f64>],
    planes: &mut [FoundPlane],
    up0: Unit<Vector3<f64>>,
    p: &SegmentParams,
) -> Result<Caps, SegmentError> {
    let cos_h = p.horizontal_deg.to_radians().cos();
    let horizontal: Vec<usize> = (0..planes.len())
        .filter(|&k| planes[k].plane.normal.dot(&up0).abs() > cos_h)
        .collect();
    let largest = horizontal
        .iter()
        .map(|&k| planes[k].points)
        .max()
        .ok_or(SegmentError::NoFloor)?;
    let big: Vec<usize> = horizontal
        .iter()
        .copied()
        .filter(|&k| planes[k].points * 5 >= largest)
        .collect();
    let heights: Vec<f64> = planes
        .iter()
        .map(|f| height(&mean_of(points, &f.inliers), &up0))
        .collect();
    let floor = *big
        .iter()
        .min_by(|&&a, &&b| heights[a].total_cmp(&heights[b]))
        .ok_or(SegmentError::NoFloor)?;
    let ceiling = *big
        .iter()
        .max_by(|&&a, &&b| heights[a].total_cmp(&heights[b]))
        .ok_or(SegmentError::NoCeiling)?;
    if floor == ceiling || heights[ceiling] - heights[floor] < 1.5 {
        return Err(SegmentError::NoCeiling);
    }
    if planes[floor].plane.normal.dot(&up0) < 0.0 {
        planes[floor].plane = planes[floor].plane.flipped();
    }
    let up = planes[floor].plane.normal;
    if planes[ceiling].plane.normal.dot(&up) > 0.0 {
        planes[ceiling].plane = planes[ceiling].plane.flipped();
    }
    for &k in &horizontal {
        if k != floor && k != ceiling {
            planes[k].class = PlaneClass::OtherHorizontal;
        }
    }
    planes[floor].class = PlaneClass::Floor;
    planes[ceiling].class = PlaneClass::Ceiling;
    Ok(Caps {
        floor,
        ceiling,
        up,
        h_floor: heights[floor],
        h_ceiling: heights[ceiling],
    })
}

/// The room's interior: the mean of points between floor and ceiling.
fn room_centre(points: &[Point3<f64>], caps: &Caps) -> Point3<f64> {
    let inside: Vec<Point3<f64>> = points
        .iter()
        .filter(|q| {
            let h = height(q, &caps.up);
            h > caps.h_floor + 0.2 && h < caps.h_ceiling - 0.2
        })
        .copied()
        .collect();
    centroid(&inside)
}

/// The bins (start, end, count) of the contiguous run of occupied 10 cm bins (gaps up to 30 cm)
/// holding the most points.
fn main_run_bins(count: &[usize]) -> (usize, usize, usize) {
    let (mut best, mut cur_start, mut gap, mut cur_n) =
        ((0usize, 0usize, 0usize), None::<usize>, 0usize, 0usize);
    for (b, &c) in count.iter().enumerate() {
        if c >= 3 {
            if cur_start.is_none() {
                cur_start = Some(b);
                cur_n = 0;
            }
            cur_n += c;
            gap = 0;
            if cur_n > best.2 {
                best = (cur_start.unwrap_or(b), b, cur_n);
            }
        } else if cur_start.is_some() {
            gap += 1;
            if gap > 3 {
                cur_start = None;
            }
        }
    }
    best
}

/// The wall's main run: 10 cm bins along it, the contiguous run (gaps up to 30 cm) holding the
/// most inliers. Inliers elsewhere on the infinite plane belong to other surfaces and are dropped;
/// returns the coverage, the occupied share of the run. A plane through the points of two corners
/// (an artefact of mixed normals) covers little of its run.
fn keep_main_run(plane: &mut FoundPlane, points: &[Point3<f64>], up: &Unit<Vector3<f64>>) -> f64 {
    let d = up.cross(&plane.plane.normal);
    let s: Vec<f64> = plane
        .inliers
        .iter()
        .map(|&i| d.dot(&points[i].coords))
        .collect();
    let lo = s.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = s.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let bins = (((hi - lo) / 0.1).ceil() as usize).clamp(1, 100_000);
    let bin = |v: f64| (((v - lo) / 0.1) as usize).min(bins - 1);
    let mut count = vec![0usize; bins];
    for v in &s {
        count[bin(*v)] += 1;
    }
    let (b0, b1, _) = main_run_bins(&count);
    plane.inliers = plane
        .inliers
        .iter()
        .zip(&s)
        .filter(|(_, v)| (b0..=b1).contains(&bin(**v)))
        .map(|(i, _)| *i)
        .collect();
    plane.points = plane.inliers.len();
    count[b0..=b1].iter().filter(|&&c| c >= 3).count() as f64 / (b1 - b0 + 1) as f64
}

/// A vertical plane through `c` with `normal` made exactly horizontal, pointing into the room.
fn vertical_plane(
    normal: &Vector3<f64>,
    c: &Point3<f64>,
    up: &Unit<Vector3<f64>>,
    centre: &Point3<f64>,
) -> Plane {
    let n = Unit::new_normalize(normal - up.as_ref() * normal.dot(up));
    let pl = Plane::from_point_normal(c, n);
    if pl.distance(centre) < 0.0 {
        pl.flipped()
    } else {
        pl
    }
}

/// Walls: vertical planes spanning much of the room's height, reaching the ceiling (furniture does
/// not), seen along most of their length; made exactly vertical, facing into the room.
fn find_walls(
    points: &[Point3<f64>],
    planes: &mut [FoundPlane],
    caps: &Caps,
    centre: &Point3<f64>,
    p: &SegmentParams,
) -> Vec<usize> {
    let sin_v = p.vertical_deg.to_radians().sin();
    let up = caps.up;
    let mut walls = Vec::new();
    for (k, plane) in planes.iter_mut().enumerate() {
        if plane.class != PlaneClass::Slanted || plane.plane.normal.dot(&up).abs() > sin_v {
            continue; // horizontal (classified above) or slanted
        }
        let mut hs: Vec<f64> = plane
            .inliers
            .iter()
            .map(|&i| height(&points[i], &up))
            .collect();
        let (bottom, top) = (percentile(&mut hs, 0.05), percentile(&mut hs, 0.98));
        let along = keep_main_run(plane, points, &up);
        if top - bottom >= p.wall_min_height_fraction * (caps.h_ceiling - caps.h_floor)
            && top >= caps.h_ceiling - p.wall_ceiling_gap_m
            && along >= 0.5
        {
            let c = mean_of(points, &plane.inliers);
            plane.plane = vertical_plane(&plane.plane.normal, &c, &up, centre);
            plane.class = PlaneClass::Wall;
            walls.push(k);
        } else {
            plane.class = PlaneClass::OtherVertical;
        }
    }
    walls
}

/// Whether walls `a` and `b` are one wall found twice: directions within `merge_deg`, lines within
/// `merge_distance_m`, extents overlapping.
fn same_wall(
    points: &[Point3<f64>],
    planes: &[FoundPlane],
    (a, b): (usize, usize),
    up: &Unit<Vector3<f64>>,
    p: &SegmentParams,
) -> bool {
    let (pa, pb) = (planes[a].plane, planes[b].plane);
    if pa.normal.dot(&pb.normal) < p.merge_deg.to_radians().cos() {
        return false;
    }
    if pa.distance(&mean_of(points, &planes[b].inliers)).abs() > p.merge_distance_m {
        return false;
    }
    let d = up.cross(&pa.normal);
    let span = |k: usize| {
        let mut s: Vec<f64> = planes[k]
            .inliers
            .iter()
            .map(|&i| d.dot(&points[i].coords))
            .collect();
        (percentile(&mut s, 0.05), percentile(&mut s, 0.95))
    };
    let ((a0, a1), (b0, b1)) = (span(a), span(b));
    a1.min(b1) - a0.max(b0) > 0.0
}

/// One wall found twice (a doubled slab in a noisy cloud): merges walls that are the same wall
/// into the first and refits it.
fn merge_doubled_walls(
    points: &[Point3<f64>],
    planes: &mut [FoundPlane],
    walls: &mut Vec<usize>,
    up: &Unit<Vector3<f64>>,
    centre: &Point3<f64>,
    p: &SegmentParams,
) {
    'again: loop {
        for a in 0..walls.len() {
            for b in (a + 1)..walls.len() {
                let (ka, kb) = (walls[a], walls[b]);
                if !same_wall(points, planes, (ka, kb), up, p) {
                    continue;
                }
                let moved = std::mem::take(&mut planes[kb].inliers);
                planes[ka].inliers.extend(moved);
                planes[ka].points = planes[ka].inliers.len();
                planes[kb].points = 0;
                planes[kb].class = PlaneClass::OtherVertical;
                let pts: Vec<Point3<f64>> = planes[ka].inliers.iter().map(|&i| points[i]).collect();
                if let Some(f) = Plane::fit(&pts) {
                    planes[ka].plane = vertical_plane(&f.normal, &centroid(&pts), up, centre);
                }
                walls.remove(b);
                continue 'again;
            }
        }
        break;
    }
}

/// A shadow of a wall: a weaker vertical plane, tilted a few degrees from a wall, whose points
/// mostly lie within the wall's slab (RANSAC's leftovers of a thick fused wall plus whatever
/// stands against it; long scans gather enough of them). It is not a wall of its own: drops walls
/// within `SHADOW_DEG` of a wall with `SHADOW_RATIO` times their points when most of their points
/// lie within two inlier distances of that wall's plane.
fn drop_shadow_walls(
    points: &[Point3<f64>],
    planes: &mut [FoundPlane],
    walls: &mut Vec<usize>,
    p: &SegmentParams,
) {
    const SHADOW_DEG: f64 = 15.0;
    const SHADOW_RATIO: usize = 4;
    let shadows: Vec<usize> = walls
        .iter()
        .copied()
        .filter(|&w| {
            walls.iter().any(|&v| {
                let (pv, pw) = (&planes[v].plane, &planes[w].plane);
                v != w
                    && planes[v].points >= SHADOW_RATIO * planes[w].points
                    && pv.normal.dot(&pw.normal) >= SHADOW_DEG.to_radians().cos()
                    && planes[w]
                        .inliers
                        .iter()
                        .filter(|&&i| pv.distance(&points[i]).abs() < 2.0 * p.plane_distance_m)
                        .count()
                        * 2
                        > planes[w].points
            })
        })
        .collect();
    for &w in &shadows {
        planes[w].class = PlaneClass::OtherVertical;
    }
    walls.retain(|w| !shadows.contains(w));
}

/// A wall's line on the floor plan and the extent of its points along it.
struct Line {
    k: usize,
    p: Point2<f64>,
    d: Vector2<f64>,
    ends: [Point2<f64>; 2],
}

impl Line {
    fn length(&self) -> f64 {
        (self.ends[1] - self.ends[0]).norm()
    }
}

/// The walls' lines and extents in the horizontal frame.
fn wall_lines(
    points: &[Point3<f64>],
    planes: &[FoundPlane],
    walls: &[usize],
    frame: &PlaneFrame,
) -> Vec<Line> {
    walls
        .iter()
        .map(|&k| {
            let pl = &planes[k].plane;
            let n2 = Vector2::new(frame.u.dot(&pl.normal), frame.v.dot(&pl.normal)).normalize();
            let d = Vector2::new(-n2.y, n2.x);
            let on = frame.to_2d(&pl.project(&frame.origin));
            let mut s: Vec<f64> = planes[k]
                .inliers
                .iter()
                .map(|&i| (frame.to_2d(&points[i]) - on).dot(&d))
                .collect();
            let (a, b) = (percentile(&mut s, 0.02), percentile(&mut s, 0.98));
            Line {
                k,
                p: on,
                d,
                ends: [on + d * a, on + d * b],
            }
        })
        .collect()
}

/// The wall lines, for an error message.
fn describe_lines(lines: &[Line], planes: &[FoundPlane]) -> String {
    lines
        .iter()
        .map(|l| {
            let d = l.ends[1] - l.ends[0];
            format!(
                "{:.0}° {:.2} m long at ({:.2}, {:.2}), {} points",
                d.y.atan2(d.x).to_degrees(),
                d.norm(),
                l.ends[0].x,
                l.ends[0].y,
                planes[l.k].points
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// At one end of a wall: the wall it meets there and the corner.
type End = Option<(usize, Point2<f64>)>;

/// Links wall ends: the corner of two walls is their lines' intersection; ends are paired
/// greedily by how far the corner lies from both ends.
fn link_ends(lines: &[Line], p: &SegmentParams) -> Vec<[End; 2]> {
    let mut pairs: Vec<(f64, usize, usize, usize, usize, Point2<f64>)> = Vec::new();
    for a in 0..lines.len() {
        for b in (a + 1)..lines.len() {
            let (la, lb) = (&lines[a], &lines[b]);
            if la.d.dot(&lb.d).abs() > p.corner_min_angle_deg.to_radians().cos() {
                continue;
            }
            let Some(c) = line_intersection(&la.p, &la.d, &lb.p, &lb.d) else {
                continue;
            };
            for ea in 0..2 {
                for eb in 0..2 {
                    let cost = (c - la.ends[ea]).norm() + (c - lb.ends[eb]).norm();
                    if cost < p.corner_max_gap_m {
                        pairs.push((cost, a, ea, b, eb, c));
                    }
                }
            }
        }
    }
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut link: Vec<[End; 2]> = vec![[None, None]; lines.len()];
    for (_, a, ea, b, eb, c) in pairs {
        if link[a][ea].is_none() && link[b][eb].is_none() && link[a][1 - ea].map(|l| l.0) != Some(b)
        {
            link[a][ea] = Some((b, c));
            link[b][eb] = Some((a, c));
        }
    }
    link
}

/// Walks the loop of linked walls from the longest: the lines in order and the corners, corner
/// `k` joining walls `k` and `k + 1`; `None` with the walls linked when the loop does not close.
fn walk_loop(lines: &[Line], link: &[[End; 2]]) -> Result<(Vec<usize>, Vec<Point2<f64>>), usize> {
    let start = (0..lines.len())
        .max_by(|&a, &b| lines[a].length().total_cmp(&lines[b].length()))
        .ok_or(0usize)?;
    let mut order = vec![start];
    let mut corners = Vec::new();
    let (mut cur, mut out_end) = (start, 1usize);
    loop {
        let Some((next, c)) = link[cur][out_end] else {
            return Err(order.len());
        };
        corners.push(c);
        if next == start {
            break;
        }
        if order.contains(&next) || order.len() > lines.len() {
            return Err(order.len());
        }
        let in_end = if link[next][0].map(|l| l.0) == Some(cur) {
            0
        } else {
            1
        };
        order.push(next);
        cur = next;
        out_end = 1 - in_end;
    }
    if order.len() < 3 {
        return Err(order.len());
    }
    Ok((order, corners))
}

/// Classifies planes against an up estimate, picks floor and ceiling, refines up from the floor,
/// links the walls into a loop and computes the corners.
pub fn envelope(
    points: &[Point3<f64>],
    mut planes: Vec<FoundPlane>,
    up0: Unit<Vector3<f64>>,
    p: &SegmentParams,
) -> Result<Envelope, SegmentError> {
    let caps = floor_and_ceiling(points, &mut planes, up0, p)?;
    let up = caps.up;
    let centre = room_centre(points, &caps);
    let mut walls = find_walls(points, &mut planes, &caps, &centre, p);
    merge_doubled_walls(points, &mut planes, &mut walls, &up, &centre, p);
    drop_shadow_walls(points, &mut planes, &mut walls, p);
    // The horizontal frame and the walls' lines and extents in it.
    let frame = PlaneFrame::new(planes[caps.floor].plane.project(&centre), up, &Vector3::x());
    let lines = wall_lines(points, &planes, &walls, &frame);
    let link = link_ends(&lines, p);
    let found = describe_lines(&lines, &planes);
    if lines.is_empty() {
        return Err(SegmentError::NoWalls);
    }
    let (order, mut corners2) =
        walk_loop(&lines, &link).map_err(|walls| SegmentError::OpenOutline {
            walls,
            found: found.clone(),
        })?;
    // corners2[k] joins order[k] and order[k+1]; rotate so corner k joins wall k−1 and wall k.
    corners2.rotate_right(1);
    let mut wall_order: Vec<usize> = order.iter().map(|&i| lines[i].k).collect();
    if signed_area(&corners2) < 0.0 {
        // Counter-clockwise seen from above: reverse, keeping corner k between walls k−1 and k
        // (the new corner k is the old corner n−k).
        wall_order.reverse();
        corners2.reverse();
        corners2.rotate_right(1);
    }
    for k in walls.iter().filter(|k| !wall_order.contains(k)) {
        planes[*k].class = PlaneClass::OtherVertical;
    }
    let n = wall_order.len();
    let corner3 = |k: usize, cap: &Plane| {
        let (a, b) = (
            &planes[wall_order[(k + n - 1) % n]].plane,
            &planes[wall_order[k]].plane,
        );
        intersect_three(a, b, cap)
    };
    let floor_corners: Option<Vec<Point3<f64>>> = (0..n)
        .map(|k| corner3(k, &planes[caps.floor].plane))
        .collect();
    let ceiling_corners: Option<Vec<Point3<f64>>> = (0..n)
        .map(|k| corner3(k, &planes[caps.ceiling].plane))
        .collect();
    let (Some(floor_corners), Some(ceiling_corners)) = (floor_corners, ceiling_corners) else {
        return Err(SegmentError::OpenOutline { walls: n, found });
    };
    Ok(Envelope {
        up,
        floor: caps.floor,
        ceiling: caps.ceiling,
        walls: wall_order,
        floor_corners,
        ceiling_corners,
        planes,
        frame,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on a rectangle spanned from `o` along `a` and `b` (5 cm grid).
    fn sheet(o: [f64; 3], a: [f64; 3], b: [f64; 3], pts: &mut Vec<Point3<f64>>) -> Vec<usize> {
        let (o, a, b) = (Vector3::from(o), Vector3::from(a), Vector3::from(b));
        let (na, nb) = ((a.norm() / 0.05) as usize, (b.norm() / 0.05) as usize);
        let start = pts.len();
        for i in 0..=na {
            for j in 0..=nb {
                pts.push(Point3::from(
                    o + a * (i as f64 / na as f64) + b * (j as f64 / nb as f64),
                ));
            }
        }
        (start..pts.len()).collect()
    }

    fn found(points: &[Point3<f64>], inliers: Vec<usize>) -> FoundPlane {
        let pts: Vec<Point3<f64>> = inliers.iter().map(|&i| points[i]).collect();
        FoundPlane {
            plane: Plane::fit(&pts).expect("a plane"),
            points: inliers.len(),
            inliers,
            class: PlaneClass::Slanted,
        }
    }

    /// A 4 × 3 × 2.7 m box room and its planes (the wall at y = 0 seen only between x = 0.6 and
    /// 3.4 m), plus `extra` planes' points.
    fn box_room(extra: &[Vec<Point3<f64>>]) -> (Vec<Point3<f64>>, Vec<FoundPlane>) {
        let (w, d, h) = (4.0, 3.0, 2.7);
        let mut pts = Vec::new();
        let sheets = [
            sheet([0.0, 0.0, 0.0], [w, 0.0, 0.0], [0.0, d, 0.0], &mut pts),
            sheet([0.0, 0.0, h], [w, 0.0, 0.0], [0.0, d, 0.0], &mut pts),
            sheet(
                [0.6, 0.0, 0.0],
                [w - 1.2, 0.0, 0.0],
                [0.0, 0.0, h],
                &mut pts,
            ),
            sheet([w, 0.0, 0.0], [0.0, d, 0.0], [0.0, 0.0, h], &mut pts),
            sheet([0.0, d, 0.0], [w, 0.0, 0.0], [0.0, 0.0, h], &mut pts),
            sheet([0.0, 0.0, 0.0], [0.0, d, 0.0], [0.0, 0.0, h], &mut pts),
        ];
        let mut planes: Vec<FoundPlane> = sheets.into_iter().map(|s| found(&pts, s)).collect();
        for e in extra {
            let start = pts.len();
            pts.extend_from_slice(e);
            planes.push(found(&pts, (start..pts.len()).collect()));
        }
        (pts, planes)
    }

    /// A weak plane tilted 6° from the wall at y = 0, along the wall's whole length and mostly
    /// within its slab: the long full-office scan's failure. With the wall's ends hidden (by
    /// furniture, say), the shadow's ends lie nearer the corners than the wall's.
    fn shadow_of_front_wall() -> Vec<Point3<f64>> {
        let tilt = 6f64.to_radians().tan();
        let mut v = Vec::new();
        for i in 0..=40 {
            for j in 0..=13 {
                let x = i as f64 * 0.1;
                v.push(Point3::new(x, -0.1 + x * tilt, j as f64 * 0.2));
            }
        }
        v
    }

    #[test]
    fn a_box_room_closes_with_four_walls() {
        let (pts, planes) = box_room(&[]);
        let env = envelope(&pts, planes, Vector3::z_axis(), &SegmentParams::default())
            .expect("an envelope");
        assert_eq!(env.walls.len(), 4);
        for c in &env.floor_corners {
            let near = [[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]]
                .iter()
                .map(|q| (c.x - q[0]).hypot(c.y - q[1]))
                .fold(f64::INFINITY, f64::min);
            assert!(near < 1e-6 && c.z.abs() < 1e-6, "corner {c:?}");
        }
    }

    /// A wall's shadow plane is dropped instead of breaking the loop of walls.
    #[test]
    fn a_shadow_of_a_wall_is_not_a_wall() {
        let (pts, planes) = box_room(&[shadow_of_front_wall()]);
        let shadow = planes.len() - 1;
        let env = envelope(&pts, planes, Vector3::z_axis(), &SegmentParams::default())
            .expect("an envelope");
        assert_eq!(env.walls.len(), 4);
        assert!(!env.walls.contains(&shadow));
        assert_eq!(env.planes[shadow].class, PlaneClass::OtherVertical);
    }
}
