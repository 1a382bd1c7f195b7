//! A frame's pose from its corners matched to a keyframe's, and how firmly the matches pin it.
//!
//! 1. The matches whose reference corner has a 3D point, with the current corner's own 3D point
//!    where it has one.
//! 2. RANSAC: triples of matches with 3D points at both ends give a pose by Kabsch (degenerate
//!    triples skipped); the pose with the most matches within the inlier radius, by reprojection,
//!    wins (the prediction, when given, competes as a hypothesis).
//! 3. Two rounds of Gauss–Newton on the reprojection error (Huber) over the matches within twice
//!    the inlier radius: the first with a wider Huber width, the second with the inlier radius.
//! 4. The inliers (within the inlier radius), their mean reprojection error, and the pose's
//!    information for the pose graph: the Gauss–Newton Hessian at the solution ([`information`]).

use mrtmap_geometry::icp::kabsch;
use mrtmap_geometry::nalgebra::{
    Isometry3, Matrix6, Point2, Point3, Translation3, UnitQuaternion, Vector3, Vector6,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{TrackParams, renormalised};

/// A point nearer than this in front of the camera (m) has no reprojection (behind it, or too
/// close to divide by its depth).
const MIN_DEPTH_M: f64 = 1e-3;

/// Gauss–Newton iterations at most.
const GN_ITERATIONS: usize = 10;

/// Gauss–Newton stops when a step moves the camera less than this (m)…
const GN_CONVERGED_TRANSLATION_M: f64 = 1e-6;

/// …and turns it less than this (rad).
const GN_CONVERGED_ROTATION_RAD: f64 = 1e-7;

/// A RANSAC triple whose 3D points span less than this (m²: the cross product's norm, twice the
/// triangle's area) is degenerate (nearly collinear or tiny) and gives no pose.
const MIN_TRIPLE_AREA_M2: f64 = 1e-3;

/// Rounds of Gauss–Newton refinement after RANSAC.
const REFINE_ROUNDS: usize = 2;

/// Each refinement round uses the matches within this many inlier radii of the pose so far, and
/// the first round's Huber width is as many inlier radii (the second's is one).
const REFINE_GATE: f64 = 2.0;

/// Reprojection residual (normalised coordinates) of reference point `x` seen at `obs` through
/// current_from_reference `t`.
fn residual(t: &Isometry3<f64>, x: &Point3<f64>, obs: &Point2<f64>) -> Option<(f64, f64)> {
    let y = t * x;
    (y.z > MIN_DEPTH_M).then(|| (y.x / y.z - obs.x, y.y / y.z - obs.y))
}

/// A reference point and where it was seen (normalised image coordinates).
type Projected = (Point3<f64>, Point2<f64>);

/// The Gauss–Newton normal equations of the reprojection error at `t` (Huber at `huber` in
/// normalised units), over a perturbation (ω, v) on the left of `t` (in the current camera's frame).
fn normal_equations(
    t: &Isometry3<f64>,
    pts: &[Projected],
    huber: f64,
) -> (Matrix6<f64>, Vector6<f64>) {
    let mut hmat = Matrix6::<f64>::zeros();
    let mut g = Vector6::<f64>::zeros();
    for (x, obs) in pts {
        let y = t * x;
        if y.z < MIN_DEPTH_M {
            continue;
        }
        let (iz, iz2) = (1.0 / y.z, 1.0 / (y.z * y.z));
        let e = [y.x * iz - obs.x, y.y * iz - obs.y];
        let norm = (e[0] * e[0] + e[1] * e[1]).sqrt();
        let w = if norm <= huber { 1.0 } else { huber / norm };
        // d(x/z, y/z)/dY, and dY/d(ω, v) = [−[Y]×, I].
        let jp = [[iz, 0.0, -y.x * iz2], [0.0, iz, -y.y * iz2]];
        for (k, row) in jp.iter().enumerate() {
            let jy = Vector3::new(row[0], row[1], row[2]);
            let jw = y.coords.cross(&jy); // row of jy · (−[Y]×) = (Y × jy)ᵀ
            let j = Vector6::new(jw.x, jw.y, jw.z, jy.x, jy.y, jy.z);
            hmat += w * j * j.transpose();
            g += w * j * e[k];
        }
    }
    (hmat, g)
}

/// Gauss–Newton on the reprojection error (Huber at `huber` in normalised units).
fn refine(mut t: Isometry3<f64>, pts: &[Projected], huber: f64) -> Isometry3<f64> {
    for _ in 0..GN_ITERATIONS {
        let (hmat, g) = normal_equations(&t, pts, huber);
        let Some(step) = hmat.cholesky().map(|c| c.solve(&(-g))) else {
            break;
        };
        let dw = Vector3::new(step[0], step[1], step[2]);
        let dv = Vector3::new(step[3], step[4], step[5]);
        let delta =
            Isometry3::from_parts(Translation3::from(dv), UnitQuaternion::from_scaled_axis(dw));
        t = renormalised(&(delta * t));
        if dv.norm() < GN_CONVERGED_TRANSLATION_M && dw.norm() < GN_CONVERGED_ROTATION_RAD {
            break;
        }
    }
    t
}

/// The information of reference_from_current found by [`refine`], for the pose graph: its
/// Hessian at the solution, reordered to the graph's (translation, rotation) and scaled to a
/// nominal reprojection error of [`GRAPH_SIGMA_PX`]. The edge's residual at the truth is minus
/// the current frame's perturbation, so the Hessian carries over; a view that pins a direction
/// weakly (a distant flat wall: turning and sliding look alike) pins the graph weakly there too.
fn information(t: &Isometry3<f64>, pts: &[Projected], huber: f64, fx: f64) -> Matrix6<f64> {
    let (h, _) = normal_equations(t, pts, huber);
    // (ω, v) → (v, ω).
    let map = [3, 4, 5, 0, 1, 2];
    Matrix6::from_fn(|i, j| h[(map[i], map[j])]) * (fx / GRAPH_SIGMA_PX).powi(2)
}

/// The reprojection error (px) an edge's information is scaled to. Only the ratios between edges
/// matter to the optimum; a nominal error of a few pixels keeps the numbers moderate.
const GRAPH_SIGMA_PX: f64 = 10.0;

/// A pose found from matches.
pub(super) struct Found {
    /// current_from_reference.
    pub(super) pose: Isometry3<f64>,
    /// Its information for the pose graph (see [`information`]).
    pub(super) information: Matrix6<f64>,
    /// Matches within the inlier radius (0: placed by depth alone).
    pub(super) inliers: usize,
    /// Their mean reprojection error (px).
    pub(super) reprojection_px: f64,
}

/// A frame's corners as pose estimation sees them: normalised coordinates and 3D points.
#[derive(Clone, Copy)]
pub(super) struct Seen<'a> {
    /// Normalised image coordinates.
    pub(super) norm: &'a [Point2<f64>],
    /// 3D points, where the depth has them.
    pub(super) xyz: &'a [Option<Point3<f64>>],
}

