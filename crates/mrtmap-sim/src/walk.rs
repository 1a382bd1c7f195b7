//! The handheld walk: a loop around the room, inset from the walls by a distance that slowly
//! varies, looking across the room with slow yaw and pitch sweeps (so walls, floor and ceiling are
//! all seen), a walking bob and a little hand shake. Poses are `room_from_depth` in OpenCV's
//! camera convention (x right, y down, z forward).
//!
//! Where it looks: at the floor plan's centroid, when that shows every wall (checked on the plan
//! over one loop, see [`Walk::faces_the_centroid`]: true of every preset). In a room where it does
//! not (a U-shaped room's wing looks at the centroid with its end wall behind it), the walker does
//! what a person scanning does and turns to the walls it has seen least: the heading is planned
//! every [`PLAN_STEP_S`] towards the direction whose visible walls have been in view least often,
//! turning at most [`PLAN_TURN_RATE`].

use std::f64::consts::TAU;

use mrtmap_geometry::nalgebra::{
    Isometry3, Matrix3, Point2, Rotation3, Translation3, UnitQuaternion, Vector3,
};
use mrtmap_geometry::polygon::segments_cross;
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
    /// The heading (radians, unwrapped) every [`HEADING_STEP_S`], turned towards the target at
    /// most [`MAX_HEADING_RATE`]; `None` where it points at the target.
    heading: Vec<Option<f64>>,
    /// The coverage-planned heading (radians, unwrapped) every [`PLAN_STEP_S`], where the
    /// centroid does not show every wall; empty otherwise.
    planned: Vec<f64>,
}

/// The coverage planner's step (s), the half field of view it counts a wall point seen within
/// (inside the D435's 43.5°), the range (m) and the largest incidence (from the wall's normal)
/// at which a point counts as seen, and the planner's turn rate (rad/s).
const PLAN_STEP_S: f64 = 0.25;
const PLAN_HALF_FOV: f64 = 40.0 * std::f64::consts::PI / 180.0;
const PLAN_RANGE_M: f64 = 5.0;
const PLAN_MAX_INCIDENCE: f64 = 70.0 * std::f64::consts::PI / 180.0;
/// The planner's fastest turn (60°/s): the sweeps add under 80°/s.
const PLAN_TURN_RATE: f64 = 60.0 * std::f64::consts::PI / 180.0;
/// Spacing of the wall points the coverage is counted on (m).
const PLAN_SAMPLE_M: f64 = 0.25;
/// The share of each wall's points the centroid must show over one loop for the walk to face it,
/// how close (m) and for how many planning steps (one second). Measured over one loop: the
/// presets 0.60 (L-shaped), 0.94 and 1.00 of their worst-seen wall; a T-shaped room whose bar's
/// end wall lies behind the walker there and 4.5 m away across the room, 0.00.
const CENTROID_COVERAGE: f64 = 0.5;
const CENTROID_RANGE_M: f64 = 4.0;
const CENTROID_STEPS: u32 = 4;

/// A point on a wall (1 cm inside the room), its wall and the wall's inward normal.
struct WallPoint {
    at: Point2<f64>,
    wall: usize,
    inward: mrtmap_geometry::nalgebra::Vector2<f64>,
}

/// Points every [`PLAN_SAMPLE_M`] along each wall of a counter-clockwise plan.
fn wall_points(plan: &[Point2<f64>]) -> Vec<WallPoint> {
    let n = plan.len();
    let mut out = Vec::new();
    for i in 0..n {
        let (a, b) = (plan[i], plan[(i + 1) % n]);
        let len = (b - a).norm();
        if len < 1e-9 {
            continue;
        }
        let e = (b - a) / len;
        let inward = mrtmap_geometry::nalgebra::Vector2::new(-e.y, e.x);
        let m = (len / PLAN_SAMPLE_M).ceil().max(1.0) as usize;
        for k in 0..m {
            let s = (k as f64 + 0.5) / m as f64 * len;
            out.push(WallPoint {
                at: a + e * s + inward * 0.01,
                wall: i,
                inward,
            });
        }
    }
    out
}

/// The bearing (radians) from `p` of each wall point it sees: within range, at an incidence
/// under [`PLAN_MAX_INCIDENCE`], with no wall in between.
fn visible(plan: &[Point2<f64>], points: &[WallPoint], p: Point2<f64>) -> Vec<(usize, f64)> {
    let n = plan.len();
    let cos_max = PLAN_MAX_INCIDENCE.cos();
    points
        .iter()
        .enumerate()
        .filter_map(|(j, w)| {
            let d = w.at - p;
            let dist = d.norm();
            if !(1e-6..=PLAN_RANGE_M).contains(&dist) || -d.dot(&w.inward) / dist < cos_max {
                return None;
            }
            let blocked = (0..n).any(|i| {
                i != w.wall && segments_cross(&p, &w.at, &plan[i], &plan[(i + 1) % n], 0.0)
            });
            (!blocked).then(|| (j, d.y.atan2(d.x)))
        })
        .collect()
}

