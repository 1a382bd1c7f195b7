//! The Rust side of `bench/run posegraph`: reads a g2o pose graph (`VERTEX_SE3:QUAT`,
//! `EDGE_SE3:QUAT` with its 6×6 upper-triangular information over x y z qx qy qz), optimises it
//! with `mrtmap_geometry::pose_graph` (as `convert` does for an RTAB-Map database), writes the poses
//! as g2o vertices and prints JSON with the median time of 3 runs.
//!
//! `cargo run --release -p mrtmap-track --example pose_graph_peer -- IN.g2o OUT.g2o`
#![allow(clippy::unwrap_used, clippy::print_stdout, clippy::expect_used)]

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::time::Instant;

use mrtmap_geometry::nalgebra::{Isometry3, Matrix6, Quaternion, Translation3, UnitQuaternion};
use mrtmap_geometry::pose_graph::{Edge, optimise};

fn pose(v: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_quaternion(Quaternion::new(v[6], v[3], v[4], v[5])),
    )
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let text = std::fs::read_to_string(&args[1]).expect("read the g2o file");
    let mut nodes = BTreeMap::new();
    let mut edges = Vec::new();
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let num = |s: &[&str]| {
            s.iter()
                .map(|x| x.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        };
        match f.first() {
            Some(&"VERTEX_SE3:QUAT") => {
                nodes.insert(f[1].parse::<i64>().unwrap(), pose(&num(&f[2..9])));
            }
            Some(&"EDGE_SE3:QUAT") => {
                let v = num(&f[3..31]);
                // Upper triangle, row by row; g2o orders the rotation part by quaternion
                // vector (≈ half the angle): × 2 per rotational index to get radians.
                let mut info = Matrix6::zeros();
                let mut k = 7;
                for i in 0..6 {
                    for j in i..6 {
                        let s = (if i >= 3 { 0.5 } else { 1.0 }) * (if j >= 3 { 0.5 } else { 1.0 });
                        info[(i, j)] = v[k] * s;
                        info[(j, i)] = v[k] * s;
                        k += 1;
                    }
                }
                edges.push(Edge {
                    from: f[1].parse().unwrap(),
                    to: f[2].parse().unwrap(),
                    measured: pose(&v[..7]),
                    information: info,
                });
            }
            _ => {}
        }
    }
    let mut times = Vec::new();
    let mut result = None;
    for _ in 0..3 {
        let t = Instant::now();
        result = Some(optimise(&nodes, &edges).expect("optimise"));
        times.push(t.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let r = result.unwrap();
    let mut out = String::new();
    for (id, p) in &r.poses {
        let q = p.rotation.quaternion();
        let t = p.translation.vector;
        writeln!(
            out,
            "VERTEX_SE3:QUAT {id} {} {} {} {} {} {} {}",
            t.x, t.y, t.z, q.i, q.j, q.k, q.w
        )
        .unwrap();
    }
    std::fs::write(&args[2], out).expect("write the result");
    println!(
        "{{\"nodes\": {}, \"edges\": {}, \"seconds\": {}, \"cost_before\": {}, \"cost_after\": {}}}",
        r.poses.len(),
        r.edges,
        times[1],
        r.cost_before,
        r.cost_after
    );
}
