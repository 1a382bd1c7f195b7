//! Thermal features on one envelope surface.
//!
//! The surface's fused points are rasterised into square texels (radiant T⁴ averages). Its
//! background is a robust fit (constant on floor and ceiling, linear in height on walls, which
//! may be stratified) through iteratively trimmed least squares; texels farther than the
//! threshold from it form warm and cold masks. Each connected region's outline is then redrawn at
//! half its own core contrast (hysteresis: a border texel joins when the feature covers more than
//! about half of it, so the outline is not biased outwards by the detection threshold), and regions
//! of at least the minimum area become features: a rectangle (the minimum-area rectangle of the region's texels) when the
//! region fills at least 75 % of it, otherwise the region's simplified convex outline, clipped to
//! the host. The host's temperature is the radiant average of its background texels only.

use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_geometry::polygon::{
    point_in_polygon_fast, polygon_inside, polygons_overlap, signed_area,
};
use mrtmap_geometry::shape2d::{clip_convex, convex_hull, min_area_rectangle, simplify_closed};
use mrtmap_physics::{RadiantAverage, Temperature, ZERO_CELSIUS_K};
use mrtmap_radiation::{RasterFile, UnseenPatch};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::SegmentParams;

/// A feature found on a surface.
#[derive(Clone, Debug)]
pub struct FoundFeature {
    /// Outline in the surface's 2D frame.
    pub polygon_2d: Vec<Point2<f64>>,
    /// Radiant temperature (K).
    pub temperature_k: f64,
    /// Standard error of that temperature (K).
    pub temperature_std_k: f64,
    /// Mean difference from the background (K): positive warm, negative cold.
    pub contrast_k: f64,
    /// Area (m²).
    pub area_m2: f64,
    /// Cloud points on it.
    pub points: Vec<usize>,
    /// Area of its outline the scan never saw, completed from the shape of what it saw (m²; see
    /// [`complete_features`]).
    pub completed_m2: f64,
}

/// What a surface's texels say.
#[derive(Clone, Debug)]
pub struct SurfaceAnalysis {
    /// Radiant temperature of the background (K), if any texel was observed.
    pub temperature_k: Option<f64>,
    /// Its standard uncertainty (K): sampling and the unobserved share (see the module docs).
    pub temperature_std_k: f64,
    /// Fraction of the surface's texels observed.
    pub observed_fraction: f64,
    /// Features.
    pub features: Vec<FoundFeature>,
    /// Features dropped (overlapping, or not fitting in the host), with why.
    pub dropped: Vec<String>,
    /// The background model.
    pub background: Background,
    /// The background's temperature raster (see [`background_raster`]), when asked for.
    pub raster: Option<RasterFile>,
}

/// Background model coefficients: T = a + b·v.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Background {
    /// Constant (K).
    pub a: f64,
    /// Slope along the frame's v axis (K/m).
    pub b: f64,
}

/// A surface's texels: which lie inside its outline, their radiant averages and their points.
struct Grid {
    lo: Point2<f64>,
    /// The host's far corner (the last row and column of texels end here, partly filled).
    hi: Point2<f64>,
    t: f64,
    nx: usize,
    ny: usize,
    inside: Vec<bool>,
    temp: Vec<RadiantAverage>,
    points: Vec<Vec<usize>>,
    /// Each texel's points in the frame and their temperatures (K).
    samples: Vec<Vec<(Point2<f64>, f64)>>,
}

