//! Furniture as occluders: what the cloud holds off the envelope (desks, cabinets, sofas) blocks
//! part of the room from view and radiates at its own temperature, so it belongs in the scene.
//!
//! Points on no envelope surface, inside the room and clear of the walls (by each wall's band and
//! 5 cm, at least `furniture_wall_clearance_m`: closer, they are the noisy remainder of a wall), are
//! grouped by connectivity on a
//! 5 cm grid. A group of at least `furniture_min_points` points, 0.02 m³ and 15 cm across both
//! horizontal axes becomes a box in the
//! room's axes (along the longest wall, across it, up), spanning the 1st–99th percentiles of its
//! points, extended to the floor when it ends within 15 cm of it (furniture stands on the floor),
//! at the radiant average of its points, grown over floor never seen on sides where a few of its
//! points continue (a sofa seen from its end). Groups reaching within 15 cm of the ceiling are wall
//! remainders too, and so are groups most of whose points were seen in one frame only (depth
//! noise off a wall; real furniture is seen frame after frame).

use std::collections::{HashMap, VecDeque};

use mrtmap_geometry::nalgebra::{Point2, Point3, Unit, Vector3};
use mrtmap_geometry::polygon::{Containment, point_in_polygon};
use mrtmap_physics::{RadiantAverage, Temperature};

use super::SegmentParams;

/// A piece of furniture: a box in the room's axes.
#[derive(Clone, Debug)]
pub struct FoundFurniture {
    /// The eight corners (world); corner c has bit 0 = along, bit 1 = across, bit 2 = up (the
    /// order of [`mrtmap_geometry::box_corners`], so [`mrtmap_geometry::BOX_TRIANGLES`] apply).
    pub corners: [Point3<f64>; 8],
    /// Size along, across and up (m).
    pub size_m: [f64; 3],
    /// Radiant temperature (K).
    pub temperature_k: f64,
    /// Its cloud points.
    pub points: Vec<usize>,
}

fn percentile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// The room as furniture is sought in it.
pub struct Room<'a> {
    /// Up.
    pub up: Unit<Vector3<f64>>,
    /// A horizontal direction the boxes are aligned with (the longest wall).
    pub along: Vector3<f64>,
    /// Height of the floor along `up`.
    pub floor_height: f64,
    /// Floor to ceiling (m).
    pub room_height: f64,
    /// The floor outline in (along, across) coordinates.
    pub floor_2d: &'a [Point2<f64>],
    /// The walls' planes with the clearance furniture keeps from each.
    pub wall_planes: &'a [(mrtmap_geometry::Plane, f64)],
    /// The 5 cm cells (along, across) where the floor was seen.
    pub floor_seen: &'a std::collections::HashSet<(i32, i32)>,
}

/// Side of a floor cell (m).
pub const FLOOR_CELL_M: f64 = 0.05;

/// The room's horizontal axes (along, across).
fn axes(room: &Room<'_>) -> (Vector3<f64>, Vector3<f64>) {
    let up = &room.up;
    let u = (room.along - up.as_ref() * room.along.dot(up)).normalize();
    (u, up.cross(&u))
}

/// A 3D cell of 5 cm.
type Cell = [i32; 3];

/// Unassigned points off the floor, below the ceiling, inside the outline and clear of the walls,
/// in 5 cm cells of the room's axes.
fn candidate_cells(
    pos: &[Point3<f64>],
    surface_id: &[i32],
    room: &Room<'_>,
    p: &SegmentParams,
) -> HashMap<Cell, Vec<usize>> {
    const CELL: f64 = 0.05;
    let (u, v) = axes(room);
    let up = &room.up;
    let mut grid: HashMap<Cell, Vec<usize>> = HashMap::new();
    for (i, q) in pos.iter().enumerate() {
        if surface_id[i] >= 0 {
            continue;
        }
        let h = up.dot(&q.coords) - room.floor_height;
        if h < 0.02 || h > room.room_height - 0.1 {
            continue;
        }
        let q2 = Point2::new(u.dot(&q.coords), v.dot(&q.coords));
        if point_in_polygon(&q2, room.floor_2d, p.furniture_wall_clearance_m) != Containment::Inside
        {
            continue;
        }
        if room
            .wall_planes
            .iter()
            .any(|(w, clearance)| w.distance(q).abs() < clearance.max(p.furniture_wall_clearance_m))
        {
            continue;
        }
        let k = [
            (u.dot(&q.coords) / CELL).floor() as i32,
            (v.dot(&q.coords) / CELL).floor() as i32,
            (h / CELL).floor() as i32,
        ];
        grid.entry(k).or_default().push(i);
    }
    grid
}

