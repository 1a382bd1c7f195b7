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

use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use mrtmap_geometry::nalgebra::{
    Isometry3, Matrix3, Point2, Point3, Quaternion, Translation3, UnitQuaternion, Vector3,
};
use serde::{Deserialize, Serialize};

use crate::CalibError;
use crate::board::Board;
use crate::detect::{Corner, Detection};
use crate::lm::{Problem, solve};
use crate::zhang::{fit_homography, init_focal, pose_from_homography};
use rayon::prelude::*;

/// Which distortion coefficients are estimated (the others stay zero).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum DistortionModel {
    /// No distortion.
    None,
    /// k1, k2.
    Radial,
    /// k1, k2, p1, p2 (OpenCV's model with k3 fixed, its advice for ordinary lenses).
    RadialTangential,
    /// k1, k2, p1, p2, k3 (OpenCV's default).
    Full,
    /// k1, k2, or k1, k2, p1, p2 when that predicts held-out views more than 1 % better: only as
    /// many coefficients as the views constrain.
    #[default]
    Auto,
}

impl DistortionModel {
    fn free(self) -> [bool; 9] {
        let (r, t, k3) = match self {
            Self::None => (false, false, false),
            Self::Radial => (true, false, false),
            Self::RadialTangential | Self::Auto => (true, true, false),
            Self::Full => (true, true, true),
        };
        [true, true, true, true, r, r, t, t, k3]
    }
}

/// Camera from the 9 intrinsic parameters (fx fy cx cy k1 k2 p1 p2 k3).
pub fn camera_from(width: u32, height: u32, g: &[f64]) -> PinholeCamera {
    let mut c = PinholeCamera::new(width, height, g[0], g[1], g[2], g[3]);
    c.distortion = BrownConrady::from_array([g[4], g[5], g[6], g[7], g[8]]);
    c
}

fn intrinsics(c: &PinholeCamera) -> [f64; 9] {
    let d = c.distortion.to_array();
    [c.fx, c.fy, c.cx, c.cy, d[0], d[1], d[2], d[3], d[4]]
}

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

/// One camera's calibration.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MonoResult {
    /// Intrinsics and distortion.
    pub camera: PinholeCamera,
    /// Standard deviations of fx fy cx cy k1 k2 p1 p2 k3 (0 for fixed ones).
    pub std: Option<[f64; 9]>,
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

struct Mono<'a> {
    board: &'a Board,
    size: (u32, u32),
    views: Vec<&'a [Corner]>,
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
    let g0 = vec![fx, fy, cx, cy, 0.0, 0.0, 0.0, 0.0, 0.0];
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
                let mut g = s.global.clone();
                g[6] = 0.0;
                g[7] = 0.0;
                g
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
    centre_free[2] = false;
    centre_free[3] = false;
    let centred = |s: &crate::lm::Solved| crate::lm::Solved {
        global: {
            let mut g = s.global.clone();
            g[2] = cx;
            g[3] = cy;
            g
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
            let mut a = [0.0; 9];
            a.copy_from_slice(&v[..9]);
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

/// What became of one pair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "status", content = "reason")]
pub enum PairStatus {
    /// Used in the stereo fit.
    Used,
    /// Not used, and why.
    Rejected(String),
}

/// One pair in the stereo result.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PairResult {
    /// Status.
    #[serde(flatten)]
    pub status: PairStatus,
    /// Colour corners found.
    pub rgb_corners: usize,
    /// Thermal corners found.
    pub thermal_corners: usize,
    /// Colour error in the joint fit.
    pub rgb_error: Option<ViewError>,
    /// Thermal error in the joint fit.
    pub thermal_error: Option<ViewError>,
}

/// The result of a stereo calibration.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StereoResult {
    /// Colour camera.
    pub rgb: PinholeCamera,
    /// Thermal camera.
    pub thermal: PinholeCamera,
    /// p_in_rgb = rgb_from_thermal · p_in_thermal.
    pub rgb_from_thermal: Isometry3<f64>,
    /// Standard deviations: colour intrinsics (9), thermal intrinsics (9), extrinsic (axis-angle
    /// rad ×3, translation m ×3, of thermal_from_rgb).
    pub std: Option<Vec<f64>>,
    /// Per input pair.
    pub pairs: Vec<PairResult>,
    /// Pooled colour error over used pairs.
    pub rgb_error: ViewError,
    /// Pooled thermal error over used pairs.
    pub thermal_error: ViewError,
    /// Single-camera results (all colour images, all thermal images).
    pub rgb_alone: MonoResult,
    /// See `rgb_alone`.
    pub thermal_alone: MonoResult,
    /// The thermal corners' labels after tying them to the colour image's numbering (per pair).
    #[serde(skip)]
    pub thermal_labels: Vec<Option<Vec<Corner>>>,
    /// Which model the held-out pairs chose, in words.
    #[serde(default)]
    pub model_choice: String,
}

