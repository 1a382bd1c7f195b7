//! The stereo problem both the fit (`stereo`) and its held-out check (`resample`) solve: where
//! each camera's intrinsics and the extrinsic sit in the solver's parameters, the board in each
//! pair's two images, each camera alone, and what became of each pair.

use std::ops::Range;

use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::Isometry3;
use serde::{Deserialize, Serialize};

use super::intrinsics::{DistortionModel, Intrinsics, camera_from};
use super::mono::{MonoResult, PrincipalPoint, calibrate_mono_with};
use super::{ViewError, iso, keep_flags, push_residuals, view_error};
use crate::CalibError;
use crate::board::Board;
use crate::detect::{Corner, Detection};
use crate::lm::{Problem, solve};

/// Where the colour camera's intrinsics sit in the stereo problem's global parameters (flat, as
/// the solver holds them: the colour camera's intrinsics, the thermal camera's, then
/// thermal_from_rgb as axis-angle and translation).
pub(super) const RGB_PARAMS: Range<usize> = 0..Intrinsics::LEN;

/// Where the thermal camera's intrinsics sit in the stereo problem's global parameters.
pub(super) const THERMAL_PARAMS: Range<usize> = Intrinsics::LEN..2 * Intrinsics::LEN;

/// Where thermal_from_rgb (axis-angle, translation) sits in the stereo problem's global
/// parameters.
pub(super) const EXTRINSIC_PARAMS: Range<usize> = 2 * Intrinsics::LEN..2 * Intrinsics::LEN + 6;

/// The stereo problem's global parameters: both cameras' intrinsics and thermal_from_rgb
/// (axis-angle, translation).
pub(super) fn stereo_params(
    rgb: &Intrinsics,
    thermal: &Intrinsics,
    thermal_from_rgb: &[f64],
) -> Vec<f64> {
    let mut g: Vec<f64> = rgb.params().to_vec();
    g.extend(thermal.params());
    g.extend(thermal_from_rgb);
    g
}

/// The colour and thermal cameras (of these image sizes) and thermal_from_rgb in the stereo
/// problem's global parameters.
pub(super) fn stereo_cameras(
    g: &[f64],
    rgb_size: (u32, u32),
    th_size: (u32, u32),
) -> (PinholeCamera, PinholeCamera, Isometry3<f64>) {
    (
        camera_from(rgb_size.0, rgb_size.1, &g[RGB_PARAMS]),
        camera_from(th_size.0, th_size.1, &g[THERMAL_PARAMS]),
        iso(&g[EXTRINSIC_PARAMS]),
    )
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

/// The extrinsic problem for the solver: the board in each pair's colour and thermal images.
pub(super) struct Stereo<'a> {
    /// The board.
    pub(super) board: &'a Board,
    /// Colour image size (px).
    pub(super) rgb_size: (u32, u32),
    /// Thermal image size (px).
    pub(super) th_size: (u32, u32),
    /// Each pair's colour corners.
    pub(super) rgb: Vec<&'a [Corner]>,
    /// Each pair's thermal corners, in the colour image's numbering.
    pub(super) th: Vec<Vec<Corner>>,
}

impl Problem for Stereo<'_> {
    fn views(&self) -> usize {
        self.rgb.len()
    }
    fn residuals(&self, v: usize, g: &[f64], p: &[f64; 6], out: &mut Vec<f64>) {
        let (cr, ct, e) = stereo_cameras(g, self.rgb_size, self.th_size);
        let pose = iso(p);
        push_residuals(&cr, &pose, self.board, self.rgb[v], out);
        push_residuals(&ct, &(e * pose), self.board, &self.th[v], out);
    }
}

/// Each camera alone, from every image of it; `principal` (colour, thermal) says how each
/// principal point is found.
pub(super) fn both_alone(
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

/// The extrinsic problem's global parameters and each pair's errors.
pub(super) struct Joint<'a> {
    /// The problem.
    pub(super) prob: Stereo<'a>,
    /// Which global parameters are fitted.
    pub(super) free: Vec<bool>,
}

impl Joint<'_> {
    /// (colour, thermal) reprojection errors of view `v` under `s`.
    pub(super) fn errors(&self, s: &crate::lm::Solved, v: usize) -> (ViewError, ViewError) {
        let (rgb_size, th_size) = (self.prob.rgb_size, self.prob.th_size);
        let (cr, ct, e) = stereo_cameras(&s.global, rgb_size, th_size);
        let pose = iso(&s.views[v]);
        (
            view_error(&cr, &pose, self.prob.board, self.prob.rgb[v]),
            view_error(&ct, &(e * pose), self.prob.board, &self.prob.th[v]),
        )
    }

    /// Refits without the pairs whose error is far above the others', twice at most and keeping
    /// at least three; `status` says why a pair was dropped.
    pub(super) fn reject_outliers(
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