impl Grid {
    /// Rasterises the points `idx` of a surface (`host` its outline in `frame`) at texel `t`, each
    /// point's temperature weighted by `weights` (its observations) in its texel's average.
    fn rasterise(
        frame: &PlaneFrame,
        host: &[Point2<f64>],
        idx: &[usize],
        (pos, temp_k, weights): (&[Point3<f64>], &[f64], &[f64]),
        t: f64,
    ) -> Self {
        let (mut lo, mut hi) = (
            Point2::new(f64::INFINITY, f64::INFINITY),
            Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for q in host {
            lo = Point2::new(lo.x.min(q.x), lo.y.min(q.y));
            hi = Point2::new(hi.x.max(q.x), hi.y.max(q.y));
        }
        let nx = ((hi.x - lo.x) / t).ceil().max(1.0) as usize;
        let ny = ((hi.y - lo.y) / t).ceil().max(1.0) as usize;
        let mut g = Grid {
            lo,
            hi,
            t,
            nx,
            ny,
            inside: vec![false; nx * ny],
            temp: vec![RadiantAverage::new(); nx * ny],
            points: vec![Vec::new(); nx * ny],
            samples: vec![Vec::new(); nx * ny],
        };
        for j in 0..ny {
            for i in 0..nx {
                g.inside[j * nx + i] = point_in_polygon_fast(&g.centre(i, j), host);
            }
        }
        for &k in idx {
            let q = frame.to_2d(&pos[k]);
            let (i, j) = (((q.x - lo.x) / t).floor(), ((q.y - lo.y) / t).floor());
            if i >= 0.0 && j >= 0.0 && (i as usize) < nx && (j as usize) < ny {
                let c = j as usize * nx + i as usize;
                g.temp[c].add(Temperature::from_kelvin(temp_k[k]), weights[k]);
                g.points[c].push(k);
                g.samples[c].push((q, temp_k[k]));
            }
        }
        g
    }

    fn centre(&self, i: usize, j: usize) -> Point2<f64> {
        Point2::new(
            self.lo.x + (i as f64 + 0.5) * self.t,
            self.lo.y + (j as f64 + 0.5) * self.t,
        )
    }

    /// The centre of texel `c`.
    fn centre_of(&self, c: usize) -> Point2<f64> {
        self.centre(c % self.nx, c / self.nx)
    }

    /// Whether texel `c` holds any point.
    fn observed(&self, c: usize) -> bool {
        self.temp[c].count() > 0
    }

    /// Texel `c`'s radiant temperature (K), NaN when unobserved.
    fn kelvin(&self, c: usize) -> f64 {
        self.temp[c].mean().map_or(f64::NAN, |x| x.kelvin())
    }

    /// The four neighbours of texel `c`: (exists, index).
    fn neighbours(&self, c: usize) -> [(bool, usize); 4] {
        let (nx, ny) = (self.nx, self.ny);
        let (i, j) = (c % nx, c / nx);
        [
            (i > 0, c.wrapping_sub(1)),
            (i + 1 < nx, c + 1),
            (j > 0, c.wrapping_sub(nx)),
            (j + 1 < ny, c + nx),
        ]
    }

    /// Which texels reach within `m` of the host's outer edge (measured: the last row and column
    /// end at the host's edge, partly filled, so the texel before a narrow last one is near it
    /// too), or lie within `m` (in whole texels) of a texel outside the surface.
    fn near_edge(&self, m: f64) -> Vec<bool> {
        let r = (m / self.t).ceil() as usize;
        let t = self.t;
        let near = |k: usize, lo: f64, hi: f64| {
            let (a, b) = (lo + k as f64 * t, (lo + (k + 1) as f64 * t).min(hi));
            a - lo < m || hi - b < m
        };
        let mut out = vec![false; self.nx * self.ny];
        for c in 0..self.nx * self.ny {
            let (i, j) = (c % self.nx, c / self.nx);
            if near(i, self.lo.x, self.hi.x) || near(j, self.lo.y, self.hi.y) {
                out[c] = true;
            }
            if self.inside[c] {
                continue;
            }
            for jj in j.saturating_sub(r)..(j + r + 1).min(self.ny) {
                for ii in i.saturating_sub(r)..(i + r + 1).min(self.nx) {
                    out[jj * self.nx + ii] = true;
                }
            }
        }
        out
    }

    /// Whether all four neighbours of texel `c` exist and are in `set`.
    fn interior_of(&self, c: usize, set: &[bool]) -> bool {
        self.neighbours(c).iter().all(|&(ok, d)| ok && set[d])
    }
}

/// A warm or cold region lying mostly within this of its surface's edge is the neighbouring
/// surface's temperature blurred in at the corner (m).
const EDGE_STRIP_M: f64 = 0.12;

/// A faint region (under [`EDGE_BLUR_MAX_K`] from the background) lying mostly within this of
/// its surface's edge is blur too (m): a corner seen obliquely spreads the next surface's
/// temperature farther along this one. On the L-shaped room's cold exterior wall the warm
/// corner column (30 cm wide, +0.6 K) and the row under the ceiling joined into an L whose convex
/// outline became a 3.7 m², +0.35 K "feature" on every field-study walk.
const EDGE_BLUR_M: f64 = 0.3;

/// The largest contrast (K) of a region that [`EDGE_BLUR_M`] may call blur: a radiator along
/// the floor or a window up to the ceiling stands out by far more.
const EDGE_BLUR_MAX_K: f64 = 1.0;

/// Texels within this of the background model count as background when fitting it (K).
const BACKGROUND_TOLERANCE_K: f64 = 0.3;

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
fn robust_background(samples: &[(f64, f64)], linear: bool) -> Background {
    let tol = BACKGROUND_TOLERANCE_K;
    let count = |bg: &Background| {
        samples
            .iter()
            .filter(|(v, t)| (t - bg.a - bg.b * v).abs() <= tol)
            .count()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(0x6267);
    let mut best = Background {
        a: samples[samples.len() / 2].1,
        b: 0.0,
    };
    let mut best_n = count(&best);
    for _ in 0..300 {
        let x = samples[rng.random_range(0..samples.len())];
        let cand = if linear {
            let y = samples[rng.random_range(0..samples.len())];
            if (x.0 - y.0).abs() < 0.3 {
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
    for _ in 0..3 {
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

fn ccw(mut p: Vec<Point2<f64>>) -> Vec<Point2<f64>> {
    if signed_area(&p) < 0.0 {
        p.reverse();
    }
    p
}

/// The texels beyond the threshold on one side of the background (`sign` +1 warm, −1 cold), with
/// one-texel holes (unobserved or noisy) closed.
fn threshold_mask(
    g: &Grid,
    resid: &dyn Fn(usize) -> f64,
    sign: f64,
    threshold_k: f64,
) -> Vec<bool> {
    let n = g.nx * g.ny;
    let raw: Vec<bool> = (0..n)
        .map(|c| g.inside[c] && g.observed(c) && sign * resid(c) > threshold_k)
        .collect();
    let mut mask = raw.clone();
    for (c, m) in mask.iter_mut().enumerate() {
        if !*m
            && g.inside[c]
            && g.neighbours(c)
                .iter()
                .filter(|&&(ok, d)| ok && raw[d])
                .count()
                >= 3
        {
            *m = true;
        }
    }
    mask
}

/// The connected components (4-connectivity) of `mask`, in order of their first texel.
fn components(g: &Grid, mask: &[bool]) -> Vec<Vec<usize>> {
    let mut label = vec![usize::MAX; mask.len()];
    let mut out = Vec::new();
    for seed in 0..mask.len() {
        if !mask[seed] || label[seed] != usize::MAX {
            continue;
        }
        let mut comp = vec![seed];
        label[seed] = seed;
        let mut k = 0;
        while k < comp.len() {
            let c = comp[k];
            k += 1;
            for (ok, d) in g.neighbours(c) {
                if ok && mask[d] && label[d] == usize::MAX {
                    label[d] = seed;
                    comp.push(d);
                }
            }
        }
        out.push(comp);
    }
    out
}

/// Why region `comp` (of `area` m²) is the next surface's temperature blurred in at the corner
/// (optics, registration, voxels) and not a feature of this one: it lies mostly within
/// [`EDGE_STRIP_M`] of the surface's edge (`near_edge`), or is faint and lies mostly within
/// [`EDGE_BLUR_M`] (`near_edge_wide`); `None` when it is not.
fn edge_blur(
    comp: &[usize],
    area: f64,
    resid: &dyn Fn(usize) -> f64,
    (near_edge, near_edge_wide): (&[bool], &[bool]),
) -> Option<String> {
    let strip = comp.iter().filter(|&&c| near_edge[c]).count();
    let wide = comp.iter().filter(|&&c| near_edge_wide[c]).count();
    let contrast = comp.iter().map(|&c| resid(c)).sum::<f64>() / comp.len() as f64;
    (strip * 5 >= comp.len() * 4
        || (wide * 5 >= comp.len() * 4 && contrast.abs() < EDGE_BLUR_MAX_K))
        .then(|| {
            format!(
                "a {area:.2} m² strip along the surface's edge ({contrast:+.1} K): the next surface's temperature blurred in"
            )
        })
}

/// Hysteresis: the region grown or shrunk to the texels beyond half its core contrast, connected
/// to its texels that are; `None` when no texel of it was observed. It grows only into texels
/// within [`GROWTH_CEILING`] times its core contrast (plus [`GROWTH_SLACK_K`]): a faint region
/// touching a hot one is not that hot one (a +0.6 K strip along the floor grew into the L-shaped
/// room's 45 °C radiator on walk 4 and, being found first, took its place with a convex outline
/// reaching the floor: 0.71 K at the grid's worst node).
fn hysteresis(
    g: &Grid,
    comp: &[usize],
    resid: &dyn Fn(usize) -> f64,
    sign: f64,
) -> Option<Vec<usize>> {
    let mut core: Vec<f64> = comp
        .iter()
        .filter(|&&c| g.observed(c))
        .map(|&c| sign * resid(c))
        .collect();
    if core.is_empty() {
        return None;
    }
    core.sort_by(f64::total_cmp);
    let median = core[core.len() / 2];
    let half = 0.5 * median;
    let ceiling = GROWTH_CEILING * median + GROWTH_SLACK_K;
    let mut member = vec![false; g.nx * g.ny];
    let mut grown = Vec::new();
    let mut queue: Vec<usize> = comp
        .iter()
        .copied()
        .filter(|&c| g.observed(c) && sign * resid(c) > half)
        .collect();
    for &c in &queue {
        member[c] = true;
    }
    while let Some(c) = queue.pop() {
        grown.push(c);
        for (ok, d) in g.neighbours(c) {
            if ok
                && !member[d]
                && g.inside[d]
                && g.observed(d)
                && (half..=ceiling).contains(&(sign * resid(d)))
            {
                member[d] = true;
                queue.push(d);
            }
        }
    }
    Some(grown)
}

/// How far beyond its core contrast (a multiple of it) a region may grow (see [`hysteresis`]).
const GROWTH_CEILING: f64 = 3.0;

/// The noise allowance (K) added to the growth ceiling.
const GROWTH_SLACK_K: f64 = 0.5;

/// A region's outline: its minimum-area rectangle when it fills at least 75 % of it, else its
/// simplified convex outline, clipped to the host; why not when it does not fit.
fn outline(
    g: &Grid,
    comp: &[usize],
    core: &[usize],
    host: &[Point2<f64>],
    area: f64,
    step: Option<&Step<'_>>,
) -> Result<Vec<Point2<f64>>, String> {
    use mrtmap_geometry::nalgebra::Vector2;
    let t = g.t;
    let corners: Vec<Point2<f64>> = comp
        .iter()
        .flat_map(|&c| {
            let o = Point2::new(
                g.lo.x + (c % g.nx) as f64 * t,
                g.lo.y + (c / g.nx) as f64 * t,
            );
            [
                o,
                o + Vector2::new(t, 0.0),
                o + Vector2::new(t, t),
                o + Vector2::new(0.0, t),
            ]
        })
        .collect();
    let Some((rect, rect_area)) = min_area_rectangle(&corners) else {
        return Err(String::new());
    };
    let mut poly = if area / rect_area >= 0.75 {
        robust_rectangle(g, core, &rect, step)
            .unwrap_or(rect)
            .to_vec()
    } else {
        simplify_closed(&convex_hull(&corners), 0.5 * t)
    };
    poly = ccw(poly);
    if !polygon_inside(&poly, host, 1e-3) {
        poly = ccw(clip_convex(&poly, &ccw(convex_hull(host))));
        poly.dedup_by(|a, b| (*a - *b).norm() < 1e-6);
    }
    // Vertices within a millimetre of the previous one (around the loop) are one vertex.
    poly.dedup_by(|a, b| (*a - *b).norm() < 1e-3);
    while poly.len() > 3 && (poly[0] - poly[poly.len() - 1]).norm() < 1e-3 {
        poly.pop();
    }
    if poly.len() < 3 || !polygon_inside(&poly, host, 1e-3) {
        return Err(format!(
            "a {area:.2} m² region does not fit inside its surface"
        ));
    }
    if mrtmap_geometry::polygon::check_simple(&poly, 1e-6).is_err() {
        return Err(format!("a {area:.2} m² region's outline is degenerate"));
    }
    Ok(poly)
}

/// The texels of region `comp` at least half as far from the background as its plateau (the
/// median of its interior texels, or its upper quartile when too few are interior), and the
/// plateau's contrast (K, signed by `sign`). A blurred step
/// crosses half its height at the true edge, while the region's threshold, a fixed contrast, lies
/// further out the hotter the feature: the L-shaped room's 45 °C radiator (1.80 × 0.60 m) came out
/// 1.86 × 0.66 m from its thresholded region.
fn half_contrast_core(
    g: &Grid,
    comp: &[usize],
    resid: &dyn Fn(usize) -> f64,
    sign: f64,
) -> (Vec<usize>, Option<f64>) {
    let mut in_comp = vec![false; g.nx * g.ny];
    for &c in comp {
        in_comp[c] = true;
    }
    let contrast = |cells: &mut Vec<f64>, q: f64| -> Option<f64> {
        if cells.is_empty() {
            return None;
        }
        cells.sort_by(f64::total_cmp);
        Some(cells[((cells.len() - 1) as f64 * q).round() as usize])
    };
    let mut interior: Vec<f64> = comp
        .iter()
        .filter(|&&c| g.observed(c) && g.interior_of(c, &in_comp))
        .map(|&c| resid(c) * sign)
        .collect();
    let mut all: Vec<f64> = comp
        .iter()
        .filter(|&&c| g.observed(c))
        .map(|&c| resid(c) * sign)
        .collect();
    let plateau = if interior.len() >= 4 {
        contrast(&mut interior, 0.5)
    } else {
        contrast(&mut all, 0.75)
    };
    let Some(plateau) = plateau else {
        return (comp.to_vec(), None);
    };
    let core: Vec<usize> = comp
        .iter()
        .copied()
        .filter(|&c| !g.observed(c) || resid(c) * sign >= 0.5 * plateau)
        .collect();
    if core.len() < 4 {
        (comp.to_vec(), Some(plateau))
    } else {
        (core, Some(plateau))
    }
}

/// The rectangle `rect` of a region's texels, each side moved to where the region fills half of
/// the texel rows along it: the extreme texels of a blurred, noisy edge (a 45 °C radiator's glow)
/// stretch the smallest enclosing rectangle outwards, but not the rows' half-occupancy.
fn robust_rectangle(
    g: &Grid,
    comp: &[usize],
    rect: &[Point2<f64>; 4],
    step: Option<&Step<'_>>,
) -> Option<[Point2<f64>; 4]> {
    let o = rect[0];
    let (ea, eb) = (rect[1] - rect[0], rect[3] - rect[0]);
    let (la, lb) = (ea.norm(), eb.norm());
    let (ua, ub) = (ea.try_normalize(1e-12)?, eb.try_normalize(1e-12)?);
    let t = g.t;
    let (na, nb) = ((la / t).ceil() as usize + 1, (lb / t).ceil() as usize + 1);
    let (mut rows_a, mut rows_b) = (vec![0usize; na], vec![0usize; nb]);
    for &c in comp {
        let d = g.centre_of(c) - o;
        let (a, b) = (d.dot(&ua), d.dot(&ub));
        rows_a[((a / t).max(0.0) as usize).min(na - 1)] += 1;
        rows_b[((b / t).max(0.0) as usize).min(nb - 1)] += 1;
    }
    // Extent along one axis: the first and last slices holding half the typical slice's texels.
    let extent = |rows: &[usize]| -> Option<(f64, f64)> {
        let mut full: Vec<usize> = rows.iter().copied().filter(|&n| n > 0).collect();
        full.sort_unstable();
        let typical = *full.get(full.len() * 3 / 4)?;
        let first = rows.iter().position(|&n| 2 * n >= typical)?;
        let last = rows.iter().rposition(|&n| 2 * n >= typical)?;
        Some((first as f64 * t, (last + 1) as f64 * t))
    };
    let ((a0, a1), (b0, b1)) = (extent(&rows_a)?, extent(&rows_b)?);
    let (mut a0, mut a1, mut b0, mut b1) = (a0.max(0.0), a1.min(la), b0.max(0.0), b1.min(lb));
    if a1 - a0 < t || b1 - b0 < t {
        return None;
    }
    if let Some(step) = step {
        // Each side to a fraction of a texel, from the points' temperatures across it.
        let local = |q: &Point2<f64>| {
            let d = q - o;
            (d.dot(&ua), d.dot(&ub))
        };
        let samples: Vec<(f64, f64, f64)> = g
            .samples
            .iter()
            .flatten()
            .map(|(q, tk)| {
                let (a, b) = local(q);
                (a, b, step.filled(q, *tk))
            })
            .collect();
        let across_b: Vec<(f64, f64, f64)> = samples.iter().map(|&(a, b, f)| (b, a, f)).collect();
        let (ra0, ra1) = (
            refine_side(&samples, a0, (b0, b1), true, t),
            refine_side(&samples, a1, (b0, b1), false, t),
        );
        let (rb0, rb1) = (
            refine_side(&across_b, b0, (a0, a1), true, t),
            refine_side(&across_b, b1, (a0, a1), false, t),
        );
        (a0, a1, b0, b1) = (ra0, ra1, rb0, rb1);
        if a1 - a0 < t || b1 - b0 < t {
            return None;
        }
    }
    let at = |a: f64, b: f64| o + ua * a + ub * b;
    Some([at(a0, b0), at(a1, b0), at(a1, b1), at(a0, b1)])
}

/// A feature's step above (or below) its surface's background: where a point lies on it.
struct Step<'a> {
    background: &'a Background,
    sign: f64,
    plateau: f64,
}

impl Step<'_> {
    /// How much of the step a point at `q` with temperature `t_k` shows: 0 on the background, 1 on
    /// the feature's plateau, clamped.
    fn filled(&self, q: &Point2<f64>, t_k: f64) -> f64 {
        let r = t_k - self.background.a - self.background.b * q.y;
        (self.sign * r / self.plateau.max(1e-9)).clamp(0.0, 1.0)
    }
}

/// One side of a feature's rectangle to a fraction of a texel: `samples` are (across, along,
/// filled) with `across` the coordinate perpendicular to the side, at `edge` from the texels; the
/// feature lies beyond it (`rising`: at larger `across`). Over a band of ± two texels across the
/// side (away from the side's ends) a blurred step keeps its integral, so the mean fill f of the
/// band's points puts the edge at the band's far end minus 4 texels × f. Unchanged with fewer than
/// 12 points in the band, and never moved by more than a texel.
fn refine_side(
    samples: &[(f64, f64, f64)],
    edge: f64,
    (lo, hi): (f64, f64),
    rising: bool,
    t: f64,
) -> f64 {
    let w = 2.0 * t;
    let (mut n, mut sum) = (0usize, 0.0);
    for &(a, b, f) in samples {
        if (a - edge).abs() <= w && b > lo + t && b < hi - t {
            n += 1;
            sum += f;
        }
    }
    if n < 12 {
        return edge;
    }
    let fill = sum / n as f64;
    let refined = if rising {
        edge + w - 2.0 * w * fill
    } else {
        edge - w + 2.0 * w * fill
    };
    refined.clamp(edge - t, edge + t)
}

/// A feature of region `comp` with outline `poly`: its temperature from interior texels (all four
/// neighbours in the feature; border texels mix in the background) clear of the surface's edge
/// (`near_edge`: there the next surface's temperature is blurred in; a 45 cm patch at the
/// L-shaped room's corner read 18.1–18.3 °C with its edge texels, 17.8 °C without, on a
/// 17.6 °C wall), or from all its texels when too few are.
fn feature(
    g: &Grid,
    comp: &[usize],
    poly: Vec<Point2<f64>>,
    resid: &dyn Fn(usize) -> f64,
    bg: &Background,
    near_edge: &[bool],
) -> FoundFeature {
    let mut in_comp = vec![false; g.nx * g.ny];
    for &c in comp {
        in_comp[c] = true;
    }
    let interior: Vec<usize> = comp
        .iter()
        .copied()
        .filter(|&c| g.interior_of(c, &in_comp))
        .collect();
    let clear: Vec<usize> = interior
        .iter()
        .copied()
        .filter(|&c| !near_edge[c])
        .collect();
    let enough = |cells: &[usize]| cells.iter().filter(|&&c| g.observed(c)).count() >= 4;
    let use_cells = if enough(&clear) {
        &clear
    } else if enough(&interior) {
        &interior
    } else {
        comp
    };
    let mut avg = RadiantAverage::new();
    let mut contrast = 0.0;
    for &c in use_cells {
        if g.observed(c) {
            avg.add(Temperature::from_kelvin(g.kelvin(c)), 1.0);
            contrast += resid(c);
        }
    }
    let n_obs = avg.count().max(1) as f64;
    FoundFeature {
        temperature_k: avg.mean().map_or(bg.a, |x| x.kelvin()),
        temperature_std_k: avg.std_dev_k().unwrap_or(0.0) / n_obs.sqrt(),
        contrast_k: contrast / n_obs,
        area_m2: signed_area(&poly).abs(),
        points: comp
            .iter()
            .flat_map(|&c| g.points[c].iter().copied())
            .collect(),
        polygon_2d: poly,
        completed_m2: 0.0,
    }
}

/// A found feature's texels: its thresholded region and its half-contrast core.
struct Region {
    comp: Vec<usize>,
    core: Vec<usize>,
    sign: f64,
}

/// Least unseen area worth completing (m²).
const COMPLETE_MIN_M2: f64 = 0.02;

/// The rectangle `cells` and `outlines` imply (the smallest that holds them) and, when what lies
/// inside it agrees with one feature there, the area of it outside `outlines` the scan never saw
/// (m²). It agrees when no more than 5 % of its texels were seen looking like the background
/// (observed, more than a texel from `regions`, under half the feature's `contrast` from the
/// background), some of it outside the outlines was never seen (at least [`COMPLETE_MIN_M2`]), and
/// no more than 60 % of it: a shape is completed from what was seen, never invented.
fn completion(
    g: &Grid,
    cells: &[usize],
    outlines: &[&[Point2<f64>]],
    in_region: &[bool],
    resid: &dyn Fn(usize) -> f64,
    sign: f64,
    contrast: f64,
) -> Option<(Vec<Point2<f64>>, f64)> {
    use mrtmap_geometry::nalgebra::Vector2;
    let t = g.t;
    let mut corners: Vec<Point2<f64>> = cells
        .iter()
        .flat_map(|&c| {
            let o = Point2::new(
                g.lo.x + (c % g.nx) as f64 * t,
                g.lo.y + (c / g.nx) as f64 * t,
            );
            [
                o,
                o + Vector2::new(t, 0.0),
                o + Vector2::new(t, t),
                o + Vector2::new(0.0, t),
            ]
        })
        .collect();
    corners.extend(outlines.iter().flat_map(|o| o.iter().copied()));
    let (rect, _) = min_area_rectangle(&corners)?;
    let rect = ccw(rect.to_vec());
    let outlined = |q: &Point2<f64>| outlines.iter().any(|o| point_in_polygon_fast(q, o));
    let near_region = |c: usize| {
        let (i, j) = (c % g.nx, c / g.nx);
        (j.saturating_sub(1)..(j + 2).min(g.ny))
            .any(|jj| (i.saturating_sub(1)..(i + 2).min(g.nx)).any(|ii| in_region[jj * g.nx + ii]))
    };
    let (mut n, mut unseen, mut other) = (0usize, 0usize, 0usize);
    for c in (0..g.nx * g.ny).filter(|&c| g.inside[c]) {
        if !point_in_polygon_fast(&g.centre_of(c), &rect) {
            continue;
        }
        n += 1;
        if !g.observed(c) {
            unseen += usize::from(!outlined(&g.centre_of(c)));
        } else if !near_region(c) && resid(c) * sign < 0.5 * contrast.abs() {
            other += 1;
        }
    }
    let unseen_m2 = unseen as f64 * t * t;
    (n > 0 && other * 20 <= n && unseen_m2 >= COMPLETE_MIN_M2 && unseen * 5 <= n * 3)
        .then_some((rect, unseen_m2))
}

/// Completes features into what the scan did not see, where what it saw implies the shape (issue
/// 37): two features of one surface, of one sign and within 1 K (or a fifth of their contrast) of
/// each other, whose common rectangle is theirs or unseen become one (a panel split by a stripe the
/// walk missed); then a feature whose rectangle is its own or unseen takes that rectangle (a
/// window whose corner was never in view). At least half of what a completion adds to the
/// outlines must be unseen: the rectangle of a feature's half-contrast core reaches a little into
/// its blur, and a radiator whose strip along the floor the walk missed grew 12 % over its true
/// 1.08 m² when any unseen area licensed the core's rectangle. Each says how much of its outline
/// is completed.
#[allow(clippy::too_many_arguments)]
fn complete_features(
    g: &Grid,
    features: &mut Vec<FoundFeature>,
    regions: &mut Vec<Region>,
    host: &[Point2<f64>],
    resid: &dyn Fn(usize) -> f64,
    bg: &Background,
    near_edge: &[bool],
) {
    let mark = |cells: &[&Region]| {
        let mut m = vec![false; g.nx * g.ny];
        for r in cells {
            for &c in &r.comp {
                m[c] = true;
            }
        }
        m
    };
    let fits = |poly: &[Point2<f64>], features: &[FoundFeature], skip: &[usize]| {
        polygon_inside(poly, host, 1e-3)
            && features
                .iter()
                .enumerate()
                .all(|(k, f)| skip.contains(&k) || !polygons_overlap(&f.polygon_2d, poly, 1e-3))
    };
    // Pairs: merge while any pair merges.
    'merging: loop {
        for i in 0..features.len() {
            for j in i + 1..features.len() {
                let (a, b) = (&features[i], &features[j]);
                let (ra, rb) = (&regions[i], &regions[j]);
                let close = (a.temperature_k - b.temperature_k).abs()
                    <= (0.2 * a.contrast_k.abs().min(b.contrast_k.abs())).max(1.0);
                if ra.sign != rb.sign || !close {
                    continue;
                }
                let core: Vec<usize> = ra.core.iter().chain(&rb.core).copied().collect();
                let in_region = mark(&[ra, rb]);
                let contrast = a.contrast_k.abs().min(b.contrast_k.abs());
                let Some((rect, unseen_m2)) = completion(
                    g,
                    &core,
                    &[&a.polygon_2d, &b.polygon_2d],
                    &in_region,
                    resid,
                    ra.sign,
                    contrast,
                ) else {
                    continue;
                };
                let grown = signed_area(&rect).abs() - a.area_m2 - b.area_m2;
                if unseen_m2 < 0.5 * grown || !fits(&rect, features, &[i, j]) {
                    continue;
                }
                let comp: Vec<usize> = ra.comp.iter().chain(&rb.comp).copied().collect();
                let mut merged = feature(g, &comp, rect, resid, bg, near_edge);
                merged.completed_m2 = unseen_m2;
                let sign = ra.sign;
                features.remove(j);
                regions.remove(j);
                features[i] = merged;
                regions[i] = Region { comp, core, sign };
                continue 'merging;
            }
        }
        break;
    }
    for i in 0..features.len() {
        if features[i].completed_m2 > 0.0 {
            continue;
        }
        let r = &regions[i];
        let in_region = mark(&[r]);
        let Some((rect, unseen_m2)) = completion(
            g,
            &r.core,
            &[&features[i].polygon_2d],
            &in_region,
            resid,
            r.sign,
            features[i].contrast_k,
        ) else {
            continue;
        };
        let grown = signed_area(&rect).abs() - features[i].area_m2;
        if grown < COMPLETE_MIN_M2 || unseen_m2 < 0.5 * grown || !fits(&rect, features, &[i]) {
            continue;
        }
        features[i].area_m2 = signed_area(&rect).abs();
        features[i].polygon_2d = rect;
        features[i].completed_m2 = unseen_m2;
    }
}

/// The host's temperature and its uncertainty: its background texels only (the features' are
/// subtracted, Algorithm 1), one texel clear of every feature's region (border texels mix both)
/// and outside every feature's outline (`in_outline`); the spread counts again for the
/// `unseen_share` of the surface.
fn host_temperature(
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

/// Analyses one surface: `frame` and `host` (its polygon in the frame), the cloud's points on it
/// (`idx` into the cloud's positions, temperatures and weights), whether the background may vary
/// linearly along v (walls).
pub fn analyse_surface(
    frame: &PlaneFrame,
    host: &[Point2<f64>],
    idx: &[usize],
    cloud: (&[Point3<f64>], &[f64], &[f64]),
    linear: bool,
    p: &SegmentParams,
) -> SurfaceAnalysis {
    let g = Grid::rasterise(frame, host, idx, cloud, p.texel_m);
    let (nx, ny) = (g.nx, g.ny);
    let cells: Vec<usize> = (0..nx * ny)
        .filter(|&c| g.inside[c] && g.observed(c))
        .collect();
    let n_inside = g.inside.iter().filter(|x| **x).count();
    let observed_fraction = cells.len() as f64 / n_inside.max(1) as f64;
    let mut out = SurfaceAnalysis {
        temperature_k: None,
        temperature_std_k: 0.0,
        observed_fraction,
        features: Vec::new(),
        dropped: Vec::new(),
        background: Background::default(),
        raster: None,
    };
    if cells.len() < 3 {
        return out;
    }
    let samples: Vec<(f64, f64)> = cells
        .iter()
        .map(|&c| (g.centre_of(c).y, g.kelvin(c)))
        .collect();
    let bg = robust_background(&samples, linear);
    out.background = bg;
    let resid = |c: usize| g.kelvin(c) - bg.a - bg.b * g.centre_of(c).y;
    let mut in_feature = vec![false; nx * ny];
    let near_edge = g.near_edge(EDGE_STRIP_M);
    let near_edge_wide = g.near_edge(EDGE_BLUR_M);
    let mut regions: Vec<Region> = Vec::new();
    for sign in [1.0f64, -1.0] {
        let mask = threshold_mask(&g, &resid, sign, p.feature_threshold_k);
        for region in components(&g, &mask) {
            let Some(comp) = hysteresis(&g, &region, &resid, sign) else {
                continue;
            };
            let area = comp.len() as f64 * g.t * g.t;
            if area < p.feature_min_area_m2 {
                continue;
            }
            if let Some(why) = edge_blur(&comp, area, &resid, (&near_edge, &near_edge_wide)) {
                out.dropped.push(why);
                continue;
            }
            let (core, plateau) = half_contrast_core(&g, &comp, &resid, sign);
            let step = plateau.map(|plateau| Step {
                background: &bg,
                sign,
                plateau,
            });
            let poly = match outline(&g, &comp, &core, host, area, step.as_ref()) {
                Ok(poly) => poly,
                Err(why) => {
                    if !why.is_empty() {
                        out.dropped.push(why);
                    }
                    continue;
                }
            };
            if out
                .features
                .iter()
                .any(|f| polygons_overlap(&f.polygon_2d, &poly, 1e-3))
            {
                out.dropped
                    .push(format!("a {area:.2} m² region overlaps another feature"));
                continue;
            }
            // A region whose texels only here and there pass the threshold, grown over texels
            // that do not, is the background's own unevenness: a feature differs from its host
            // by the threshold on average (a 30 s walk of the panel room found a 0.7 m² patch
            // of floor 0.24 K cold, and one of wall 0.17 K cold, where the truth has neither).
            let found = feature(&g, &comp, poly, &resid, &bg, &near_edge);
            if sign * found.contrast_k < p.feature_threshold_k {
                out.dropped.push(format!(
                    "a {area:.2} m² region {:+.2} K from the background on average, under the {} K threshold: the background's own unevenness",
                    found.contrast_k, p.feature_threshold_k
                ));
                continue;
            }
            for &c in &comp {
                in_feature[c] = true;
            }
            out.features.push(found);
            regions.push(Region { comp, core, sign });
        }
    }
    complete_features(
        &g,
        &mut out.features,
        &mut regions,
        host,
        &resid,
        &bg,
        &near_edge,
    );
    background_of(
        &g,
        &cells,
        &in_feature,
        &bg,
        frame,
        p,
        observed_fraction,
        &mut out,
    );
    out
}

/// The surface's background once its features are known: the raster (without the features'
/// outlines) and the host's temperature and uncertainty, into `out`.
#[allow(clippy::too_many_arguments)]
fn background_of(
    g: &Grid,
    cells: &[usize],
    in_feature: &[bool],
    bg: &Background,
    frame: &PlaneFrame,
    p: &SegmentParams,
    observed_fraction: f64,
    out: &mut SurfaceAnalysis,
) {
    // The texels inside a feature's outline.
    let in_outline: Vec<bool> = (0..g.nx * g.ny)
        .map(|c| {
            g.inside[c] && {
                let centre = g.centre_of(c);
                out.features
                    .iter()
                    .any(|f| point_in_polygon_fast(&centre, &f.polygon_2d))
            }
        })
        .collect();
    if p.raster_m > 0.0 {
        // The raster leaves out what the features' outlines cover: a feature's texels outside
        // its outline (a window whose upper corner was never seen, outlined as the rectangle
        // seen in full) radiate from the raster at their own temperature.
        let outlines: Vec<&[Point2<f64>]> = out
            .features
            .iter()
            .map(|f| f.polygon_2d.as_slice())
            .collect();
        out.raster = background_raster(g, &in_outline, &outlines, bg, frame, p.raster_m);
    }
    // With a raster, what was not seen is in its unseen patches (each bounded by what was seen
    // around it); without one, the host's temperature carries it.
    let unseen_share = if out.raster.is_some() {
        0.0
    } else {
        1.0 - observed_fraction
    };
    if let Some((t, std)) = host_temperature(g, cells, in_feature, &in_outline, unseen_share) {
        out.temperature_k = Some(t);
        out.temperature_std_k = std;
    }
}

/// The background's temperature raster at about `raster_m` (a whole number of analysis texels):
/// each raster texel the radiant average of its observed background texels, leaving out the
/// features' outlines (`in_feature`) and a 10 cm margin around them and along the surface's edges (where the thermal camera's blur
/// spreads a feature's or the next surface's temperature); a raster texel with less than a quarter of its texels so observed is filled
/// as the background model plus its neighbours' departure from it (repeatedly, then the model
/// alone where nothing is near) and listed as filled.
fn background_raster(
    g: &Grid,
    in_feature: &[bool],
    outlines: &[&[Point2<f64>]],
    bg: &Background,
    frame: &PlaneFrame,
    raster_m: f64,
) -> Option<RasterFile> {
    let k = ((raster_m / g.t).round() as usize).max(1);
    let (cols, rows) = (g.nx.div_ceil(k), g.ny.div_ceil(k));
    // Features and the surface's own edges (where a corner mixes in the next surface's
    // temperature), grown by the margin.
    let margin = (0.10 / g.t).ceil() as usize;
    let mut near_feature = in_feature.to_vec();
    let edge = |c: usize| {
        let (i, j) = (c % g.nx, c / g.nx);
        !g.inside[c] || i == 0 || j == 0 || i + 1 == g.nx || j + 1 == g.ny
    };
    for c in (0..in_feature.len()).filter(|&c| in_feature[c] || edge(c)) {
        let (i, j) = (c % g.nx, c / g.nx);
        for jj in j.saturating_sub(margin)..(j + margin + 1).min(g.ny) {
            for ii in i.saturating_sub(margin)..(i + margin + 1).min(g.nx) {
                near_feature[jj * g.nx + ii] = true;
            }
        }
    }
    let mut value: Vec<Option<f64>> = vec![None; cols * rows];
    let mut on_surface = vec![false; cols * rows];
    for j in 0..g.ny {
        for i in 0..g.nx {
            let c = j * g.nx + i;
            if g.inside[c] {
                on_surface[(j / k) * cols + i / k] = true;
            }
        }
    }
    for r in 0..cols * rows {
        if !on_surface[r] {
            continue;
        }
        let (col, row) = (r % cols, r / cols);
        let mut avg = RadiantAverage::new();
        let mut inside = 0usize;
        for j in row * k..((row + 1) * k).min(g.ny) {
            for i in col * k..((col + 1) * k).min(g.nx) {
                let c = j * g.nx + i;
                if !g.inside[c] {
                    continue;
                }
                inside += 1;
                if g.observed(c) && !near_feature[c] {
                    avg.add(Temperature::from_kelvin(g.kelvin(c)), 1.0);
                }
            }
        }
        if avg.count() * 4 >= inside.max(1) as u64
            && let Some(t) = avg.mean()
        {
            value[r] = Some(t.kelvin());
        }
    }
    if value.iter().all(Option::is_none) {
        return None;
    }
    // What was not seen is filled as the background model plus its neighbours' departure from
    // it: on a stratified wall a hole follows the gradient, not the row it was entered from (a
    // 20 s radiant-ceiling walk's 2.5 m² wall patch, filled from its lower edge, differed from
    // the gradient by enough to state 0.30 K at a node where the error was 0.15 K).
    let model = |r: usize| bg.a + bg.b * (g.lo.y + ((r / cols) as f64 + 0.5) * k as f64 * g.t);
    let filled = fill_on_model(&mut value, &on_surface, (cols, rows), model);
    let reaches: Vec<Reach> = outlines.iter().map(|o| Reach::of(g, o, bg)).collect();
    let unseen = unseen_patches(
        g,
        (in_feature, &near_feature),
        &reaches,
        bg,
        k,
        (cols, rows),
        &on_surface,
    );
    let o = frame.to_3d(&g.lo);
    Some(RasterFile {
        texel_m: k as f64 * g.t,
        origin: [o.x, o.y, o.z],
        u: [frame.u.x, frame.u.y, frame.u.z],
        v: [frame.v.x, frame.v.y, frame.v.z],
        cols,
        rows,
        temperature_c: value
            .iter()
            .map(|t| t.map(|t| t - ZERO_CELSIUS_K))
            .collect(),
        filled,
        unseen,
    })
}

/// Where a feature may continue into what the scan did not see: the box of its outline, open
/// (unbounded) on each side beyond which the scan saw no background. A window or a radiator is a
/// rectangle: seen with wall above it, it does not continue upwards, whatever lies beside it.
#[derive(Clone, Copy, Debug)]
struct Reach {
    /// The outline's box.
    lo: Point2<f64>,
    hi: Point2<f64>,
    /// The box the feature may fill: `lo`/`hi`, infinite on its open sides.
    may_lo: Point2<f64>,
    may_hi: Point2<f64>,
    /// The temperatures seen inside its outline, as departures from the background (K).
    range_k: Option<(f64, f64)>,
}

/// How far beyond a feature's side the scan must have seen background for the side to be its
/// end (m): one raster texel.
const REACH_PROBE_M: f64 = 0.15;

impl Reach {
    /// The reach of the feature outlined by `poly` on the surface of `g` with background `bg`.
    fn of(g: &Grid, poly: &[Point2<f64>], bg: &Background) -> Self {
        let (mut lo, mut hi) = (
            Point2::new(f64::INFINITY, f64::INFINITY),
            Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for q in poly {
            lo = lo.inf(q);
            hi = hi.sup(q);
        }
        // A side is open when the strip just beyond it, on the surface, was mostly not seen; a
        // side on the surface's edge is closed.
        let open = |within: &dyn Fn(&Point2<f64>) -> bool| {
            let (mut n, mut seen) = (0usize, 0usize);
            for c in (0..g.nx * g.ny).filter(|&c| g.inside[c]) {
                if within(&g.centre_of(c)) {
                    n += 1;
                    seen += usize::from(g.observed(c));
                }
            }
            n > 0 && seen * 2 < n
        };
        let w = REACH_PROBE_M;
        let along_y = |q: &Point2<f64>| (lo.y..=hi.y).contains(&q.y);
        let along_x = |q: &Point2<f64>| (lo.x..=hi.x).contains(&q.x);
        let (mut may_lo, mut may_hi) = (lo, hi);
        if open(&|q| along_y(q) && q.x < lo.x && q.x >= lo.x - w) {
            may_lo.x = f64::NEG_INFINITY;
        }
        if open(&|q| along_y(q) && q.x > hi.x && q.x <= hi.x + w) {
            may_hi.x = f64::INFINITY;
        }
        if open(&|q| along_x(q) && q.y < lo.y && q.y >= lo.y - w) {
            may_lo.y = f64::NEG_INFINITY;
        }
        if open(&|q| along_x(q) && q.y > hi.y && q.y <= hi.y + w) {
            may_hi.y = f64::INFINITY;
        }
        let (mut t_lo, mut t_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for c in (0..g.nx * g.ny).filter(|&c| g.inside[c] && g.observed(c)) {
            let q = g.centre_of(c);
            if q.x >= lo.x
                && q.x <= hi.x
                && q.y >= lo.y
                && q.y <= hi.y
                && point_in_polygon_fast(&q, poly)
            {
                let t = g.kelvin(c) - bg.a - bg.b * q.y;
                t_lo = t_lo.min(t);
                t_hi = t_hi.max(t);
            }
        }
        Self {
            lo,
            hi,
            may_lo,
            may_hi,
            range_k: (t_lo <= t_hi).then_some((t_lo, t_hi)),
        }
    }

    /// The distance from `q` to the outline's box (m; the larger of the two axes').
    fn distance(&self, q: &Point2<f64>) -> f64 {
        let dx = (self.lo.x - q.x).max(q.x - self.hi.x).max(0.0);
        let dy = (self.lo.y - q.y).max(q.y - self.hi.y).max(0.0);
        dx.max(dy)
    }

    /// Whether the feature may cover `q` (within `margin` of its reach).
    fn may_hold(&self, q: &Point2<f64>, margin: f64) -> bool {
        q.x >= self.may_lo.x - margin
            && q.x <= self.may_hi.x + margin
            && q.y >= self.may_lo.y - margin
            && q.y <= self.may_hi.y + margin
    }
}

/// The 8-connected patch of `unseen` raster texels (`cols` × `rows`) holding `start`, marked in
/// `done`, in index order.
fn grow_patch(
    start: usize,
    unseen: &[bool],
    done: &mut [bool],
    (cols, rows): (usize, usize),
) -> Vec<usize> {
    let mut texels = vec![start];
    done[start] = true;
    let mut next = 0;
    while next < texels.len() {
        let r = texels[next];
        next += 1;
        let (col, row) = (r % cols, r / cols);
        for rr in row.saturating_sub(1)..(row + 2).min(rows) {
            for cc in col.saturating_sub(1)..(col + 2).min(cols) {
                let q = rr * cols + cc;
                if unseen[q] && !done[q] {
                    done[q] = true;
                    texels.push(q);
                }
            }
        }
    }
    texels.sort_unstable();
    texels
}

/// The analysis texels of raster texel `r` (`k` × `k` of them, `cols` raster texels per row).
fn raster_cells(g: &Grid, k: usize, cols: usize, r: usize) -> impl Iterator<Item = usize> + '_ {
    let (col, row) = (r % cols, r / cols);
    (row * k..((row + 1) * k).min(g.ny))
        .flat_map(move |j| (col * k..((col + 1) * k).min(g.nx)).map(move |i| j * g.nx + i))
}

/// Whether the scan never saw a raster texel of analysis texels `cells`: under a quarter of
/// those on the surface observed, and mostly outside every feature's outline (`in_feature`).
fn never_seen(g: &Grid, cells: impl Iterator<Item = usize>, in_feature: &[bool]) -> bool {
    let (mut inside, mut seen, mut feature) = (0usize, 0usize, 0usize);
    for c in cells.filter(|&c| g.inside[c]) {
        inside += 1;
        seen += usize::from(g.observed(c));
        feature += usize::from(in_feature[c]);
    }
    inside > 0 && seen * 4 < inside && feature * 2 < inside
}

/// The box, in analysis texels `[i0, j0, i1, j1)`, of raster texels `texels` (`k` × `k` analysis
/// texels each, `cols` per row), grown by `ring` analysis texels and clipped to the grid.
fn patch_box(g: &Grid, texels: &[usize], k: usize, cols: usize, ring: usize) -> [usize; 4] {
    let (mut i0, mut j0, mut i1, mut j1) = (usize::MAX, usize::MAX, 0, 0);
    for &r in texels {
        let (col, row) = (r % cols, r / cols);
        i0 = i0.min(col * k);
        j0 = j0.min(row * k);
        i1 = i1.max(((col + 1) * k).min(g.nx));
        j1 = j1.max(((row + 1) * k).min(g.ny));
    }
    [
        i0.saturating_sub(ring),
        j0.saturating_sub(ring),
        (i1 + ring).min(g.nx),
        (j1 + ring).min(g.ny),
    ]
}

/// Fills the raster texels on the surface (`on_surface`, `cols` × `rows`) that have no value as
/// `model` (the background model at a texel) plus the departure from it of their neighbours,
/// spread in from the texels that have one; where nothing reaches, the model alone. Returns the
/// texels filled.
fn fill_on_model(
    value: &mut [Option<f64>],
    on_surface: &[bool],
    (cols, rows): (usize, usize),
    model: impl Fn(usize) -> f64,
) -> Vec<usize> {
    let mut departure: Vec<Option<f64>> = value
        .iter()
        .enumerate()
        .map(|(r, t)| t.map(|t| t - model(r)))
        .collect();
    let mut filled = Vec::new();
    loop {
        let mut next = departure.clone();
        let mut changed = false;
        for r in (0..cols * rows).filter(|&r| on_surface[r] && departure[r].is_none()) {
            let (col, row) = (r % cols, r / cols);
            let (mut n, mut sum) = (0usize, 0.0);
            for rr in row.saturating_sub(1)..(row + 2).min(rows) {
                for cc in col.saturating_sub(1)..(col + 2).min(cols) {
                    if let Some(d) = departure[rr * cols + cc] {
                        n += 1;
                        sum += d;
                    }
                }
            }
            if n > 0 {
                next[r] = Some(sum / n as f64);
                filled.push(r);
                changed = true;
            }
        }
        departure = next;
        if !changed {
            break;
        }
    }
    for (r, t) in value.iter_mut().enumerate() {
        if on_surface[r] && t.is_none() {
            *t = Some(model(r) + departure[r].unwrap_or(0.0));
            if departure[r].is_none() {
                filled.push(r);
            }
        }
    }
    filled.sort_unstable();
    filled
}

/// How far around an unseen patch the seen texels bound its temperature (m).
const UNSEEN_SURROUNDINGS_M: f64 = 0.5;

/// The raster's texels (`k` × `k` analysis texels each, `cols` × `rows`) that the scan never saw
/// (under a quarter of their analysis texels observed, and mostly outside every feature's outline
/// `in_feature`, where the feature's temperature applies), grouped into 8-connected patches, each
/// with the range of the temperatures seen within [`UNSEEN_SURROUNDINGS_M`] of it, else anywhere
/// on the surface, as departures from the background model `bg` placed on the background over
/// the patch (a stratified wall's gradient is known; a 20 s radiant-ceiling walk's unseen wall
/// patches took its whole 2 K span as possible). A feature's temperatures bound a patch only when the patch touches its outline
/// (a window or a panel may continue into what was not seen); a feature whose edge was seen, with
/// background beyond it, ends there, and its cells and their blur (`near_feature`) are left out:
/// a 20 s office walk's 1.3 m² unseen patch of wall 0.4 m from the window's seen edge took the
/// window's 11.4 °C as possible and stated ±1.45 K at the node beside it, where the error was
/// 0.14 K. A touching patch is split by the features that may cover each of its texels (their
/// [`Reach`]): each part is bounded by the background seen around the patch and by those
/// features' own temperatures.
fn unseen_patches(
    g: &Grid,
    (in_feature, near_feature): (&[bool], &[bool]),
    reaches: &[Reach],
    bg: &Background,
    k: usize,
    (cols, rows): (usize, usize),
    on_surface: &[bool],
) -> Vec<UnseenPatch> {
    let cells_of = |r: usize| raster_cells(g, k, cols, r);
    let unseen: Vec<bool> = (0..cols * rows)
        .map(|r| on_surface[r] && never_seen(g, cells_of(r), in_feature))
        .collect();
    // Temperatures seen are taken relative to the surface's background model (a wall's vertical
    // gradient), and the range is placed on the background over the patch: a patch on a
    // stratified wall follows the gradient as its neighbours do, and what is uncertain is how
    // far it strays from it.
    let bg_at = |c: usize| bg.a + bg.b * g.centre_of(c).y;
    let observed_range = |cells: &mut dyn Iterator<Item = usize>, features: bool| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for c in cells.filter(|&c| g.inside[c] && g.observed(c) && (features || !near_feature[c])) {
            let t = g.kelvin(c) - bg_at(c);
            lo = lo.min(t);
            hi = hi.max(t);
        }
        (lo <= hi).then_some((lo, hi))
    };
    let ring = (UNSEEN_SURROUNDINGS_M / g.t).ceil() as usize;
    let mut done = vec![false; cols * rows];
    let mut out = Vec::new();
    for start in 0..cols * rows {
        if !unseen[start] || done[start] {
            continue;
        }
        let texels = grow_patch(start, &unseen, &mut done, (cols, rows));
        let [i0, j0, i1, j1] = patch_box(g, &texels, k, cols, ring);
        // Does the patch touch a feature's outline (one within a raster texel of an unseen
        // cell of it: the patch's texels start where a raster texel is mostly unseen)?
        let reach = k + 1;
        let unseen_cells = || {
            texels
                .iter()
                .flat_map(|&r| cells_of(r))
                .filter(|&c| !g.observed(c))
        };
        let touches = unseen_cells().any(|c| {
            let (i, j) = (c % g.nx, c / g.nx);
            (j.saturating_sub(reach)..(j + reach + 1).min(g.ny)).any(|jj| {
                (i.saturating_sub(reach)..(i + reach + 1).min(g.nx))
                    .any(|ii| in_feature[jj * g.nx + ii])
            })
        });
        // Which features it touches, and where in it they may continue: within each one's
        // reach (its box, open on the sides beyond which no background was seen).
        let near_m = reach as f64 * g.t;
        let touching: Vec<&Reach> = if touches {
            reaches
                .iter()
                .filter(|f| unseen_cells().any(|c| f.distance(&g.centre_of(c)) <= near_m))
                .collect()
        } else {
            Vec::new()
        };
        let half_texel = 0.5 * k as f64 * g.t;
        let raster_centre = |r: usize| {
            Point2::new(
                g.lo.x + ((r % cols) as f64 + 0.5) * k as f64 * g.t,
                g.lo.y + ((r / cols) as f64 + 0.5) * k as f64 * g.t,
            )
        };
        // The patch's texels grouped by the touching features that may cover them: each group
        // is bounded by the background seen around the patch and by those features' own
        // temperatures (a texel beside a window but above a radiator may be the window, not
        // the radiator).
        let mut groups: std::collections::BTreeMap<Vec<usize>, Vec<usize>> =
            std::collections::BTreeMap::new();
        for &r in &texels {
            let q = raster_centre(r);
            let by = (0..touching.len()).filter(|&i| touching[i].may_hold(&q, half_texel));
            groups.entry(by.collect()).or_default().push(r);
        }
        let around = |features: bool| {
            observed_range(
                &mut (j0..j1).flat_map(|j| (i0..i1).map(move |i| j * g.nx + i)),
                features,
            )
        };
        let background = around(false)
            .or_else(|| around(true))
            .or_else(|| observed_range(&mut (0..g.nx * g.ny), true));
        for (by, part) in groups {
            let range = by
                .iter()
                .filter_map(|&i| touching[i].range_k)
                .chain(background)
                .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)));
            // The background over the part's own cells.
            let (n, sum) = part
                .iter()
                .flat_map(|&r| cells_of(r))
                .filter(|&c| g.inside[c])
                .fold((0usize, 0.0), |(n, s), c| (n + 1, s + bg_at(c)));
            let base = if n > 0 { sum / n as f64 } else { bg.a };
            if let Some((lo, hi)) = range {
                out.push(UnseenPatch {
                    texels: part,
                    range_c: [base + lo - ZERO_CELSIUS_K, base + hi - ZERO_CELSIUS_K],
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A blurred step at 0.913 m, sampled every centimetre with noise: the texel grid says 0.90 (a
    /// 3 cm texel's boundary); the band's mean fill puts the side within 3 mm, on either side.
    #[test]
    fn a_feature_side_is_placed_between_texel_boundaries() {
        let (edge, blur) = (0.913, 0.015);
        let fill = |a: f64| 0.5 * (1.0 + ((a - edge) / blur).tanh());
        let mut rising = Vec::new();
        let mut falling = Vec::new();
        for i in 0..200 {
            for j in 0..20 {
                let (a, b) = (0.5 + i as f64 * 0.005, j as f64 * 0.05);
                let noise = 0.05 * (((i * 7 + j * 13) % 11) as f64 / 11.0 - 0.5);
                rising.push((a, b, (fill(a) + noise).clamp(0.0, 1.0)));
                falling.push((-a, b, (fill(a) + noise).clamp(0.0, 1.0)));
            }
        }
        let r = refine_side(&rising, 0.90, (0.0, 1.0), true, 0.03);
        assert!((r - edge).abs() < 0.003, "{r}");
        let f = refine_side(&falling, -0.90, (0.0, 1.0), false, 0.03);
        assert!((f + edge).abs() < 0.003, "{f}");
        // Too few points in the band: the texel's side stays.
        assert_eq!(
            refine_side(&rising[..5], 0.90, (0.0, 1.0), true, 0.03),
            0.90
        );
    }

    /// A `w` × `h` m wall in the plane y = 0 from the origin: its frame and outline.
    fn wall_in_y0(w: f64, h: f64) -> (PlaneFrame, Vec<Point2<f64>>) {
        use mrtmap_geometry::nalgebra::{Unit, Vector3};
        let frame = PlaneFrame::new(
            Point3::origin(),
            Unit::new_normalize(Vector3::y()),
            &Vector3::x(),
        );
        let host = [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]
            .iter()
            .map(|q| frame.to_2d(&Point3::new(q[0], 0.0, q[1])))
            .collect();
        (frame, host)
    }

    /// A 0.9 × 0.6 m patch 0.22 K warm with a 0.21 m spot 0.35 K warm in it: the spot passes
    /// the 0.3 K threshold and the region grows over the patch, but the patch is, on average,
    /// under it: no feature (a 30 s walk of the panel room found such patches on its floor and a
    /// wall). A patch 0.35 K warm throughout is one.
    #[test]
    fn a_region_under_the_threshold_on_average_is_no_feature() {
        let mut extra = patch(1.5, 2.4, 1.0, 1.6, 17.82);
        // Where the two overlap, a texel reads their mean: 17.95 °C.
        extra.extend(patch(1.8, 2.01, 1.2, 1.41, 18.08));
        let a = wall_with(&extra);
        assert!(a.features.is_empty(), "{:?}", a.features);
        assert!(
            a.dropped.iter().any(|d| d.contains("on average")),
            "{:?}",
            a.dropped
        );
        let b = wall_with(&patch(1.5, 2.4, 1.0, 1.6, 17.95));
        assert_eq!(b.features.len(), 1, "{:?}", b.dropped);
        assert!((b.features[0].contrast_k - 0.35).abs() < 0.05);
    }

    /// A 4 × 2.5 m wall at 17.6 °C in the plane y = 0, each point seen 40 times, and `extra`
    /// points (x, z, °C, observations) on it.
    fn wall_with(extra: &[(f64, f64, f64, f64)]) -> SurfaceAnalysis {
        let (mut pos, mut temp, mut w) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..134 {
            for j in 0..84 {
                pos.push(Point3::new(
                    (i as f64 + 0.5) * 0.03,
                    0.0,
                    (j as f64 + 0.5) * 0.03,
                ));
                temp.push(ZERO_CELSIUS_K + 17.6);
                w.push(40.0);
            }
        }
        for &(x, z, c, o) in extra {
            pos.push(Point3::new(x, 0.0, z));
            temp.push(ZERO_CELSIUS_K + c);
            w.push(o);
        }
        let (frame, host) = wall_in_y0(4.0, 2.5);
        let idx: Vec<usize> = (0..pos.len()).collect();
        analyse_surface(
            &frame,
            &host,
            &idx,
            (&pos, &temp, &w),
            true,
            &SegmentParams::default(),
        )
    }

    /// As many points seen once each at 21 °C as the wall's own over a 0.6 m patch (a far
    /// surface's noise, a corner's blur): counted as points they make a +1.7 K feature; weighted
    /// by their observations the patch reads +0.08 K and is no feature.
    #[test]
    fn a_texel_averages_its_measurements_not_its_points() {
        let patch: Vec<(f64, f64, f64, f64)> = (0..20)
            .flat_map(|i| (0..20).map(move |j| (i, j)))
            .map(|(i, j)| (1.5 + (i as f64 + 0.5) * 0.03, 1.0 + (j as f64 + 0.5) * 0.03))
            .map(|(x, z)| (x, z, 21.0, 1.0))
            .collect();
        assert!(wall_with(&patch).features.is_empty(), "weighted");
        let counted: Vec<_> = patch.iter().map(|&(x, z, c, _)| (x, z, c, 40.0)).collect();
        let a = wall_with(&counted);
        assert_eq!(a.features.len(), 1, "counted: {:?}", a.dropped);
        assert!(
            (a.features[0].contrast_k - 1.7).abs() < 0.1,
            "{}",
            a.features[0].contrast_k
        );
    }

    /// Points (x, z, °C) on every 3 cm texel of `x0..x1` × `z0..z1` of [`wall_with`]'s wall,
    /// each seen 4000 times (so the texel reads their temperature).
    fn patch(x0: f64, x1: f64, z0: f64, z1: f64, c: f64) -> Vec<(f64, f64, f64, f64)> {
        let mut out = Vec::new();
        for i in 0..134 {
            for j in 0..84 {
                let (x, z) = ((i as f64 + 0.5) * 0.03, (j as f64 + 0.5) * 0.03);
                if (x0..x1).contains(&x) && (z0..z1).contains(&z) {
                    out.push((x, z, c, 4000.0));
                }
            }
        }
        out
    }

    /// A feature of [`wall_with`]'s wall: its extent along x and z.
    fn extent(f: &FoundFeature) -> (f64, f64, f64, f64) {
        let frame = wall_in_y0(4.0, 2.5).0;
        f.polygon_2d.iter().map(|q| frame.to_3d(q)).fold(
            (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ),
            |(a, b, c, d), q| (a.min(q.x), b.max(q.x), c.min(q.z), d.max(q.z)),
        )
    }

    /// A +0.4 K strip along the floor (z 0…0.12) under a 45 °C radiator (z 0.15…0.75), a row
    /// between them +0.25 K (under the 0.3 K threshold, above the strip's half contrast): grown
    /// from its own texels, the strip stops at the radiator (on the L-shaped room's walk 4 it grew
    /// into it and, found first, took its place with an outline reaching the floor).
    #[test]
    fn a_faint_strip_does_not_grow_into_a_hot_feature() {
        let mut extra = patch(0.0, 4.0, 0.0, 0.12, 18.0);
        extra.extend(patch(0.0, 4.0, 0.12, 0.15, 17.85));
        extra.extend(patch(1.11, 2.91, 0.15, 0.75, 45.0));
        let (frame, host) = wall_in_y0(4.0, 2.5);
        let pos: Vec<Point3<f64>> = extra.iter().map(|e| Point3::new(e.0, 0.0, e.1)).collect();
        let temp: Vec<f64> = extra.iter().map(|e| ZERO_CELSIUS_K + e.2).collect();
        let w = vec![1.0; pos.len()];
        let idx: Vec<usize> = (0..pos.len()).collect();
        let g = Grid::rasterise(&frame, &host, &idx, (&pos, &temp, &w), 0.03);
        let resid = |c: usize| g.kelvin(c) - (ZERO_CELSIUS_K + 17.6);
        let z_of = |c: usize| frame.to_3d(&g.centre_of(c)).z;
        let strip: Vec<usize> = (0..g.nx * g.ny)
            .filter(|&c| g.observed(c) && z_of(c) < 0.12)
            .collect();
        let grown = hysteresis(&g, &strip, &resid, 1.0).expect("observed");
        assert!(
            grown.len() >= strip.len(),
            "{} of {}",
            grown.len(),
            strip.len()
        );
        let hot = grown.iter().filter(|&&c| resid(c) > 10.0).count();
        assert_eq!(hot, 0, "the strip grew into {hot} radiator texels");
    }

    /// The L-shaped room's cold exterior wall: a 30 cm column at its corner and a 12 cm row under
    /// the ceiling, both +0.6 K (the next surfaces blurred in), are no feature; a +0.6 K painting
    /// in the middle is.
    #[test]
    fn a_faint_blur_along_the_edges_is_no_feature_but_a_faint_painting_is() {
        let mut extra = patch(3.7, 4.0, 0.0, 2.5, 18.2);
        extra.extend(patch(0.0, 4.0, 2.38, 2.5, 18.2));
        let a = wall_with(&extra);
        assert!(a.features.is_empty(), "{:?}", a.features);
        assert!(
            a.dropped.iter().any(|d| d.contains("blurred in")),
            "{:?}",
            a.dropped
        );
        extra.extend(patch(1.5, 2.4, 1.0, 1.6, 18.2));
        let b = wall_with(&extra);
        assert_eq!(b.features.len(), 1, "{:?}", b.dropped);
        let (x0, x1, _, _) = extent(&b.features[0]);
        assert!(
            (x0 - 1.5).abs() < 0.04 && (x1 - 2.4).abs() < 0.04,
            "{x0} {x1}"
        );
    }

    /// The host's last texel column is 3 mm wide (the wall 4.053 m long, 15 cm texels): the
    /// column before it, reaching within 3 mm of the edge, is near the edge too.
    #[test]
    fn a_texel_before_a_narrow_last_one_is_near_the_edge() {
        let (frame, host) = wall_in_y0(4.053, 2.5);
        let g = Grid::rasterise(&frame, &host, &[], (&[], &[], &[]), 0.15);
        assert_eq!(g.nx, 28);
        let near = g.near_edge(EDGE_STRIP_M);
        let row = g.ny / 2;
        let near_in_row: Vec<usize> = (0..g.nx).filter(|&i| near[row * g.nx + i]).collect();
        assert_eq!(near_in_row, vec![0, 26, 27]);
    }

    /// A 10 × 4 m wall at 19.8 °C with a 9 °C window 8 × 2.4 m (x 1…9, z 0.8…3.2) whose upper
    /// end the walk never saw (as on a 10 × 7 m hall's walk 2): the feature's outline is the
    /// rectangle seen in full (x 1…7.5), and wherever else the window was seen the scene radiates
    /// cold from the raster (it radiated the wall's 19.8 °C when the raster left out the whole
    /// cold region).
    #[test]
    fn a_window_seen_in_part_radiates_cold_wherever_it_was_seen() {
        use mrtmap_geometry::nalgebra::Vector3;
        let unseen = |x: f64, z: f64| {
            (x > 7.5 && z > 1.8)
                || (x > 8.0 && z > 1.4)
                || ((6.0..7.5).contains(&x) && (1.4..1.9).contains(&z))
        };
        let window = |x: f64, z: f64| (1.0..9.0).contains(&x) && (0.8..3.2).contains(&z);
        let (mut pos, mut temp) = (Vec::new(), Vec::new());
        for i in 0..334 {
            for j in 0..134 {
                let (x, z) = ((i as f64 + 0.5) * 0.03, (j as f64 + 0.5) * 0.03);
                if unseen(x, z) {
                    continue;
                }
                pos.push(Point3::new(x, 0.0, z));
                temp.push(ZERO_CELSIUS_K + if window(x, z) { 9.0 } else { 19.8 });
            }
        }
        let (frame, host) = wall_in_y0(10.0, 4.0);
        let idx: Vec<usize> = (0..pos.len()).collect();
        let ones = vec![1.0; pos.len()];
        let a = analyse_surface(
            &frame,
            &host,
            &idx,
            (&pos, &temp, &ones),
            true,
            &SegmentParams::default(),
        );
        let raster = a.raster.as_ref().expect("a raster");
        // Every point seen on the window, 20 cm or more inside its edges and its unseen part.
        for (q, t) in pos.iter().zip(&temp) {
            let inner = window(q.x - 0.2, q.z - 0.2) && window(q.x + 0.2, q.z + 0.2);
            let clear = [
                (-0.2, -0.2),
                (0.2, -0.2),
                (-0.2, 0.2),
                (0.2, 0.2),
                (0.0, 0.2),
                (0.2, 0.0),
            ]
            .iter()
            .all(|(dx, dz)| !unseen(q.x + dx, q.z + dz));
            if *t > ZERO_CELSIUS_K + 10.0 || !inner || !clear {
                continue;
            }
            let q2 = frame.to_2d(q);
            let radiates = match a
                .features
                .iter()
                .find(|f| point_in_polygon_fast(&q2, &f.polygon_2d))
            {
                Some(f) => f.temperature_k,
                None => {
                    let o = Point3::from(raster.origin);
                    let d = q - o;
                    let (u, v) = (Vector3::from(raster.u), Vector3::from(raster.v));
                    let (c, r) = (
                        (d.dot(&u) / raster.texel_m) as usize,
                        (d.dot(&v) / raster.texel_m) as usize,
                    );
                    ZERO_CELSIUS_K + raster.temperature_c[r * raster.cols + c].expect("filled")
                }
            };
            assert!(
                radiates < ZERO_CELSIUS_K + 12.0,
                "at ({:.2}, {:.2}) {:.1} °C",
                q.x,
                q.z,
                radiates - ZERO_CELSIUS_K
            );
        }
    }

    /// A `w` × `h` m wall in the plane y = 0 sampled every centimetre: `seen(x, z)` is the
    /// temperature (°C) where the walk saw it, `None` where it did not; analysed with a linear
    /// background when `linear`.
    fn analyse_seen(
        w: f64,
        h: f64,
        seen: impl Fn(f64, f64) -> Option<f64>,
        linear: bool,
    ) -> (PlaneFrame, SurfaceAnalysis) {
        let (mut pos, mut temp) = (Vec::new(), Vec::new());
        for i in 0..(w * 100.0).round() as usize {
            for j in 0..(h * 100.0).round() as usize {
                let (x, z) = ((i as f64 + 0.5) * 0.01, (j as f64 + 0.5) * 0.01);
                if let Some(t) = seen(x, z) {
                    pos.push(Point3::new(x, 0.0, z));
                    temp.push(ZERO_CELSIUS_K + t);
                }
            }
        }
        let (frame, host) = wall_in_y0(w, h);
        let idx: Vec<usize> = (0..pos.len()).collect();
        let ones = vec![1.0; pos.len()];
        let a = analyse_surface(
            &frame,
            &host,
            &idx,
            (&pos, &temp, &ones),
            linear,
            &SegmentParams::default(),
        );
        (frame, a)
    }

    /// A 4 × 2.5 m wall at 18 °C with a 30 °C panel (x 1…2, z 1…2) and two holes the walk never
    /// saw: one 0.6 m square by the panel (from x `a_from`), one far from it (x 3.2…3.8,
    /// z 0.2…0.6). Each is an unseen patch covering its hole, bounded by what was seen around it:
    /// the second is pinned near 18 °C; the panel's 30 °C may continue into the first when the
    /// hole touches the panel (`a_from` 2.0), not when the panel's edge was seen with wall beyond
    /// it (`a_from` 2.3). The panel is seen, so none of its texels is unseen.
    #[test]
    fn unseen_holes_become_patches_bounded_by_their_surroundings() {
        for (a_from, touches) in [(2.0, true), (2.3, false)] {
            unseen_holes_by_a_panel(a_from, touches);
        }
    }

    fn unseen_holes_by_a_panel(a_from: f64, touches: bool) {
        let hole_a =
            |x: f64, z: f64| (a_from..a_from + 0.6).contains(&x) && (1.2..1.8).contains(&z);
        let hole_b = |x: f64, z: f64| (3.2..3.8).contains(&x) && (0.2..0.6).contains(&z);
        let panel = |x: f64, z: f64| (1.0..2.0).contains(&x) && (1.0..2.0).contains(&z);
        let (_, a) = analyse_seen(
            4.0,
            2.5,
            |x, z| {
                (!(hole_a(x, z) || hole_b(x, z))).then_some(if panel(x, z) { 30.0 } else { 18.0 })
            },
            false,
        );
        assert_eq!(a.features.len(), 1, "the panel: {:?}", a.dropped);
        let r = a.raster.as_ref().expect("a raster");
        assert_eq!(r.unseen.len(), 2, "{:?}", r.unseen);
        let centre = |t: usize| {
            use mrtmap_geometry::nalgebra::Vector3;
            let (c, row) = ((t % r.cols) as f64 + 0.5, (t / r.cols) as f64 + 0.5);
            let p = Point3::from(r.origin)
                + Vector3::from(r.u) * (c * r.texel_m)
                + Vector3::from(r.v) * (row * r.texel_m);
            (p.x, p.z)
        };
        for patch in &r.unseen {
            let (x, z) = centre(patch.texels[0]);
            let area = patch.texels.len() as f64 * r.texel_m * r.texel_m;
            let near_panel = x < 3.0;
            let hole_area = if near_panel { 0.36 } else { 0.24 };
            assert!(
                area >= 0.5 * hole_area && area <= 1.6 * hole_area,
                "patch at ({x:.2}, {z:.2}): {area:.2} m² for a {hole_area} m² hole"
            );
            for &t in &patch.texels {
                let (x, z) = centre(t);
                assert!(!panel(x, z), "a panel texel ({x:.2}, {z:.2}) is not unseen");
            }
            let [lo, hi] = patch.range_c;
            assert!((lo - 18.0).abs() < 0.3, "{:?}", patch.range_c);
            if near_panel && touches {
                assert!(
                    hi > 29.0,
                    "the panel's 30 °C is beside it: {:?}",
                    patch.range_c
                );
            } else {
                assert!(
                    hi < 18.5,
                    "only the wall's 18 °C around it: {:?}",
                    patch.range_c
                );
            }
        }
        // The host's temperature no longer carries the unseen share: the raster's patches do.
        assert!(a.temperature_std_k < 0.05, "{}", a.temperature_std_k);
    }

    /// A 4 × 2.5 m wall at 18 °C with a 45 °C radiator (x 1…2, z 0.15…0.75) whose right end
    /// the walk never saw, nor the wall beside and above it (x 2…3.6, z 0…2.3: 3.7 m²). The
    /// radiator may continue to the right, not upwards (wall was seen above it): only the band
    /// beside it may be 45 °C; the rest of the hole is bounded by the wall (the L-shaped room's
    /// 20 s walks let a 4–4.9 m² patch beside its radiator and window be anything from 9.5 to
    /// 45 °C, and stated ±6.3 K where the error was 1 K).
    #[test]
    fn an_unseen_patch_may_be_a_feature_only_where_the_feature_may_continue() {
        let hole = |x: f64, z: f64| (2.0..3.6).contains(&x) && z < 2.3;
        let radiator = |x: f64, z: f64| (1.0..2.0).contains(&x) && (0.15..0.75).contains(&z);
        let (_, a) = analyse_seen(
            4.0,
            2.5,
            |x, z| (!hole(x, z)).then_some(if radiator(x, z) { 45.0 } else { 18.0 }),
            false,
        );
        assert_eq!(a.features.len(), 1, "the radiator: {:?}", a.dropped);
        let r = a.raster.as_ref().expect("a raster");
        let z_of = |t: usize| r.origin[2] + r.v[2] * ((t / r.cols) as f64 + 0.5) * r.texel_m;
        let area = |p: &UnseenPatch| p.texels.len() as f64 * r.texel_m * r.texel_m;
        let hot: Vec<&UnseenPatch> = r.unseen.iter().filter(|p| p.range_c[1] > 44.0).collect();
        let plain: Vec<&UnseenPatch> = r.unseen.iter().filter(|p| p.range_c[1] < 18.5).collect();
        assert_eq!(hot.len() + plain.len(), r.unseen.len(), "{:?}", r.unseen);
        let hot_m2: f64 = hot.iter().map(|p| area(p)).sum();
        let plain_m2: f64 = plain.iter().map(|p| area(p)).sum();
        assert!((0.5..1.6).contains(&hot_m2), "{hot_m2:.2} m² may be 45 °C");
        assert!(plain_m2 > 2.2, "{plain_m2:.2} m² bounded by the wall");
        for p in &hot {
            for &t in &p.texels {
                let z = z_of(t);
                assert!((0.0..0.95).contains(&z), "a texel at z {z:.2} may be 45 °C");
            }
        }
    }

    /// A 5 × 4 m ceiling at 22.4 °C with a 2.0 × 1.1 m radiant panel at 38 °C (x 1.5…3.5,
    /// y 1.2…2.3), and a stripe across it (x 2.3…2.6) that the walk saw (`stripe_seen`, at the
    /// ceiling's temperature: two panels) or missed (one panel split by it).
    fn ceiling_with_stripe(stripe_seen: bool, corner_unseen: bool) -> SurfaceAnalysis {
        let panel = |x: f64, y: f64| (1.5..3.5).contains(&x) && (1.2..2.3).contains(&y);
        let stripe = |x: f64, y: f64| (2.3..2.6).contains(&x) && (0.9..2.6).contains(&y);
        let corner = |x: f64, y: f64| x > 3.0 && y > 1.9 && x < 4.0 && y < 2.8;
        let seen = |x: f64, y: f64| {
            let unseen = (stripe(x, y) && !stripe_seen) || (corner_unseen && corner(x, y));
            let hot = panel(x, y) && !stripe(x, y);
            (!unseen).then_some(if hot { 38.0 } else { 22.4 })
        };
        analyse_seen(5.0, 4.0, seen, false).1
    }

    /// Issue 37: a 30 s scan found a 2.0 × 1.1 m panel as two "recessed lights" of 0.99 and
    /// 0.69 m², the stripe between them unseen and radiating at the ceiling's temperature. What
    /// the walk saw implies one rectangle: it is completed (within 10 % of its area), and says how
    /// much was not seen; seen as ceiling, the stripe keeps two features.
    #[test]
    fn a_panel_split_by_a_stripe_the_walk_missed_is_completed() {
        let a = ceiling_with_stripe(false, false);
        assert_eq!(a.features.len(), 1, "{:?}", a.features);
        let f = &a.features[0];
        assert!((f.area_m2 - 2.2).abs() < 0.22, "{} m²", f.area_m2);
        assert!((f.temperature_k - ZERO_CELSIUS_K - 38.0).abs() < 0.2);
        // The stripe inside the panel is 0.3 × 1.1 m; the completed area is what lies outside
        // both parts' outlines, which reach a few centimetres into the stripe.
        assert!(
            f.completed_m2 > 0.2 && f.completed_m2 <= 0.33,
            "{}",
            f.completed_m2
        );
        let two = ceiling_with_stripe(true, false);
        assert_eq!(two.features.len(), 2, "{:?}", two.features);
        assert!(two.features.iter().all(|f| f.completed_m2 == 0.0));
    }

    /// A panel whose corner (0.5 × 0.4 m) the walk never saw takes the rectangle of what was seen;
    /// the stripe and the corner together too.
    #[test]
    fn a_feature_whose_corner_was_never_seen_takes_its_rectangle() {
        let a = ceiling_with_stripe(true, true);
        let big = a
            .features
            .iter()
            .find(|f| f.polygon_2d.iter().any(|q| q.x.abs() > 3.3))
            .expect("the panel's right part");
        // x 2.6…3.5, y 1.2…2.3: 0.99 m², of which x 3.0…3.5, y 1.9…2.3 (0.2 m²) unseen.
        assert!((big.area_m2 - 0.99).abs() < 0.1, "{} m²", big.area_m2);
        assert!(
            (big.completed_m2 - 0.2).abs() < 0.05,
            "{}",
            big.completed_m2
        );
        let both = ceiling_with_stripe(false, true);
        assert_eq!(both.features.len(), 1, "{:?}", both.features);
        assert!(
            (both.features[0].area_m2 - 2.2).abs() < 0.22,
            "{}",
            both.features[0].area_m2
        );
    }

    /// A wall stratified by 0.8 K/m (18 °C at the floor, 20 °C at 2.5 m) with a 0.6 m hole the
    /// walk never saw at mid-height: the seen surroundings span 1.3 K of height, but the wall's
    /// gradient is known, so the patch is bounded by how far the wall strays from it (nowhere
    /// here), placed on the gradient at the hole.
    #[test]
    fn an_unseen_patch_on_a_stratified_wall_follows_its_gradient() {
        let hole = |x: f64, z: f64| (1.7..2.3).contains(&x) && (0.95..1.55).contains(&z);
        let (_, a) = analyse_seen(
            4.0,
            2.5,
            |x, z| (!hole(x, z)).then_some(18.0 + 0.8 * z),
            true,
        );
        let r = a.raster.as_ref().expect("a raster");
        assert_eq!(r.unseen.len(), 1, "{:?}", r.unseen);
        let [lo, hi] = r.unseen[0].range_c;
        assert!(hi - lo < 0.1, "{:?}", r.unseen[0].range_c);
        // The hole's middle (z 1.25 m) is at 19.0 °C.
        assert!(
            ((lo + hi) / 2.0 - 19.0).abs() < 0.1,
            "{:?}",
            r.unseen[0].range_c
        );
    }

    /// The same stratified wall whose upper metre the walk never saw, along its whole width: the
    /// raster fills it on the gradient (19.6 °C at 2 m), not with the last row seen (about
    /// 19.1 °C everywhere, as filling from the neighbours alone did).
    #[test]
    fn an_unseen_band_on_a_stratified_wall_is_filled_on_its_gradient() {
        let (_, a) = analyse_seen(4.0, 2.5, |_, z| (z < 1.5).then_some(18.0 + 0.8 * z), true);
        let r = a.raster.as_ref().expect("a raster");
        assert!(!r.filled.is_empty());
        let mut high = 0;
        for &t in &r.filled {
            let z = r.origin[2] + r.v[2] * ((t / r.cols) as f64 + 0.5) * r.texel_m;
            let want = 18.0 + 0.8 * z.min(2.5);
            let got = r.temperature_c[t].expect("filled");
            assert!(
                (got - want).abs() < 0.1,
                "texel {t} at z {z:.2}: {got:.2} °C, not {want:.2}"
            );
            high += usize::from(z > 2.0);
        }
        assert!(high > 10, "{high} filled texels above 2 m");
    }

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
