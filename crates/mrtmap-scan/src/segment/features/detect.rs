//! Finding a surface's thermal features: the warm and cold regions that stand out from its
//! background, and what each one measures.
//!
//! For each side of the background (warm, then cold):
//!
//! 1. The threshold mask: texels farther than the threshold from the background, with one-texel
//!    holes (unobserved or noisy) closed.
//! 2. Its connected regions (4-connectivity), in order of their first texel.
//! 3. Hysteresis: each region redrawn at half its own core contrast, so that its outline is not
//!    biased outwards by the detection threshold, growing only into texels not much hotter than
//!    it (a faint strip does not become the radiator it touches).
//! 4. A region lying mostly along the surface's edge is the next surface's temperature blurred in
//!    at the corner, not a feature of this one.
//! 5. A region that becomes a feature (its outline from [`super::shape`]) is measured: its
//!    temperature from its interior texels clear of the surface's edge, its contrast, area and
//!    points.

use mrtmap_geometry::nalgebra::Point2;
use mrtmap_geometry::polygon::signed_area;
use mrtmap_physics::{RadiantAverage, Temperature};

use super::background::Background;
use super::grid::Grid;

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
    /// [`complete_features`](super::complete::complete_features)).
    pub completed_m2: f64,
}

/// A warm or cold region lying mostly within this of its surface's edge is the neighbouring
/// surface's temperature blurred in at the corner (m).
pub(super) const EDGE_STRIP_M: f64 = 0.12;

/// A faint region (under [`EDGE_BLUR_MAX_K`] from the background) lying mostly within this of
/// its surface's edge is blur too (m): a corner seen obliquely spreads the next surface's
/// temperature farther along this one. On the L-shaped room's cold exterior wall the warm
/// corner column (30 cm wide, +0.6 K) and the row under the ceiling joined into an L whose convex
/// outline became a 3.7 m², +0.35 K "feature" on every field-study walk.
pub(super) const EDGE_BLUR_M: f64 = 0.3;

/// The largest contrast (K) of a region that [`EDGE_BLUR_M`] may call blur: a radiator along
/// the floor or a window up to the ceiling stands out by far more.
const EDGE_BLUR_MAX_K: f64 = 1.0;

/// A region lies mostly within a strip along the edge when at least this share of its texels do
/// (numerator, denominator: 4 in 5).
const EDGE_SHARE: (usize, usize) = (4, 5);

/// A texel off the threshold mask joins it when at least this many of its four neighbours are on
/// it: a one-texel hole (unobserved or noisy) in a region is closed.
const HOLE_NEIGHBOURS: usize = 3;

/// A region is redrawn at this share of its core contrast (see [`hysteresis`]): a blurred step
/// crosses half its height at the true edge, while the threshold lies further out the hotter the
/// feature.
const HYSTERESIS_SHARE: f64 = 0.5;

/// A feature's temperature is measured on its interior texels clear of the surface's edge when at
/// least this many of them were observed, else on its interior texels, else on all of them (see
/// [`feature`]).
const MIN_MEASURED_TEXELS: usize = 4;

/// The texels beyond the threshold on one side of the background (`sign` +1 warm, −1 cold), with
/// one-texel holes (unobserved or noisy) closed.
pub(super) fn threshold_mask(
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
                >= HOLE_NEIGHBOURS
        {
            *m = true;
        }
    }
    mask
}

/// The connected components (4-connectivity) of `mask`, in order of their first texel.
pub(super) fn components(g: &Grid, mask: &[bool]) -> Vec<Vec<usize>> {
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
pub(super) fn edge_blur(
    comp: &[usize],
    area: f64,
    resid: &dyn Fn(usize) -> f64,
    (near_edge, near_edge_wide): (&[bool], &[bool]),
) -> Option<String> {
    let strip = comp.iter().filter(|&&c| near_edge[c]).count();
    let wide = comp.iter().filter(|&&c| near_edge_wide[c]).count();
    let contrast = comp.iter().map(|&c| resid(c)).sum::<f64>() / comp.len() as f64;
    let (num, den) = EDGE_SHARE;
    (strip * den >= comp.len() * num
        || (wide * den >= comp.len() * num && contrast.abs() < EDGE_BLUR_MAX_K))
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
pub(super) fn hysteresis(
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
    let half = HYSTERESIS_SHARE * median;
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

/// A feature of region `comp` with outline `poly`: its temperature from interior texels (all four
/// neighbours in the feature; border texels mix in the background) clear of the surface's edge
/// (`near_edge`: there the next surface's temperature is blurred in; a 45 cm patch at the
/// L-shaped room's corner read 18.1–18.3 °C with its edge texels, 17.8 °C without, on a
/// 17.6 °C wall), or from all its texels when too few are.
pub(super) fn feature(
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
    let enough =
        |cells: &[usize]| cells.iter().filter(|&&c| g.observed(c)).count() >= MIN_MEASURED_TEXELS;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::features::testing::{extent, patch, wall_in_y0, wall_with};
    use mrtmap_geometry::nalgebra::Point3;
    use mrtmap_physics::ZERO_CELSIUS_K;

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
}
