//! Scoring a fused thermal cloud against the room it was simulated from: the true temperature of
//! the surface under each voxel, the voxel's distance to the true surfaces, and whether it lies
//! within one voxel of a border where the temperature jumps (feature and furniture edges, room
//! corners), where a voxel mixes two surfaces by construction.

use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Vector3};
use mrtmap_geometry::polygon::{Containment, point_in_polygon, point_segment_distance};
use mrtmap_io::ThermalCloud;
use serde::{Deserialize, Serialize};

use crate::room::Room;

/// Errors of a cloud against the truth.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CloudScore {
    /// Voxels scored.
    pub voxels: usize,
    /// Fraction of voxels within one voxel of a temperature border.
    pub near_border_fraction: f64,
    /// Fraction of voxels farther than one voxel from every true surface (depth noise).
    pub off_surface_fraction: f64,
    /// Median |T − T_true| of voxels on a surface (within one voxel) and away from borders (K).
    pub abs_error_median_k: f64,
    /// 95th percentile of |T − T_true| away from borders (K).
    pub abs_error_p95_k: f64,
    /// Mean T − T_true away from borders (K).
    pub bias_k: f64,
    /// Median |T − T_true| of voxels near borders (K).
    pub border_abs_error_median_k: f64,
    /// Median distance of voxel positions to the true surfaces (m).
    pub distance_median_m: f64,
    /// 95th percentile of that distance (m).
    pub distance_p95_m: f64,
}

fn percentile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

struct Face {
    origin: Point3<f64>,
    u: Vector3<f64>,
    v: Vector3<f64>,
    n: Vector3<f64>,
    poly: Vec<Point2<f64>>,
}

fn box_faces(min: [f64; 3], max: [f64; 3]) -> Vec<Face> {
    let lo = Point3::from(min);
    let hi = Point3::from(max);
    let d = hi - lo;
    let rect = |w: f64, h: f64| {
        vec![
            Point2::new(0.0, 0.0),
            Point2::new(w, 0.0),
            Point2::new(w, h),
            Point2::new(0.0, h),
        ]
    };
    let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
    vec![
        Face {
            origin: lo,
            u: y,
            v: z,
            n: -x,
            poly: rect(d.y, d.z),
        },
        Face {
            origin: Point3::new(hi.x, lo.y, lo.z),
            u: y,
            v: z,
            n: x,
            poly: rect(d.y, d.z),
        },
        Face {
            origin: lo,
            u: x,
            v: z,
            n: -y,
            poly: rect(d.x, d.z),
        },
        Face {
            origin: Point3::new(lo.x, hi.y, lo.z),
            u: x,
            v: z,
            n: y,
            poly: rect(d.x, d.z),
        },
        Face {
            origin: lo,
            u: x,
            v: y,
            n: -z,
            poly: rect(d.x, d.y),
        },
        Face {
            origin: Point3::new(lo.x, lo.y, hi.z),
            u: x,
            v: y,
            n: z,
            poly: rect(d.x, d.y),
        },
    ]
}

fn edge_distance(q: &Point2<f64>, poly: &[Point2<f64>]) -> f64 {
    (0..poly.len())
        .map(|i| point_segment_distance(q, &poly[i], &poly[(i + 1) % poly.len()]))
        .fold(f64::INFINITY, f64::min)
}

/// The true temperature (°C) at a room point on (or near) the room, its distance to the nearest
/// surface, and its distance to the nearest temperature border on that surface.
pub fn truth_at(room: &Room, p: &Point3<f64>) -> (f64, f64, f64) {
    let mut best = (f64::NAN, f64::INFINITY, f64::INFINITY);
    for s in room.surfaces() {
        let (o, u, v) = room.surface_frame(s);
        let n = room.inward_normal(s);
        let d = p - o;
        let q = Point2::new(u.dot(&d), v.dot(&d));
        let poly = room.surface_polygon_2d(s);
        let off = n.dot(&d).abs();
        let outside = if point_in_polygon(&q, &poly, 0.0) == Containment::Outside {
            edge_distance(&q, &poly)
        } else {
            0.0
        };
        let dist = off.hypot(outside);
        if dist < best.1 {
            let mut t = room.background_radiant_c(s, p.z);
            let mut border = edge_distance(&q, &poly);
            for (k, f) in room.features.iter().enumerate().filter(|(_, f)| f.on == s) {
                border = border.min(edge_distance(&q, &f.polygon_2d));
                if point_in_polygon(&q, &f.polygon_2d, 0.0) != Containment::Outside {
                    t = room.feature_radiant_c(k);
                }
            }
            best = (t, dist, border);
        }
    }
    for b in &room.file.furniture {
        for f in box_faces(b.min, b.max) {
            let d = p - f.origin;
            let q = Point2::new(f.u.dot(&d), f.v.dot(&d));
            let off = f.n.dot(&d).abs();
            let outside = if point_in_polygon(&q, &f.poly, 0.0) == Containment::Outside {
                edge_distance(&q, &f.poly)
            } else {
                0.0
            };
            let dist = off.hypot(outside);
            if dist < best.1 {
                best = (b.temperature_c, dist, edge_distance(&q, &f.poly));
            }
        }
    }
    best
}

/// Scores a cloud in the world frame of a recording whose room frame is `world_from_room`.
pub fn score_cloud(
    room: &Room,
    world_from_room: &Isometry3<f64>,
    cloud: &ThermalCloud,
    voxel_m: f64,
) -> CloudScore {
    let room_from_world = world_from_room.inverse();
    let mut err = Vec::new();
    let mut signed = Vec::new();
    let mut border_err = Vec::new();
    let mut off_surface = 0usize;
    let mut dist = Vec::new();
    for (i, p) in cloud.positions.iter().enumerate() {
        let q = room_from_world * Point3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        let (t_true, d, border) = truth_at(room, &q);
        dist.push(d);
        let e = cloud.temperature_k[i] as f64 - 273.15 - t_true;
        if d.is_nan() || d >= voxel_m {
            off_surface += 1;
        } else if border < voxel_m {
            border_err.push(e.abs());
        } else {
            err.push(e.abs());
            signed.push(e);
        }
    }
    let n = cloud.len();
    CloudScore {
        voxels: n,
        near_border_fraction: border_err.len() as f64 / n.max(1) as f64,
        off_surface_fraction: off_surface as f64 / n.max(1) as f64,
        bias_k: signed.iter().sum::<f64>() / signed.len().max(1) as f64,
        abs_error_median_k: percentile(&mut err.clone(), 0.5),
        abs_error_p95_k: percentile(&mut err, 0.95),
        border_abs_error_median_k: percentile(&mut border_err, 0.5),
        distance_median_m: percentile(&mut dist.clone(), 0.5),
        distance_p95_m: percentile(&mut dist, 0.95),
    }
}
