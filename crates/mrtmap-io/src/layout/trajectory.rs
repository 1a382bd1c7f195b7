//! TUM trajectories (`timestamp tx ty tz qx qy qz qw`, pose = world_from_camera, Hamilton
//! quaternion in x y z w order) and pose interpolation (linear translation, slerp rotation).

use std::path::Path;

use mrtmap_geometry::nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use crate::error::{FileError, FileErrorKind};

/// Largest |‖q‖ − 1| accepted for a quaternion read from a file.
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// Poses over time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    /// Timestamps (s), strictly increasing.
    pub stamps: Vec<f64>,
    /// Poses world_from_camera.
    pub poses: Vec<Isometry3<f64>>,
}

/// How far interpolation may reach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InterpolationLimits {
    /// Largest gap between two poses to interpolate across (s).
    pub max_gap_secs: f64,
    /// How far beyond the first or last pose a time may lie and take that pose (s).
    pub max_extrapolation_secs: f64,
}

impl Default for InterpolationLimits {
    fn default() -> Self {
        Self {
            max_gap_secs: 0.5,
            max_extrapolation_secs: 0.02,
        }
    }
}

/// A quaternion (x, y, z, w) as read from a file, checked.
pub fn unit_quaternion(q: [f64; 4]) -> Result<UnitQuaternion<f64>, FileErrorKind> {
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    if !norm.is_finite() || (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(FileErrorKind::BadQuaternion { q, norm });
    }
    Ok(UnitQuaternion::from_quaternion(Quaternion::new(
        q[3], q[0], q[1], q[2],
    )))
}

/// (x, y, z, w) of a rotation.
pub fn quaternion_xyzw(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.i, q.j, q.k, q.w]
}

impl Trajectory {
    /// Parses TUM trajectory text. Lines starting with `#` and blank lines are skipped; a
    /// duplicate timestamp keeps the first pose.
    pub fn parse(text: &str, path: &Path) -> Result<Self, FileError> {
        // A byte-order mark (Windows editors) is read past, as in every list mrtmap reads.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut t = Trajectory::default();
        for (i, line) in text.lines().enumerate() {
            let line_no = i + 1;
            let s = line.trim();
            if s.is_empty() || s.starts_with('#') {
                continue;
            }
            let v: Vec<f64> = s
                .split_whitespace()
                .map(|x| x.parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| {
                    FileError::syntax(path, line_no, format!("expected 8 numbers, got '{s}'"))
                })?;
            if v.len() != 8 {
                return Err(FileError::syntax(
                    path,
                    line_no,
                    format!(
                        "expected 8 numbers (timestamp tx ty tz qx qy qz qw), got {}",
                        v.len()
                    ),
                ));
            }
            if v.iter().any(|x| !x.is_finite()) {
                return Err(FileError::syntax(
                    path,
                    line_no,
                    "a value is not a finite number",
                ));
            }
            if let Some(&prev) = t.stamps.last() {
                if v[0] < prev {
                    return Err(FileError::new(
                        path,
                        Some(line_no),
                        FileErrorKind::TimestampBackwards {
                            t: v[0],
                            previous: prev,
                        },
                    ));
                }
                if v[0] == prev {
                    continue;
                }
            }
            let q = unit_quaternion([v[4], v[5], v[6], v[7]])
                .map_err(|k| FileError::new(path, Some(line_no), k))?;
            t.stamps.push(v[0]);
            t.poses.push(Isometry3::from_parts(
                Translation3::new(v[1], v[2], v[3]),
                q,
            ));
        }
        Ok(t)
    }

    /// Reads a TUM trajectory file.
    pub fn read(path: &Path) -> Result<Self, FileError> {
        let text = std::fs::read_to_string(path).map_err(|e| FileError::io(path, e))?;
        Self::parse(&text, path)
    }

    /// TUM text (9 decimals for times and positions, 9 for quaternions).
    pub fn to_tum(&self, header: &str) -> String {
        let mut s = String::with_capacity(self.stamps.len() * 100);
        for l in header.lines() {
            s.push_str(&format!("# {l}\n"));
        }
        for (t, p) in self.stamps.iter().zip(&self.poses) {
            let q = quaternion_xyzw(&p.rotation);
            let tr = p.translation.vector;
            s.push_str(&format!(
                "{t:.6} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9}\n",
                tr.x, tr.y, tr.z, q[0], q[1], q[2], q[3]
            ));
        }
        s
    }

    /// Number of poses.
    pub fn len(&self) -> usize {
        self.stamps.len()
    }

    /// Whether there are no poses.
    pub fn is_empty(&self) -> bool {
        self.stamps.is_empty()
    }

    /// The pose at time `t`: interpolated between the two poses around it (linear translation,
    /// slerp rotation), the end pose within `max_extrapolation_secs` of either end, else `None`
    /// (also across a gap longer than `max_gap_secs`).
    pub fn interpolate(&self, t: f64, limits: &InterpolationLimits) -> Option<Isometry3<f64>> {
        let n = self.stamps.len();
        if n == 0 || !t.is_finite() {
            return None;
        }
        if t <= self.stamps[0] {
            return (self.stamps[0] - t <= limits.max_extrapolation_secs).then_some(self.poses[0]);
        }
        if t >= self.stamps[n - 1] {
            return (t - self.stamps[n - 1] <= limits.max_extrapolation_secs)
                .then_some(self.poses[n - 1]);
        }
        let k = self.stamps.partition_point(|&s| s <= t);
        let (t0, t1) = (self.stamps[k - 1], self.stamps[k]);
        if t1 - t0 > limits.max_gap_secs {
            return None;
        }
        let a = (t - t0) / (t1 - t0);
        let (p0, p1) = (&self.poses[k - 1], &self.poses[k]);
        let tr = p0.translation.vector.lerp(&p1.translation.vector, a);
        let rot = p0
            .rotation
            .try_slerp(&p1.rotation, a, 1e-12)
            .unwrap_or(p0.rotation);
        Some(Isometry3::from_parts(Translation3::from(tr), rot))
    }
}