/// Relabels corners by k quarter turns then a shift that brings the smallest labels to (0, 0);
/// returns the new corners and the board-frame isometry S with X_new = S · X_old.
fn relabel(corners: &[Corner], k: u32, board: &Board) -> (Vec<Corner>, Isometry3<f64>) {
    let rot = |i: i32, j: i32| match k % 4 {
        0 => (i, j),
        1 => (-j, i),
        2 => (-i, -j),
        _ => (j, -i),
    };
    let turned: Vec<(i32, i32)> = corners.iter().map(|c| rot(c.i, c.j)).collect();
    let mi = turned.iter().map(|t| t.0).min().unwrap_or(0);
    let mj = turned.iter().map(|t| t.1).min().unwrap_or(0);
    let out = corners
        .iter()
        .zip(&turned)
        .map(|(c, t)| Corner {
            i: t.0 - mi,
            j: t.1 - mj,
            ..*c
        })
        .collect();
    let s = Isometry3::from_parts(
        Translation3::new(
            -mi as f64 * board.square_m,
            -mj as f64 * board.square_m,
            0.0,
        ),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), k as f64 * std::f64::consts::FRAC_PI_2),
    );
    (out, s)
}

fn shift(corners: &[Corner], di: i32, dj: i32) -> Vec<Corner> {
    corners
        .iter()
        .map(|c| Corner {
            i: c.i + di,
            j: c.j + dj,
            ..*c
        })
        .collect()
}

fn board_shift(board: &Board, di: i32, dj: i32) -> Isometry3<f64> {
    Isometry3::translation(di as f64 * board.square_m, dj as f64 * board.square_m, 0.0)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() { 0.0 } else { v[v.len() / 2] }
}

fn mean_rotation(q: &[UnitQuaternion<f64>]) -> UnitQuaternion<f64> {
    let Some(q0) = q.first() else {
        return UnitQuaternion::identity();
    };
    let mut acc = Quaternion::new(0.0, 0.0, 0.0, 0.0);
    for x in q {
        let s = if x.coords.dot(&q0.coords) < 0.0 {
            -1.0
        } else {
            1.0
        };
        acc += x.into_inner() * s;
    }
    UnitQuaternion::from_quaternion(acc)
}

struct Stereo<'a> {
    board: &'a Board,
    rgb_size: (u32, u32),
    th_size: (u32, u32),
    rgb: Vec<&'a [Corner]>,
    th: Vec<Vec<Corner>>,
}

impl Problem for Stereo<'_> {
    fn views(&self) -> usize {
        self.rgb.len()
    }
    fn residuals(&self, v: usize, g: &[f64], p: &[f64; 6], out: &mut Vec<f64>) {
        let cr = camera_from(self.rgb_size.0, self.rgb_size.1, &g[0..9]);
        let ct = camera_from(self.th_size.0, self.th_size.1, &g[9..18]);
        let pose = iso(p);
        let e = iso(&g[18..24]);
        push_residuals(&cr, &pose, self.board, self.rgb[v], out);
        push_residuals(&ct, &(e * pose), self.board, &self.th[v], out);
    }
}

/// A pair of detections (`None` where the board was not found) with image sizes.
pub struct PairInput<'a> {
    /// Colour detection.
    pub rgb: Option<&'a Detection>,
    /// Thermal detection.
    pub thermal: Option<&'a Detection>,
}

/// Settings of a stereo calibration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StereoOptions {
    /// Colour camera distortion model.
    pub model_rgb: DistortionModel,
    /// Thermal camera distortion model.
    pub model_thermal: DistortionModel,
    /// Use only the corners found in both images of a pair in the joint fit (as OpenCV's
    /// `stereoCalibrate` requires); by default every corner of either image counts.
    pub common_corners: bool,
}

/// Each camera alone, from every image of it; `principal` (colour, thermal) says how each
/// principal point is found.
fn both_alone(
    board: &Board,
    rgb_size: (u32, u32),
    thermal_size: (u32, u32),
    dets: (&[Option<Detection>], &[Option<Detection>]),
    models: (DistortionModel, DistortionModel),
    principal: (PrincipalPoint, PrincipalPoint),
) -> Result<(MonoResult, MonoResult), CalibError> {
    let alone = |camera: &'static str, (w, h): (u32, u32), d, model, pp| {
        calibrate_mono_with(board, w, h, d, model, pp).map_err(|e| CalibError::Camera {
            camera,
            source: Box::new(e),
        })
    };
    Ok((
        alone("colour", rgb_size, dets.0, models.0, principal.0)?,
        alone("thermal", thermal_size, dets.1, models.1, principal.1)?,
    ))
}