/// A match: the reference's 3D point, the current corner and its own 3D point.
type Observation = (Point3<f64>, Point2<f64>, Option<Point3<f64>>);

/// current_from_reference from matched corners: RANSAC on 3D–3D triples, scored by reprojection,
/// then Gauss–Newton on the inliers' reprojection errors.
pub(super) fn estimate(
    r_xyz: &[Option<Point3<f64>>],
    c: Seen<'_>,
    matches: &[(usize, usize)],
    prior: Option<&Isometry3<f64>>,
    fx: f64,
    p: &TrackParams,
    seed: u64,
) -> Option<Found> {
    let obs: Vec<Observation> = matches
        .iter()
        .filter_map(|&(i, j)| Some((r_xyz[i]?, c.norm[j], c.xyz[j])))
        .collect();
    if obs.len() < p.min_inliers {
        return None;
    }
    let tol = p.inlier_px / fx;
    let count = |t: &Isometry3<f64>| -> usize {
        obs.iter()
            .filter(|(x, o, _)| residual(t, x, o).is_some_and(|(a, b)| a * a + b * b < tol * tol))
            .count()
    };
    let both: Vec<usize> = (0..obs.len()).filter(|&k| obs[k].2.is_some()).collect();
    let mut best: Option<(usize, Isometry3<f64>)> = prior.map(|t| (count(t), *t));
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    if both.len() >= 3 {
        for _ in 0..p.ransac_iterations {
            let k: [usize; 3] = std::array::from_fn(|_| both[rng.random_range(0..both.len())]);
            if k[0] == k[1] || k[1] == k[2] || k[0] == k[2] {
                continue;
            }
            let a: Vec<Point3<f64>> = k.iter().map(|&i| obs[i].0).collect();
            let b: Vec<Point3<f64>> = k.iter().filter_map(|&i| obs[i].2).collect();
            // A degenerate triple (nearly collinear or tiny) gives no pose.
            let area = (a[1] - a[0]).cross(&(a[2] - a[0])).norm();
            if area < MIN_TRIPLE_AREA_M2 {
                continue;
            }
            let Some(t) = kabsch(&a, &b) else { continue };
            let n = count(&t);
            if best.as_ref().is_none_or(|(m, _)| n > *m) {
                best = Some((n, t));
            }
        }
    }
    let (_, mut t) = best?;
    for round in 0..REFINE_ROUNDS {
        let huber = if round == 0 { REFINE_GATE * tol } else { tol };
        let inl: Vec<Projected> = obs
            .iter()
            .filter(|(x, o, _)| {
                residual(&t, x, o)
                    .is_some_and(|(a, b)| a * a + b * b < REFINE_GATE * REFINE_GATE * tol * tol)
            })
            .map(|(x, o, _)| (*x, *o))
            .collect();
        if inl.len() < p.min_inliers {
            return None;
        }
        t = refine(t, &inl, huber);
    }
    let (inl, errs): (Vec<Projected>, Vec<f64>) = obs
        .iter()
        .filter_map(|(x, o, _)| {
            let (a, b) = residual(&t, x, o)?;
            let e = (a * a + b * b).sqrt();
            (e < tol).then_some(((*x, *o), e))
        })
        .unzip();
    (inl.len() >= p.min_inliers).then(|| Found {
        pose: t,
        information: information(&t, &inl, tol, fx),
        inliers: inl.len(),
        reprojection_px: fx * errs.iter().sum::<f64>() / errs.len() as f64,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_distant_flat_view_pins_turning_against_sliding_weakly() {
        // Corners on a 40°-wide patch of a wall, seen exactly; with a second wall nearer.
        let grid = |z: f64| -> Vec<Projected> {
            let mut v = Vec::new();
            for i in -6..=6 {
                for j in -4..=4 {
                    let x = Point3::new(i as f64 * 0.06 * z, j as f64 * 0.06 * z, z);
                    v.push((x, Point2::new(x.x / x.z, x.y / x.z)));
                }
            }
            v
        };
        let id = Isometry3::identity();
        // (t, θ) order: sliding right by 3 m·θ while turning by −θ about y keeps a wall at 3 m
        // nearly in place.
        let coupled = Vector6::new(1.0, 0.0, 0.0, 0.0, -1.0 / 3.0, 0.0).normalize();
        let slide = Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let ratio = |info: &Matrix6<f64>| {
            (coupled.transpose() * info * coupled)[0] / (slide.transpose() * info * slide)[0]
        };
        let flat = information(&id, &grid(3.0), 1.0, 600.0);
        let mut deep_pts = grid(3.0);
        deep_pts.extend(grid(1.0));
        let deep = information(&id, &deep_pts, 1.0, 600.0);
        assert!((flat - flat.transpose()).norm() < 1e-6 * flat.norm() && flat.cholesky().is_some());
        assert!(ratio(&flat) < 0.05, "flat wall: {}", ratio(&flat));
        assert!(
            ratio(&deep) > 5.0 * ratio(&flat),
            "deep {} flat {}",
            ratio(&deep),
            ratio(&flat)
        );
        // Nearer points pin the translation harder (as 1/z²).
        let near = information(&id, &grid(1.0), 1.0, 600.0);
        let r = near[(0, 0)] / flat[(0, 0)];
        assert!(
            (r - 9.0).abs() < 0.5,
            "near/far translation information {r}"
        );
    }
}
