//! One camera's calibration from its views of the board.
//!
//! 1. Zhang's start ([`zhang_start`]): a homography per view, the focal lengths from them with the
//!    principal point at the image centre, and each view's pose from its homography.
//! 2. Levenberg–Marquardt over the intrinsics and every pose, first without distortion, then with
//!    the distortion model's coefficients.
//! 3. Views whose RMS error is far above the others' dropped and the fit repeated, twice at most
//!    ([`drop_outlier_views`]).
//! 4. With [`DistortionModel::Auto`]: k1 k2 alone unless p1 p2 predict held-out views more than
//!    1 % better.
//! 5. The principal point free or at the image centre, whichever predicts held-out views better
//!    (or as asked), and the fit repeated with it centred when chosen.
//! 6. Each used view's pose and error, and the pooled error.

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Isometry3, Matrix3, Point2};
use serde::{Deserialize, Serialize};

use super::intrinsics::{DistortionModel, Intrinsics, camera_from};
use super::{ViewError, corners_of, iso, keep_flags, pooled, push_residuals, vec6, view_error};
use crate::CalibError;
use crate::board::Board;
use crate::detect::{Corner, Detection};
use crate::lm::{Problem, solve};
use crate::zhang::{fit_homography, init_focal, pose_from_homography};

/// One camera's calibration.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MonoResult {
    /// Intrinsics and distortion.
    pub camera: PinholeCamera,
    /// Standard deviations of fx fy cx cy k1 k2 p1 p2 k3 (0 for fixed ones).
    pub std: Option<[f64; Intrinsics::LEN]>,
    /// Per input view: the board pose (camera_from_board) when the view was used.
    #[serde(skip)]
    pub poses: Vec<Option<Isometry3<f64>>>,
    /// Per input view: its error when used.
    pub view_errors: Vec<Option<ViewError>>,
    /// Views rejected as outliers (indices into the input).
    pub rejected: Vec<usize>,
    /// Pooled error over the used views.
    pub error: ViewError,
    /// Whether the principal point was fixed at the image centre (the views did not predict
    /// held-out views better with it free).
    #[serde(default)]
    pub principal_point_centred: bool,
    /// Held-out RMS error (px) with the principal point free and at the centre, when compared.
    #[serde(default)]
    pub held_out_rms_px: Option<(f64, f64)>,
    /// The distortion model fitted (`Auto` resolved).
    #[serde(default)]
    pub model: DistortionModel,
    /// With `Auto`: held-out RMS error (px) of k1 k2 and of k1 k2 p1 p2.
    #[serde(default)]
    pub model_held_out_px: Option<(f64, f64)>,
}

/// Where a camera's principal point comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrincipalPoint {
    /// Free or at the image centre, whichever predicts held-out views better (five folds).
    Choose,
    /// Fitted.
    Free,
    /// At the image centre.
    Centre,
}

/// Held-out RMS error (px) of a model: fitted on four fifths of the active views, the others'
/// poses fitted with the intrinsics fixed, over five folds; `None` with fewer than ten views.
fn held_out_rms(
    prob: &Mono<'_>,
    s: &crate::lm::Solved,
    free: &[bool],
    active: &[bool],
) -> Option<f64> {
    let act: Vec<usize> = (0..active.len()).filter(|v| active[*v]).collect();
    if act.len() < 10 {
        return None;
    }
    let none = vec![false; free.len()];
    let (mut sum, mut count) = (0.0, 0usize);
    for fold in 0..5 {
        let in_test = |v: usize| {
            act.iter()
                .position(|a| *a == v)
                .is_some_and(|i| i % 5 == fold)
        };
        let train: Vec<bool> = (0..active.len())
            .map(|v| active[v] && !in_test(v))
            .collect();
        let test: Vec<bool> = (0..active.len()).map(|v| active[v] && in_test(v)).collect();
        let fit = solve(prob, s.global.clone(), s.views.clone(), free, &train, 100);
        let posed = solve(prob, fit.global, fit.views, &none, &test, 50);
        sum += posed.sum_sq;
        count += posed.residuals / 2;
    }
    Some((sum / count.max(1) as f64).sqrt())
}

/// One camera's problem for the solver: the board seen in each view.
pub(super) struct Mono<'a> {
    /// The board.
    pub(super) board: &'a Board,
    /// Image size (px).
    pub(super) size: (u32, u32),
    /// Each view's corners.
    pub(super) views: Vec<&'a [Corner]>,
}