/// How a recalibration keeps a camera's principal point: as the full calibration chose it.
fn as_chosen(m: &MonoResult) -> PrincipalPoint {
    if m.principal_point_centred {
        PrincipalPoint::Centre
    } else {
        PrincipalPoint::Free
    }
}

/// Why each pair is not used, until the joint fit uses it.
fn initial_status(rgb: &[Option<Detection>], th: &[Option<Detection>]) -> Vec<PairStatus> {
    rgb.iter()
        .zip(th)
        .map(|d| {
            PairStatus::Rejected(match d {
                (None, None) => "no board found in either image".into(),
                (None, _) => "no board found in the colour image".into(),
                (_, None) => "no board found in the thermal image".into(),
                _ => "rejected as an outlier by the single-camera fit".into(),
            })
        })
        .collect()
}

/// A pair whose thermal corners were turned to the colour corners' orientation.
struct Cand {
    k: usize,
    th: Vec<Corner>,
    /// colour camera_from_board.
    tc: Isometry3<f64>,
    /// thermal camera_from_board, in the turned numbering.
    tt: Isometry3<f64>,
}

/// Ties thermal labels to the colour labels, the quarter turn first: the turn that makes the
/// thermal camera's rotation relative to the colour camera smallest.
fn quarter_turns(
    board: &Board,
    th_dets: &[Option<Detection>],
    rgb_alone: &MonoResult,
    thermal_alone: &MonoResult,
) -> Vec<Cand> {
    let mut cands = Vec::new();
    for (k, dt) in th_dets.iter().enumerate() {
        let (Some(tc), Some(tt), Some(dt)) =
            (rgb_alone.poses[k], thermal_alone.poses[k], dt.as_ref())
        else {
            continue;
        };
        let best = (0..4)
            .map(|q| {
                let (c, s) = relabel(&dt.corners, q, board);
                let tt2 = tt * s.inverse();
                let e = tt2 * tc.inverse();
                (e.rotation.angle(), c, tt2)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, c, tt2)) = best {
            cands.push(Cand {
                k,
                th: c,
                tc,
                tt: tt2,
            });
        }
    }
    cands
}

/// The thermal camera's position relative to the colour camera: the median over the pairs that
/// show the whole board in both images (their numbering is not ambiguous up to a shift).
/// Whether a detection holds every inner corner of the board.
fn full(board: &Board, d: &Option<Detection>) -> bool {
    d.as_ref().is_some_and(|d| {
        let (w, h) = d.extent();
        d.corners.len() == board.corners()
            && ((w, h) == (board.cols as i32, board.rows as i32)
                || (w, h) == (board.rows as i32, board.cols as i32))
    })
}

fn median_offset(
    board: &Board,
    cands: &[Cand],
    rgb_dets: &[Option<Detection>],
    th_dets: &[Option<Detection>],
) -> Result<Vector3<f64>, CalibError> {
    let ts: Vec<Vector3<f64>> = cands
        .iter()
        .filter(|c| full(board, &rgb_dets[c.k]) && full(board, &th_dets[c.k]))
        .map(|c| (c.tt * c.tc.inverse()).translation.vector)
        .collect();
    if ts.is_empty() {
        return Err(CalibError::NoCompletePair {
            cols: board.cols,
            rows: board.rows,
        });
    }
    Ok(Vector3::new(
        median(ts.iter().map(|t| t.x).collect()),
        median(ts.iter().map(|t| t.y).collect()),
        median(ts.iter().map(|t| t.z).collect()),
    ))
}

/// The pairs tied: index, colour camera_from_board, thermal_from_colour.
type Tied = Vec<(usize, Isometry3<f64>, Isometry3<f64>)>;

/// The thermal camera's rotation relative to the colour camera from the pairs that show the whole
/// board in both images: the mean of those within 3° of their medoid (the one nearest all
/// others), so that a mismatched pair does not turn it.
fn mean_whole_rotation(cands: &[Cand], whole: &dyn Fn(usize) -> bool) -> UnitQuaternion<f64> {
    let q: Vec<UnitQuaternion<f64>> = cands
        .iter()
        .filter(|c| whole(c.k))
        .map(|c| (c.tt * c.tc.inverse()).rotation)
        .collect();
    let spread = |a: &UnitQuaternion<f64>| q.iter().map(|b| a.angle_to(b)).sum::<f64>();
    let Some(medoid) = q.iter().min_by(|a, b| spread(a).total_cmp(&spread(b))) else {
        return UnitQuaternion::identity();
    };
    let near: Vec<UnitQuaternion<f64>> = q
        .iter()
        .filter(|r| r.angle_to(medoid) < 3f64.to_radians())
        .copied()
        .collect();
    mean_rotation(&near)
}

