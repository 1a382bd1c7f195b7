//! The handheld walk: a loop around the room, inset from the walls by a distance that slowly
//! varies, looking across the room with slow yaw and pitch sweeps (so walls, floor and ceiling are
//! all seen), a walking bob and a little hand shake. Poses are `room_from_depth` in OpenCV's
//! camera convention (x right, y down, z forward).

use std::f64::consts::TAU;

use mrtmap_geometry::nalgebra::{
    Isometry3, Matrix3, Point2, Rotation3, Translation3, UnitQuaternion, Vector3,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::room::Room;

/// Walk settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WalkParams {
    /// Walking speed along the loop (m/s).
    pub speed_m_s: f64,
    /// Mean distance of the loop from the walls (m); `None` picks 25 % of the room's smaller
    /// extent, at most 1 m.
    pub inset_m: Option<f64>,
    /// Camera height (m).
    pub camera_height_m: f64,
    /// Yaw sweep amplitude around the look direction (degrees) and period (s).
    pub yaw_sweep_deg: f64,
    /// Yaw sweep period (s).
    pub yaw_period_s: f64,
    /// Pitch sweep amplitude (degrees; up and down) and period (s).
    pub pitch_sweep_deg: f64,
    /// Pitch sweep period (s).
    pub pitch_period_s: f64,
    /// Hand shake: rotation (degrees) and translation (m) amplitudes.
    pub shake_deg: f64,
    /// Hand shake translation (m).
    pub shake_m: f64,
}

impl Default for WalkParams {
    fn default() -> Self {
        Self {
            speed_m_s: 0.5,
            inset_m: None,
            camera_height_m: 1.45,
            yaw_sweep_deg: 50.0,
            yaw_period_s: 11.0,
            pitch_sweep_deg: 55.0,
            pitch_period_s: 7.3,
            shake_deg: 0.6,
            shake_m: 0.004,
        }
    }
}

/// A walk through a room.
pub struct Walk {
    plan: Vec<Point2<f64>>,
    target: Point2<f64>,
    inset: f64,
    perimeter: f64,
    params: WalkParams,
    /// (frequency Hz, phase) per shake channel: 3 rotation + 3 translation, 3 sinusoids each.
    shake: Vec<[(f64, f64); 3]>,
    phase_pitch: f64,
}

/// The floor plan offset inward by `d` (counter-clockwise plan): each edge moved along its inward
/// normal, consecutive offset lines intersected.
pub fn inset_polygon(plan: &[Point2<f64>], d: f64) -> Vec<Point2<f64>> {
    let n = plan.len();
    let line = |i: usize| {
        let (a, b) = (plan[i], plan[(i + 1) % n]);
        let e = (b - a).normalize();
        let normal = mrtmap_geometry::nalgebra::Vector2::new(-e.y, e.x);
        (a + normal * d, e)
    };
    (0..n)
        .map(|i| {
            let (p0, e0) = line((i + n - 1) % n);
            let (p1, e1) = line(i);
            let den = e0.perp(&e1);
            if den.abs() < 1e-12 {
                p1
            } else {
                p0 + e0 * ((p1 - p0).perp(&e1) / den)
            }
        })
        .collect()
}

fn perimeter(p: &[Point2<f64>]) -> f64 {
    (0..p.len())
        .map(|i| (p[(i + 1) % p.len()] - p[i]).norm())
        .sum()
}

fn at_fraction(p: &[Point2<f64>], f: f64) -> Point2<f64> {
    let total = perimeter(p);
    let mut s = f.rem_euclid(1.0) * total;
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        let l = (b - a).norm();
        if s <= l {
            return a + (b - a) * (s / l.max(1e-12));
        }
        s -= l;
    }
    p[0]
}

fn area_centroid(p: &[Point2<f64>]) -> Point2<f64> {
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for i in 0..p.len() {
        let (u, v) = (p[i], p[(i + 1) % p.len()]);
        let c = u.x * v.y - v.x * u.y;
        a += c;
        cx += (u.x + v.x) * c;
        cy += (u.y + v.y) * c;
    }
    Point2::new(cx / (3.0 * a), cy / (3.0 * a))
}

/// Distance from `q` to the closed polygon's edges, and whether `q` lies inside it (even-odd).
fn edge_distance(p: &[Point2<f64>], q: Point2<f64>) -> (f64, bool) {
    let (mut d, mut inside) = (f64::INFINITY, false);
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        let ab = b - a;
        let s = ((q - a).dot(&ab) / ab.norm_squared().max(1e-18)).clamp(0.0, 1.0);
        d = d.min((a + ab * s - q).norm());
        if (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) / (b.y - a.y) * ab.x {
            inside = !inside;
        }
    }
    (d, inside)
}

