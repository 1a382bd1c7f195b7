//! Pose-graph optimisation: node poses from odometry and loop-closure constraints, as RTAB-Map
//! keeps them in its `Link` table, solved with tiny-solver (Levenberg–Marquardt on SE(3), sparse
//! Cholesky, automatic derivatives). Used by the tracker's loop closure (mrtmap-track) and for
//! RTAB-Map databases that did not save their optimised graph (mrtmap-sources).
//!
//! Each edge says where node `to` sits in node `from`'s frame, with a 6×6 information matrix over
//! (x, y, z, roll, pitch, yaw) — RTAB-Map's order. The residual of an edge is
//! `U · [t; θ]` of `measured⁻¹ · from⁻¹ · to`, with `Uᵀ U` the information (so each edge counts as
//! much as the information says). The first node is held where it is (the gauge).

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use nalgebra::{Isometry3, Matrix6, Quaternion, Translation3, UnitQuaternion};
use tiny_solver::factors::Factor;
use tiny_solver::manifold::se3::{SE3, SE3Manifold};
use tiny_solver::na::{DVector, RealField};
use tiny_solver::optimizer::Optimizer;

/// One constraint between two nodes.
#[derive(Clone, Debug)]
pub struct Edge {
    /// From node.
    pub from: i64,
    /// To node.
    pub to: i64,
    /// from_T_to as measured.
    pub measured: Isometry3<f64>,
    /// Information over (x, y, z, roll, pitch, yaw); not positive definite, or not finite and
    /// below 1e12, → identity.
    pub information: Matrix6<f64>,
}

/// What the optimisation did.
#[derive(Clone, Debug)]
pub struct Optimised {
    /// world_from_node for every node the edges reach from the first node.
    pub poses: BTreeMap<i64, Isometry3<f64>>,
    /// Weighted squared error before and after.
    pub cost_before: f64,
    /// After.
    pub cost_after: f64,
    /// Edges used.
    pub edges: usize,
    /// Edges whose information was not positive definite (weighted as identity).
    pub identity_weighted: usize,
}

fn to_vec(p: &Isometry3<f64>) -> DVector<f64> {
    let q = p.rotation.quaternion();
    let t = p.translation.vector;
    DVector::from_vec(vec![q.i, q.j, q.k, q.w, t.x, t.y, t.z])
}

fn from_vec(v: &DVector<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(v[4], v[5], v[6]),
        UnitQuaternion::from_quaternion(Quaternion::new(v[3], v[0], v[1], v[2])),
    )
}

#[derive(Clone)]
struct Between {
    measured_inv: DVector<f64>,
    sqrt_info: Matrix6<f64>,
}

impl<T: RealField> Factor<T> for Between {
    fn residual_func(&self, p: &[DVector<T>]) -> DVector<T> {
        let a = SE3::from_vec(p[0].as_view());
        let b = SE3::from_vec(p[1].as_view());
        let z = SE3::from_vec(self.measured_inv.as_view()).cast::<T>();
        let l = (z * (a.inverse() * b)).log();
        // tiny-solver's log is (θ, t); RTAB-Map's information is over (t, θ).
        let e = [
            l[3].clone(),
            l[4].clone(),
            l[5].clone(),
            l[0].clone(),
            l[1].clone(),
            l[2].clone(),
        ];
        DVector::from_fn(6, |i, _| {
            let mut s = T::zero();
            for (j, ej) in e.iter().enumerate() {
                let u = self.sqrt_info[(i, j)];
                if u != 0.0 {
                    s += T::from_f64(u).unwrap_or_else(T::zero) * ej.clone();
                }
            }
            s
        })
    }
}

/// Holds the first node: a stiff prior on its 7 parameters.
struct Anchor {
    at: DVector<f64>,
}

impl<T: RealField> Factor<T> for Anchor {
    fn residual_func(&self, p: &[DVector<T>]) -> DVector<T> {
        let w = T::from_f64(1e4).unwrap_or_else(T::one);
        DVector::from_fn(7, |i, _| {
            (p[0][i].clone() - T::from_f64(self.at[i]).unwrap_or_else(T::zero)) * w.clone()
        })
    }
}

fn cost(initial: &HashMap<String, DVector<f64>>, factors: &[(Between, [String; 2])]) -> f64 {
    factors
        .iter()
        .map(|(f, [a, b])| {
            let r: DVector<f64> = f.residual_func(&[initial[a].clone(), initial[b].clone()]);
            r.norm_squared()
        })
        .sum()
}

