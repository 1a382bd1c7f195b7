//! A surface's background: the model its texels follow away from its features, and the host's
//! temperature once the features are known.
//!
//! The model is T = a + b·v: constant on floors and ceilings, linear in height on walls (which may
//! be stratified). It is found by consensus, not by trimming around a median, so that it holds
//! when features cover a large part of the surface and the background has a gradient, as long as
//! the background is the largest part:
//!
//! 1. Candidate models through one texel (constant) or two texels at least
//!    [`CANDIDATE_MIN_SPAN_M`] apart (linear), [`CANDIDATES`] of them drawn with a fixed seed,
//!    each counting the texels within [`BACKGROUND_TOLERANCE_K`] of it; the model through the
//!    middle texel starts as the best.
//! 2. The model with the most such texels is refitted by least squares to them, [`REFITS`]
//!    times.
//!
//! Once the features are found, the host's temperature is the radiant average of its background
//! texels only (Algorithm 1: the features' share is subtracted), clear of every feature.

use mrtmap_physics::{RadiantAverage, Temperature};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::grid::Grid;

/// Background model coefficients: T = a + b·v.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Background {
    /// Constant (K).
    pub a: f64,
    /// Slope along the frame's v axis (K/m).
    pub b: f64,
}

/// Texels within this of the background model count as background when fitting it (K).
const BACKGROUND_TOLERANCE_K: f64 = 0.3;

/// Candidate models drawn in the consensus (set with the consensus fit, for stratified walls with
/// large windows).
const CANDIDATES: usize = 300;

/// The seed of the candidates' draws: the same texels give the same background, run after run.
const CANDIDATE_SEED: u64 = 0x6267;

/// A linear candidate is drawn through two texels at least this far apart along v (m): closer
/// ones give a slope made of their noise.
const CANDIDATE_MIN_SPAN_M: f64 = 0.3;

/// How many times the best candidate is refitted by least squares to the texels near it.
const REFITS: usize = 3;

/// Least squares T = a + b·v over `samples` (constant when `linear` is false or v does not vary).
fn least_squares(samples: &[&(f64, f64)], linear: bool) -> Option<Background> {
    let n = samples.len() as f64;
    if samples.is_empty() {
        return None;
    }
    let (sv, st) = (
        samples.iter().map(|s| s.0).sum::<f64>(),
        samples.iter().map(|s| s.1).sum::<f64>(),
    );
    if linear {
        let svv = samples.iter().map(|s| s.0 * s.0).sum::<f64>();
        let svt = samples.iter().map(|s| s.0 * s.1).sum::<f64>();
        let den = n * svv - sv * sv;
        if den.abs() > 1e-9 * n * n {
            let b = (n * svt - sv * st) / den;
            return Some(Background {
                a: (st - b * sv) / n,
                b,
            });
        }
    }
    Some(Background { a: st / n, b: 0.0 })
}

/// The background of a surface: the model (constant, or linear in v) that the most texels lie
/// within [`BACKGROUND_TOLERANCE_K`] of, found by consensus over candidate models through one or
/// two texels, then refitted by least squares to those texels. Unlike trimming around a median,
/// this holds when features cover a large part of the surface and the background has a gradient,
/// as long as the background is the largest part.
pub(super) fn robust_background(samples: &[(f64, f64)], linear: bool) -> Background {
    let tol = BACKGROUND_TOLERANCE_K;
    let count = |bg: &Background| {
        samples
            .iter()
            .filter(|(v, t)| (t - bg.a - bg.b * v).abs() <= tol)
            .count()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(CANDIDATE_SEED);
    let mut best = Background {
        a: samples[samples.len() / 2].1,
        b: 0.0,
    };
    let mut best_n = count(&best);
    for _ in 0..CANDIDATES {
        let x = samples[rng.random_range(0..samples.len())];
        let cand = if linear {
            let y = samples[rng.random_range(0..samples.len())];
            if (x.0 - y.0).abs() < CANDIDATE_MIN_SPAN_M {
                continue;
            }
            let b = (y.1 - x.1) / (y.0 - x.0);
            Background {
                a: x.1 - b * x.0,
                b,
            }
        } else {
            Background { a: x.1, b: 0.0 }
        };
        let n = count(&cand);
        if n > best_n {
            (best, best_n) = (cand, n);
        }
    }
    for _ in 0..REFITS {
        let inliers: Vec<&(f64, f64)> = samples
            .iter()
            .filter(|(v, t)| (t - best.a - best.b * v).abs() <= tol)
            .collect();
        match least_squares(&inliers, linear) {
            Some(b) => best = b,
            None => break,
        }
    }
    best
}

/// The host's temperature and its uncertainty: its background texels only (the features' are
/// subtracted, Algorithm 1), one texel clear of every feature's region (border texels mix both)
/// and outside every feature's outline (`in_outline`); the spread counts again for the
/// `unseen_share` of the surface.
pub(super) fn host_temperature(
    g: &Grid,
    cells: &[usize],
    in_feature: &[bool],
    in_outline: &[bool],
    unseen_share: f64,
) -> Option<(f64, f64)> {
    let (nx, ny) = (g.nx, g.ny);
    let near_feature = |c: usize| {
        let (i, j) = (c % nx, c / nx);
        (j.saturating_sub(1)..=(j + 1).min(ny - 1)).any(|jj| {
            (i.saturating_sub(1)..=(i + 1).min(nx - 1)).any(|ii| in_feature[jj * nx + ii])
        })
    };
    let mut host_avg = RadiantAverage::new();
    for &c in cells {
        if !near_feature(c) && !in_outline[c] {
            host_avg.add(Temperature::from_kelvin(g.kelvin(c)), 1.0);
        }
    }
    let m = host_avg.mean()?;
    let sigma = host_avg.std_dev_k().unwrap_or(0.0);
    let n = host_avg.count().max(1) as f64;
    let std = ((sigma * sigma) / n + (unseen_share * sigma).powi(2)).sqrt();
    Some((m.kelvin(), std))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stratified wall (18 °C at mid-height, 0.8 K/m) with a 14 °C window over a quarter of it.
    #[test]
    fn background_ignores_a_large_cold_window() {
        let mut s = Vec::new();
        for j in 0..100 {
            for i in 0..133 {
                let (u, v) = (i as f64 * 0.03, -1.5 + j as f64 * 0.03);
                let window = (1.0..3.0).contains(&u) && (-0.5..0.9).contains(&v);
                s.push((v, if window { 287.15 } else { 291.15 + 0.8 * v }));
            }
        }
        let bg = robust_background(&s, true);
        assert!(
            (bg.a - 291.15).abs() < 0.01 && (bg.b - 0.8).abs() < 0.01,
            "{bg:?}"
        );
    }
}
