//! Point-to-plane ICP against a target cloud with normals, nearest neighbours by k-d tree.
//!
//! Each iteration pairs every source point with its nearest target point within
//! `max_correspondence_m`, then solves the linearised point-to-plane problem
//! min Σ wᵢ (nᵢ · (R sᵢ + t − qᵢ))² (Huber weights) for a small rotation and translation. Directions
//! the data do not constrain (a single wall leaves translation along it free) are detected from the
//! eigenvalues of the normal equations and left unchanged instead of drifting
//! (degeneracy-aware ICP, Zhang & Singh 2016).

use std::num::NonZero;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{
    Isometry3, Matrix3, Matrix6, Point3, Rotation3, Translation3, UnitQuaternion, Vector3, Vector6,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Convergence and robustness settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct IcpParams {
    /// Largest distance of a correspondence (m).
    pub max_correspondence_m: f64,
    /// Iteration limit.
    pub max_iterations: usize,
    /// Stop when an update moves less than this (m)…
    pub converged_translation_m: f64,
    /// …and turns less than this (rad).
    pub converged_rotation_rad: f64,
    /// Huber threshold on point-to-plane residuals (m).
    pub huber_m: f64,
    /// Eigenvalues of the normal equations below this fraction of the largest count as
    /// unconstrained directions.
    pub degenerate_ratio: f64,
}

impl Default for IcpParams {
    fn default() -> Self {
        Self {
            max_correspondence_m: 0.05,
            max_iterations: 30,
            converged_translation_m: 1e-5,
            converged_rotation_rad: 1e-5,
            huber_m: 0.01,
            degenerate_ratio: 1e-3,
        }
    }
}

/// An ICP result with its quality (Open3D's `RegistrationResult` plus degeneracy).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Registration {
    /// target_from_source: maps source points onto the target.
    pub target_from_source: Isometry3<f64>,
    /// Fraction of source points with a correspondence within the distance limit.
    pub fitness: f64,
    /// RMS point-to-point distance of those correspondences (m).
    pub inlier_rmse_m: f64,
    /// RMS point-to-plane residual of those correspondences (m).
    pub inlier_plane_rmse_m: f64,
    /// Iterations run.
    pub iterations: usize,
    /// Whether the updates fell below the convergence thresholds.
    pub converged: bool,
    /// How many of the 6 degrees of freedom the data leave unconstrained (0 = well posed).
    pub degenerate_dofs: usize,
}

/// Two, for the two nearest neighbours.
const TWO: NonZero<usize> = NonZero::new(2).unwrap();

/// A target cloud: points, unit normals and a k-d tree over the points.
pub struct IcpTarget {
    tree: ImmutableKdTree<f32, 3>,
    points: Vec<Point3<f64>>,
    normals: Vec<Vector3<f64>>,
}

