//! A frame placed by its depth alone, where its corners do not suffice (a close-up of a plain
//! surface, motion blur): point-to-plane ICP of its depth on the reference keyframe's.
//!
//! 1. The frame's depth cloud moved to the colour frame's time and thinned; too few points: none.
//! 2. Point-to-plane ICP on the keyframe's depth, from the predicted pose.
//! 3. Accepted only near the prediction (far from it is a wrong minimum, a wall slid along a wall,
//!    not a fast camera), with most points fitted, a small plane error and every direction
//!    constrained.
//! 4. The link's information is fixed ([`depth_only_information`]): as a weakly matched visual
//!    link.

use mrtmap_geometry::icp::{IcpParams, icp_point_to_plane};
use mrtmap_geometry::nalgebra::{Isometry3, Matrix6, Vector6};

use super::features::Features;
use super::pose::Found;
use super::{Keyframe, rotation_deg};

/// The depth-only link's standard deviation in translation (m)…
const LINK_SIGMA_M: f64 = 0.008;

/// …and in rotation (degrees).
const LINK_SIGMA_DEG: f64 = 0.17;

/// The frame's depth cloud is thinned to about this many points for ICP…
const SOURCE_POINTS: usize = 2_000;

/// …and needs at least this many.
const MIN_SOURCE_POINTS: usize = 300;

/// ICP pairs a point with the keyframe's surface within this distance (m).
const MAX_CORRESPONDENCE_M: f64 = 0.08;

/// ICP iterations at most.
const ICP_ITERATIONS: usize = 30;

/// ICP stops when a step moves the camera less than this (m)…
const ICP_CONVERGED_M: f64 = 1e-4;

/// …and turns it less than this (rad).
const ICP_CONVERGED_RAD: f64 = 1e-4;

/// The fit must lie within this distance (m)…
const MAX_FROM_PREDICTION_M: f64 = 0.05;

/// …and this angle (degrees) of the prediction.
const MAX_FROM_PREDICTION_DEG: f64 = 3.0;

/// At least this share of the points must find the keyframe's surface…
const MIN_FITNESS: f64 = 0.7;

/// …with an RMS distance to its planes of at most this (m).
const MAX_PLANE_RMSE_M: f64 = 0.015;

/// A depth-only link's information in the units of [`information`](super::pose::information): as a weakly matched visual
/// link (about 8 mm and 0.17° at the nominal error; the median visual link of a simulated walk is
/// pinned to about 4.5 mm and 0.09° there).
fn depth_only_information() -> Matrix6<f64> {
    let (st, sr) = (LINK_SIGMA_M, LINK_SIGMA_DEG.to_radians());
    let d = 1.0 / (st * st);
    let r = 1.0 / (sr * sr);
    Matrix6::from_diagonal(&Vector6::new(d, d, d, r, r, r))
}

/// current_from_keyframe by point-to-plane ICP of the frame's depth on the keyframe's, from the
/// prediction; `None` when the fit is poor or leaves a direction unconstrained.
pub(super) fn depth_only(
    kf: &Keyframe,
    f: &Features,
    motion: &Isometry3<f64>,
    predicted: &Isometry3<f64>,
) -> Option<Found> {
    let target = kf.target.as_ref()?;
    let src = f.cloud_at(motion, SOURCE_POINTS)?;
    if src.points.len() < MIN_SOURCE_POINTS {
        return None;
    }
    let icp = IcpParams {
        max_correspondence_m: MAX_CORRESPONDENCE_M,
        max_iterations: ICP_ITERATIONS,
        converged_translation_m: ICP_CONVERGED_M,
        converged_rotation_rad: ICP_CONVERGED_RAD,
        ..IcpParams::default()
    };
    // ICP gives keyframe_from_frame; the prediction is frame_from_keyframe.
    let reg = icp_point_to_plane(&src.points, target, &predicted.inverse(), &icp);
    // Far from the prediction is a wrong minimum (a wall slid along a wall), not a fast camera.
    let moved = predicted * reg.target_from_source;
    let near = moved.translation.vector.norm() < MAX_FROM_PREDICTION_M
        && rotation_deg(&moved) < MAX_FROM_PREDICTION_DEG;
    (near
        && reg.fitness >= MIN_FITNESS
        && reg.inlier_plane_rmse_m <= MAX_PLANE_RMSE_M
        && reg.degenerate_dofs == 0)
        .then(|| Found {
            pose: reg.target_from_source.inverse(),
            information: depth_only_information(),
            inliers: 0,
            reprojection_px: 0.0,
        })
}
