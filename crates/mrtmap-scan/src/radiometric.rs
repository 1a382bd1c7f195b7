//! Radiometric self-calibration during fusion.
//!
//! A thermal camera's readings carry an offset common to the whole image that jumps at every
//! flat-field correction and drifts between them, and a radial vignetting. Every surface point is
//! seen in many frames, so each frame can be compared with the map fused from the frames before
//! it, as direct SLAM does photometric calibration: the residuals r = T_frame − T_map over the
//! voxels both hold (well observed, uniform ones) give the frame's offset b (their median, robust
//! to mis-registered edges) and, pooled over frames with each frame's mean removed, the vignetting
//! a in r ≈ b + a ρ (ρ = r²/r_max², 1 at the image corners). Each frame's temperatures are
//! corrected by b + a ρ before they are fused. The map's level stays that of the first frames
//! (the camera's): only references (contact readings) fix the absolute level and the gain.

use serde::{Deserialize, Serialize};

/// Self-calibration settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SelfCalibration {
    /// Whether per-frame offsets and vignetting are estimated and removed.
    pub enabled: bool,
    /// Samples (every third observation) a frame must share with the map to get its own offset
    /// (else the last one is kept).
    pub min_overlap: usize,
    /// Map voxels used need this many observations …
    pub min_map_observations: u64,
    /// … and at most this spread (K): uniform surfaces, not edges.
    pub max_map_spread_k: f64,
    /// Residuals farther than this from the frame's median are left out (K).
    pub outlier_k: f64,
    /// Whether a first pass over the scan's first frames estimates the vignetting, so that it
    /// applies from the first frame on (else those frames are fused without it).
    pub warm_up: bool,
}

impl Default for SelfCalibration {
    fn default() -> Self {
        Self {
            enabled: true,
            min_overlap: 100,
            min_map_observations: 4,
            max_map_spread_k: 0.4,
            outlier_k: 1.0,
            warm_up: true,
        }
    }
}

/// One frame's comparison with the map.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameResiduals {
    /// Residuals used.
    pub n: usize,
    /// Median residual (K) after the vignetting correction in force.
    pub median_k: f64,
    /// Σ (ρ − ρ̄)(r − r̄) and Σ (ρ − ρ̄)² over the inliers (for the vignetting).
    pub sxy: f64,
    /// See `sxy`.
    pub sxx: f64,
    /// Σ r² and n of the inlier residuals after the frame's offset (for consistency).
    pub sum_sq_after: f64,
}

/// Compares one frame with the map: `pairs` are (residual uncorrected, ρ); `a` the vignetting in
/// force.
pub fn frame_residuals(pairs: &[(f64, f64)], a: f64, outlier_k: f64) -> FrameResiduals {
    if pairs.is_empty() {
        return FrameResiduals::default();
    }
    let mut adj: Vec<f64> = pairs.iter().map(|(r, rho)| r - a * rho).collect();
    adj.sort_unstable_by(f64::total_cmp);
    let median = adj[adj.len() / 2];
    let inl: Vec<(f64, f64)> = pairs
        .iter()
        .copied()
        .filter(|(r, rho)| (r - a * rho - median).abs() <= outlier_k)
        .collect();
    let n = inl.len().max(1) as f64;
    let (mr, mp) = inl
        .iter()
        .fold((0.0, 0.0), |acc, (r, p)| (acc.0 + r / n, acc.1 + p / n));
    let (mut sxy, mut sxx, mut sq) = (0.0, 0.0, 0.0);
    for (r, p) in &inl {
        sxy += (p - mp) * (r - mr);
        sxx += (p - mp) * (p - mp);
        sq += (r - a * p - median).powi(2);
    }
    FrameResiduals {
        n: inl.len(),
        median_k: median,
        sxy,
        sxx,
        sum_sq_after: sq,
    }
}

/// What self-calibration found: `fusion.json`'s `radiometric`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RadiometricReport {
    /// Whether it ran.
    pub enabled: bool,
    /// Frames that got their own offset.
    pub frames_calibrated: usize,
    /// Frames that kept the previous frame's offset (too little overlap with the map).
    pub frames_carried: usize,
    /// (thermal time, offset removed in K) per fused frame.
    pub offsets_k: Vec<(f64, f64)>,
    /// The vignetting removed: corners minus centre (K).
    pub vignetting_k: f64,
    /// RMS of the frames' residuals against the map before their offsets were removed (K).
    pub residual_rms_before_k: f64,
    /// … and after (K): how consistent the frames became.
    pub residual_rms_after_k: f64,
    /// Largest and smallest offset removed (K).
    pub offset_range_k: [f64; 2],
    /// Frames a first pass took to estimate the vignetting, which then applied from the first
    /// frame on (0: none was needed or possible).
    #[serde(default)]
    pub vignetting_warm_up_frames: usize,
}