/// The heading table's step (s) and length (s): beyond it the heading points at the target.
const HEADING_STEP_S: f64 = 0.01;
const HEADING_SPAN_S: f64 = 7200.0;
/// The fastest the walker turns to keep facing the target (rad/s, 120°/s). Where the walk passes
/// close to its target (the L-shaped preset's centroid lies on its loop) the direction to it flips
/// round in milliseconds; a person turns round in a few seconds instead.
const MAX_HEADING_RATE: f64 = 120.0 * std::f64::consts::PI / 180.0;

/// `a` − `b` wrapped to (−π, π].
fn wrapped(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    if d > std::f64::consts::PI { d - TAU } else { d }
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
        let mut walk = Self {
            perimeter: perimeter(&loop_),
            target: area_centroid(&room.plan),
            plan: room.plan.clone(),
            inset,
            params,
            shake,
            phase_pitch: rng.random_range(0.0..TAU),
            heading: Vec::new(),
            planned: Vec::new(),
        };
        if walk.faces_the_centroid() {
            walk.heading = walk.limited_heading();
        } else {
            walk.planned = walk.coverage_heading();
        }
        walk
    }

    /// One loop's duration (s).
    pub fn loop_time(&self) -> f64 {
        self.perimeter / self.params.speed_m_s
    }

    /// Whether looking at the plan's centroid shows every wall: over one loop, sampled every
    /// [`PLAN_STEP_S`] (sweeps left out), at least [`CENTROID_COVERAGE`] of each wall's points
    /// are within [`PLAN_HALF_FOV`] of the heading, [`CENTROID_RANGE_M`] of the walker and in
    /// sight for [`CENTROID_STEPS`] steps or more.
    pub fn faces_the_centroid(&self) -> bool {
        let steps = (self.loop_time() / PLAN_STEP_S).ceil() as usize;
        self.steps_to_see_every_wall(steps, &|t| self.target_heading(t))
            .is_some()
    }

    /// The first step (of `steps`, every [`PLAN_STEP_S`]) at which every wall has been in view
    /// (the test of [`Self::faces_the_centroid`]) with the walker looking along `heading(t)`.
    fn steps_to_see_every_wall(&self, steps: usize, heading: &dyn Fn(f64) -> f64) -> Option<usize> {
        let points = wall_points(&self.plan);
        let mut seen = vec![0u32; points.len()];
        let covered = |seen: &[u32]| {
            (0..self.plan.len()).all(|wall| {
                let (mut all, mut ok) = (0usize, 0usize);
                for (w, s) in points.iter().zip(seen) {
                    if w.wall == wall {
                        all += 1;
                        ok += usize::from(*s >= CENTROID_STEPS);
                    }
                }
                all == 0 || ok as f64 >= CENTROID_COVERAGE * all as f64
            })
        };
        for k in 0..steps {
            let t = k as f64 * PLAN_STEP_S;
            let (p, yaw) = (self.position(t), heading(t));
            for (j, bearing) in visible(&self.plan, &points, p) {
                if wrapped(bearing, yaw).abs() <= PLAN_HALF_FOV
                    && (points[j].at - p).norm() <= CENTROID_RANGE_M
                {
                    seen[j] += 1;
                }
            }
            if covered(&seen) {
                return Some(k);
            }
        }
        None
    }

    /// How long (s) the walk takes until every wall has been in view (the plan's test of
    /// [`Self::faces_the_centroid`], sweeps left out, on the headings the walk takes); `None`
    /// when not within `max_s`.
    pub fn seconds_to_see_every_wall(&self, max_s: f64) -> Option<f64> {
        let steps = (max_s / PLAN_STEP_S).ceil() as usize + 1;
        self.steps_to_see_every_wall(steps, &|t| self.heading_at(t))
            .map(|k| k as f64 * PLAN_STEP_S)
    }

    /// The heading every [`PLAN_STEP_S`] over [`HEADING_SPAN_S`], planned for coverage: at each
    /// step the goal is the direction (of 72) whose visible wall points have been in view least,
    /// each point weighing 1/(1 + the steps it was in view) and the goal's score discounted by a
    /// tenth per radian of turn; the walker turns towards it at most [`PLAN_TURN_RATE`].
    fn coverage_heading(&self) -> Vec<f64> {
        let points = wall_points(&self.plan);
        let mut count = vec![0u32; points.len()];
        let steps = (HEADING_SPAN_S / PLAN_STEP_S) as usize;
        let max_turn = PLAN_TURN_RATE * PLAN_STEP_S;
        let mut yaw = self.target_heading(0.0);
        let mut out = Vec::with_capacity(steps + 1);
        for k in 0..=steps {
            let t = k as f64 * PLAN_STEP_S;
            let vis = visible(&self.plan, &points, self.position(t));
            let score = |dir: f64| -> f64 {
                vis.iter()
                    .filter(|(_, b)| wrapped(*b, dir).abs() <= PLAN_HALF_FOV)
                    .map(|(j, _)| 1.0 / (1.0 + count[*j] as f64))
                    .sum()
            };
            let (mut best, mut best_score) = (yaw, f64::NEG_INFINITY);
            for c in 0..72 {
                let dir = yaw + wrapped(c as f64 * TAU / 72.0, yaw);
                let s = score(dir) * (1.0 - 0.1 * wrapped(dir, yaw).abs());
                if s > best_score {
                    (best, best_score) = (dir, s);
                }
            }
            yaw += (best - yaw).clamp(-max_turn, max_turn);
            for (j, b) in &vis {
                if wrapped(*b, yaw).abs() <= PLAN_HALF_FOV {
                    count[*j] += 1;
                }
            }
            out.push(yaw);
        }
        out
    }

    /// Where the walker stands at `t` (the loop's inset breathes by ±25 % over three loops).
    fn position(&self, t: f64) -> Point2<f64> {
        let loop_time = self.perimeter / self.params.speed_m_s;
        let d = self.inset * (1.0 + 0.25 * (TAU * t / (3.0 * loop_time)).sin());
        at_fraction(&inset_polygon(&self.plan, d), t / loop_time)
    }

    /// The direction from the walker to the target at `t`.
    fn target_heading(&self, t: f64) -> f64 {
        let to = self.target - self.position(t);
        to.y.atan2(to.x)
    }

    /// The heading turned towards the target at no more than [`MAX_HEADING_RATE`], every
    /// [`HEADING_STEP_S`]: `None` while it is on the target, so a walk that never needs the limit
    /// (every convex room) keeps the exact direction.
    fn limited_heading(&self) -> Vec<Option<f64>> {
        let n = (HEADING_SPAN_S / HEADING_STEP_S) as usize;
        let max_step = MAX_HEADING_RATE * HEADING_STEP_S;
        let mut yaw = self.target_heading(0.0);
        let mut out = Vec::with_capacity(n + 1);
        let mut limited = false;
        for k in 0..=n {
            let goal = self.target_heading(k as f64 * HEADING_STEP_S);
            let d = wrapped(goal, yaw);
            if d.abs() <= max_step {
                yaw += d;
                out.push(None);
            } else {
                yaw += max_step.copysign(d);
                out.push(Some(yaw));
                limited = true;
            }
        }
        if !limited {
            out.clear();
        }
        out
    }

    /// The walker's heading at `t`: the coverage plan's where there is one (its last heading
    /// beyond [`HEADING_SPAN_S`]), else towards the target, or the turn-rate-limited one around it.
    fn heading_at(&self, t: f64) -> f64 {
        if let Some(last) = self.planned.last() {
            let x = (t / PLAN_STEP_S).max(0.0);
            let k = x.floor() as usize;
            return match (self.planned.get(k), self.planned.get(k + 1)) {
                (Some(a), Some(b)) => a + (b - a) * (x - k as f64),
                _ => *last,
            };
        }
        let x = t / HEADING_STEP_S;
        let k = x.floor();
        let i = k as usize;
        match (k >= 0.0).then(|| (self.heading.get(i), self.heading.get(i + 1))) {
            Some((Some(Some(a)), Some(Some(b)))) => a + (b - a) * (x - k),
            // At the limiter's edges, on the target within one step: ease the lag in or out.
            Some((Some(Some(a)), Some(None))) => {
                let g = self.target_heading(t);
                g + wrapped(*a, g) * (1.0 - (x - k))
            }
            Some((Some(None), Some(Some(b)))) => {
                let g = self.target_heading(t);
                g + wrapped(*b, g) * (x - k)
            }
            _ => self.target_heading(t),
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
        let pos = self.position(t);
        let yaw =
            self.heading_at(t) + p.yaw_sweep_deg.to_radians() * (TAU * t / p.yaw_period_s).sin();
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
