//! Levenberg–Marquardt for calibration problems: a few global parameters (intrinsics, an
//! extrinsic) shared by many views with six pose parameters each. Jacobians by central
//! differences, one view at a time in parallel; dense normal equations (a few hundred unknowns).

use mrtmap_geometry::nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// A least-squares problem over global parameters and per-view 6-vectors.
pub trait Problem: Sync {
    /// Number of views.
    fn views(&self) -> usize;
    /// Appends view `v`'s residuals at the global parameters `g` and the view's `p`.
    fn residuals(&self, v: usize, g: &[f64], p: &[f64; 6], out: &mut Vec<f64>);
}

/// The solver's result.
#[derive(Clone, Debug)]
pub struct Solved {
    /// Global parameters.
    pub global: Vec<f64>,
    /// Per-view parameters.
    pub views: Vec<[f64; 6]>,
    /// Sum of squared residuals.
    pub sum_sq: f64,
    /// Number of residuals.
    pub residuals: usize,
    /// Iterations taken.
    pub iterations: usize,
    /// Standard deviation of each global parameter (0 for fixed ones), from the inverse normal
    /// matrix scaled by the residual variance; `None` when singular.
    pub global_std: Option<Vec<f64>>,
}

fn step(x: f64) -> f64 {
    1e-6 * x.abs().max(1e-2)
}

fn view_cost<P: Problem>(p: &P, v: usize, g: &[f64], x: &[f64; 6]) -> (f64, usize) {
    let mut r = Vec::new();
    p.residuals(v, g, x, &mut r);
    (r.iter().map(|e| e * e).sum(), r.len())
}

fn total<P: Problem>(p: &P, g: &[f64], views: &[[f64; 6]], active: &[bool]) -> (f64, usize) {
    (0..p.views())
        .into_par_iter()
        .filter(|v| active[*v])
        .map(|v| view_cost(p, v, g, &views[v]))
        .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

struct Block {
    /// JgᵀJg (nf × nf).
    gg: DMatrix<f64>,
    /// JgᵀJp (nf × 6).
    gp: DMatrix<f64>,
    /// JpᵀJp (6 × 6).
    pp: DMatrix<f64>,
    /// Jgᵀr.
    rg: DVector<f64>,
    /// Jpᵀr.
    rp: DVector<f64>,
}

fn view_block<P: Problem>(p: &P, v: usize, g: &[f64], x: &[f64; 6], free: &[usize]) -> Block {
    let mut r0 = Vec::new();
    p.residuals(v, g, x, &mut r0);
    let m = r0.len();
    let nf = free.len();
    let mut j = DMatrix::<f64>::zeros(m, nf + 6);
    let (mut rp, mut rm) = (Vec::with_capacity(m), Vec::with_capacity(m));
    let mut gg = g.to_vec();
    for (c, &k) in free.iter().enumerate() {
        let h = step(g[k]);
        gg[k] = g[k] + h;
        rp.clear();
        p.residuals(v, &gg, x, &mut rp);
        gg[k] = g[k] - h;
        rm.clear();
        p.residuals(v, &gg, x, &mut rm);
        gg[k] = g[k];
        for i in 0..m.min(rp.len()).min(rm.len()) {
            j[(i, c)] = (rp[i] - rm[i]) / (2.0 * h);
        }
    }
    let mut xx = *x;
    for c in 0..6 {
        let h = step(x[c]);
        xx[c] = x[c] + h;
        rp.clear();
        p.residuals(v, g, &xx, &mut rp);
        xx[c] = x[c] - h;
        rm.clear();
        p.residuals(v, g, &xx, &mut rm);
        xx[c] = x[c];
        for i in 0..m.min(rp.len()).min(rm.len()) {
            j[(i, nf + c)] = (rp[i] - rm[i]) / (2.0 * h);
        }
    }
    let r = DVector::from_vec(r0);
    let jg = j.columns(0, nf);
    let jp = j.columns(nf, 6);
    Block {
        gg: jg.transpose() * jg,
        gp: jg.transpose() * jp,
        pp: jp.transpose() * jp,
        rg: jg.transpose() * &r,
        rp: jp.transpose() * &r,
    }
}

/// Minimises the sum of squared residuals over the free global parameters and the active views'
/// parameters.
pub fn solve<P: Problem>(
    p: &P,
    global: Vec<f64>,
    views: Vec<[f64; 6]>,
    free_global: &[bool],
    active: &[bool],
    max_iterations: usize,
) -> Solved {
    let free: Vec<usize> = (0..global.len()).filter(|k| free_global[*k]).collect();
    let nf = free.len();
    let act: Vec<usize> = (0..p.views()).filter(|v| active[*v]).collect();
    let n = nf + 6 * act.len();
    let mut g = global;
    let mut x = views;
    let (mut cost, mut m) = total(p, &g, &x, active);
    let mut lambda = 1e-3;
    let mut iterations = 0;
    let mut last_a = None;
    for it in 0..max_iterations {
        iterations = it + 1;
        let blocks: Vec<Block> = act
            .par_iter()
            .map(|&v| view_block(p, v, &g, &x[v], &free))
            .collect();
        let mut a = DMatrix::<f64>::zeros(n, n);
        let mut b = DVector::<f64>::zeros(n);
        for (bi, blk) in blocks.iter().enumerate() {
            let o = nf + 6 * bi;
            let mut s = a.view_mut((0, 0), (nf, nf));
            s += &blk.gg;
            a.view_mut((0, o), (nf, 6)).copy_from(&blk.gp);
            a.view_mut((o, 0), (6, nf)).copy_from(&blk.gp.transpose());
            a.view_mut((o, o), (6, 6)).copy_from(&blk.pp);
            let mut bs = b.rows_mut(0, nf);
            bs += &blk.rg;
            b.rows_mut(o, 6).copy_from(&blk.rp);
        }
        let mut improved = false;
        for _ in 0..12 {
            let mut damped = a.clone();
            for k in 0..n {
                damped[(k, k)] += lambda * a[(k, k)].max(1e-9);
            }
            let Some(chol) = damped.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let delta = chol.solve(&(-&b));
            let mut g2 = g.clone();
            for (c, &k) in free.iter().enumerate() {
                g2[k] += delta[c];
            }
            let mut x2 = x.clone();
            for (bi, &v) in act.iter().enumerate() {
                for c in 0..6 {
                    x2[v][c] += delta[nf + 6 * bi + c];
                }
            }
            let (c2, m2) = total(p, &g2, &x2, active);
            if c2.is_finite() && c2 < cost && m2 == m {
                let rel = (cost - c2) / cost.max(1e-300);
                g = g2;
                x = x2;
                cost = c2;
                m = m2;
                lambda = (lambda * 0.3).max(1e-12);
                improved = rel > 1e-12;
                break;
            }
            lambda *= 8.0;
        }
        last_a = Some(a);
        if !improved {
            break;
        }
    }
    let global_std = last_a.and_then(|a| {
        let dof = m.saturating_sub(n);
        if dof == 0 {
            return None;
        }
        let sigma2 = cost / dof as f64;
        let inv = a.cholesky()?.inverse();
        let mut std = vec![0.0; g.len()];
        for (c, &k) in free.iter().enumerate() {
            std[k] = (inv[(c, c)] * sigma2).max(0.0).sqrt();
        }
        Some(std)
    });
    Solved {
        global: g,
        views: x,
        sum_sq: cost,
        residuals: m,
        iterations,
        global_std,
    }
}
