//! The texel grid of one surface: its fused points rasterised into square texels.
//!
//! 1. The grid covers the host's outline in its plane frame, from its lowest corner, in texels of
//!    the analysis size; the last row and column end at the host's edge, partly filled.
//! 2. A texel is on the surface when its centre lies inside the host's outline.
//! 3. Each point falls into one texel and adds its temperature to the texel's radiant (T⁴)
//!    average, weighted by its observations (a point seen forty times counts forty times, so a
//!    texel averages its measurements, not its points); the texel keeps its points and their
//!    positions and temperatures.
//!
//! The grid then answers where texels are (centres, neighbours, the host's edge) and what they
//! read (observed or not, radiant temperature).

use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_geometry::polygon::point_in_polygon_fast;
use mrtmap_physics::{RadiantAverage, Temperature};

/// A surface's texels: which lie inside its outline, their radiant averages and their points.
pub(super) struct Grid {
    /// The grid's lowest corner in the frame.
    pub(super) lo: Point2<f64>,
    /// The host's far corner (the last row and column of texels end here, partly filled).
    hi: Point2<f64>,
    /// The texel size (m).
    pub(super) t: f64,
    /// Texels along the frame's u axis.
    pub(super) nx: usize,
    /// Texels along the frame's v axis.
    pub(super) ny: usize,
    /// Whether each texel's centre lies inside the host's outline.
    pub(super) inside: Vec<bool>,
    /// Each texel's radiant average.
    temp: Vec<RadiantAverage>,
    /// Each texel's points (indices into the cloud).
    pub(super) points: Vec<Vec<usize>>,
    /// Each texel's points in the frame and their temperatures (K).
    pub(super) samples: Vec<Vec<(Point2<f64>, f64)>>,
}

impl Grid {
    /// Rasterises the points `idx` of a surface (`host` its outline in `frame`) at texel `t`, each
    /// point's temperature weighted by `weights` (its observations) in its texel's average.
    pub(super) fn rasterise(
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

    /// The centre of texel (`i`, `j`).
    fn centre(&self, i: usize, j: usize) -> Point2<f64> {
        Point2::new(
            self.lo.x + (i as f64 + 0.5) * self.t,
            self.lo.y + (j as f64 + 0.5) * self.t,
        )
    }

    /// The centre of texel `c`.
    pub(super) fn centre_of(&self, c: usize) -> Point2<f64> {
        self.centre(c % self.nx, c / self.nx)
    }

    /// Whether texel `c` holds any point.
    pub(super) fn observed(&self, c: usize) -> bool {
        self.temp[c].count() > 0
    }

    /// Texel `c`'s radiant temperature (K), NaN when unobserved.
    pub(super) fn kelvin(&self, c: usize) -> f64 {
        self.temp[c].mean().map_or(f64::NAN, |x| x.kelvin())
    }

    /// The four neighbours of texel `c`: (exists, index).
    pub(super) fn neighbours(&self, c: usize) -> [(bool, usize); 4] {
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
    pub(super) fn near_edge(&self, m: f64) -> Vec<bool> {
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
    pub(super) fn interior_of(&self, c: usize, set: &[bool]) -> bool {
        self.neighbours(c).iter().all(|&(ok, d)| ok && set[d])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::features::detect::EDGE_STRIP_M;
    use crate::segment::features::testing::{wall_in_y0, wall_with};

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
}
