//! A tracked trajectory against true poses: the rigid alignment between their world frames and
//! TUM's trajectory errors.
//!
//! 1. Pairs: each estimated pose with the true pose interpolated at its time.
//! 2. Alignment: the rigid transform (Horn/Kabsch on the positions) that carries the estimated
//!    positions onto the true ones ([`align`], [`expressed_in`]).
//! 3. Absolute trajectory error: position and orientation errors after the alignment.
//! 4. Relative pose errors: the motion between each pose and the first at least a span later,
//!    estimated against true, frame to frame and over the drift span ([`trajectory_error`]).

use mrtmap_geometry::icp::kabsch;
use mrtmap_geometry::nalgebra::{Isometry3, Point3};
use mrtmap_io::Trajectory;
use serde::{Deserialize, Serialize};

use super::renormalised;

/// The drift figures' span (s), or the whole trajectory when it is shorter.
const DRIFT_SPAN_S: f64 = 1.0;

/// Times closer than this (s) count as equal when looking for the pose a span later.
const TIME_TOLERANCE_S: f64 = 1e-9;

/// Absolute trajectory error (TUM's definition: poses associated by time, rigidly aligned).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryError {
    /// Poses compared.
    pub poses: usize,
    /// RMSE of the positions after alignment (m).
    pub ate_rmse_m: f64,
    /// Largest position error (m).
    pub ate_max_m: f64,
    /// RMSE of the orientations after the same alignment (degrees; ill-determined on a short,
    /// nearly straight trajectory, whose alignment the positions do not fix).
    pub ate_rotation_rmse_deg: f64,
    /// Relative pose error between consecutive poses (TUM's RPE at one frame): translation RMSE (m)…
    pub rpe_translation_rmse_m: f64,
    /// …and rotation RMSE (degrees).
    pub rpe_rotation_rmse_deg: f64,
    /// The span of the drift figures (s): 1 s, or the whole trajectory if shorter.
    pub drift_span_s: f64,
    /// Drift: the relative pose error over `drift_span_s`, translation RMSE (m)…
    pub drift_translation_rmse_m: f64,
    /// …and rotation RMSE (degrees).
    pub drift_rotation_rmse_deg: f64,
}

/// Each estimated pose with the true pose interpolated at its time: (time, estimated, true).
fn paired(est: &Trajectory, truth: &Trajectory) -> Vec<(f64, Isometry3<f64>, Isometry3<f64>)> {
    let limits = mrtmap_io::InterpolationLimits::default();
    est.stamps
        .iter()
        .zip(&est.poses)
        .filter_map(|(&t, p)| Some((t, *p, truth.interpolate(t, &limits)?)))
        .collect()
}

/// The rigid transform (Horn/Kabsch on the positions) that carries the pairs' estimated poses
/// onto the true ones; `None` below three pairs.
fn align_pairs(pairs: &[(f64, Isometry3<f64>, Isometry3<f64>)]) -> Option<Isometry3<f64>> {
    if pairs.len() < 3 {
        return None;
    }
    let (a, b): (Vec<Point3<f64>>, Vec<Point3<f64>>) = pairs
        .iter()
        .map(|(_, p, q)| {
            (
                Point3::from(p.translation.vector),
                Point3::from(q.translation.vector),
            )
        })
        .unzip();
    kabsch(&a, &b)
}

/// truth_world_from_est_world: the rigid transform (Horn/Kabsch on the positions, poses paired by
/// time) that carries an estimated trajectory onto the true one; `None` below three pairs.
pub fn align(est: &Trajectory, truth: &Trajectory) -> Option<Isometry3<f64>> {
    align_pairs(&paired(est, truth))
}

/// `est` carried into `reference`'s world frame by [`align`] (a re-tracked recording keeps the
/// frame its references and points are given in); `None` below three poses paired in time.
pub fn expressed_in(est: &Trajectory, reference: &Trajectory) -> Option<Trajectory> {
    let w = align(est, reference)?;
    Some(Trajectory {
        stamps: est.stamps.clone(),
        poses: est.poses.iter().map(|p| renormalised(&(w * p))).collect(),
    })
}