/// The points of each group of touching cells (26-connectivity), groups in cell order.
fn cell_components(grid: &HashMap<Cell, Vec<usize>>) -> Vec<Vec<usize>> {
    let mut seen: HashMap<Cell, bool> = HashMap::new();
    let mut keys: Vec<Cell> = grid.keys().copied().collect();
    keys.sort_unstable();
    let mut out = Vec::new();
    for start in keys {
        if seen.contains_key(&start) {
            continue;
        }
        let mut comp = Vec::new();
        let mut queue = VecDeque::from([start]);
        seen.insert(start, true);
        while let Some(c) = queue.pop_front() {
            comp.extend(grid[&c].iter().copied());
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let n = [c[0] + dx, c[1] + dy, c[2] + dz];
                        if grid.contains_key(&n) && !seen.contains_key(&n) {
                            seen.insert(n, true);
                            queue.push_back(n);
                        }
                    }
                }
            }
        }
        out.push(comp);
    }
    out
}

/// A box standing on the floor (`h0` = 0) grown, on the sides where a few of its points lie more
/// than 10 cm beyond it (`beyond`: the part of a sofa the walk saw only from its end), 5 cm at a
/// time and by at most 1 m, over floor that was never seen and lies inside the room (that part hides
/// the floor under it); growth stops at floor seen (a fifth of a strip) or at the outline.
fn grow_over_hidden_floor(
    room: &Room<'_>,
    [mut a0, mut a1, mut b0, mut b1]: [f64; 4],
    beyond: [f64; 4],
    h0: f64,
) -> (f64, f64, f64, f64) {
    if h0 > 0.0 || room.floor_seen.is_empty() {
        return (a0, a1, b0, b1);
    }
    let c = FLOOR_CELL_M;
    // Whether the strip of floor cells from `s0` to `s1` at `t` (across the strip) is hidden
    // floor inside the room; `along_b` when the strip runs along b.
    let hidden = |along_b: bool, s0: f64, s1: f64, t: f64| {
        let kt = (t / c).floor() as i32;
        let (mut seen, mut total) = (0usize, 0usize);
        for k in (s0 / c).floor() as i32..=(s1 / c).floor() as i32 {
            let cell = if along_b { (kt, k) } else { (k, kt) };
            let centre = Point2::new((cell.0 as f64 + 0.5) * c, (cell.1 as f64 + 0.5) * c);
            if point_in_polygon(&centre, room.floor_2d, 0.0) != Containment::Inside {
                return false;
            }
            total += 1;
            seen += usize::from(room.floor_seen.contains(&cell));
        }
        total > 0 && seen * 5 < total
    };
    let grow = beyond.map(|d| d > 0.1);
    for _ in 0..20 {
        let mut grew = false;
        if grow[0] && hidden(true, b0, b1, a0 - c / 2.0) {
            a0 -= c;
            grew = true;
        }
        if grow[1] && hidden(true, b0, b1, a1 + c / 2.0) {
            a1 += c;
            grew = true;
        }
        if grow[2] && hidden(false, a0, a1, b0 - c / 2.0) {
            b0 -= c;
            grew = true;
        }
        if grow[3] && hidden(false, a0, a1, b1 + c / 2.0) {
            b1 += c;
            grew = true;
        }
        if !grew {
            break;
        }
    }
    (a0, a1, b0, b1)
}