/// The largest error (in squares of the board as the thermal camera sees it) at which a thermal
/// numbering predicted from the colour view and the other pairs' extrinsic is accepted: a
/// neighbouring numbering lies one square away.
const TIE_SQUARES: f64 = 0.35;

/// Ties each candidate's thermal numbering to the colour one: of every shift of the board's
/// numbering, the one whose corners lie nearest where the colour camera's view of the board puts
/// them in the thermal image (through `e0`, the extrinsic of the pairs showing the whole board).
/// A pair whose best numbering is more than `TIE_SQUARES` of a square off, or not clearly better
/// than the next, is rejected with both distances.
fn tie_shifts(
    board: &Board,
    cands: &[Cand],
    e0: &Isometry3<f64>,
    thermal: &PinholeCamera,
    whole: &dyn Fn(usize) -> bool,
    status: &mut [PairStatus],
) -> (Tied, Vec<Option<Vec<Corner>>>) {
    let mut used = Vec::new();
    let mut th_labels: Vec<Option<Vec<Corner>>> = vec![None; status.len()];
    let reach = (board.cols as i32).max(board.rows as i32);
    for cand in cands {
        let predicted = e0 * cand.tc;
        let mut tries: Vec<(f64, i32, i32)> = Vec::new();
        for di in -reach..=reach {
            for dj in -reach..=reach {
                // The colour numbering of a partly seen board starts where its view does, so
                // the thermal labels may run beyond it either way.
                let c = shift(&cand.th, di, dj);
                tries.push((view_error(thermal, &predicted, board, &c).rms_px, di, dj));
            }
        }
        tries.sort_by(|a, b| a.0.total_cmp(&b.0));
        let Some(&(mut d, mut di, mut dj)) = tries.first() else {
            continue;
        };
        let mut next = tries.get(1).map_or(f64::INFINITY, |t| t.0);
        // The board's square as the thermal camera sees it at this pair's distance.
        let z = predicted.translation.vector.z.max(1e-3);
        let square_px = thermal.fx * board.square_m / z;
        // A pair whose both images show the whole board needs no shift (its numbering is fixed
        // once turned): kept unless it lies two squares off, for the fit's outlier test to judge.
        let (limit, ratio) = if whole(cand.k) {
            d = view_error(thermal, &predicted, board, &cand.th).rms_px;
            (di, dj, next) = (0, 0, f64::INFINITY);
            (2.0 * square_px, 0.0)
        } else {
            (TIE_SQUARES * square_px, 2.0)
        };
        if d > limit || next < ratio * d {
            status[cand.k] = PairStatus::Rejected(format!(
                "the thermal corners cannot be matched to the colour corners: the best numbering lies {d:.1} px from where the colour view and the other pairs put the board (the next {next:.1} px; accepted: under {limit:.1} px and half the next)"
            ));
            continue;
        }
        let tt = cand.tt * board_shift(board, di, dj).inverse();
        used.push((cand.k, cand.tc, tt * cand.tc.inverse()));
        th_labels[cand.k] = Some(shift(&cand.th, di, dj));
    }
    (used, th_labels)
}

/// The extrinsic problem's global parameters and each pair's errors.
struct Joint<'a> {
    prob: Stereo<'a>,
    free: Vec<bool>,
}

impl Joint<'_> {
    /// (colour, thermal) reprojection errors of view `v` under `s`.
    fn errors(&self, s: &crate::lm::Solved, v: usize) -> (ViewError, ViewError) {
        let (rgb_size, th_size) = (self.prob.rgb_size, self.prob.th_size);
        let cr = camera_from(rgb_size.0, rgb_size.1, &s.global[0..9]);
        let ct = camera_from(th_size.0, th_size.1, &s.global[9..18]);
        let pose = iso(&s.views[v]);
        let e = iso(&s.global[18..24]);
        (
            view_error(&cr, &pose, self.prob.board, self.prob.rgb[v]),
            view_error(&ct, &(e * pose), self.prob.board, &self.prob.th[v]),
        )
    }

    /// Refits without the pairs whose error is far above the others', twice at most and keeping
    /// at least three; `status` says why a pair was dropped.
    fn reject_outliers(
        &self,
        mut s: crate::lm::Solved,
        active: &mut [bool],
        idx: &[usize],
        status: &mut [PairStatus],
    ) -> crate::lm::Solved {
        for _ in 0..2 {
            let errs: Vec<Option<(ViewError, ViewError)>> = (0..idx.len())
                .map(|v| active[v].then(|| self.errors(&s, v)))
                .collect();
            let rms = |pick: fn(&(ViewError, ViewError)) -> f64| {
                errs.iter()
                    .map(|e| e.as_ref().map(pick))
                    .collect::<Vec<_>>()
            };
            let kr = keep_flags(&rms(|x| x.0.rms_px), 0.5);
            let kt = keep_flags(&rms(|x| x.1.rms_px), 0.5);
            let newly: Vec<usize> = (0..idx.len())
                .filter(|&v| active[v] && !(kr[v] && kt[v]))
                .collect();
            if newly.is_empty() || active.iter().filter(|a| **a).count() - newly.len() < 3 {
                break;
            }
            for v in newly {
                active[v] = false;
                let (er, et) = errs[v].unwrap_or_default();
                status[idx[v]] = PairStatus::Rejected(format!(
                    "outlier: RMS error {:.2} px colour, {:.2} px thermal, more than three times the pairs' median",
                    er.rms_px, et.rms_px
                ));
            }
            s = solve(&self.prob, s.global, s.views, &self.free, active, 100);
        }
        s
    }
}

