//! Thermal features on one envelope surface, its background and its temperature raster.
//!
//! 1. The texel grid ([`grid`]): the surface's fused points rasterised into square texels (radiant
//!    T⁴ averages, each point weighted by its observations).
//! 2. The background ([`background`]): a robust fit (constant on floor and ceiling, linear in
//!    height on walls, which may be stratified) by consensus, refitted by least squares.
//! 3. Detection ([`detect`]): texels farther than the threshold from the background form warm and
//!    cold masks; each connected region is redrawn at half its own core contrast (hysteresis: a
//!    border texel joins when the feature covers more than about half of it, so the outline is
//!    not biased outwards by the detection threshold); regions along the surface's edge (the next
//!    surface blurred in) are dropped.
//! 4. Shape ([`shape`]): regions of at least the minimum area become features, a rectangle (the
//!    minimum-area rectangle of the region's texels) when the region fills at least 75 % of it,
//!    otherwise the region's simplified convex outline, clipped to the host. A feature that
//!    overlaps one found before, or differs from the background by less than the threshold on
//!    average, is dropped.
//! 5. Completion ([`complete`]): features completed into what the scan did not see, where what it
//!    saw implies the shape.
//! 6. The raster ([`raster`]) of the background without the features' outlines, with its unseen
//!    patches ([`unseen`]); the host's temperature is the radiant average of its background
//!    texels only.

mod background;
mod complete;
mod detect;
mod grid;
mod raster;
mod shape;
#[cfg(test)]
mod testing;
mod unseen;

use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_geometry::polygon::{point_in_polygon_fast, polygons_overlap};
use mrtmap_radiation::RasterFile;

use super::SegmentParams;
use background::{host_temperature, robust_background};
use complete::{Region, complete_features};
use detect::{
    EDGE_BLUR_M, EDGE_STRIP_M, components, edge_blur, feature, hysteresis, threshold_mask,
};
use grid::Grid;
use raster::background_raster;
use shape::{FIT_TOLERANCE_M, Step, half_contrast_core, outline};

pub use background::Background;
pub use detect::FoundFeature;

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
                .any(|f| polygons_overlap(&f.polygon_2d, &poly, FIT_TOLERANCE_M))
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

#[cfg(test)]
mod tests {
    use super::testing::{patch, wall_with};

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
}
