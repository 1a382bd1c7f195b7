//! The Rust side of `bench/run fusion`: writes the clouds both tools work on, then times mrtmap's
//! voxel downsampling and point-to-plane ICP on them (medians of 5) and prints JSON.
//!
//! `cargo run --release -p mrtmap-scan --example open3d_peer -- RECORDING OUT_DIR`
//! - raw.ply: depth points of 40 frames in the world frame (true poses): the downsampling input.
//! - target.ply: raw downsampled at 3 cm, with normals (PCA of 3×3×3 voxel neighbourhoods).
//! - source.ply: one frame's points at stride 4, moved by a known transform (truth.json of the run).
#![allow(clippy::unwrap_used, clippy::print_stdout)]

use std::time::Instant;

use mrtmap_geometry::cloud::{pca_normal, voxel_downsample_from, voxel_key};
use mrtmap_geometry::icp::{IcpParams, IcpTarget, icp_point_to_plane};
use mrtmap_geometry::nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use mrtmap_io::{InterpolationLimits, Recording};
use mrtmap_scan::frame::{DepthSampling, RayTable, depth_points};

fn write_xyz(path: &std::path::Path, pts: &[Point3<f64>], normals: Option<&[Vector3<f64>]>) {
    let mut s = format!("ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n", pts.len()).into_bytes();
    if normals.is_some() {
        s.extend_from_slice(b"property double nx\nproperty double ny\nproperty double nz\n");
    }
    s.extend_from_slice(b"end_header\n");
    for (i, p) in pts.iter().enumerate() {
        for c in [p.x, p.y, p.z] {
            s.extend_from_slice(&c.to_le_bytes());
        }
        if let Some(n) = normals {
            for c in [n[i].x, n[i].y, n[i].z] {
                s.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    std::fs::write(path, s).unwrap();
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rec = Recording::open(std::path::Path::new(&args[1])).unwrap();
    let out = std::path::Path::new(&args[2]);
    std::fs::create_dir_all(out).unwrap();
    let gt = rec
        .groundtruth
        .clone()
        .unwrap_or_else(|| rec.trajectory.clone());
    let rays = RayTable::new(&rec.rig.depth);
    let lim = InterpolationLimits::default();
    let sampling = DepthSampling {
        stride: 1,
        ..Default::default()
    };
    let mut raw = Vec::new();
    for e in rec.depth.iter().step_by(rec.depth.len() / 40).take(40) {
        let d = depth_points(
            &rec.read_depth(e).unwrap(),
            &rays,
            rec.rig.depth_scale,
            &sampling,
        );
        let pose = gt.interpolate(e.t, &lim).unwrap();
        raw.extend(d.points.iter().map(|p| pose * p));
    }
    write_xyz(&out.join("raw.ply"), &raw, None);
    // Downsampling timing, on Open3D's grid (minimum bound minus half a voxel) so that both give
    // the same voxels.
    let mut times = Vec::new();
    let mut down = Vec::new();
    for _ in 0..5 {
        let t = Instant::now();
        let lo = raw.iter().fold(
            Point3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
            |a, p| Point3::new(a.x.min(p.x), a.y.min(p.y), a.z.min(p.z)),
        );
        down = voxel_downsample_from(&raw, 0.03, &(lo - Vector3::repeat(0.015)));
        times.push(t.elapsed().as_secs_f64());
    }
    let t_down = median(times);
    write_xyz(&out.join("down.ply"), &down, None);
    // Target normals: PCA over each voxel's 3×3×3 neighbourhood of centroids.
    let mut grid = std::collections::HashMap::new();
    for p in &down {
        grid.insert(voxel_key(p, 0.03), *p);
    }
    let (mut tp, mut tn) = (Vec::new(), Vec::new());
    for p in &down {
        let k = voxel_key(p, 0.03);
        let neigh: Vec<Point3<f64>> = (0..27)
            .filter_map(|i| {
                grid.get(&[k[0] + i % 3 - 1, k[1] + (i / 3) % 3 - 1, k[2] + i / 9 - 1])
                    .copied()
            })
            .collect();
        if let Some(n) = pca_normal(&neigh).filter(|_| neigh.len() >= 5) {
            tp.push(*p);
            tn.push(n);
        }
    }
    write_xyz(&out.join("target.ply"), &tp, Some(&tn));
    // Source: the best-constrained of every 50th frame (largest smallest eigenvalue of Σ n nᵀ /
    // N), moved by a known transform.
    let src_sampling = DepthSampling {
        stride: 4,
        ..Default::default()
    };
    let (e, d) = rec
        .depth
        .iter()
        .step_by(50)
        .map(|e| {
            (
                e,
                depth_points(
                    &rec.read_depth(e).unwrap(),
                    &rays,
                    rec.rig.depth_scale,
                    &src_sampling,
                ),
            )
        })
        .max_by(|a, b| {
            let score = |d: &mrtmap_scan::frame::DepthPoints| {
                let m = d
                    .normals
                    .iter()
                    .fold(mrtmap_geometry::nalgebra::Matrix3::zeros(), |m, n| {
                        m + n * n.transpose()
                    })
                    / d.normals.len().max(1) as f64;
                m.symmetric_eigenvalues().min()
            };
            score(&a.1).total_cmp(&score(&b.1))
        })
        .unwrap();
    let truth = Isometry3::from_parts(
        Translation3::new(0.03, -0.02, 0.015),
        UnitQuaternion::from_euler_angles(0.01, -0.012, 0.008),
    );
    let pose = gt.interpolate(e.t, &lim).unwrap();
    let src: Vec<Point3<f64>> = d
        .points
        .iter()
        .map(|p| truth.inverse() * (pose * p))
        .collect();
    write_xyz(&out.join("source.ply"), &src, None);
    std::fs::write(
        out.join("truth.txt"),
        format!("{:?}", truth.to_homogeneous().as_slice()),
    )
    .unwrap();
    let params = IcpParams {
        max_correspondence_m: 0.1,
        max_iterations: 30,
        huber_m: 1.0,
        ..IcpParams::default()
    };
    let mut times = Vec::new();
    let mut reg = None;
    for _ in 0..5 {
        let t = Instant::now();
        let target = IcpTarget::new(tp.clone(), tn.clone());
        reg = Some(icp_point_to_plane(
            &src,
            &target,
            &Isometry3::identity(),
            &params,
        ));
        times.push(t.elapsed().as_secs_f64());
    }
    let reg = reg.unwrap();
    let err = reg.target_from_source * truth.inverse();
    println!(
        "{{\"raw_points\": {}, \"downsampled\": {}, \"downsample_s\": {:.5}, \"target\": {}, \"source\": {}, \"icp_s\": {:.5}, \"icp_fitness\": {:.4}, \"icp_inlier_rmse_m\": {:.5}, \"icp_translation_error_m\": {:.6}, \"icp_rotation_error_deg\": {:.5}, \"icp_iterations\": {}}}",
        raw.len(),
        down.len(),
        t_down,
        tp.len(),
        src.len(),
        median(times),
        reg.fitness,
        reg.inlier_rmse_m,
        err.translation.vector.norm(),
        err.rotation.angle().to_degrees(),
        reg.iterations
    );
}