/// A group's box in the room's axes (1–99 % of its points; standing on the floor when within
/// 15 cm of it), unless it is the remainder of a wall, the floor or a picture.
fn furniture_box(
    comp: Vec<usize>,
    pos: &[Point3<f64>],
    temp_k: &[f64],
    observations: &[u32],
    room: &Room<'_>,
) -> Option<FoundFurniture> {
    // Most of its points seen in one frame only: depth noise off a wall, not an object (furniture
    // is seen from frame after frame like the walls behind it).
    let mut obs: Vec<u32> = comp
        .iter()
        .map(|&i| observations.get(i).copied().unwrap_or(1))
        .collect();
    obs.sort_unstable();
    if obs[obs.len() / 2] <= 1 {
        return None;
    }
    let (u, v) = axes(room);
    let up = &room.up;
    let mut a: Vec<f64> = comp.iter().map(|&i| u.dot(&pos[i].coords)).collect();
    let mut b: Vec<f64> = comp.iter().map(|&i| v.dot(&pos[i].coords)).collect();
    let mut h: Vec<f64> = comp
        .iter()
        .map(|&i| up.dot(&pos[i].coords) - room.floor_height)
        .collect();
    let (a0, a1) = (percentile(&mut a, 0.01), percentile(&mut a, 0.99));
    let (b0, b1) = (percentile(&mut b, 0.01), percentile(&mut b, 0.99));
    // The extreme points beyond the trimmed box, per side (a, b; low, high).
    let beyond = [
        a0 - a[0],
        a[a.len() - 1] - a1,
        b0 - b[0],
        b[b.len() - 1] - b1,
    ];
    let (mut h0, h1) = (percentile(&mut h, 0.01), percentile(&mut h, 0.99));
    if h0 < 0.15 {
        h0 = 0.0;
    }
    // Reaching the ceiling, it is the noisy remainder of a wall; lower than 20 cm, the remainder
    // of the floor (or a rug, which is floor): not furniture.
    if h1 > room.room_height - 0.15 || h1 < 0.2 {
        return None;
    }
    let (a0, a1, b0, b1) = grow_over_hidden_floor(room, [a0, a1, b0, b1], beyond, h0);
    let size = [a1 - a0, b1 - b0, h1 - h0];
    // Thinner than 15 cm across, it is the noisy remainder of a wall or a picture, not furniture.
    if size[0].min(size[1]) < 0.15 || size[2] < 0.05 || size[0] * size[1] * size[2] < 0.02 {
        return None;
    }
    let mut avg = RadiantAverage::new();
    for &i in &comp {
        avg.add(Temperature::from_kelvin(temp_k[i]), 1.0);
    }
    let t = avg.mean()?;
    let corners = std::array::from_fn(|c| {
        let x = if c & 1 == 0 { a0 } else { a1 };
        let y = if c & 2 == 0 { b0 } else { b1 };
        let z = room.floor_height + if c & 4 == 0 { h0 } else { h1 };
        Point3::from(u * x + v * y + up.as_ref() * z)
    });
    Some(FoundFurniture {
        corners,
        size_m: size,
        temperature_k: t.kelvin(),
        points: comp,
    })
}

/// Finds furniture among the points on no surface (`surface_id` −1).
pub fn find_furniture(
    pos: &[Point3<f64>],
    temp_k: &[f64],
    observations: &[u32],
    surface_id: &[i32],
    room: &Room<'_>,
    p: &SegmentParams,
) -> Vec<FoundFurniture> {
    let grid = candidate_cells(pos, surface_id, room, p);
    cell_components(&grid)
        .into_iter()
        .filter(|comp| comp.len() >= p.furniture_min_points)
        .filter(|comp| !comp.is_empty())
        .filter_map(|comp| furniture_box(comp, pos, temp_k, observations, room))
        .collect()
}
