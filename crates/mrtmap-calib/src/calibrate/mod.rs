//! Intrinsic (Zhang) and stereo calibration.
//!
//! One camera: homographies → focal lengths with the principal point at the centre → board poses
//! → Levenberg–Marquardt over the intrinsics, the distortion model's coefficients and every pose,
//! first without distortion, then with it; views whose RMS error is far above the others' are
//! rejected and the fit repeated.
//!
//! Two cameras: each is first calibrated alone, from all of its own images. The thermal corners'
//! numbering is then tied to the colour image's (a plain checkerboard is numbered from what each
//! camera sees: a quarter turn apart, or shifted on a partly visible board): the quarter turn that
//! makes the two cameras look the same way, then the shift whose corners lie nearest where the
//! colour view of the board, carried through the extrinsic of the pairs that show the whole board
//! in both images, puts them. Last, the extrinsic and every board pose are fitted with the
//! intrinsics fixed (as OpenCV's `stereoCalibrate` with `CALIB_FIX_INTRINSIC`), pairs whose error
//! stands out are rejected and reported, and the extrinsic's spread is bootstrapped over the pairs.
//!
//! Why not refine the intrinsics jointly: on a hand-made board, whose squares are irregular by a
//! millimetre, both cameras' residuals are the board's, not pixel noise; a joint fit then lets
//! the camera with more pixels drag the other's focal length (on the real foil-board pairs the
//! thermal f went from 152 px alone to 163 px jointly, while OpenCV's is 152 px).
//!
//! Where each part lives:
//!
//! - `intrinsics.rs`: a camera's intrinsics by name ([`Intrinsics`]), flat only for the solver,
//!   and which of them each distortion model frees;
//! - `mono.rs`: one camera (Zhang's start, Levenberg–Marquardt, outlier views, the distortion model
//!   and principal point chosen by held-out views);
//! - `correspondence.rs`: the thermal corners' numbering tied to the colour image's, and the first
//!   extrinsic from the pairs that show the whole board;
//! - `stereo.rs`: the extrinsic fit (intrinsics fixed or refined jointly), outlier pairs and the
//!   result;
//! - `resample.rs`: refits on subsets of the pairs: held-out errors and the bootstrap's spread;
//! - `mod.rs`: the reprojection residuals and errors all of them share.

mod correspondence;
mod intrinsics;
mod joint;
mod mono;
mod resample;
mod stereo;

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::board::Board;
use crate::detect::{Corner, Detection};

pub use intrinsics::{DistortionModel, Intrinsics, camera_from};
pub use joint::PairStatus;
pub use mono::{MonoResult, PrincipalPoint, calibrate_mono, calibrate_mono_with};
pub use stereo::{PairInput, PairResult, StereoOptions, StereoResult, calibrate_stereo};

/// Isometry from (axis-angle, translation).
pub fn iso(p: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p[3], p[4], p[5]),
        UnitQuaternion::from_scaled_axis(Vector3::new(p[0], p[1], p[2])),
    )
}

/// (axis-angle, translation) of an isometry.
pub fn vec6(i: &Isometry3<f64>) -> [f64; 6] {
    let w = i.rotation.scaled_axis();
    let t = i.translation.vector;
    [w.x, w.y, w.z, t.x, t.y, t.z]
}

/// A pixel far off for a point behind the camera, so residual counts never change.
const BEHIND: f64 = 1e3;

/// Appends each corner's reprojection residual (x, y; px) through `cam` and the board pose.
fn push_residuals(
    cam: &PinholeCamera,
    pose: &Isometry3<f64>,
    board: &Board,
    corners: &[Corner],
    out: &mut Vec<f64>,
) {
    for c in corners {
        let p = pose * board.point(c.i, c.j);
        match cam.project(&p) {
            Some(px) => {
                out.push(px.x - c.x);
                out.push(px.y - c.y);
            }
            None => {
                out.push(BEHIND);
                out.push(BEHIND);
            }
        }
    }
}

/// Reprojection errors of one view: RMS and mean of the per-corner distances (px).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ViewError {
    /// Root mean square distance.
    pub rms_px: f64,
    /// Mean distance (the "mean reprojection error").
    pub mean_px: f64,
    /// Corners.
    pub corners: usize,
}

/// The reprojection errors of one view of the board.
fn view_error(
    cam: &PinholeCamera,
    pose: &Isometry3<f64>,
    board: &Board,
    c: &[Corner],
) -> ViewError {
    let mut r = Vec::new();
    push_residuals(cam, pose, board, c, &mut r);
    let d: Vec<f64> = r.chunks(2).map(|e| e[0].hypot(e[1])).collect();
    let n = d.len().max(1) as f64;
    ViewError {
        rms_px: (d.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
        mean_px: d.iter().sum::<f64>() / n,
        corners: d.len(),
    }
}

/// Pooled error over views (weighted by corners).
fn pooled(v: &[ViewError]) -> ViewError {
    let n: usize = v.iter().map(|e| e.corners).sum();
    let nf = n.max(1) as f64;
    ViewError {
        rms_px: (v
            .iter()
            .map(|e| e.rms_px * e.rms_px * e.corners as f64)
            .sum::<f64>()
            / nf)
            .sqrt(),
        mean_px: v.iter().map(|e| e.mean_px * e.corners as f64).sum::<f64>() / nf,
        corners: n,
    }
}

/// Rejects views whose RMS exceeds max(3 × median, `floor_px`): returns the flags of kept views.
fn keep_flags(rms: &[Option<f64>], floor_px: f64) -> Vec<bool> {
    let mut v: Vec<f64> = rms.iter().flatten().copied().collect();
    if v.is_empty() {
        return rms.iter().map(|_| false).collect();
    }
    v.sort_by(f64::total_cmp);
    let limit = (3.0 * v[v.len() / 2]).max(floor_px);
    rms.iter().map(|r| r.is_some_and(|x| x <= limit)).collect()
}

/// The corners of a detection (none when absent).
fn corners_of(d: &Option<Detection>) -> &[Corner] {
    d.as_ref().map(|d| d.corners.as_slice()).unwrap_or(&[])
}

/// The board point seen at a colour pixel, through the board plane of a pose (camera_from_board).
pub fn board_plane_point(
    cam: &PinholeCamera,
    pose: &Isometry3<f64>,
    px: &Point2<f64>,
) -> Option<Point3<f64>> {
    let ray = cam.unproject(px);
    let inv = pose.inverse();
    let o = inv * Point3::origin();
    let d = inv * ray;
    if d.z.abs() < 1e-12 {
        return None;
    }
    let s = -o.z / d.z;
    (s > 0.0).then(|| pose * (o + d * s))
}