impl Problem for Mono<'_> {
    fn views(&self) -> usize {
        self.views.len()
    }
    fn residuals(&self, v: usize, g: &[f64], p: &[f64; 6], out: &mut Vec<f64>) {
        let cam = camera_from(self.size.0, self.size.1, g);
        push_residuals(&cam, &iso(p), self.board, self.views[v], out);
    }
}

/// Views that gave a pose: their index among the detections and their pose.
type PosedViews = Vec<(usize, [f64; 6])>;

/// Zhang's start: a homography per view, the focal lengths from them (the principal point at the
/// centre), and each view's pose from its homography. Returns (fx, fy) and the views that gave a
/// pose, with their index and pose.
fn zhang_start(
    board: &Board,
    (width, height): (u32, u32),
    dets: &[Option<Detection>],
    usable: &[usize],
) -> ((f64, f64), PosedViews) {
    let (cx, cy) = ((width as f64 - 1.0) / 2.0, (height as f64 - 1.0) / 2.0);
    let homs: Vec<Option<Matrix3<f64>>> = usable
        .iter()
        .map(|&k| {
            let d = corners_of(&dets[k]);
            let src: Vec<Point2<f64>> = d
                .iter()
                .map(|c| {
                    let p = board.point(c.i, c.j);
                    Point2::new(p.x, p.y)
                })
                .collect();
            let dst: Vec<Point2<f64>> = d.iter().map(|c| Point2::new(c.x, c.y)).collect();
            fit_homography(&src, &dst)
        })
        .collect();
    let good: Vec<Matrix3<f64>> = homs.iter().flatten().copied().collect();
    let (fx, fy) = init_focal(&good, cx, cy).unwrap_or((width as f64, width as f64));
    let k = Matrix3::new(fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0);
    let posed = homs
        .iter()
        .zip(usable)
        .filter_map(|(h, &vi)| {
            let p = h.as_ref().and_then(|h| pose_from_homography(h, &k))?;
            Some((vi, vec6(&p)))
        })
        .collect();
    ((fx, fy), posed)
}

/// Refits without the views whose error is far above the others', twice at most and keeping at
/// least three; returns the fit and the views dropped (indices into `index`'s detections).
fn drop_outlier_views(
    prob: &Mono<'_>,
    mut s: crate::lm::Solved,
    model: DistortionModel,
    active: &mut [bool],
    index: &[usize],
) -> (crate::lm::Solved, Vec<usize>) {
    let mut rejected = Vec::new();
    for _ in 0..2 {
        let cam = camera_from(prob.size.0, prob.size.1, &s.global);
        let rms: Vec<Option<f64>> = (0..index.len())
            .map(|v| {
                active[v]
                    .then(|| view_error(&cam, &iso(&s.views[v]), prob.board, prob.views[v]).rms_px)
            })
            .collect();
        let keep = keep_flags(&rms, 0.5);
        let newly: Vec<usize> = (0..index.len())
            .filter(|&v| active[v] && !keep[v])
            .collect();
        if newly.is_empty() || active.iter().filter(|a| **a).count() - newly.len() < 3 {
            break;
        }
        for v in newly {
            active[v] = false;
            rejected.push(index[v]);
        }
        s = solve(prob, s.global, s.views, &model.free(), active, 100);
    }
    rejected.sort_unstable();
    (s, rejected)
}

/// Calibrates one camera from its detections (`None` where the board was not found); the
/// principal point free or at the centre, whichever predicts held-out views better.
pub fn calibrate_mono(
    board: &Board,
    width: u32,
    height: u32,
    dets: &[Option<Detection>],
    model: DistortionModel,
) -> Result<MonoResult, CalibError> {
    calibrate_mono_with(board, width, height, dets, model, PrincipalPoint::Choose)
}

