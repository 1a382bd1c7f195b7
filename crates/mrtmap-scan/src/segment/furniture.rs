//! Furniture as occluders: what the cloud holds off the envelope (desks, cabinets, sofas) blocks
//! part of the room from view and radiates at its own temperature, so it belongs in the scene.
//!
//! Points on no envelope surface, inside the room and clear of the walls (by each wall's band and
//! 5 cm, at least `furniture_wall_clearance_m`: closer, they are the noisy remainder of a wall), are
//! grouped by connectivity on a
//! 5 cm grid; a group then takes in, up to 25 cm into a wall's band, the points of vertical faces
//! running across the wall next to it (a bookcase's front reaching to within 11 cm of a wall whose
//! band is 28 cm thick). A group of at least `furniture_min_points` points, 0.02 m³ and 15 cm across both
//! horizontal axes becomes a box in the
//! room's axes (along the longest wall, across it, up), each side at the median of its face's
//! points (those whose normals point out of it: a face is fused as thick as the depth noise) or,
//! without a face, at the 1st/99th percentile of its points, extended to the floor when it ends
//! within 15 cm of it (furniture stands on the floor), at the radiant average of its points, grown
//! over floor never seen on sides where a few of its points continue (a sofa seen from its end) or
//! that end within reach of a wall (its points near the wall were left to the wall: a bookcase
//! against it). Groups reaching within 15 cm of the ceiling are wall
//! remainders too unless they stand 30 cm or more from every wall (a column, taken to the
//! ceiling), and so are groups most of whose points were seen in one frame only (depth
//! noise off a wall; real furniture is seen frame after frame).

use std::collections::{HashMap, VecDeque};

use mrtmap_geometry::nalgebra::{Point2, Point3, Unit, Vector3};
use mrtmap_geometry::polygon::{Containment, point_in_polygon};
use mrtmap_physics::{RadiantAverage, Temperature};

use super::Envelope;
use super::SegmentParams;
use super::membership::Points;

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

/// A group reaching the ceiling is a column, not a wall's remainder, when its box stands at least
/// this far (m) from every wall (a wall's noisy remainder lies within its band and 5 cm).
const FREE_STANDING_M: f64 = 0.3;

/// A 3D cell of 5 cm.
type Cell = [i32; 3];

/// Unassigned points off the floor, below the ceiling, inside the outline and clear of the walls,
/// in 5 cm cells of the room's axes.
fn candidate_cells(
    pos: &[Point3<f64>],
    nrm: &[Vector3<f64>],
    surface_id: &[i32],
    room: &Room<'_>,
    p: &SegmentParams,
) -> (HashMap<Cell, Vec<usize>>, HashMap<Cell, Vec<usize>>) {
    const CELL: f64 = 0.05;
    let (u, v) = axes(room);
    let up = &room.up;
    let mut grid: HashMap<Cell, Vec<usize>> = HashMap::new();
    let mut band: HashMap<Cell, Vec<usize>> = HashMap::new();
    for (i, q) in pos.iter().enumerate() {
        if surface_id[i] >= 0 {
            continue;
        }
        let h = up.dot(&q.coords) - room.floor_height;
        if h < 0.02 || h > room.room_height - 0.1 {
            continue;
        }
        let q2 = Point2::new(u.dot(&q.coords), v.dot(&q.coords));
        let k = [
            (u.dot(&q.coords) / CELL).floor() as i32,
            (v.dot(&q.coords) / CELL).floor() as i32,
            (h / CELL).floor() as i32,
        ];
        let near = room.wall_planes.iter().filter(|(w, clearance)| {
            w.distance(q).abs() < clearance.max(p.furniture_wall_clearance_m)
        });
        let inside = point_in_polygon(&q2, room.floor_2d, p.furniture_wall_clearance_m)
            == Containment::Inside;
        if inside && near.clone().next().is_none() {
            grid.entry(k).or_default().push(i);
        } else if point_in_polygon(&q2, room.floor_2d, 0.0) == Containment::Inside
            && nrm[i].dot(up).abs() < 0.3
            && near
                .clone()
                .all(|(w, _)| w.distance(q).abs() > 0.03 && nrm[i].dot(&w.normal).abs() < 0.3)
        {
            // In a wall's band but a vertical face across it, more than 3 cm off it: perhaps
            // the end of a face of furniture standing near the wall (a bookcase's front running
            // into the band; taken only next to furniture found outside it).
            band.entry(k).or_default().push(i);
        }
    }
    (grid, band)
}

