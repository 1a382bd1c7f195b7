//! Two cameras' calibration: each camera alone, then the extrinsic between them.
//!
//! 1. Each camera calibrated alone from all of its own images ([`both_alone`](super::joint::both_alone)).
//! 2. The thermal corners' numbering tied to the colour image's, and a first extrinsic from the
//!    pairs that show the whole board in both images ([`correspondence`](super::correspondence)).
//! 3. Levenberg–Marquardt over the extrinsic and every board pose with the intrinsics fixed (as
//!    OpenCV's `stereoCalibrate` with `CALIB_FIX_INTRINSIC`); pairs whose error stands out are
//!    rejected and reported, twice at most.
//! 4. The intrinsics refined jointly with the extrinsic only when that predicts held-out pairs'
//!    thermal corners from their colour view better ([`resample`](super::resample)).
//! 5. The extrinsic's spread: the larger of the fit's and a bootstrap over the image pairs.
//! 6. Each pair's result and errors, and how the fit was made, in words.

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Isometry3, Translation3};
use serde::{Deserialize, Serialize};

use super::correspondence::{full, mean_whole_rotation, median_offset, quarter_turns, tie_shifts};
use super::intrinsics::{DistortionModel, Intrinsics};
use super::joint::{
    EXTRINSIC_PARAMS, Joint, PairStatus, RGB_PARAMS, Stereo, THERMAL_PARAMS, both_alone,
    stereo_cameras, stereo_params,
};
use super::mono::{MonoResult, PrincipalPoint};
use super::resample::Resample;
use super::{ViewError, corners_of, pooled, vec6};
use crate::CalibError;
use crate::board::Board;
use crate::detect::{Corner, Detection};
use crate::lm::solve;

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
    let g = stereo_params(
        &Intrinsics::of(&rgb_alone.camera),
        &Intrinsics::of(&thermal_alone.camera),
        &vec6(&e0),
    );
    let mut free = vec![false; EXTRINSIC_PARAMS.start];
    free.resize(EXTRINSIC_PARAMS.end, true);
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
            fit[..EXTRINSIC_PARAMS.start].to_vec()
        } else {
            let mut v = rgb_alone
                .std
                .map_or(vec![0.0; Intrinsics::LEN], |a| a.to_vec());
            v.extend(thermal_alone.std.map_or([0.0; Intrinsics::LEN], |a| a));
            v
        };
        v.extend((0..6).map(|k| fit[EXTRINSIC_PARAMS.start + k].max(boot.map_or(0.0, |b| b[k]))));
        v
    });
    let (rgb, thermal, e) = stereo_cameras(&s.global, rgb_size, thermal_size);
    let model_choice = model_choice(
        (&rgb_alone, &thermal_alone),
        (fixed_err, joint_err),
        jointly,
        boot.is_some(),
    );
    Ok(StereoResult {
        rgb,
        thermal,
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
    for (at, m) in [
        (RGB_PARAMS.start, rgb_alone),
        (THERMAL_PARAMS.start, thermal_alone),
    ] {
        if m.principal_point_centred {
            refined[at + Intrinsics::CX] = false;
            refined[at + Intrinsics::CY] = false;
        }
    }
    refined.resize(EXTRINSIC_PARAMS.end, true);
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
