//! Completing features into what the scan did not see, where what it saw implies the shape
//! (issue 37).
//!
//! 1. Pairs: two features of one surface, of one sign and close in temperature, whose common
//!    rectangle holds nothing seen as background and some texels never seen become one feature
//!    (a panel split by a stripe the walk missed); repeated while any pair merges.
//! 2. Single features: a feature whose rectangle is its own or unseen takes that rectangle (a
//!    window whose corner was never in view).
//!
//! A completion must fit in the host and clear the other features, and at least half of what it
//! adds to the outlines must be unseen. Each completed feature says how much of its outline was
//! never seen (`completed_m2`).

use mrtmap_geometry::nalgebra::Point2;
use mrtmap_geometry::polygon::{
    point_in_polygon_fast, polygon_inside, polygons_overlap, signed_area,
};
use mrtmap_geometry::shape2d::min_area_rectangle;

use super::background::Background;
use super::detect::{FoundFeature, feature};
use super::grid::Grid;
use super::shape::{FIT_TOLERANCE_M, ccw};

/// A found feature's texels: its thresholded region and its half-contrast core.
pub(super) struct Region {
    /// The thresholded region's texels.
    pub(super) comp: Vec<usize>,
    /// Its half-contrast core's texels.
    pub(super) core: Vec<usize>,
    /// +1 for a warm feature, −1 for a cold one.
    pub(super) sign: f64,
}

/// Least unseen area worth completing (m²).
const COMPLETE_MIN_M2: f64 = 0.02;

/// A completion's rectangle may hold at most this share of texels seen looking like the
/// background (numerator, denominator: 1 in 20): a gap seen as background is never filled.
const MAX_BACKGROUND_SHARE: (usize, usize) = (1, 20);

/// A completion's rectangle may be at most this share unseen (numerator, denominator: 3 in 5): a
/// shape is completed from what was seen, never invented.
const MAX_UNSEEN_SHARE: (usize, usize) = (3, 5);

/// A texel looks like the background when it is under this share of the feature's contrast from
/// the background.
const BACKGROUND_CONTRAST_SHARE: f64 = 0.5;

/// Two features are close in temperature when within this share of the fainter one's contrast…
const MERGE_CLOSE_SHARE: f64 = 0.2;

/// …or within this (K), whichever is larger.
const MERGE_CLOSE_K: f64 = 1.0;

/// At least this share of what a completion adds to the outlines must be unseen: the rectangle of
/// a feature's half-contrast core reaches a little into its blur, and a radiator whose strip along
/// the floor the walk missed grew 12 % over its true 1.08 m² when any unseen area licensed the
/// core's rectangle.
const MIN_UNSEEN_SHARE_OF_GROWTH: f64 = 0.5;

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
        } else if !near_region(c) && resid(c) * sign < BACKGROUND_CONTRAST_SHARE * contrast.abs() {
            other += 1;
        }
    }
    let unseen_m2 = unseen as f64 * t * t;
    let (bg_num, bg_den) = MAX_BACKGROUND_SHARE;
    let (unseen_num, unseen_den) = MAX_UNSEEN_SHARE;
    (n > 0
        && other * bg_den <= n * bg_num
        && unseen_m2 >= COMPLETE_MIN_M2
        && unseen * unseen_den <= n * unseen_num)
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
pub(super) fn complete_features(
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
        polygon_inside(poly, host, FIT_TOLERANCE_M)
            && features.iter().enumerate().all(|(k, f)| {
                skip.contains(&k) || !polygons_overlap(&f.polygon_2d, poly, FIT_TOLERANCE_M)
            })
    };
    // Pairs: merge while any pair merges.
    'merging: loop {
        for i in 0..features.len() {
            for j in i + 1..features.len() {
                let (a, b) = (&features[i], &features[j]);
                let (ra, rb) = (&regions[i], &regions[j]);
                let close = (a.temperature_k - b.temperature_k).abs()
                    <= (MERGE_CLOSE_SHARE * a.contrast_k.abs().min(b.contrast_k.abs()))
                        .max(MERGE_CLOSE_K);
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
                if unseen_m2 < MIN_UNSEEN_SHARE_OF_GROWTH * grown || !fits(&rect, features, &[i, j])
                {
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
        if grown < COMPLETE_MIN_M2
            || unseen_m2 < MIN_UNSEEN_SHARE_OF_GROWTH * grown
            || !fits(&rect, features, &[i])
        {
            continue;
        }
        features[i].area_m2 = signed_area(&rect).abs();
        features[i].polygon_2d = rect;
        features[i].completed_m2 = unseen_m2;
    }
}

#[cfg(test)]
mod tests {
    use crate::segment::features::SurfaceAnalysis;
    use crate::segment::features::testing::analyse_seen;
    use mrtmap_physics::ZERO_CELSIUS_K;

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
}