impl IcpTarget {
    /// Builds the target (points and normals of equal length, normals of unit length).
    pub fn new(points: Vec<Point3<f64>>, normals: Vec<Vector3<f64>>) -> Self {
        // f32: a micrometre at 10 m, and half the memory traffic of f64.
        let raw: Vec<[f32; 3]> = points
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        let tree = ImmutableKdTree::new_from_slice(&raw).unwrap_or_default();
        Self {
            tree,
            points,
            normals,
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether it is empty.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The nearest target point to `p` within `radius` and its distance, and the distance of the
    /// second nearest, or `radius` when there is none within it (a lower bound of its distance:
    /// what the query cache needs). A bounded search prunes most of the tree.
    fn nearest_two(&self, p: &Point3<f64>, radius: f64) -> Option<(usize, f64, f64)> {
        let r = radius as f32;
        let found = self
            .tree
            .query(&[p.x as f32, p.y as f32, p.z as f32])
            .nearest_n::<SquaredEuclidean<f32>>(TWO)
            .within(r * r)
            .execute();
        let first = found.first()?;
        let k = first.item as usize;
        let second = found.get(1).map_or(radius, |r| (r.distance as f64).sqrt());
        Some((k, (p - self.points[k]).norm(), second))
    }
}

/// A source point's last nearest-neighbour query: where it was asked, the nearest target point,
/// and half the gap to the second nearest. While the point has moved less than that half-gap, its
/// nearest neighbour cannot have changed (triangle inequality), so the query is not repeated: after
/// the first iterations the updates move points by millimetres and two queries in three are saved,
/// with exactly the correspondences a fresh query would give.
#[derive(Clone, Copy)]
struct Query {
    at: Point3<f64>,
    nearest: usize,
    half_gap: f64,
}

impl Query {
    /// The nearest target point to `p` within `radius` and its distance, from the cache when it
    /// still holds. A point with none within `radius` is asked again next time (the bounded search
    /// finds nothing fast).
    fn nearest(
        cached: &mut Option<Query>,
        target: &IcpTarget,
        p: &Point3<f64>,
        radius: f64,
    ) -> Option<(usize, f64)> {
        if let Some(q) = cached
            && (p - q.at).norm() < q.half_gap
        {
            return Some((q.nearest, (p - target.points[q.nearest]).norm()));
        }
        let Some((k, d1, d2)) = target.nearest_two(p, radius) else {
            *cached = None;
            return None;
        };
        // The tree's distances are f32: a margin of 10 µm keeps the test exact.
        *cached = Some(Query {
            at: *p,
            nearest: k,
            half_gap: 0.5 * (d2 - d1) - 1e-5,
        });
        Some((k, d1))
    }
}

#[derive(Default)]
struct Accum {
    h: Matrix6<f64>,
    g: Vector6<f64>,
    n: usize,
    sq: f64,
    sq_plane: f64,
}

impl Accum {
    fn add(mut self, o: &Accum) -> Accum {
        self.h += o.h;
        self.g += o.g;
        self.n += o.n;
        self.sq += o.sq;
        self.sq_plane += o.sq_plane;
        self
    }
}

fn exp_se3(x: &Vector6<f64>) -> Isometry3<f64> {
    let rot = UnitQuaternion::from_scaled_axis(Vector3::new(x[0], x[1], x[2]));
    Isometry3::from_parts(Translation3::new(x[3], x[4], x[5]), rot)
}

/// Registers `source` onto `target` starting from `init` (target_from_source).
pub fn icp_point_to_plane(
    source: &[Point3<f64>],
    target: &IcpTarget,
    init: &Isometry3<f64>,
    params: &IcpParams,
) -> Registration {
    let mut t = *init;
    let mut result = Registration {
        target_from_source: t,
        fitness: 0.0,
        inlier_rmse_m: f64::INFINITY,
        inlier_plane_rmse_m: f64::INFINITY,
        iterations: 0,
        converged: false,
        degenerate_dofs: 6,
    };
    if source.is_empty() || target.is_empty() {
        return result;
    }
    let mut queries: Vec<Option<Query>> = vec![None; source.len()];
    // Correspondences farther than the limit are not used: the search looks no farther (a
    // millimetre beyond it, so the f32 tree never drops one the f64 test keeps).
    let radius = params.max_correspondence_m + 1e-3;
    for it in 0..params.max_iterations {
        // Normal equations over all correspondences (in parallel for large sources; the sum is
        // taken in a fixed chunk order, so results do not depend on the thread count).
        let acc = |(chunk, cache): (&[Point3<f64>], &mut [Option<Query>])| {
            let mut a = Accum::default();
            for (s, cached) in chunk.iter().zip(cache) {
                let p = t * s;
                let Some((k, d)) = Query::nearest(cached, target, &p, radius) else {
                    continue;
                };
                if d > params.max_correspondence_m {
                    continue;
                }
                let n = target.normals[k];
                let r = n.dot(&(p - target.points[k]));
                let w = if r.abs() <= params.huber_m {
                    1.0
                } else {
                    params.huber_m / r.abs()
                };
                let j = Vector6::new(
                    p.y * n.z - p.z * n.y,
                    p.z * n.x - p.x * n.z,
                    p.x * n.y - p.y * n.x,
                    n.x,
                    n.y,
                    n.z,
                );
                a.h += j * j.transpose() * w;
                a.g += j * (w * r);
                a.n += 1;
                a.sq += d * d;
                a.sq_plane += r * r;
            }
            a
        };
        let parts: Vec<Accum> = if source.len() >= 4096 {
            source
                .par_chunks(1024)
                .zip(queries.par_chunks_mut(1024))
                .map(acc)
                .collect()
        } else {
            vec![acc((source, &mut queries))]
        };
        let total = parts.into_iter().fold(Accum::default(), |a, b| a.add(&b));
        let (h, g, n_in, sq, sq_plane) = (total.h, total.g, total.n, total.sq, total.sq_plane);
        result.iterations = it + 1;
        result.fitness = n_in as f64 / source.len() as f64;
        if n_in < 6 {
            result.degenerate_dofs = 6;
            break;
        }
        result.inlier_rmse_m = (sq / n_in as f64).sqrt();
        result.inlier_plane_rmse_m = (sq_plane / n_in as f64).sqrt();
        // Solve in the well-constrained eigen-directions only.
        let eig = nalgebra::SymmetricEigen::new(h);
        let lmax = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
        let mut x = Vector6::zeros();
        let mut degenerate = 0;
        for k in 0..6 {
            let l = eig.eigenvalues[k];
            let v = eig.eigenvectors.column(k);
            if l > params.degenerate_ratio * lmax && l > 0.0 {
                x -= v * (v.dot(&g) / l);
            } else {
                degenerate += 1;
            }
        }
        result.degenerate_dofs = degenerate;
        t = exp_se3(&x) * t;
        if x.fixed_rows::<3>(3).norm() < params.converged_translation_m
            && x.fixed_rows::<3>(0).norm() < params.converged_rotation_rad
        {
            result.converged = true;
            break;
        }
    }
    result.target_from_source = t;
    result
}

/// The rigid transform b = T · a of three or more pairs (Kabsch).
pub fn kabsch(a: &[Point3<f64>], b: &[Point3<f64>]) -> Option<Isometry3<f64>> {
    let n = a.len() as f64;
    let ca = a.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / n;
    let cb = b.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / n;
    let mut h = Matrix3::zeros();
    for (p, q) in a.iter().zip(b) {
        h += (p.coords - ca) * (q.coords - cb).transpose();
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut d = Matrix3::identity();
    if (vt.transpose() * u.transpose()).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let r = vt.transpose() * d * u.transpose();
    let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    let t = cb - rot * ca;
    Some(Isometry3::from_parts(Translation3::from(t), rot))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kabsch_recovers_a_rigid_transform() {
        let t = Isometry3::from_parts(
            Translation3::new(0.3, -0.2, 1.1),
            UnitQuaternion::from_scaled_axis(Vector3::new(0.1, -0.4, 0.25)),
        );
        let a: Vec<Point3<f64>> = (0..7)
            .map(|k| {
                Point3::new(
                    k as f64 * 0.3,
                    (k * k) as f64 * 0.1 - 1.0,
                    2.0 - k as f64 * 0.2,
                )
            })
            .collect();
        let b: Vec<Point3<f64>> = a.iter().map(|p| t * p).collect();
        let got = kabsch(&a, &b).unwrap();
        assert!((got.translation.vector - t.translation.vector).norm() < 1e-9);
        assert!((got.rotation.inverse() * t.rotation).angle() < 1e-9);
    }
}
