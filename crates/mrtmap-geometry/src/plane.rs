//! Planes: least-squares fits and RANSAC with normal agreement, and plane intersections.

use nalgebra::{Matrix3, Point3, Unit, Vector3};
use rand::Rng;
use serde::{Deserialize, Serialize};

/// A plane n·p = d with a unit normal.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    /// Unit normal.
    pub normal: Unit<Vector3<f64>>,
    /// Offset along the normal.
    pub d: f64,
}

impl Plane {
    /// The plane through `p` with normal `n`.
    pub fn from_point_normal(p: &Point3<f64>, n: Unit<Vector3<f64>>) -> Self {
        Self {
            d: n.dot(&p.coords),
            normal: n,
        }
    }

    /// Signed distance of a point.
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        self.normal.dot(&p.coords) - self.d
    }

    /// The same plane with the opposite normal.
    pub fn flipped(&self) -> Self {
        Self {
            normal: -self.normal,
            d: -self.d,
        }
    }

    /// Projection of a point onto the plane.
    pub fn project(&self, p: &Point3<f64>) -> Point3<f64> {
        p - self.normal.as_ref() * self.distance(p)
    }

    /// Least-squares plane of points (PCA), or `None` for fewer than 3 or collinear points.
    pub fn fit(points: &[Point3<f64>]) -> Option<Self> {
        if points.len() < 3 {
            return None;
        }
        let (c, scatter) = crate::cloud::centroid_and_scatter(points);
        Self::from_scatter(c, scatter)
    }

    /// Weighted least-squares plane (PCA of the weighted scatter): a fused cloud's point stands
    /// for as many measurements as its voxel holds, and its sparsely seen points (the depth
    /// noise's tails) should count for less. `None` for fewer than 3 points of positive weight,
    /// collinear points or a weight that is not finite.
    pub fn fit_weighted(points: &[Point3<f64>], weights: &[f64]) -> Option<Self> {
        let used = || points.iter().zip(weights).filter(|(_, w)| **w > 0.0);
        if used().count() < 3 || weights.iter().any(|w| !w.is_finite()) {
            return None;
        }
        let total: f64 = used().map(|(_, w)| w).sum();
        let c = used().fold(Vector3::zeros(), |a, (p, w)| a + p.coords * *w) / total;
        let scatter = used().fold(Matrix3::zeros(), |s, (p, w)| {
            let d = p.coords - c;
            s + d * d.transpose() * *w
        });
        Self::from_scatter(Point3::from(c), scatter)
    }

    fn from_scatter(c: Point3<f64>, scatter: Matrix3<f64>) -> Option<Self> {
        let eig = nalgebra::SymmetricEigen::new(scatter);
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        if eig.eigenvalues[idx[1]] <= 1e-12 {
            return None;
        }
        let n = Unit::try_new(eig.eigenvectors.column(idx[0]).into_owned(), 1e-9)?;
        Some(Self::from_point_normal(&c, n))
    }
}

/// The point where three planes meet, or `None` when they do not meet in one point.
pub fn intersect_three(a: &Plane, b: &Plane, c: &Plane) -> Option<Point3<f64>> {
    let m = Matrix3::from_rows(&[
        a.normal.transpose(),
        b.normal.transpose(),
        c.normal.transpose(),
    ]);
    let det = m.determinant();
    if det.abs() < 1e-9 {
        return None;
    }
    m.try_inverse()
        .map(|inv| Point3::from(inv * Vector3::new(a.d, b.d, c.d)))
}

/// RANSAC settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RansacParams {
    /// Largest point-to-plane distance of an inlier (m).
    pub distance_m: f64,
    /// Largest angle between a point's normal and the plane's (degrees).
    pub normal_deg: f64,
    /// Hypotheses drawn.
    pub iterations: usize,
    /// Hypotheses are scored on at most this many points.
    pub sample: usize,
}

impl Default for RansacParams {
    fn default() -> Self {
        Self {
            distance_m: 0.05,
            normal_deg: 30.0,
            iterations: 400,
            sample: 20_000,
        }
    }
}

