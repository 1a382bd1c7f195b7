//! The motion model: where the camera is expected to be at a frame's time, from its velocity and,
//! where the recording has one, the gyro.
//!
//! 1. The velocity ([`Twist`]): the motion between the last two tracked frames over their time
//!    apart, in the camera's own frame.
//! 2. The gyro ([`Gyro`]): imu.txt's rates carried into the colour camera's frame, integrated
//!    between two times (held from each sample to the next).
//! 3. The prediction ([`predict`]): the velocity's translation over the interval, with the gyro's
//!    rotation where the samples cover it, else the velocity's.

use mrtmap_geometry::nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// The gyro's samples must come this close (s) to each end of an interval, and lie no farther
/// apart within it, for its rotation to be integrated.
const MAX_GYRO_GAP_S: f64 = 0.05;

/// The camera's velocity in its own frame: translation (m/s) and rotation (rad/s, scaled axis).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Twist {
    v: Vector3<f64>,
    w: Vector3<f64>,
}

impl Twist {
    /// From the motion `rel` (earlier_from_later) over `dt` seconds.
    pub(super) fn from_motion(rel: &Isometry3<f64>, dt: f64) -> Self {
        Self {
            v: rel.translation.vector / dt,
            w: rel.rotation.scaled_axis() / dt,
        }
    }

    /// The motion over `dt` seconds (now_from_later; negative `dt`: now_from_earlier).
    fn over(&self, dt: f64) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::from(self.v * dt),
            UnitQuaternion::from_scaled_axis(self.w * dt),
        )
    }
}

/// The rig's gyro in the colour camera's frame: turns between two times, for the prediction.
pub(super) struct Gyro {
    /// Sample times (s).
    pub(super) t: Vec<f64>,
    /// Rates (rad/s) in the colour camera's frame.
    w: Vec<Vector3<f64>>,
}

impl Gyro {
    /// From `imu.txt`'s samples (depth camera frame); `None` without samples.
    pub(super) fn new(
        imu: &[mrtmap_io::ImuSample],
        colour_from_depth: &Isometry3<f64>,
    ) -> Option<Self> {
        (imu.len() >= 2).then(|| Self {
            t: imu.iter().map(|m| m.t).collect(),
            w: imu
                .iter()
                .map(|m| colour_from_depth.rotation * m.gyro)
                .collect(),
        })
    }

    /// The rotation from `t0` to `t1` as earlier_from_later (the camera at `t0` from the camera
    /// at `t1`; `t1` < `t0` gives the inverse), integrating the rates held from each sample to
    /// the next; `None` when the samples do not cover the interval (a gap over 50 ms).
    fn turn(&self, t0: f64, t1: f64) -> Option<UnitQuaternion<f64>> {
        if t1 < t0 {
            return self.turn(t1, t0).map(|q| q.inverse());
        }
        let n = self.t.len();
        if self.t[0] > t0 + MAX_GYRO_GAP_S || self.t[n - 1] < t1 - MAX_GYRO_GAP_S {
            return None;
        }
        let mut k = self.t.partition_point(|&x| x <= t0).saturating_sub(1);
        let mut q = UnitQuaternion::identity();
        let mut at = t0;
        while at < t1 {
            let next = if k + 1 < n { self.t[k + 1].min(t1) } else { t1 };
            if next - self.t[k].max(at) > MAX_GYRO_GAP_S && k + 1 < n {
                return None;
            }
            q *= UnitQuaternion::from_scaled_axis(self.w[k] * (next - at));
            at = next;
            k += 1;
            if k >= n {
                break;
            }
        }
        Some(q)
    }
}

/// The predicted motion from `t0` to `t1` (earlier_from_later): the velocity's translation and
/// rotation, the rotation from the gyro where there is one.
pub(super) fn predict(velocity: &Twist, gyro: Option<&Gyro>, t0: f64, t1: f64) -> Isometry3<f64> {
    let m = velocity.over(t1 - t0);
    match gyro.and_then(|g| g.turn(t0, t1)) {
        Some(q) => Isometry3::from_parts(m.translation, q),
        None => m,
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn pose(t: [f64; 3], axis_angle: [f64; 3]) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(t[0], t[1], t[2]),
            UnitQuaternion::from_scaled_axis(Vector3::from(axis_angle)),
        )
    }

    #[test]
    fn a_twist_gives_back_the_motion_it_came_from_and_scales_with_time() {
        let rel = pose([0.02, 0.0, -0.01], [0.0, 0.012, 0.003]);
        let v = Twist::from_motion(&rel, 1.0 / 30.0);
        let back = v.over(1.0 / 30.0);
        assert!((back.translation.vector - rel.translation.vector).norm() < 1e-12);
        assert!((back.rotation.inverse() * rel.rotation).angle() < 1e-12);
        let half = v.over(0.5 / 30.0);
        assert!((half.rotation.angle() - rel.rotation.angle() / 2.0).abs() < 1e-12);
        // Backwards in time: the inverse motion (to first order in the rotation: 0.3 mm here).
        let before = v.over(-1.0 / 30.0) * back;
        assert!(before.translation.vector.norm() < 5e-4 && before.rotation.angle() < 1e-9);
    }

    #[test]
    fn the_gyro_turn_integrates_the_rates_and_refuses_a_gap() {
        // 0.5 rad/s about y, then about x after t = 1 s; 200 Hz, a gap from 1.5 to 1.6 s.
        let imu: Vec<mrtmap_io::ImuSample> = (0..400)
            .map(|k| k as f64 * 0.005)
            .filter(|t| !(1.5..1.6).contains(t))
            .map(|t| mrtmap_io::ImuSample {
                t,
                gyro: if t < 1.0 {
                    Vector3::new(0.0, 0.5, 0.0)
                } else {
                    Vector3::new(0.5, 0.0, 0.0)
                },
                accel: Vector3::new(0.0, -9.81, 0.0),
            })
            .collect();
        let g = Gyro::new(&imu, &Isometry3::identity()).unwrap();
        let q = g.turn(0.2, 0.6).unwrap();
        let want = UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.2, 0.0));
        assert!(q.angle_to(&want) < 1e-9, "{q:?}");
        // Backwards: the inverse; across the change of axis: y then x.
        assert!(g.turn(0.6, 0.2).unwrap().angle_to(&want.inverse()) < 1e-9);
        let both = UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.05, 0.0))
            * UnitQuaternion::from_scaled_axis(Vector3::new(0.05, 0.0, 0.0));
        assert!(g.turn(0.9, 1.1).unwrap().angle_to(&both) < 1e-9);
        assert!(g.turn(1.4, 1.7).is_none(), "a 100 ms gap");
        assert!(g.turn(2.5, 2.6).is_none(), "beyond the samples");
        // In the colour camera's frame: a camera turned 90° about z sees the y rate about x.
        let turned = Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2)),
        );
        let g = Gyro::new(&imu, &turned).unwrap();
        let q = g.turn(0.2, 0.6).unwrap();
        let want = UnitQuaternion::from_scaled_axis(Vector3::new(-0.2, 0.0, 0.0));
        assert!(q.angle_to(&want) < 1e-9, "{q:?}");
    }
}