/// Why a pose graph could not be optimised.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PoseGraphError {
    /// The graph has no nodes.
    #[error("no nodes")]
    NoNodes,
    /// An edge names a node without a pose.
    #[error("a link names node {0}, which has no pose")]
    UnknownNode(i64),
    /// An edge's transform is not finite or not plausible.
    #[error("the link {from} → {to} has a non-finite or implausible transform")]
    BadTransform {
        /// First node.
        from: i64,
        /// Second node.
        to: i64,
    },
    /// Levenberg–Marquardt did not converge.
    #[error("the pose graph optimisation did not converge")]
    NotConverged,
    /// The result holds non-finite poses.
    #[error("the pose graph optimisation diverged (non-finite poses)")]
    Diverged,
}

/// Refuses edges naming unknown nodes or carrying implausible transforms.
fn check_edges(
    initial: &BTreeMap<i64, Isometry3<f64>>,
    edges: &[Edge],
) -> Result<(), PoseGraphError> {
    for e in edges {
        for id in [e.from, e.to] {
            if !initial.contains_key(&id) {
                return Err(PoseGraphError::UnknownNode(id));
            }
        }
        let m = e.measured;
        if !m
            .translation
            .vector
            .iter()
            .all(|x| x.is_finite() && x.abs() < 1e6)
            || !m.rotation.coords.iter().all(|x| x.is_finite())
        {
            return Err(PoseGraphError::BadTransform {
                from: e.from,
                to: e.to,
            });
        }
    }
    Ok(())
}

/// The start: the first node where it is, the others along a breadth-first spanning tree of the
/// edges (as g2o and RTAB-Map start), so sessions whose odometry frames differ start together.
/// Nodes the edges do not connect to the first are absent.
fn spanning_start(
    first: i64,
    first_pose: &Isometry3<f64>,
    edges: &[Edge],
) -> HashMap<i64, Isometry3<f64>> {
    let mut start: HashMap<i64, Isometry3<f64>> = HashMap::from([(first, *first_pose)]);
    let mut by_node: HashMap<i64, Vec<(i64, Isometry3<f64>)>> = HashMap::new();
    for e in edges.iter().filter(|e| e.from != e.to) {
        by_node.entry(e.from).or_default().push((e.to, e.measured));
        by_node
            .entry(e.to)
            .or_default()
            .push((e.from, e.measured.inverse()));
    }
    let mut queue = std::collections::VecDeque::from([first]);
    while let Some(n) = queue.pop_front() {
        let at = start[&n];
        for (m, z) in by_node.get(&n).map(Vec::as_slice).unwrap_or(&[]) {
            if !start.contains_key(m) {
                start.insert(*m, at * z);
                queue.push_back(*m);
            }
        }
    }
    start
}

/// The variable name of a node.
fn name(id: i64) -> String {
    format!("x{id}")
}

/// A Between factor per edge among the reached nodes, with the square root of its information
/// (identity where the information is unusable), and how many were weighted as identity.
fn between_factors(
    edges: &[Edge],
    reached: &std::collections::BTreeSet<i64>,
) -> (Vec<(Between, [String; 2])>, usize) {
    let mut factors = Vec::new();
    let mut identity_weighted = 0;
    for e in edges
        .iter()
        .filter(|e| e.from != e.to && reached.contains(&e.from))
    {
        let info = (e.information + e.information.transpose()) * 0.5;
        let sqrt_info = match info.cholesky() {
            // RTAB-Map's largest is 1/0.0001² = 1e8; far beyond is a broken matrix.
            Some(c) if info.iter().all(|x| x.is_finite() && x.abs() < 1e12) => c.l().transpose(),
            _ => {
                identity_weighted += 1;
                Matrix6::identity()
            }
        };
        let f = Between {
            measured_inv: to_vec(&e.measured.inverse()),
            sqrt_info,
        };
        factors.push((f, [name(e.from), name(e.to)]));
    }
    (factors, identity_weighted)
}