/// Band cells (see [`candidate_cells`]) reached from a group's cells through touching band cells,
/// at most `steps` cells away: the part of a piece of furniture inside a wall's band.
fn reach_into_band(
    comp_cells: &[Cell],
    band: &HashMap<Cell, Vec<usize>>,
    steps: usize,
) -> Vec<usize> {
    let mut seen: std::collections::HashSet<Cell> = comp_cells.iter().copied().collect();
    let mut front: Vec<Cell> = comp_cells.to_vec();
    let mut out = Vec::new();
    for _ in 0..steps {
        let mut next = Vec::new();
        for c in &front {
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let n = [c[0] + dx, c[1] + dy, c[2] + dz];
                        if band.contains_key(&n) && seen.insert(n) {
                            out.extend(band[&n].iter().copied());
                            next.push(n);
                        }
                    }
                }
            }
        }
        if next.is_empty() {
            break;
        }
        front = next;
    }
    out
}

/// The points of each group of touching cells (26-connectivity), groups in cell order. Groups
/// grow through `strong` cells only (those with a point seen in more than one frame); a cell of
/// points seen once joins a group it touches but does not carry it further. Such points are often
/// depth noise: a wall seen from afar is fused as a slab scattered beyond its band (a T-shaped
/// room's west wall out to 1.3 m, 91 % of those points seen once), and a chain of their cells
/// joined a cabinet into a box 2.7 m deep and 1.7 m tall (82 % of the cabinet's own points were
/// seen twice or more). Groups of such cells alone are not furniture either (see
/// [`furniture_box`]).
fn cell_components(
    grid: &HashMap<Cell, Vec<usize>>,
    strong: impl Fn(&Cell) -> bool,
) -> Vec<(Vec<Cell>, Vec<usize>)> {
    let mut seen: HashMap<Cell, bool> = HashMap::new();
    let mut keys: Vec<Cell> = grid.keys().copied().filter(|c| strong(c)).collect();
    keys.sort_unstable();
    let mut out = Vec::new();
    for start in keys {
        if seen.contains_key(&start) {
            continue;
        }
        let (mut comp, mut cells) = (Vec::new(), Vec::new());
        let mut queue = VecDeque::from([start]);
        seen.insert(start, true);
        while let Some(c) = queue.pop_front() {
            comp.extend(grid[&c].iter().copied());
            cells.push(c);
            if !strong(&c) {
                continue;
            }
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
        out.push((cells, comp));
    }
    out
}

/// A box standing on the floor (`h0` = 0) grown, on the sides where a few of its points lie more
/// than 10 cm beyond it (`beyond`: the part of a sofa the walk saw only from its end), 5 cm at a
/// time and by at most 1 m, over floor that was never seen and lies inside the room (that part hides
/// the floor under it); growth stops at floor seen (a fifth of a strip's cells inside the room) or
/// where most of the strip lies beyond the outline.
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
    // floor inside the room; `along_b` when the strip runs along b. Cells beyond the outline do
    // not count (a box grown to a wall on one side reaches the outline at the ends of its strips
    // on the others); a strip mostly beyond it is the outline reached.
    let hidden = |along_b: bool, s0: f64, s1: f64, t: f64| {
        let kt = (t / c).floor() as i32;
        let (mut seen, mut inside, mut total) = (0usize, 0usize, 0usize);
        for k in (s0 / c).floor() as i32..=(s1 / c).floor() as i32 {
            let cell = if along_b { (kt, k) } else { (k, kt) };
            let centre = Point2::new((cell.0 as f64 + 0.5) * c, (cell.1 as f64 + 0.5) * c);
            total += 1;
            if point_in_polygon(&centre, room.floor_2d, 0.0) != Containment::Inside {
                continue;
            }
            inside += 1;
            seen += usize::from(room.floor_seen.contains(&cell));
        }
        inside * 2 > total && seen * 5 < inside
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

/// The cloud's positions, normals, radiant temperatures (K) and observation counts.
type CloudView<'a> = (&'a [Point3<f64>], &'a [Vector3<f64>], &'a [f64], &'a [u32]);

/// A side of a box at the middle of its face: the median of the points whose normals point out
/// of that side (within 37° of the axis) in the outer 30 cm, when there are enough of them. A
/// face is fused as thick as the depth noise at the distance it was seen from (±12 cm on the
/// L-shaped room's bookcase, seen from 3–4 m), and the 1st or 99th percentile lies at its outer
/// edge: the bookcase's front came out 15 cm into the room, its face's median within 6 mm.
fn face_side(coord: &[f64], normal: &[f64], outward: f64, edge: f64) -> f64 {
    let mut face: Vec<f64> = coord
        .iter()
        .zip(normal)
        .filter(|(c, n)| *n * outward > 0.8 && (edge - *c) * outward < 0.3)
        .map(|(c, _)| *c)
        .collect();
    if face.len() < 50.max(coord.len() / 20) {
        return edge;
    }
    let m = percentile(&mut face, 0.5);
    // Never beyond the points' own extent.
    if outward > 0.0 {
        m.min(edge)
    } else {
        m.max(edge)
    }
}

/// A group's box in the room's axes (its sides' and top's faces' medians, or 1–99 % of its points;
/// standing on the floor when within 15 cm of it), unless it is the remainder of a wall, the floor or a picture.
fn furniture_box(
    comp: Vec<usize>,
    cloud: CloudView<'_>,
    room: &Room<'_>,
    wall_reach_m: f64,
) -> Option<FoundFurniture> {
    let (pos, nrm, temp_k, observations) = cloud;
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
    let na: Vec<f64> = comp.iter().map(|&i| u.dot(&nrm[i])).collect();
    let nb: Vec<f64> = comp.iter().map(|&i| v.dot(&nrm[i])).collect();
    let nh: Vec<f64> = comp.iter().map(|&i| up.dot(&nrm[i])).collect();
    let (ca, cb, ch) = (a.clone(), b.clone(), h.clone());
    let (a0, a1) = (percentile(&mut a, 0.01), percentile(&mut a, 0.99));
    let (b0, b1) = (percentile(&mut b, 0.01), percentile(&mut b, 0.99));
    // The extreme points beyond the trimmed box, per side (a, b; low, high).
    let mut beyond = [
        a0 - a[0],
        a[a.len() - 1] - a1,
        b0 - b[0],
        b[b.len() - 1] - b1,
    ];
    let (a0, a1) = (face_side(&ca, &na, -1.0, a0), face_side(&ca, &na, 1.0, a1));
    let (b0, b1) = (face_side(&cb, &nb, -1.0, b0), face_side(&cb, &nb, 1.0, b1));
    // A side within reach of a wall: its points near the wall were left out as the wall's own
    // (furniture keeps a clearance from walls), so furniture standing against the wall grows to
    // it over floor never seen.
    let (mid_a, mid_b) = ((a0 + a1) / 2.0, (b0 + b1) / 2.0);
    let near_wall = |x: f64, y: f64| {
        point_in_polygon(&Point2::new(x, y), room.floor_2d, 0.0) != Containment::Inside
    };
    let sides = [
        (a0 - wall_reach_m, mid_b),
        (a1 + wall_reach_m, mid_b),
        (mid_a, b0 - wall_reach_m),
        (mid_a, b1 + wall_reach_m),
    ];
    for (k, (x, y)) in sides.into_iter().enumerate() {
        if near_wall(x, y) {
            beyond[k] = beyond[k].max(1.0);
        }
    }
    let (mut h0, mut h1) = (percentile(&mut h, 0.01), percentile(&mut h, 0.99));
    if h0 < 0.15 {
        h0 = 0.0;
    }
    // Reaching the ceiling, it is the noisy remainder of a wall, unless it stands at least
    // [`FREE_STANDING_M`] from every wall: a column, which then reaches the ceiling (the points
    // sought stop 10 cm below it). Lower than 20 cm, the remainder of the floor (or a rug, which
    // is floor): not furniture.
    if h1 > room.room_height - 0.15 {
        let clear = |x: f64, y: f64| {
            point_in_polygon(&Point2::new(x, y), room.floor_2d, 0.0) == Containment::Inside
        };
        let f = FREE_STANDING_M;
        let free = [
            (a0 - f, b0 - f),
            (a1 + f, b0 - f),
            (a0 - f, b1 + f),
            (a1 + f, b1 + f),
        ]
        .into_iter()
        .all(|(x, y)| clear(x, y));
        if !free {
            return None;
        }
        h1 = room.room_height;
    } else {
        // The top like the sides: its face's median (a desk's 99th percentile came out 2 cm
        // above it on the 343 s office scan, the face fused ±2.5 cm thick).
        h1 = face_side(&ch, &nh, 1.0, h1);
    }
    if h1 < 0.2 {
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
    nrm: &[Vector3<f64>],
    temp_k: &[f64],
    observations: &[u32],
    surface_id: &[i32],
    room: &Room<'_>,
    p: &SegmentParams,
) -> Vec<FoundFurniture> {
    let (grid, band) = candidate_cells(pos, nrm, surface_id, room, p);
    // How far from a wall a box's side may end and still stand against it: the widest clearance
    // candidates keep from a wall, and 10 cm.
    let wall_reach_m = room
        .wall_planes
        .iter()
        .map(|(_, c)| c.max(p.furniture_wall_clearance_m))
        .fold(p.furniture_wall_clearance_m, f64::max)
        + 0.1;
    let strong = |c: &Cell| {
        grid[c]
            .iter()
            .any(|&i| observations.get(i).is_none_or(|&o| o >= 2))
    };
    cell_components(&grid, strong)
        .into_iter()
        .filter(|(_, comp)| comp.len() >= p.furniture_min_points)
        .map(|(cells, mut comp)| {
            // Up to 25 cm into a wall's band, through points facing across it.
            comp.extend(reach_into_band(&cells, &band, 5));
            comp
        })
        .filter_map(|comp| {
            furniture_box(comp, (pos, nrm, temp_k, observations), room, wall_reach_m)
        })
        .collect()
}

/// Furniture: what stands off the envelope, kept clear of the walls by their band and 5 cm.
pub(super) fn furniture_of(
    env: &Envelope,
    longest: &Vector3<f64>,
    bands: &[f64],
    pts: &Points,
    surface_id: &[i32],
    height_m: f64,
    p: &SegmentParams,
) -> Vec<FoundFurniture> {
    let up = env.up;
    let floor_height = up.dot(&env.floor_corners[0].coords);
    let u = (longest - up.as_ref() * longest.dot(&up)).normalize();
    let v = up.cross(&u);
    let floor_2d: Vec<Point2<f64>> = env
        .floor_corners
        .iter()
        .map(|q| Point2::new(u.dot(&q.coords), v.dot(&q.coords)))
        .collect();
    let wall_planes: Vec<(mrtmap_geometry::Plane, f64)> = env
        .walls
        .iter()
        .enumerate()
        .map(|(w, &k)| (env.planes[k].plane, bands[w + 2] + 0.05))
        .collect();
    // Where the floor (surface 0) was seen, in 5 cm cells of the room's axes.
    let c = FLOOR_CELL_M;
    let floor_seen: std::collections::HashSet<(i32, i32)> = pts
        .pos
        .iter()
        .zip(surface_id)
        .filter(|(_, s)| **s == 0)
        .map(|(q, _)| {
            (
                (u.dot(&q.coords) / c).floor() as i32,
                (v.dot(&q.coords) / c).floor() as i32,
            )
        })
        .collect();
    let room = Room {
        up,
        along: *longest,
        floor_height,
        room_height: height_m,
        floor_2d: &floor_2d,
        wall_planes: &wall_planes,
        floor_seen: &floor_seen,
    };
    find_furniture(
        &pts.pos, &pts.nrm, &pts.temp, &pts.obs, surface_id, &room, p,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrtmap_geometry::Plane;

    /// The one piece of furniture found among `pos` (at 21 °C, seen in 6 frames, on no surface) in
    /// a 2.7 m high room with z up and boxes along x.
    fn the_one(
        pos: &[Point3<f64>],
        nrm: &[Vector3<f64>],
        floor_2d: &[Point2<f64>],
        walls: &[(Plane, f64)],
        floor_seen: &std::collections::HashSet<(i32, i32)>,
    ) -> FoundFurniture {
        the_one_seen(
            pos,
            nrm,
            &vec![6u32; pos.len()],
            floor_2d,
            walls,
            floor_seen,
        )
    }

    /// [`the_one`] with each point's number of frames.
    fn the_one_seen(
        pos: &[Point3<f64>],
        nrm: &[Vector3<f64>],
        obs: &[u32],
        floor_2d: &[Point2<f64>],
        walls: &[(Plane, f64)],
        floor_seen: &std::collections::HashSet<(i32, i32)>,
    ) -> FoundFurniture {
        let room = Room {
            up: Unit::new_normalize(Vector3::z()),
            along: Vector3::x(),
            floor_height: 0.0,
            room_height: 2.7,
            floor_2d,
            wall_planes: walls,
            floor_seen,
        };
        let n = pos.len();
        let (temp, sid) = (vec![294.15; n], vec![-1i32; n]);
        let mut found =
            find_furniture(pos, nrm, &temp, obs, &sid, &room, &SegmentParams::default());
        assert_eq!(found.len(), 1, "{found:?}");
        found.remove(0)
    }

    /// Point `k` of a deterministic, evenly spread sequence in the unit cube.
    fn spread(k: usize) -> [f64; 3] {
        let f = k as f64;
        [0.618_034, 0.414_214, 0.732_051].map(|a| (f * a).fract())
    }

    /// A `w` × `d` m room from the origin: its floor plan and its walls (x = 0, x = w, y = 0,
    /// y = d) with their bands.
    fn box_room(w: f64, d: f64, bands: [f64; 4]) -> ([Point2<f64>; 4], [(Plane, f64); 4]) {
        let wall = |p: [f64; 3], n: Vector3<f64>, band: f64| {
            (
                Plane::from_point_normal(&Point3::from(p), Unit::new_normalize(n)),
                band,
            )
        };
        (
            [
                Point2::new(0.0, 0.0),
                Point2::new(w, 0.0),
                Point2::new(w, d),
                Point2::new(0.0, d),
            ],
            [
                wall([0.0, 0.0, 0.0], Vector3::x(), bands[0]),
                wall([w, 0.0, 0.0], -Vector3::x(), bands[1]),
                wall([0.0, 0.0, 0.0], Vector3::y(), bands[2]),
                wall([0.0, d, 0.0], -Vector3::y(), bands[3]),
            ],
        )
    }

    /// The floor cells of a `w` × `d` m room seen, all but those whose centres are `hidden`.
    fn floor_seen_but(
        w: f64,
        d: f64,
        hidden: impl Fn(f64, f64) -> bool,
    ) -> std::collections::HashSet<(i32, i32)> {
        let c = FLOOR_CELL_M;
        let (nx, ny) = ((w / c + 1e-9) as i32, (d / c + 1e-9) as i32);
        (0..nx)
            .flat_map(|i| (0..ny).map(move |j| (i, j)))
            .filter(|&(i, j)| !hidden((i as f64 + 0.5) * c, (j as f64 + 0.5) * c))
            .collect()
    }

    /// A cabinet against the wall y = 3 (x 0.1…1.3, y 2.4…2.9, 1 m high; its points seen in 6
    /// frames) beside a slab of depth noise seen once each, scattered beyond the far wall x = 0's
    /// band from y = 0.3 to the cabinet, up to 1.7 m (a wall seen from afar). The noise does not
    /// carry the cabinet's box along the wall (it made a box 2.7 m deep and 1.7 m tall on a
    /// T-shaped room's scan).
    #[test]
    fn depth_noise_seen_once_does_not_join_a_cabinet() {
        let (mut pos, mut nrm, mut obs) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..3000 {
            let [r1, r2, _] = spread(k);
            // Front face (y = 2.4) and top.
            pos.push(Point3::new(0.1 + 1.2 * r1, 2.4, 0.05 + 0.95 * r2));
            nrm.push(-Vector3::y());
            pos.push(Point3::new(0.1 + 1.2 * r1, 2.4 + 0.5 * r2, 1.0));
            nrm.push(Vector3::z());
            obs.extend([6, 6]);
        }
        for k in 0..12000 {
            let [r1, r2, r3] = spread(k);
            let n = Vector3::new(r2 - 0.5, r3 - 0.5, r1 - 0.5).normalize();
            pos.push(Point3::new(
                0.2 + 0.2 * r1,
                0.3 + 2.1 * r2,
                0.05 + 1.65 * r3,
            ));
            nrm.push(n);
            obs.push(1);
        }
        let (floor_2d, walls) = box_room(8.0, 3.0, [0.15; 4]);
        let floor_seen = floor_seen_but(8.0, 3.0, |x, y| x < 1.3 && y > 2.4);
        let f = the_one_seen(&pos, &nrm, &obs, &floor_2d, &walls, &floor_seen);
        let y0 = f.corners.iter().map(|p| p.y).fold(f64::MAX, f64::min);
        assert!((y0 - 2.4).abs() < 0.06, "front at y = {y0:.3}");
        assert!(
            (f.size_m[2] - 1.0).abs() < 0.06,
            "height {:.3}",
            f.size_m[2]
        );
    }

    /// A desk (x 1.0…2.3, y 1.0…1.8, 0.75 m high) whose top is fused ±3 cm thick (a face is as
    /// thick as the depth noise) and whose front face is seen too: its top is at the top face's
    /// middle, not at the noise's upper edge (the 99th percentile: 0.78 m).
    #[test]
    fn a_desk_s_top_is_at_the_middle_of_its_thick_top_face() {
        let (mut pos, mut nrm) = (Vec::new(), Vec::new());
        for k in 0..4000 {
            let [r1, r2, r3] = spread(k);
            pos.push(Point3::new(
                1.0 + 1.3 * r1,
                1.0 + 0.8 * r2,
                0.75 + (r3 - 0.5) * 0.06,
            ));
            nrm.push(Vector3::z());
            pos.push(Point3::new(1.0 + 1.3 * r1, 1.0, 0.05 + 0.67 * r2));
            nrm.push(-Vector3::y());
        }
        let (floor_2d, walls) = box_room(5.0, 4.0, [0.15; 4]);
        let floor_seen = floor_seen_but(5.0, 4.0, |x, y| {
            (1.0..2.3).contains(&x) && (1.0..1.8).contains(&y)
        });
        let f = the_one(&pos, &nrm, &floor_2d, &walls, &floor_seen);
        let top = f.corners.iter().map(|p| p.z).fold(f64::MIN, f64::max);
        assert!((top - 0.75).abs() < 0.005, "top at z = {top:.4}");
        assert!(
            (f.size_m[2] - 0.75).abs() < 0.005,
            "height {:.4}",
            f.size_m[2]
        );
    }

    /// A 0.4 m square column from floor to ceiling (x 3.6…4.0, y 2.2…2.6) in the middle of a
    /// 6 × 5 m room, 2.7 m high, and a 40 cm slab of a wall's depth noise reaching the ceiling
    /// just beyond the wall x = 0's band: the column is furniture up to the ceiling (its points
    /// stop 10 cm below it), the slab is not (without the 30 cm test both are).
    #[test]
    fn a_column_reaching_the_ceiling_is_furniture_and_a_wall_s_remainder_is_not() {
        let (mut pos, mut nrm) = (Vec::new(), Vec::new());
        for k in 0..2000 {
            let [r1, r2, _] = spread(k);
            let (s, z) = (0.4 * r1, 0.05 + 2.55 * r2);
            for (p, n) in [
                (Point3::new(3.6 + s, 2.2, z), -Vector3::y()),
                (Point3::new(3.6 + s, 2.6, z), Vector3::y()),
                (Point3::new(3.6, 2.2 + s, z), -Vector3::x()),
                (Point3::new(4.0, 2.2 + s, z), Vector3::x()),
            ] {
                pos.push(p);
                nrm.push(n);
            }
        }
        for k in 0..40000 {
            let [r1, r2, r3] = spread(k);
            pos.push(Point3::new(
                0.22 + 0.4 * r1,
                1.0 + 2.0 * r2,
                0.05 + 2.55 * r3,
            ));
            nrm.push(Vector3::new(1.0, r2 - 0.5, r3 - 0.5).normalize());
        }
        let (floor_2d, walls) = box_room(6.0, 5.0, [0.15; 4]);
        let floor_seen = floor_seen_but(6.0, 5.0, |x, y| {
            (3.6..4.0).contains(&x) && (2.2..2.6).contains(&y)
        });
        let f = the_one(&pos, &nrm, &floor_2d, &walls, &floor_seen);
        let max = |k: usize| f.corners.iter().map(|p| p[k]).fold(f64::MIN, f64::max);
        let min = |k: usize| f.corners.iter().map(|p| p[k]).fold(f64::MAX, f64::min);
        assert!(
            (min(0) - 3.6).abs() < 0.03 && (max(0) - 4.0).abs() < 0.03,
            "x {:.3}…{:.3}",
            min(0),
            max(0)
        );
        assert!(
            (min(1) - 2.2).abs() < 0.03 && (max(1) - 2.6).abs() < 0.03,
            "y {:.3}…{:.3}",
            min(1),
            max(1)
        );
        assert!(
            min(2).abs() < 1e-9 && (max(2) - 2.7).abs() < 1e-9,
            "z {:.3}…{:.3}",
            min(2),
            max(2)
        );
    }

    /// A bookcase standing against the wall x = 0 (truth: x 0.02…0.42, y 2.69…3.89, 1.9 m tall,
    /// its end 11 cm from the wall y = 4, whose fused band is 30 cm thick) seen only from the
    /// front, whose face is fused ±12 cm thick (depth noise from 3–4 m away), and from above. Its
    /// box is put at the face's middle, not at the noise's outer edge, reaches back to the wall
    /// over the floor nobody saw, and its front runs on into the far wall's band to its end.
    #[test]
    fn a_bookcase_seen_from_the_front_stands_against_the_wall_at_its_face() {
        let (mut pos, mut nrm) = (Vec::new(), Vec::new());
        // Front face: a deterministic spread of ±12 cm around x = 0.42.
        for k in 0..4000 {
            let [r1, r2, r3] = spread(k);
            let (y, z) = (2.69 + 1.2 * r2, 0.05 + 1.8 * r3);
            pos.push(Point3::new(0.42 + (r1 - 0.5) * 0.24, y, z));
            nrm.push(Vector3::x());
        }
        // Top, seen from above.
        for k in 0..600 {
            let [r1, r2, _] = spread(k);
            let (x, y) = (0.20 + 0.22 * r1, 2.69 + 1.2 * r2);
            pos.push(Point3::new(x, y, 1.9));
            nrm.push(Vector3::z());
        }
        let (floor_2d, walls) = box_room(4.0, 4.0, [0.15, 0.15, 0.15, 0.30]);
        // The floor was seen everywhere but under and behind the bookcase, and at the foot of its
        // front (its points are as noisy as the face's).
        let floor_seen = floor_seen_but(4.0, 4.0, |x, y| x < 0.35 && (2.67..3.91).contains(&y));
        let f = &the_one(&pos, &nrm, &floor_2d, &walls, &floor_seen);
        let xs: Vec<f64> = f.corners.iter().map(|p| p.x).collect();
        let (x0, x1) = (
            xs.iter().copied().fold(f64::MAX, f64::min),
            xs.iter().copied().fold(f64::MIN, f64::max),
        );
        // The face within 2 cm (the percentile alone put it at 0.53); the back at the wall.
        assert!((x1 - 0.42).abs() < 0.02, "front at x = {x1:.3}");
        assert!(x0 < 0.05, "back at x = {x0:.3}, not against the wall");
        assert!(
            (f.size_m[2] - 1.9).abs() < 0.05,
            "height {:.3}",
            f.size_m[2]
        );
        // Its end in the far wall's band (the band alone would end it at y = 3.70).
        let y1 = f.corners.iter().map(|p| p.y).fold(f64::MIN, f64::max);
        assert!((y1 - 3.89).abs() < 0.03, "end at y = {y1:.3}");
    }

    /// A sofa in a corner (truth: x 4.0…5.9, y 1.6…2.48, 0.8 m high, in a 6 × 2.53 m room) of
    /// which the walk saw the near 1.1 m and a glimpse of the top beyond: the box grows over the
    /// hidden floor to the wall behind it and, at the same time, on along its length to the end
    /// wall (growing to the back wall used to stop the growth along it).
    #[test]
    fn a_sofa_in_a_corner_seen_from_its_end_grows_to_both_walls() {
        let (mut pos, mut nrm) = (Vec::new(), Vec::new());
        let mut add = |p: Point3<f64>, n: Vector3<f64>| {
            pos.push(p);
            nrm.push(n);
        };
        for k in 0..3000 {
            let [r1, r2, _] = spread(k);
            // Top, front face and the near end (their points in the back wall's band are left
            // to the wall).
            add(
                Point3::new(4.0 + 1.1 * r1, 1.6 + 0.88 * r2, 0.8),
                Vector3::z(),
            );
            add(
                Point3::new(4.0 + 1.1 * r1, 1.6, 0.05 + 0.75 * r2),
                -Vector3::y(),
            );
            add(
                Point3::new(4.0, 1.6 + 0.88 * r1, 0.05 + 0.75 * r2),
                -Vector3::x(),
            );
        }
        // A glimpse of the top further on.
        for k in 0..6 {
            add(Point3::new(5.12 + 0.03 * k as f64, 1.9, 0.8), Vector3::z());
        }
        let (floor_2d, walls) = box_room(6.0, 2.53, [0.15; 4]);
        // The floor was seen everywhere but under and beyond the sofa's seen part.
        let floor_seen = floor_seen_but(6.0, 2.53, |x, y| x > 3.97 && y > 1.57);
        let f = &the_one(&pos, &nrm, &floor_2d, &walls, &floor_seen);
        let max = |k: usize| f.corners.iter().map(|p| p[k]).fold(f64::MIN, f64::max);
        let min = |k: usize| f.corners.iter().map(|p| p[k]).fold(f64::MAX, f64::min);
        assert!((min(0) - 4.0).abs() < 0.03, "near end at x = {:.3}", min(0));
        assert!((min(1) - 1.6).abs() < 0.03, "front at y = {:.3}", min(1));
        assert!(max(1) > 2.4, "back at y = {:.3}, not at the wall", max(1));
        assert!(
            max(0) > 5.8,
            "far end at x = {:.3}, not at the wall",
            max(0)
        );
    }
}