/// TUM's absolute trajectory error: each estimated pose against the true pose interpolated at its
/// time, after the rigid alignment (Horn) that minimises the position errors.
pub fn trajectory_error(est: &Trajectory, truth: &Trajectory) -> Option<TrajectoryError> {
    let pairs = paired(est, truth);
    let align = align_pairs(&pairs)?;
    let (mut se, mut max, mut sr) = (0.0, 0.0f64, 0.0);
    for (_, p, q) in &pairs {
        let a = align * p;
        let e = (a.translation.vector - q.translation.vector).norm();
        se += e * e;
        max = max.max(e);
        sr += (a.rotation.inverse() * q.rotation)
            .angle()
            .to_degrees()
            .powi(2);
    }
    let n = pairs.len() as f64;
    // Relative pose errors between pose k and the first pose at least `span` seconds later.
    let rpe = |span: f64| -> (f64, f64) {
        let (mut st, mut sr, mut m) = (0.0, 0.0, 0usize);
        let mut j = 0;
        for k in 0..pairs.len() {
            j = j.max(k + 1);
            while j < pairs.len() && pairs[j].0 - pairs[k].0 < span - TIME_TOLERANCE_S {
                j += 1;
            }
            if j >= pairs.len() {
                break;
            }
            let de = pairs[k].1.inverse() * pairs[j].1;
            let dg = pairs[k].2.inverse() * pairs[j].2;
            let e = dg.inverse() * de;
            st += e.translation.vector.norm_squared();
            sr += e.rotation.angle().to_degrees().powi(2);
            m += 1;
        }
        let m = m.max(1) as f64;
        ((st / m).sqrt(), (sr / m).sqrt())
    };
    let (rt, rr) = rpe(0.0);
    let span = (pairs[pairs.len() - 1].0 - pairs[0].0).min(DRIFT_SPAN_S);
    let (dt, dr) = rpe(span);
    Some(TrajectoryError {
        poses: pairs.len(),
        ate_rmse_m: (se / n).sqrt(),
        ate_max_m: max,
        ate_rotation_rmse_deg: (sr / n).sqrt(),
        rpe_translation_rmse_m: rt,
        rpe_rotation_rmse_deg: rr,
        drift_span_s: span,
        drift_translation_rmse_m: dt,
        drift_rotation_rmse_deg: dr,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use mrtmap_geometry::nalgebra::{Translation3, UnitQuaternion, Vector3};

    fn pose(t: [f64; 3], axis_angle: [f64; 3]) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(t[0], t[1], t[2]),
            UnitQuaternion::from_scaled_axis(Vector3::from(axis_angle)),
        )
    }

    #[test]
    fn the_trajectory_error_ignores_the_world_frame_and_sees_a_bent_path() {
        let truth = Trajectory {
            stamps: (0..40).map(|k| k as f64 * 0.1).collect(),
            poses: (0..40)
                .map(|k| {
                    let s = k as f64 * 0.1;
                    pose([s, (s * 2.0).sin(), 0.3 * s], [0.0, 0.0, 0.2 * s])
                })
                .collect(),
        };
        // The same path in another world frame: no error.
        let w = pose([1.0, 2.0, -0.5], [0.2, 0.1, 1.0]);
        let moved = Trajectory {
            stamps: truth.stamps.clone(),
            poses: truth.poses.iter().map(|p| w * p).collect(),
        };
        let e = trajectory_error(&moved, &truth).unwrap();
        assert_eq!(e.poses, 40);
        // Carried back into the truth's frame: the truth.
        let back = expressed_in(&moved, &truth).unwrap();
        assert!(back.poses.iter().zip(&truth.poses).all(|(a, b)| {
            (a.translation.vector - b.translation.vector).norm() < 1e-9
                && a.rotation.angle_to(&b.rotation) < 1e-9
        }));
        assert!(
            e.ate_rmse_m < 1e-9 && e.rpe_translation_rmse_m < 1e-9,
            "{e:?}"
        );
        assert!(e.ate_rotation_rmse_deg < 1e-6, "{e:?}");
        assert!(e.drift_rotation_rmse_deg < 1e-6, "{e:?}");
        assert!((e.drift_span_s - 1.0).abs() < 1e-9);
        // A path that drifts 1 cm per pose along x: seen by the ATE and by the relative errors.
        let drifted = Trajectory {
            stamps: truth.stamps.clone(),
            poses: truth
                .poses
                .iter()
                .enumerate()
                .map(|(k, p)| pose([0.01 * k as f64, 0.0, 0.0], [0.0, 0.0, 0.0]) * p)
                .collect(),
        };
        let e = trajectory_error(&drifted, &truth).unwrap();
        assert!(e.ate_rmse_m > 0.005, "{e:?}");
        assert!((e.drift_translation_rmse_m - 0.1).abs() < 0.02, "{e:?}");
    }
}