/// The best plane among `candidates` (indices into `points`): RANSAC over three-point hypotheses
/// (one point and its normal when no three-point hypothesis agrees with its points' normals)
/// scored on a subsample (inliers within `distance_m` whose normal agrees within `normal_deg`),
/// then refitted by least squares to all its inliers. Returns the plane and its inliers.
pub fn ransac_plane<R: Rng>(
    points: &[Point3<f64>],
    normals: &[Vector3<f64>],
    candidates: &[usize],
    params: &RansacParams,
    rng: &mut R,
) -> Option<(Plane, Vec<usize>)> {
    if candidates.len() < 3 {
        return None;
    }
    let cos = params.normal_deg.to_radians().cos();
    let step = (candidates.len() / params.sample.max(1)).max(1);
    let sample: Vec<usize> = candidates.iter().step_by(step).copied().collect();
    let is_inlier = |pl: &Plane, i: usize, tol: f64| {
        pl.distance(&points[i]).abs() <= tol && pl.normal.dot(&normals[i]).abs() >= cos
    };
    let score = |pl: &Plane| {
        sample
            .iter()
            .filter(|&&i| is_inlier(pl, i, params.distance_m))
            .count()
    };
    let mut best: Option<(Plane, usize)> = None;
    for _ in 0..params.iterations {
        let (a, b, c) = (
            candidates[rng.random_range(0..candidates.len())],
            candidates[rng.random_range(0..candidates.len())],
            candidates[rng.random_range(0..candidates.len())],
        );
        let n = (points[b] - points[a]).cross(&(points[c] - points[a]));
        let Some(n) = Unit::try_new(n, 1e-9) else {
            continue;
        };
        let pl = Plane::from_point_normal(&points[a], n);
        if [a, b, c]
            .iter()
            .any(|&i| pl.normal.dot(&normals[i]).abs() < cos)
        {
            continue;
        }
        let s = score(&pl);
        if best.is_none_or(|b| s > b.1) {
            best = Some((pl, s));
        }
    }
    if best.is_none() {
        // No three points agreed with their normals (thick, noisy surfaces): hypotheses from one
        // point and its own normal instead.
        for _ in 0..params.iterations {
            let a = candidates[rng.random_range(0..candidates.len())];
            let Some(n) = Unit::try_new(normals[a], 1e-9) else {
                continue;
            };
            let pl = Plane::from_point_normal(&points[a], n);
            let s = score(&pl);
            if best.is_none_or(|b| s > b.1) {
                best = Some((pl, s));
            }
        }
    }
    let (mut pl, _) = best?;
    // Refine twice: fit to inliers, recollect.
    for _ in 0..2 {
        let inliers: Vec<usize> = candidates
            .iter()
            .copied()
            .filter(|&i| is_inlier(&pl, i, params.distance_m))
            .collect();
        let pts: Vec<Point3<f64>> = inliers.iter().map(|&i| points[i]).collect();
        if let Some(f) = Plane::fit(&pts) {
            pl = if f.normal.dot(&pl.normal) < 0.0 {
                f.flipped()
            } else {
                f
            };
        }
    }
    let inliers = candidates
        .iter()
        .copied()
        .filter(|&i| is_inlier(&pl, i, params.distance_m))
        .collect();
    Some((pl, inliers))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A floor at z = 0 seen as a fused cloud: three layers about the surface (weight 30) and a
    /// sparse tail 2–6 cm below it (weight 1), on a 2 × 2 m patch.
    fn floor_with_tail() -> (Vec<Point3<f64>>, Vec<f64>) {
        let (mut pts, mut w) = (Vec::new(), Vec::new());
        for i in 0..40 {
            for j in 0..40 {
                for layer in -6..=1 {
                    pts.push(Point3::new(
                        0.05 * i as f64,
                        0.05 * j as f64,
                        0.01 * layer as f64,
                    ));
                    w.push(if layer >= -1 { 30.0 } else { 1.0 });
                }
            }
        }
        (pts, w)
    }

    #[test]
    fn a_weighted_fit_follows_the_measurements_not_the_points() {
        let (pts, w) = floor_with_tail();
        let counted = Plane::fit(&pts).expect("a plane");
        let weighted = Plane::fit_weighted(&pts, &w).expect("a plane");
        let up = |p: &Plane| if p.normal.z < 0.0 { p.flipped() } else { *p };
        let (counted, weighted) = (up(&counted), up(&weighted));
        // Per column the layers sum to −0.2 m: 8 points, or 3 × 30 + 5 × 1 of weight.
        assert!((counted.d + 0.2 / 8.0).abs() < 1e-9, "plain: {}", counted.d);
        assert!(
            (weighted.d + 0.2 / 95.0).abs() < 1e-9,
            "weighted: {}",
            weighted.d
        );
        assert!(weighted.normal.z > 1.0 - 1e-12);
        // Equal weights are the plain fit.
        let same = up(&Plane::fit_weighted(&pts, &vec![2.5; pts.len()]).expect("a plane"));
        assert!((same.d - counted.d).abs() < 1e-12);
        assert!((same.normal.into_inner() - counted.normal.into_inner()).norm() < 1e-9);
    }

    #[test]
    fn a_weighted_fit_needs_three_weighted_points_and_finite_weights() {
        let (pts, mut w) = floor_with_tail();
        assert!(Plane::fit_weighted(&pts[..3], &[1.0, 1.0, 0.0]).is_none());
        assert!(Plane::fit_weighted(&pts[..2], &[1.0, 1.0]).is_none());
        w[7] = f64::NAN;
        assert!(Plane::fit_weighted(&pts, &w).is_none());
    }
}