/// What a bootstrap over the image pairs refits from.
struct Resample<'a> {
    board: &'a Board,
    sizes: ((u32, u32), (u32, u32)),
    dets: (&'a [Option<Detection>], &'a [Option<Detection>]),
    /// The distortion models the full calibration chose (kept in every draw).
    models: (DistortionModel, DistortionModel),
    /// How each camera's principal point was found (kept in every draw).
    principal: (PrincipalPoint, PrincipalPoint),
    /// Per pair of the extrinsic fit: its input index, whether it is used.
    idx: &'a [usize],
    active: &'a [bool],
}

impl Resample<'_> {
    /// Standard deviations of the extrinsic (axis-angle, translation) from a bootstrap over the
    /// image pairs: each draw recalibrates both cameras from the drawn images and refits the
    /// extrinsic from the drawn used pairs. The spread carries what the fit's covariance with
    /// fixed intrinsics does not: the intrinsics' own uncertainty (a small camera's principal
    /// point trades with the rotation) and a hand-made board's irregular squares.
    fn std(&self, joint: &Joint<'_>, s: &crate::lm::Solved) -> Option<[f64; 6]> {
        let n = self.dets.0.len();
        let act: Vec<usize> = (0..self.active.len()).filter(|v| self.active[*v]).collect();
        if act.len() < 4 {
            return None;
        }
        // A fixed seed: the same input gives the same report.
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let draws: Vec<Vec<usize>> = (0..BOOTSTRAP_DRAWS)
            .map(|_| (0..n).map(|_| (next() % n as u64) as usize).collect())
            .collect();
        let base = &s.global[18..24];
        let samples: Vec<[f64; 6]> = draws
            .par_iter()
            .filter_map(|draw| self.one(joint, s, draw))
            .map(|g| std::array::from_fn(|k| g[k] - base[k]))
            .collect();
        if samples.len() < BOOTSTRAP_DRAWS / 2 {
            return None;
        }
        let m = samples.len() as f64;
        Some(std::array::from_fn(|k| {
            let mean = samples.iter().map(|d| d[k]).sum::<f64>() / m;
            (samples.iter().map(|d| (d[k] - mean).powi(2)).sum::<f64>() / (m - 1.0)).sqrt()
        }))
    }

    /// Two-fold held-out error over the used pairs of predicting the thermal corners from the
    /// colour view: both cameras calibrated from the images of every other used pair (and the
    /// images in no used pair), the extrinsic fitted on those pairs (with `free`: the intrinsics
    /// fixed, or refined jointly), then for each held-out pair the board posed from its colour
    /// corners alone and carried into the thermal image. RMS (px) over the held-out thermal
    /// corners; `None` with fewer than six used pairs.
    fn held_out(&self, joint: &Joint<'_>, s: &crate::lm::Solved, free: &[bool]) -> Option<f64> {
        let act: Vec<usize> = (0..self.active.len()).filter(|v| self.active[*v]).collect();
        if act.len() < 6 {
            return None;
        }
        let (mut sum, mut count) = (0.0, 0usize);
        for fold in 0..2 {
            let test: Vec<usize> = act.iter().copied().skip(fold).step_by(2).collect();
            let train: Vec<usize> = act.iter().copied().filter(|v| !test.contains(v)).collect();
            // Both cameras without the held-out pairs' images.
            let held: Vec<usize> = test.iter().map(|&v| self.idx[v]).collect();
            let without = |d: &[Option<Detection>]| -> Vec<Option<Detection>> {
                (0..d.len())
                    .map(|k| {
                        if held.contains(&k) {
                            None
                        } else {
                            d[k].clone()
                        }
                    })
                    .collect()
            };
            let (r, t) = (without(self.dets.0), without(self.dets.1));
            let fit = self.refit(joint, s, (&r, &t), &train, free, 100)?;
            let cr = camera_from(self.sizes.0.0, self.sizes.0.1, &fit.global[0..9]);
            let ct = camera_from(self.sizes.1.0, self.sizes.1.1, &fit.global[9..18]);
            let e = iso(&fit.global[18..24]);
            for &v in &test {
                let colour = Mono {
                    board: self.board,
                    size: self.sizes.0,
                    views: vec![joint.prob.rgb[v]],
                };
                let posed = solve(
                    &colour,
                    intrinsics(&cr).to_vec(),
                    vec![s.views[v]],
                    &[false; 9],
                    &[true],
                    50,
                );
                let mut r = Vec::new();
                push_residuals(
                    &ct,
                    &(e * iso(&posed.views[0])),
                    self.board,
                    &joint.prob.th[v],
                    &mut r,
                );
                sum += r.iter().map(|x| x * x).sum::<f64>();
                count += r.len() / 2;
            }
        }
        Some((sum / count.max(1) as f64).sqrt())
    }

    /// One draw: the extrinsic refitted with both cameras recalibrated from the drawn images.
    fn one(&self, joint: &Joint<'_>, s: &crate::lm::Solved, draw: &[usize]) -> Option<Vec<f64>> {
        let pick = |d: &[Option<Detection>]| -> Vec<Option<Detection>> {
            draw.iter().map(|&k| d[k].clone()).collect()
        };
        // The drawn pairs that the extrinsic fit used, each as often as drawn.
        let views: Vec<usize> = draw
            .iter()
            .filter_map(|k| self.idx.iter().position(|i| i == k))
            .filter(|&v| self.active[v])
            .collect();
        if views.len() < 3 {
            return None;
        }
        let (r, t) = (pick(self.dets.0), pick(self.dets.1));
        let fit = self.refit(joint, s, (&r, &t), &views, &joint.free, 50)?;
        let e = fit.global[18..24].to_vec();
        e.iter().all(|x| x.is_finite()).then_some(e)
    }

    /// Both cameras recalibrated from `dets` (with the models and principal points chosen), then
    /// the extrinsic problem refitted with `free` on the pairs `views` (indices into the fit's
    /// pairs, repeats allowed), starting from `s`.
    fn refit(
        &self,
        joint: &Joint<'_>,
        s: &crate::lm::Solved,
        dets: (&[Option<Detection>], &[Option<Detection>]),
        views: &[usize],
        free: &[bool],
        iterations: usize,
    ) -> Option<crate::lm::Solved> {
        let (rgb, th) = both_alone(
            self.board,
            self.sizes.0,
            self.sizes.1,
            dets,
            self.models,
            self.principal,
        )
        .ok()?;
        let prob = Stereo {
            board: joint.prob.board,
            rgb_size: joint.prob.rgb_size,
            th_size: joint.prob.th_size,
            rgb: views.iter().map(|&v| joint.prob.rgb[v]).collect(),
            th: views.iter().map(|&v| joint.prob.th[v].clone()).collect(),
        };
        let mut g: Vec<f64> = intrinsics(&rgb.camera).to_vec();
        g.extend(intrinsics(&th.camera));
        g.extend(&s.global[18..24]);
        let poses: Vec<[f64; 6]> = views.iter().map(|&v| s.views[v]).collect();
        let all = vec![true; views.len()];
        Some(solve(&prob, g, poses, free, &all, iterations))
    }
}

