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
//! at the radiant average of its points. Groups reaching within 15 cm of the ceiling are wall
//! remainders too.

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

/// Finds furniture among the unassigned points.
#[allow(clippy::too_many_arguments)]
pub fn find_furniture(
    pos: &[Point3<f64>],
    temp_k: &[f64],
    surface_id: &[i32],
    up: &Unit<Vector3<f64>>,
    along: &Vector3<f64>,
    floor_height: f64,
    room_height: f64,
    floor_2d: &[Point2<f64>],
    wall_planes: &[(mrtmap_geometry::Plane, f64)],
    p: &SegmentParams,
) -> Vec<FoundFurniture> {
    let u = (along - up.as_ref() * along.dot(up)).normalize();
    let v = up.cross(&u);
    let to2 = |q: &Point3<f64>| Point2::new(u.dot(&q.coords), v.dot(&q.coords));
    let cell = 0.05;
    let mut grid: HashMap<[i32; 3], Vec<usize>> = HashMap::new();
    for (i, q) in pos.iter().enumerate() {
        if surface_id[i] >= 0 {
            continue;
        }
        let h = up.dot(&q.coords) - floor_height;
        if h < 0.02 || h > room_height - 0.1 {
            continue;
        }
        if point_in_polygon(&to2(q), floor_2d, p.furniture_wall_clearance_m) != Containment::Inside
        {
            continue;
        }
        if wall_planes
            .iter()
            .any(|(w, clearance)| w.distance(q).abs() < clearance.max(p.furniture_wall_clearance_m))
        {
            continue;
        }
        let k = [
            (u.dot(&q.coords) / cell).floor() as i32,
            (v.dot(&q.coords) / cell).floor() as i32,
            (h / cell).floor() as i32,
        ];
        grid.entry(k).or_default().push(i);
    }
    let mut seen: HashMap<[i32; 3], bool> = HashMap::new();
    let mut keys: Vec<[i32; 3]> = grid.keys().copied().collect();
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
        if comp.len() < p.furniture_min_points {
            continue;
        }
        let mut a: Vec<f64> = comp.iter().map(|&i| u.dot(&pos[i].coords)).collect();
        let mut b: Vec<f64> = comp.iter().map(|&i| v.dot(&pos[i].coords)).collect();
        let mut h: Vec<f64> = comp
            .iter()
            .map(|&i| up.dot(&pos[i].coords) - floor_height)
            .collect();
        let (a0, a1) = (percentile(&mut a, 0.01), percentile(&mut a, 0.99));
        let (b0, b1) = (percentile(&mut b, 0.01), percentile(&mut b, 0.99));
        let (mut h0, h1) = (percentile(&mut h, 0.01), percentile(&mut h, 0.99));
        if h0 < 0.15 {
            h0 = 0.0;
        }
        // Reaching the ceiling, it is the noisy remainder of a wall; lower than 20 cm, the remainder
        // of the floor (or a rug, which is floor): not furniture.
        if h1 > room_height - 0.15 || h1 < 0.2 {
            continue;
        }
        let size = [a1 - a0, b1 - b0, h1 - h0];
        // Thinner than 15 cm across, it is the noisy remainder of a wall or a picture, not furniture.
        if size[0].min(size[1]) < 0.15 || size[2] < 0.05 || size[0] * size[1] * size[2] < 0.02 {
            continue;
        }
        let mut avg = RadiantAverage::new();
        for &i in &comp {
            avg.add(Temperature::from_kelvin(temp_k[i]), 1.0);
        }
        let Some(t) = avg.mean() else { continue };
        let corner = |c: usize| {
            let x = if c & 1 == 0 { a0 } else { a1 };
            let y = if c & 2 == 0 { b0 } else { b1 };
            let z = floor_height + if c & 4 == 0 { h0 } else { h1 };
            Point3::from(u * x + v * y + up.as_ref() * z)
        };
        out.push(FoundFurniture {
            corners: [
                corner(0),
                corner(1),
                corner(2),
                corner(3),
                corner(4),
                corner(5),
                corner(6),
                corner(7),
            ],
            size_m: size,
            temperature_k: t.kelvin(),
            points: comp,
        });
    }
    out
}
