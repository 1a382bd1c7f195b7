//! Refits of the stereo calibration on subsets of the image pairs.
//!
//! - Held-out error ([`Resample::held_out`]): two folds over the used pairs; both cameras
//!   recalibrated and the extrinsic fitted without a fold's pairs, then each held-out pair's board
//!   posed from its colour corners alone and carried into the thermal image. It chooses between
//!   fixed and jointly refined intrinsics.
//! - Bootstrap ([`Resample::std`]): a fixed number of draws of the pairs with replacement (a fixed
//!   seed); each draw recalibrates both cameras from the drawn images and refits the extrinsic;
//!   the spread of the draws is the extrinsic's standard deviation.

use rayon::prelude::*;

use super::intrinsics::{DistortionModel, Intrinsics};
use super::joint::{EXTRINSIC_PARAMS, Joint, Stereo, both_alone, stereo_cameras, stereo_params};
use super::mono::{Mono, PrincipalPoint};
use super::{iso, push_residuals};
use crate::board::Board;
use crate::detect::Detection;
use crate::lm::solve;

/// What a bootstrap over the image pairs refits from.
pub(super) struct Resample<'a> {
    /// The board.
    pub(super) board: &'a Board,
    /// Image sizes (colour, thermal; px).
    pub(super) sizes: ((u32, u32), (u32, u32)),
    /// Every pair's detections (colour, thermal).
    pub(super) dets: (&'a [Option<Detection>], &'a [Option<Detection>]),
    /// The distortion models the full calibration chose (kept in every draw).
    pub(super) models: (DistortionModel, DistortionModel),
    /// How each camera's principal point was found (kept in every draw).
    pub(super) principal: (PrincipalPoint, PrincipalPoint),
    /// Per pair of the extrinsic fit: its input index, whether it is used.
    pub(super) idx: &'a [usize],
    pub(super) active: &'a [bool],
}

impl Resample<'_> {
    /// Standard deviations of the extrinsic (axis-angle, translation) from a bootstrap over the
    /// image pairs: each draw recalibrates both cameras from the drawn images and refits the
    /// extrinsic from the drawn used pairs. The spread carries what the fit's covariance with
    /// fixed intrinsics does not: the intrinsics' own uncertainty (a small camera's principal
    /// point trades with the rotation) and a hand-made board's irregular squares.
    pub(super) fn std(&self, joint: &Joint<'_>, s: &crate::lm::Solved) -> Option<[f64; 6]> {
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
        let base = &s.global[EXTRINSIC_PARAMS];
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
    pub(super) fn held_out(
        &self,
        joint: &Joint<'_>,
        s: &crate::lm::Solved,
        free: &[bool],
    ) -> Option<f64> {
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
            let (cr, ct, e) = stereo_cameras(&fit.global, self.sizes.0, self.sizes.1);
            for &v in &test {
                let colour = Mono {
                    board: self.board,
                    size: self.sizes.0,
                    views: vec![joint.prob.rgb[v]],
                };
                let posed = solve(
                    &colour,
                    Intrinsics::of(&cr).params().to_vec(),
                    vec![s.views[v]],
                    &[false; Intrinsics::LEN],
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
        let e = fit.global[EXTRINSIC_PARAMS].to_vec();
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
        let g = stereo_params(
            &Intrinsics::of(&rgb.camera),
            &Intrinsics::of(&th.camera),
            &s.global[EXTRINSIC_PARAMS],
        );
        let poses: Vec<[f64; 6]> = views.iter().map(|&v| s.views[v]).collect();
        let all = vec![true; views.len()];
        Some(solve(&prob, g, poses, free, &all, iterations))
    }
}

/// Refits of the bootstrap over pairs.
const BOOTSTRAP_DRAWS: usize = 64;