/// Refits of the bootstrap over pairs.
const BOOTSTRAP_DRAWS: usize = 64;

/// Calibrates both cameras and the extrinsic between them.
///
/// Each camera's intrinsics come from all of its own images (many more views than complete
/// pairs, and a small camera's focal length is not dragged by the other's), then the extrinsic
/// and the board poses are fitted with the intrinsics fixed, as OpenCV's `stereoCalibrate` does
/// with `CALIB_FIX_INTRINSIC`.
pub fn calibrate_stereo(
    board: &Board,
    rgb_size: (u32, u32),
    thermal_size: (u32, u32),
    pairs: &[PairInput<'_>],
    opts: &StereoOptions,
) -> Result<StereoResult, CalibError> {
    let rgb_dets: Vec<Option<Detection>> = pairs.iter().map(|p| p.rgb.cloned()).collect();
    let th_dets: Vec<Option<Detection>> = pairs.iter().map(|p| p.thermal.cloned()).collect();
    let (rgb_alone, thermal_alone) = both_alone(
        board,
        rgb_size,
        thermal_size,
        (&rgb_dets, &th_dets),
        (opts.model_rgb, opts.model_thermal),
        (PrincipalPoint::Choose, PrincipalPoint::Choose),
    )?;
    let mut status = initial_status(&rgb_dets, &th_dets);
    let cands = quarter_turns(board, &th_dets, &rgb_alone, &thermal_alone);
    let whole = |k: usize| full(board, &rgb_dets[k]) && full(board, &th_dets[k]);
    let t0 = median_offset(board, &cands, &rgb_dets, &th_dets)?;
    let e0 = Isometry3::from_parts(Translation3::from(t0), mean_whole_rotation(&cands, &whole));
    let (used, th_labels) = tie_shifts(
        board,
        &cands,
        &e0,
        &thermal_alone.camera,
        &whole,
        &mut status,
    );
    let idx: Vec<usize> = used.iter().map(|u| u.0).collect();
    let (rgb_views, th_views) = pair_views(&idx, &rgb_dets, &th_labels, opts.common_corners);
    let prob = Stereo {
        board,
        rgb_size,
        th_size: thermal_size,
        rgb: rgb_views.iter().map(Vec::as_slice).collect(),
        th: th_views,
    };
    let mut g: Vec<f64> = intrinsics(&rgb_alone.camera).to_vec();
    g.extend(intrinsics(&thermal_alone.camera));
    g.extend(vec6(&e0));
    let mut free = vec![false; 18];
    free.extend([true; 6]);
    let mut joint = Joint { prob, free };
    let views: Vec<[f64; 6]> = used.iter().map(|u| vec6(&u.1)).collect();
    let mut active = vec![true; idx.len()];
    let first = solve(&joint.prob, g, views, &joint.free, &active, 100);
    let mut s = joint.reject_outliers(first, &mut active, &idx, &mut status);
    // Intrinsics fixed, or refined with the extrinsic in one fit: whichever predicts held-out
    // pairs' thermal corners from their colour view better. A joint fit is the better estimator
    // when the residuals are pixel noise; on a hand-made board they are the board's own
    // irregularity, and a joint fit lets the camera with more pixels drag the other's focal
    // length (the real foil-board pairs' thermal f: 152 px alone, 163 px jointly).
    let refined = refinable(&rgb_alone, &thermal_alone);
    let resample = Resample {
        board,
        sizes: (rgb_size, thermal_size),
        dets: (&rgb_dets, &th_dets),
        models: (rgb_alone.model, thermal_alone.model),
        principal: (as_chosen(&rgb_alone), as_chosen(&thermal_alone)),
        idx: &idx,
        active: &active,
    };
    let fixed_err = resample.held_out(&joint, &s, &joint.free);
    let joint_err = resample.held_out(&joint, &s, &refined);
    let jointly = matches!((fixed_err, joint_err), (Some(f), Some(j)) if j < f);
    if jointly {
        s = solve(&joint.prob, s.global, s.views, &refined, &active, 100);
        joint.free = refined;
    }
    let boot = resample.std(&joint, &s);
    let (results, er_all, et_all) =
        pair_results((&rgb_dets, &th_dets), &status, &joint, &s, &idx, &active);
    // The intrinsics' deviations are each camera's own (or the joint fit's); the extrinsic's the
    // larger of the fit's and the bootstrap's.
    let std = s.global_std.map(|fit| {
        let mut v = if jointly {
            fit[..18].to_vec()
        } else {
            let mut v = rgb_alone.std.map_or(vec![0.0; 9], |a| a.to_vec());
            v.extend(thermal_alone.std.map_or([0.0; 9], |a| a));
            v
        };
        v.extend((0..6).map(|k| fit[18 + k].max(boot.map_or(0.0, |b| b[k]))));
        v
    });
    let e = iso(&s.global[18..24]);
    let model_choice = model_choice(
        (&rgb_alone, &thermal_alone),
        (fixed_err, joint_err),
        jointly,
        boot.is_some(),
    );
    Ok(StereoResult {
        rgb: camera_from(rgb_size.0, rgb_size.1, &s.global[0..9]),
        thermal: camera_from(thermal_size.0, thermal_size.1, &s.global[9..18]),
        rgb_from_thermal: e.inverse(),
        std,
        pairs: results,
        rgb_error: pooled(&er_all),
        thermal_error: pooled(&et_all),
        rgb_alone,
        thermal_alone,
        thermal_labels: th_labels,
        model_choice,
    })
}

/// The parameters a joint fit refines: each camera's free distortion terms and its principal
/// point unless it was put at the image centre, then the extrinsic.
fn refinable(rgb_alone: &MonoResult, thermal_alone: &MonoResult) -> Vec<bool> {
    let mut refined = [rgb_alone.model.free(), thermal_alone.model.free()].concat();
    for (k, m) in [(2, rgb_alone), (11, thermal_alone)] {
        if m.principal_point_centred {
            refined[k] = false;
            refined[k + 1] = false;
        }
    }
    refined.extend([true; 6]);
    refined
}

/// Each pair's result (corners, errors, status), and the used pairs' colour and thermal errors.
fn pair_results(
    (rgb_dets, th_dets): (&[Option<Detection>], &[Option<Detection>]),
    status: &[PairStatus],
    joint: &Joint<'_>,
    s: &crate::lm::Solved,
    idx: &[usize],
    active: &[bool],
) -> (Vec<PairResult>, Vec<ViewError>, Vec<ViewError>) {
    let mut results: Vec<PairResult> = (0..status.len())
        .map(|k| PairResult {
            status: status[k].clone(),
            rgb_corners: rgb_dets[k].as_ref().map_or(0, |d| d.corners.len()),
            thermal_corners: th_dets[k].as_ref().map_or(0, |d| d.corners.len()),
            rgb_error: None,
            thermal_error: None,
        })
        .collect();
    let (mut er_all, mut et_all) = (Vec::new(), Vec::new());
    for v in 0..idx.len() {
        let (er, et) = joint.errors(s, v);
        let r = &mut results[idx[v]];
        r.rgb_error = Some(er);
        r.thermal_error = Some(et);
        if active[v] {
            r.status = PairStatus::Used;
            er_all.push(er);
            et_all.push(et);
        }
    }
    (results, er_all, et_all)
}

/// Each camera's colour and thermal views of the pairs `idx`: all their corners, or only those
/// both cameras found.
fn pair_views(
    idx: &[usize],
    rgb_dets: &[Option<Detection>],
    th_labels: &[Option<Vec<Corner>>],
    common_corners: bool,
) -> (Vec<Vec<Corner>>, Vec<Vec<Corner>>) {
    let common = |rgb: &[Corner], th: &[Corner]| -> (Vec<Corner>, Vec<Corner>) {
        let has = |cs: &[Corner], c: &Corner| cs.iter().any(|d| d.i == c.i && d.j == c.j);
        (
            rgb.iter().filter(|c| has(th, c)).copied().collect(),
            th.iter().filter(|c| has(rgb, c)).copied().collect(),
        )
    };
    idx.iter()
        .map(|&k| {
            let rgb = corners_of(&rgb_dets[k]).to_vec();
            let th = th_labels[k].clone().unwrap_or_default();
            if common_corners {
                common(&rgb, &th)
            } else {
                (rgb, th)
            }
        })
        .unzip()
}

/// How one camera's distortion model and principal point were chosen, in words.
fn intrinsics_choice(m: &MonoResult) -> String {
    let model = match (m.model, m.model_held_out_px) {
        (DistortionModel::Radial, Some((r, t))) => {
            format!("k1 k2 (held-out RMS {r:.3} px; with p1 p2 {t:.3} px, not 1 % better), ")
        }
        (DistortionModel::RadialTangential, Some((r, t))) => {
            format!("k1 k2 p1 p2 (held-out RMS {t:.3} px; k1 k2 alone {r:.3} px), ")
        }
        _ => String::new(),
    };
    let point = match m.held_out_rms_px {
        Some((free, centre)) => format!(
            "principal point {} (held-out RMS {free:.3} px free, {centre:.3} px at the centre)",
            if m.principal_point_centred {
                "at the image centre"
            } else {
                "fitted"
            }
        ),
        None => "principal point fitted (too few views to compare on held-out ones)".into(),
    };
    model + &point
}

/// How the stereo fit was made, in words: each camera's choices, intrinsics fixed or refined
/// (with the held-out errors `(fixed, refined)` that chose), and where the extrinsic's ± is from.
fn model_choice(
    (rgb_alone, thermal_alone): (&MonoResult, &MonoResult),
    (fixed_err, joint_err): (Option<f64>, Option<f64>),
    jointly: bool,
    bootstrap: bool,
) -> String {
    let how = match (fixed_err, joint_err) {
        (Some(f), Some(j)) => format!(
            "{} (held-out pairs' thermal corners predicted from their colour view: RMS {f:.3} px fixed, {j:.3} px refined)",
            if jointly {
                "refined with the extrinsic"
            } else {
                "fixed in the extrinsic fit"
            }
        ),
        _ => "fixed in the extrinsic fit (too few pairs to compare on held-out ones)".into(),
    };
    format!(
        "intrinsics from each camera's own images ({} colour, {} thermal views), {how}; colour {}; thermal {}; extrinsic ± from {}",
        rgb_alone.view_errors.iter().flatten().count(),
        thermal_alone.view_errors.iter().flatten().count(),
        intrinsics_choice(rgb_alone),
        intrinsics_choice(thermal_alone),
        if bootstrap {
            "the fit and a bootstrap over the image pairs (both cameras recalibrated in each draw), whichever is larger"
        } else {
            "the fit (too few pairs for a bootstrap)"
        }
    )
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