/// `calibrate_mono` with the principal point's treatment given.
///
/// Longer than 120 lines (123): Zhang's initialisation, the LM refinement and the distortion
/// model's choice by held-out views share the per-view residual set-up; not split yet.
pub fn calibrate_mono_with(
    board: &Board,
    width: u32,
    height: u32,
    dets: &[Option<Detection>],
    model: DistortionModel,
    principal: PrincipalPoint,
) -> Result<MonoResult, CalibError> {
    let usable: Vec<usize> = (0..dets.len())
        .filter(|&k| dets[k].as_ref().is_some_and(|d| d.corners.len() >= 6))
        .collect();
    if usable.len() < 3 {
        return Err(CalibError::TooFewViews {
            found: usable.len(),
            width,
            height,
        });
    }
    let (cx, cy) = ((width as f64 - 1.0) / 2.0, (height as f64 - 1.0) / 2.0);
    let ((fx, fy), posed) = zhang_start(board, (width, height), dets, &usable);
    let index: Vec<usize> = posed.iter().map(|p| p.0).collect();
    let prob = Mono {
        board,
        size: (width, height),
        views: index.iter().map(|&vi| corners_of(&dets[vi])).collect(),
    };
    let g0 = Intrinsics::new(fx, fy, cx, cy).params().to_vec();
    let mut active = vec![true; index.len()];
    let poses = posed.iter().map(|p| p.1).collect();
    let s0 = solve(&prob, g0, poses, &DistortionModel::None.free(), &active, 50);
    let s1 = solve(&prob, s0.global, s0.views, &model.free(), &active, 100);
    let (mut s, rejected) = drop_outlier_views(&prob, s1, model, &mut active, &index);
    // Only as many coefficients as the views constrain: the tangential pair must predict held-out
    // views more than 1 % better than k1 k2 alone.
    let mut model_held_out_px = None;
    let model = if model == DistortionModel::Auto {
        let radial = crate::lm::Solved {
            global: {
                let mut k = Intrinsics::from_params(&s.global);
                k.distortion.p1 = 0.0;
                k.distortion.p2 = 0.0;
                k.params().to_vec()
            },
            ..s.clone()
        };
        let r = held_out_rms(&prob, &radial, &DistortionModel::Radial.free(), &active);
        let t = held_out_rms(
            &prob,
            &s,
            &DistortionModel::RadialTangential.free(),
            &active,
        );
        model_held_out_px = r.zip(t);
        if matches!((r, t), (Some(r), Some(t)) if t >= 0.99 * r) {
            s = solve(
                &prob,
                radial.global,
                radial.views,
                &DistortionModel::Radial.free(),
                &active,
                100,
            );
            DistortionModel::Radial
        } else {
            DistortionModel::RadialTangential
        }
    } else {
        model
    };
    let mut centre_free = model.free();
    centre_free[Intrinsics::CX] = false;
    centre_free[Intrinsics::CY] = false;
    let centred = |s: &crate::lm::Solved| crate::lm::Solved {
        global: {
            let mut k = Intrinsics::from_params(&s.global);
            k.cx = cx;
            k.cy = cy;
            k.params().to_vec()
        },
        ..s.clone()
    };
    let held_out_rms_px = match principal {
        PrincipalPoint::Choose => held_out_rms(&prob, &s, &model.free(), &active)
            .zip(held_out_rms(&prob, &centred(&s), &centre_free, &active)),
        _ => None,
    };
    let principal_point_centred = match principal {
        PrincipalPoint::Centre => true,
        PrincipalPoint::Free => false,
        PrincipalPoint::Choose => held_out_rms_px.is_some_and(|(free, centre)| centre <= free),
    };
    if principal_point_centred {
        let c = centred(&s);
        s = solve(&prob, c.global, c.views, &centre_free, &active, 100);
    }
    let cam = camera_from(width, height, &s.global);
    let mut pose_out = vec![None; dets.len()];
    let mut errs = vec![None; dets.len()];
    for v in 0..index.len() {
        if active[v] {
            let p = iso(&s.views[v]);
            pose_out[index[v]] = Some(p);
            errs[index[v]] = Some(view_error(&cam, &p, board, prob.views[v]));
        }
    }
    let error = pooled(&errs.iter().flatten().copied().collect::<Vec<_>>());
    Ok(MonoResult {
        camera: cam,
        std: s.global_std.map(|v| {
            let mut a = [0.0; Intrinsics::LEN];
            a.copy_from_slice(&v[..Intrinsics::LEN]);
            a
        }),
        poses: pose_out,
        view_errors: errs,
        rejected,
        error,
        principal_point_centred,
        held_out_rms_px,
        model,
        model_held_out_px,
    })
}