/// Optimises the graph. Of `initial`, the first node's pose is kept (the gauge) and the ids say
/// which nodes exist: the others start along a spanning tree of the edges, whatever frame their
/// odometry was in. Nodes the edges do not connect to the first node are left out of the result;
/// edges naming unknown nodes are an error.
pub fn optimise(
    initial: &BTreeMap<i64, Isometry3<f64>>,
    edges: &[Edge],
) -> Result<Optimised, PoseGraphError> {
    let Some((&first, first_pose)) = initial.iter().next() else {
        return Err(PoseGraphError::NoNodes);
    };
    check_edges(initial, edges)?;
    let start = spanning_start(first, first_pose, edges);
    // The nodes connected to the first one are the ones the tree reached; only their edges count.
    let reached: std::collections::BTreeSet<i64> = start.keys().copied().collect();
    let values: HashMap<String, DVector<f64>> = reached
        .iter()
        .map(|&id| (name(id), to_vec(&start[&id])))
        .collect();
    let (factors, identity_weighted) = between_factors(edges, &reached);
    let mut problem = tiny_solver::Problem::new();
    for (f, names) in &factors {
        problem.add_residual_block(6, &[&names[0], &names[1]], Box::new(f.clone()), None);
    }
    problem.add_residual_block(
        7,
        &[&name(first)],
        Box::new(Anchor {
            at: to_vec(first_pose),
        }),
        None,
    );
    for id in &reached {
        problem.set_variable_manifold(&name(*id), Arc::new(SE3Manifold));
    }
    let cost_before = cost(&values, &factors);
    let result = tiny_solver::LevenbergMarquardtOptimizer::default()
        .optimize(&problem, &values, None)
        .ok_or(PoseGraphError::NotConverged)?;
    let cost_after = cost(&result, &factors);
    let poses: BTreeMap<i64, Isometry3<f64>> = reached
        .iter()
        .filter_map(|&id| result.get(&name(id)).map(|v| (id, from_vec(v))))
        .collect();
    let finite = |p: &Isometry3<f64>| {
        p.translation.vector.iter().all(|x| x.is_finite())
            && p.rotation.coords.iter().all(|x| x.is_finite())
    };
    if poses.len() != reached.len() || !poses.values().all(finite) || !cost_after.is_finite() {
        return Err(PoseGraphError::Diverged);
    }
    Ok(Optimised {
        poses,
        cost_before,
        cost_after,
        edges: factors.len(),
        identity_weighted,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// A loop around a 4 m × 3 m room: 40 nodes, turning as it goes.
    fn truth() -> BTreeMap<i64, Isometry3<f64>> {
        (0..40)
            .map(|i| {
                let a = i as f64 / 40.0 * std::f64::consts::TAU;
                (
                    i as i64 + 1,
                    Isometry3::new(
                        Vector3::new(2.0 * a.cos(), 1.5 * a.sin(), 1.2 + 0.1 * (3.0 * a).sin()),
                        Vector3::new(0.05 * a.sin(), 0.0, a + 1.0),
                    ),
                )
            })
            .collect()
    }

    fn info(sigma_t: f64, sigma_r: f64) -> Matrix6<f64> {
        Matrix6::from_diagonal(&nalgebra::Vector6::new(
            1.0 / sigma_t.powi(2),
            1.0 / sigma_t.powi(2),
            1.0 / sigma_t.powi(2),
            1.0 / sigma_r.powi(2),
            1.0 / sigma_r.powi(2),
            1.0 / sigma_r.powi(2),
        ))
    }

    fn max_error(a: &BTreeMap<i64, Isometry3<f64>>, b: &BTreeMap<i64, Isometry3<f64>>) -> f64 {
        a.iter()
            .map(|(id, p)| (p.translation.vector - b[id].translation.vector).norm())
            .fold(0.0, f64::max)
    }

    #[test]
    fn loop_closures_remove_odometry_drift() {
        let truth = truth();
        let ids: Vec<i64> = truth.keys().copied().collect();
        // Odometry: each step's yaw 0.01 rad too large and its length 2 % too long.
        let bias = Isometry3::new(Vector3::zeros(), Vector3::new(0.0, 0.0, 0.01));
        let mut edges = Vec::new();
        let mut odom = BTreeMap::from([(ids[0], truth[&ids[0]])]);
        for w in ids.windows(2) {
            let rel = truth[&w[0]].inverse() * truth[&w[1]];
            let meas = Isometry3::from_parts(
                Translation3::from(rel.translation.vector * 1.02),
                rel.rotation,
            ) * bias;
            odom.insert(w[1], odom[&w[0]] * meas);
            edges.push(Edge {
                from: w[0],
                to: w[1],
                measured: meas,
                information: info(0.02, 0.01),
            });
        }
        // Loop closures, exact and trusted: the last node sees the first, and two chords.
        for (a, b) in [(40, 1), (30, 10), (20, 1)] {
            edges.push(Edge {
                from: a,
                to: b,
                measured: truth[&a].inverse() * truth[&b],
                information: info(0.002, 0.001),
            });
        }
        let before = max_error(&odom, &truth);
        let r = optimise(&odom, &edges).unwrap();
        let after = max_error(&r.poses, &truth);
        println!("largest position error: odometry {before:.3} m, optimised {after:.4} m");
        assert_eq!(r.poses.len(), 40);
        assert_eq!((r.edges, r.identity_weighted), (42, 0));
        assert!(before > 0.5, "odometry drift {before} m");
        assert!(after < before / 5.0, "{before} m → {after} m");
        assert!(
            r.cost_after < r.cost_before / 10.0,
            "{} → {}",
            r.cost_before,
            r.cost_after
        );
        // The first node stays put.
        assert!((r.poses[&1].translation.vector - truth[&1].translation.vector).norm() < 1e-6);
    }

    #[test]
    fn a_second_session_in_another_frame_is_joined_by_its_closures() {
        // Nodes 21–40 are a second session: its odometry frame is turned 3.2 rad about a tilted axis and 47 m away, so
        // their initial poses are far off; neighbour links inside each session, closures between.
        let truth = truth();
        let away = Isometry3::new(Vector3::new(40.0, -25.0, 3.0), Vector3::new(1.2, -0.8, 2.9));
        let initial: BTreeMap<i64, Isometry3<f64>> = truth
            .iter()
            .map(|(&id, p)| (id, if id > 20 { away * p } else { *p }))
            .collect();
        let rel = |a: i64, b: i64| truth[&a].inverse() * truth[&b];
        let mut edges: Vec<Edge> = (1..40)
            .filter(|&i| i != 20)
            .map(|i| Edge {
                from: i,
                to: i + 1,
                measured: rel(i, i + 1),
                information: info(0.01, 0.01),
            })
            .collect();
        for (a, b) in [(21, 20), (30, 10), (40, 1)] {
            edges.push(Edge {
                from: a,
                to: b,
                measured: rel(a, b),
                information: info(0.005, 0.005),
            });
        }
        let r = optimise(&initial, &edges).unwrap();
        assert_eq!(r.poses.len(), 40);
        assert!(
            max_error(&r.poses, &truth) < 1e-4,
            "{}",
            max_error(&r.poses, &truth)
        );
        assert!(r.cost_after < 1e-6, "{}", r.cost_after);
    }

    #[test]
    fn consistent_edges_recover_the_truth_from_a_bad_start() {
        let truth = truth();
        let ids: Vec<i64> = truth.keys().copied().collect();
        let mut edges: Vec<Edge> = ids
            .windows(2)
            .map(|w| Edge {
                from: w[0],
                to: w[1],
                measured: truth[&w[0]].inverse() * truth[&w[1]],
                // All zeros, as some writers leave it: weighted as identity.
                information: Matrix6::zeros(),
            })
            .collect();
        edges.push(Edge {
            from: 40,
            to: 1,
            measured: truth[&40].inverse() * truth[&1],
            information: Matrix6::identity(),
        });
        let start: BTreeMap<i64, Isometry3<f64>> = truth
            .iter()
            .map(|(&id, p)| {
                let k = id as f64;
                let off = Isometry3::new(
                    Vector3::new(0.05 * (k * 0.7).sin(), 0.04 * (k * 1.3).cos(), 0.03),
                    Vector3::new(0.0, 0.02 * (k * 0.9).sin(), 0.03 * (k * 0.5).cos()),
                );
                (id, if id == 1 { *p } else { p * off })
            })
            .collect();
        let r = optimise(&start, &edges).unwrap();
        assert_eq!(r.identity_weighted, 39);
        assert!(
            max_error(&r.poses, &truth) < 1e-4,
            "{}",
            max_error(&r.poses, &truth)
        );
        for (id, p) in &r.poses {
            assert!(p.rotation.angle_to(&truth[id].rotation) < 1e-4, "node {id}");
        }
    }

    #[test]
    fn unknown_nodes_and_disconnected_parts() {
        let truth = truth();
        let e = Edge {
            from: 1,
            to: 99,
            measured: Isometry3::identity(),
            information: Matrix6::identity(),
        };
        assert!(
            optimise(&truth, &[e])
                .unwrap_err()
                .to_string()
                .contains("node 99")
        );
        // Only nodes 1–3 are linked to the first: the rest, linked among themselves or not at
        // all, are left out.
        let edges: Vec<Edge> = [(1, 2), (2, 3), (5, 6), (6, 7)]
            .iter()
            .map(|&(a, b)| Edge {
                from: a,
                to: b,
                measured: truth[&a].inverse() * truth[&b],
                information: Matrix6::identity(),
            })
            .collect();
        let r = optimise(&truth, &edges).unwrap();
        assert_eq!(r.poses.keys().copied().collect::<Vec<_>>(), vec![1, 2, 3]);
        assert_eq!(r.edges, 2);
        assert!(optimise(&BTreeMap::new(), &[]).is_err());
        // Implausible measurements are refused, not optimised into NaN.
        let wild = Edge {
            from: 1,
            to: 2,
            measured: Isometry3::translation(1e30, 0.0, 0.0),
            information: Matrix6::identity(),
        };
        assert!(
            optimise(&truth, &[wild])
                .unwrap_err()
                .to_string()
                .contains("1 → 2")
        );
        // An information matrix of 1e300 counts as identity.
        let huge = Edge {
            from: 1,
            to: 2,
            measured: truth[&1].inverse() * truth[&2],
            information: Matrix6::identity() * 1e300,
        };
        assert_eq!(optimise(&truth, &[huge]).unwrap().identity_weighted, 1);
    }
}