/// The point the camera looks at: the floor plan's centroid, unless the walk passes close to it
/// (a re-entrant room: the L-shaped preset's centroid lies on its walk, where looking at it would
/// whip the camera round at over 1000°/s); then the point inside the innermost loop farthest from
/// it, the one nearest the centroid among equals.
fn look_target(plan: &[Point2<f64>], innermost: &[Point2<f64>]) -> Point2<f64> {
    let c = area_centroid(plan);
    let (lo, hi) = innermost.iter().fold(
        (
            Point2::new(f64::INFINITY, f64::INFINITY),
            Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        ),
        |(a, b), q| {
            (
                Point2::new(a.x.min(q.x), a.y.min(q.y)),
                Point2::new(b.x.max(q.x), b.y.max(q.y)),
            )
        },
    );
    let step = 0.02;
    let (nx, ny) = (
        ((hi.x - lo.x) / step).ceil() as usize,
        ((hi.y - lo.y) / step).ceil() as usize,
    );
    let mut best: Option<(f64, f64, Point2<f64>)> = None;
    for i in 0..=nx {
        for j in 0..=ny {
            let q = Point2::new(lo.x + i as f64 * step, lo.y + j as f64 * step);
            let (d, inside) = edge_distance(innermost, q);
            if !inside {
                continue;
            }
            let key = ((d / step).round() * step, -(q - c).norm());
            if best.is_none_or(|(bd, bc, _)| key.0 > bd || (key.0 == bd && key.1 > bc)) {
                best = Some((key.0, key.1, q));
            }
        }
    }
    let Some((r_max, _, far)) = best else {
        return c;
    };
    let (dc, inside) = edge_distance(innermost, c);
    if inside && dc >= 0.8 * r_max { c } else { far }
}

impl Walk {
    /// A walk through `room` with `params`, shake drawn from `seed`.
    pub fn new(room: &Room, params: WalkParams, seed: u64) -> Self {
        let (lo, hi) = room.plan.iter().fold(
            (
                Point2::new(f64::INFINITY, f64::INFINITY),
                Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
            ),
            |(a, b), q| {
                (
                    Point2::new(a.x.min(q.x), a.y.min(q.y)),
                    Point2::new(b.x.max(q.x), b.y.max(q.y)),
                )
            },
        );
        let inset = params
            .inset_m
            .unwrap_or_else(|| (0.25 * (hi.x - lo.x).min(hi.y - lo.y)).min(1.0));
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x77616c6b);
        let shake = (0..6)
            .map(|_| [0, 1, 2].map(|_| (rng.random_range(0.4..3.0), rng.random_range(0.0..TAU))))
            .collect();
        let loop_ = inset_polygon(&room.plan, inset);
        // The loop's inset breathes by ±25 %: the target keeps away from its innermost form.
        let innermost = inset_polygon(&room.plan, 1.25 * inset);
        Self {
            perimeter: perimeter(&loop_),
            target: look_target(&room.plan, &innermost),
            plan: room.plan.clone(),
            inset,
            params,
            shake,
            phase_pitch: rng.random_range(0.0..TAU),
        }
    }

    fn shake(&self, ch: usize, t: f64) -> f64 {
        self.shake[ch]
            .iter()
            .map(|(f, ph)| (TAU * f * t + ph).sin())
            .sum::<f64>()
            / 3.0
    }

    /// The depth camera's pose in the room at time `t` (s from the start of the walk).
    pub fn room_from_depth(&self, t: f64) -> Isometry3<f64> {
        let p = &self.params;
        // The inset breathes by ±25 % over three loops.
        let loop_time = self.perimeter / p.speed_m_s;
        let d = self.inset * (1.0 + 0.25 * (TAU * t / (3.0 * loop_time)).sin());
        let pos = at_fraction(&inset_polygon(&self.plan, d), t / loop_time);
        let to = self.target - pos;
        let yaw =
            to.y.atan2(to.x) + p.yaw_sweep_deg.to_radians() * (TAU * t / p.yaw_period_s).sin();
        let pitch =
            p.pitch_sweep_deg.to_radians() * (TAU * t / p.pitch_period_s + self.phase_pitch).sin();
        let roll = 3f64.to_radians() * (TAU * t / 5.3).sin();
        let fwd = Vector3::new(
            pitch.cos() * yaw.cos(),
            pitch.cos() * yaw.sin(),
            pitch.sin(),
        );
        let right = Vector3::new(yaw.sin(), -yaw.cos(), 0.0);
        let down = fwd.cross(&right);
        let base = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[right, down, fwd]));
        let s = p.shake_deg.to_radians();
        let wobble = UnitQuaternion::from_euler_angles(
            s * self.shake(0, t),
            s * self.shake(1, t),
            s * self.shake(2, t),
        );
        let rot = UnitQuaternion::from_rotation_matrix(&base)
            * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), roll)
            * wobble;
        let bob = 0.02 * (TAU * 1.8 * t).sin();
        let jitter = Vector3::new(self.shake(3, t), self.shake(4, t), self.shake(5, t)) * p.shake_m;
        let trans = Vector3::new(pos.x, pos.y, p.camera_height_m + bob) + jitter;
        Isometry3::from_parts(Translation3::from(trans), rot)
    }
}