/// The spread in ρ (Σ (ρ − ρ̄)² over the frames' samples) the vignetting needs before it is used.
const VIGNETTING_MIN_SXX: f64 = 50.0;

/// The running state: the vignetting estimate and the last offset.
#[derive(Clone, Debug, Default)]
pub struct Calibrator {
    sxy: f64,
    sxx: f64,
    /// The vignetting in force until the frames' own estimate is ready: a first pass's (K).
    prior_vignetting: f64,
    last_offset: f64,
    sum_sq_before: f64,
    sum_sq_after: f64,
    n_resid: usize,
    report: RadiometricReport,
}

impl Calibrator {
    /// A calibrator whose vignetting is `prior_k` until the frames' own estimate is ready (a
    /// first pass's estimate over the scan's first frames, `warm_up_frames` of them).
    pub fn with_prior(prior_k: f64, warm_up_frames: usize) -> Self {
        let mut c = Self {
            prior_vignetting: prior_k,
            ..Self::default()
        };
        c.report.vignetting_warm_up_frames = warm_up_frames;
        c
    }

    /// Whether the frames recorded so far estimate the vignetting (`spread` times the spread in ρ
    /// it needs).
    pub fn vignetting_ready(&self, spread: f64) -> bool {
        self.sxx > spread * VIGNETTING_MIN_SXX
    }

    /// The vignetting in force (K at the corners): the frames' own estimate once enough spread
    /// in ρ was seen, else the prior (none without one).
    pub fn vignetting(&self) -> f64 {
        if self.vignetting_ready(1.0) {
            self.sxy / self.sxx
        } else {
            self.prior_vignetting
        }
    }

    /// The offset removed from the last frame recorded (what a frame without enough overlap with
    /// the map keeps).
    pub fn last_offset(&self) -> f64 {
        self.last_offset
    }

    /// Records a frame in time order.
    pub fn record(&mut self, t: f64, r: &FrameResiduals, offset: f64, min_overlap: usize) {
        if r.n >= min_overlap {
            self.report.frames_calibrated += 1;
            self.sxy += r.sxy;
            self.sxx += r.sxx;
            self.sum_sq_before += r.sum_sq_after + r.median_k * r.median_k * r.n as f64;
            self.sum_sq_after += r.sum_sq_after;
            self.n_resid += r.n;
        } else {
            self.report.frames_carried += 1;
        }
        self.last_offset = offset;
        self.report.offsets_k.push((t, offset));
    }

    /// The report.
    pub fn finish(mut self, enabled: bool) -> RadiometricReport {
        let vignetting = self.vignetting();
        let r = &mut self.report;
        r.enabled = enabled;
        r.vignetting_k = vignetting;
        let n = self.n_resid.max(1) as f64;
        r.residual_rms_before_k = (self.sum_sq_before / n).sqrt();
        r.residual_rms_after_k = (self.sum_sq_after / n).sqrt();
        r.offset_range_k = r
            .offsets_k
            .iter()
            .fold([f64::INFINITY, f64::NEG_INFINITY], |m, (_, o)| {
                [m[0].min(*o), m[1].max(*o)]
            });
        if r.offsets_k.is_empty() {
            r.offset_range_k = [0.0, 0.0];
        }
        self.report
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_offset_and_vignetting_are_recovered_from_residuals() {
        // r = 0.7 + (−0.5) ρ, with a few mis-registered edges far off.
        let mut pairs: Vec<(f64, f64)> = (0..1000)
            .map(|i| {
                let rho = i as f64 / 1000.0;
                (
                    0.7 - 0.5 * rho + 0.01 * ((i * 7919) % 13) as f64 / 13.0,
                    rho,
                )
            })
            .collect();
        pairs.extend((0..30).map(|i| (5.0 + i as f64, 0.5)));
        let r = frame_residuals(&pairs, 0.0, 1.0);
        assert!((r.sxy / r.sxx + 0.5).abs() < 0.02, "{}", r.sxy / r.sxx);
        let r = frame_residuals(&pairs, -0.5, 1.0);
        assert!((r.median_k - 0.705).abs() < 0.01, "{}", r.median_k);
        assert_eq!(r.n, 1000);
    }
}
