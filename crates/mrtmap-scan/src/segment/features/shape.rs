//! A feature's shape: the outline drawn around a region of texels.
//!
//! 1. The region's core: its texels at least half as far from the background as its plateau
//!    (the median of its interior texels, or its upper quartile when too few are interior), since
//!    a blurred step crosses half its height at the true edge.
//! 2. The minimum-area rectangle of the region's texels. When the region fills at least
//!    [`RECTANGLE_FILL`] of it, the outline is a rectangle: that of the core, each side moved to
//!    where the core fills half of the texel rows along it, then to a fraction of a texel from
//!    the points' temperatures across it. Otherwise the outline is the region's convex hull,
//!    simplified.
//! 3. The outline is turned counter-clockwise and clipped to the host; it is dropped when it
//!    still does not fit inside the host or is degenerate.

use mrtmap_geometry::nalgebra::Point2;
use mrtmap_geometry::polygon::{polygon_inside, signed_area};
use mrtmap_geometry::shape2d::{clip_convex, convex_hull, min_area_rectangle, simplify_closed};

use super::background::Background;
use super::grid::Grid;

/// A region becomes a rectangle when it fills at least this share of its minimum-area rectangle;
/// otherwise its outline is its convex hull (module docs).
const RECTANGLE_FILL: f64 = 0.75;

/// A region's convex hull is simplified to within this many texels.
const SIMPLIFY_TEXELS: f64 = 0.5;

/// An outline counts as inside its host, or clear of another feature's outline, to within this
/// (m): the millimetre to which scene.json's validation checks a feature against its host and the
/// other features (`FEATURE_PLANE_TOLERANCE_M`).
pub(super) const FIT_TOLERANCE_M: f64 = 1e-3;

/// Vertices of an outline within this of the previous one (around the loop) are one vertex (m).
const SAME_VERTEX_M: f64 = 1e-3;

/// A region's plateau is the median of its interior texels when at least this many of them were
/// observed, else the upper quartile of all its observed texels.
const PLATEAU_MIN_INTERIOR: usize = 4;

/// The quantile of a region's interior texels that is its plateau (the median).
const PLATEAU_QUANTILE: f64 = 0.5;

/// The quantile of all of a region's texels that is its plateau when too few are interior (the
/// upper quartile: its border texels mix in the background).
const PLATEAU_QUANTILE_FEW_INTERIOR: f64 = 0.75;

/// The core is the texels at least this share of the plateau from the background: a blurred step
/// crosses half its height at the true edge.
const CORE_SHARE: f64 = 0.5;

/// A core of fewer texels than this is no core: the whole region is used.
const MIN_CORE_TEXELS: usize = 4;

/// A rectangle's side is placed from the points within this many texels of it, on either side.
const REFINE_BAND_TEXELS: f64 = 2.0;

/// A side with fewer points than this in its band stays where the texels put it (set with the
/// sub-texel sides).
const REFINE_MIN_POINTS: usize = 12;

/// `p` turned counter-clockwise.
pub(super) fn ccw(mut p: Vec<Point2<f64>>) -> Vec<Point2<f64>> {
    if signed_area(&p) < 0.0 {
        p.reverse();
    }
    p
}

/// A region's outline: its minimum-area rectangle when it fills at least 75 % of it, else its
/// simplified convex outline, clipped to the host; why not when it does not fit.
pub(super) fn outline(
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
    let mut poly = if area / rect_area >= RECTANGLE_FILL {
        robust_rectangle(g, core, &rect, step)
            .unwrap_or(rect)
            .to_vec()
    } else {
        simplify_closed(&convex_hull(&corners), SIMPLIFY_TEXELS * t)
    };
    poly = ccw(poly);
    if !polygon_inside(&poly, host, FIT_TOLERANCE_M) {
        poly = ccw(clip_convex(&poly, &ccw(convex_hull(host))));
        poly.dedup_by(|a, b| (*a - *b).norm() < 1e-6);
    }
    // Vertices within a millimetre of the previous one (around the loop) are one vertex.
    poly.dedup_by(|a, b| (*a - *b).norm() < SAME_VERTEX_M);
    while poly.len() > 3 && (poly[0] - poly[poly.len() - 1]).norm() < SAME_VERTEX_M {
        poly.pop();
    }
    if poly.len() < 3 || !polygon_inside(&poly, host, FIT_TOLERANCE_M) {
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
pub(super) fn half_contrast_core(
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
    let plateau = if interior.len() >= PLATEAU_MIN_INTERIOR {
        contrast(&mut interior, PLATEAU_QUANTILE)
    } else {
        contrast(&mut all, PLATEAU_QUANTILE_FEW_INTERIOR)
    };
    let Some(plateau) = plateau else {
        return (comp.to_vec(), None);
    };
    let core: Vec<usize> = comp
        .iter()
        .copied()
        .filter(|&c| !g.observed(c) || resid(c) * sign >= CORE_SHARE * plateau)
        .collect();
    if core.len() < MIN_CORE_TEXELS {
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
pub(super) struct Step<'a> {
    /// The surface's background.
    pub(super) background: &'a Background,
    /// +1 for a warm feature, −1 for a cold one.
    pub(super) sign: f64,
    /// The feature's plateau: its contrast with the background (K, signed by `sign`).
    pub(super) plateau: f64,
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
    let w = REFINE_BAND_TEXELS * t;
    let (mut n, mut sum) = (0usize, 0.0);
    for &(a, b, f) in samples {
        if (a - edge).abs() <= w && b > lo + t && b < hi - t {
            n += 1;
            sum += f;
        }
    }
    if n < REFINE_MIN_POINTS {
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
}
