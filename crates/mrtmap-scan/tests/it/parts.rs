use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::cloud::voxel_downsample;
use mrtmap_geometry::icp::{IcpParams, IcpTarget, icp_point_to_plane};
use mrtmap_geometry::nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use mrtmap_io::{ThermalCloud, read_cloud_ply, write_cloud_ply};
use mrtmap_scan::frame::ThermalImage;
use mrtmap_scan::observe::{ObservationParams, observe};

/// Points on the inside of a box room (three visible walls, floor, ceiling corner region).
fn room_points() -> (Vec<Point3<f64>>, Vec<Vector3<f64>>) {
    let mut p = Vec::new();
    let mut n = Vec::new();
    let s = 0.05;
    for i in 0..80 {
        for j in 0..50 {
            let (a, b) = (i as f64 * s, j as f64 * s);
            p.push(Point3::new(a, 0.0, b));
            n.push(Vector3::y());
            p.push(Point3::new(0.0, a * 0.8, b));
            n.push(Vector3::x());
            p.push(Point3::new(a, b * 1.3, 0.0));
            n.push(Vector3::z());
        }
    }
    (p, n)
}

/// ICP recovers a known transform (within 1 mm and 0.05°).
#[test]
fn icp_recovers_a_known_transform() {
    let (p, n) = room_points();
    let target = IcpTarget::new(p.clone(), n);
    let truth = Isometry3::from_parts(
        Translation3::new(0.02, -0.015, 0.01),
        UnitQuaternion::from_euler_angles(0.01, -0.008, 0.015),
    );
    // Every other point: the three planes are interleaved, so all of them stay in the source.
    let source: Vec<Point3<f64>> = p.iter().step_by(2).map(|q| truth.inverse() * q).collect();
    let reg = icp_point_to_plane(
        &source,
        &target,
        &Isometry3::identity(),
        &IcpParams::default(),
    );
    let err = reg.target_from_source * truth.inverse();
    assert!(
        err.translation.vector.norm() < 1e-3,
        "{} {reg:?}",
        err.translation.vector.norm()
    );
    assert!(err.rotation.angle().to_degrees() < 0.05);
    assert!(
        reg.fitness > 0.99 && reg.converged && reg.degenerate_dofs == 0,
        "{reg:?}"
    );
}

/// A single plane leaves three directions free: they are reported and left unchanged.
#[test]
fn icp_reports_degenerate_directions() {
    let p: Vec<Point3<f64>> = (0..2500)
        .map(|k| Point3::new((k % 50) as f64 * 0.04, (k / 50) as f64 * 0.04, 0.0))
        .collect();
    let n = vec![Vector3::z(); p.len()];
    let target = IcpTarget::new(p.clone(), n);
    let source: Vec<Point3<f64>> = p.iter().map(|q| q + Vector3::new(0.0, 0.0, 0.01)).collect();
    let reg = icp_point_to_plane(
        &source,
        &target,
        &Isometry3::identity(),
        &IcpParams::default(),
    );
    assert_eq!(reg.degenerate_dofs, 3, "{reg:?}");
    let t = reg.target_from_source.translation.vector;
    assert!(
        (t.z + 0.01).abs() < 1e-6 && t.x.abs() < 1e-9 && t.y.abs() < 1e-9,
        "{t}"
    );
}

#[test]
fn voxel_downsample_averages_each_voxel() {
    let pts = vec![
        Point3::new(0.01, 0.01, 0.01),
        Point3::new(0.02, 0.02, 0.02),
        Point3::new(0.5, 0.5, 0.5),
    ];
    let d = voxel_downsample(&pts, 0.1);
    assert_eq!(d.len(), 2);
    assert!((d[0] - Point3::new(0.015, 0.015, 0.015)).norm() < 1e-12);
}

/// A point hidden from the thermal camera behind a nearer one on the same line of sight takes no
/// temperature; a bilinear sample across a hot/cold edge is dropped as a mixed pixel.
#[test]
fn visibility_and_mixed_pixels() {
    let cam = PinholeCamera::new(16, 12, 10.0, 10.0, 7.5, 5.5);
    let mut img = ThermalImage {
        width: 16,
        height: 12,
        kelvin: vec![293.15; 16 * 12],
    };
    for v in 0..12 {
        for u in 8..16 {
            img.kelvin[v * 16 + u] = 303.15;
        }
    }
    let pose = Isometry3::identity();
    // A wall at 2 m filling the view and, in front of its left part, a post at 1 m.
    let mut pts = Vec::new();
    let mut nrm = Vec::new();
    for k in 0..40 {
        let x = -1.2 + k as f64 * 0.06;
        pts.push(Point3::new(x, 0.0, 2.0));
        nrm.push(-Vector3::z());
    }
    let hidden = Point3::new(-1.0, 0.1, 2.0);
    let post = Point3::new(-0.5, 0.05, 1.0); // on the line of sight to `hidden`
    pts.push(hidden);
    nrm.push(-Vector3::z());
    pts.push(post);
    nrm.push(-Vector3::z());
    let (obs, counts) = observe(&pts, &nrm, &pose, &cam, &img, &ObservationParams::default());
    assert!(counts.occluded >= 1, "{counts:?}");
    assert!(
        !obs.iter().any(|o| (o.p - hidden).norm() < 1e-9),
        "the hidden point took a temperature"
    );
    assert!(obs.iter().any(|o| (o.p - post).norm() < 1e-9));
    assert!(
        counts.edge >= 1,
        "samples straddling the 10 K edge are dropped: {counts:?}"
    );
    assert!(
        obs.iter()
            .all(|o| (o.t_k - 293.15).abs() < 1e-4 || (o.t_k - 303.15).abs() < 1e-4),
        "no mixed values kept (f32 pixels)"
    );
}

#[test]
fn ply_round_trip_keeps_every_field() {
    let dir = tempfile::tempdir().unwrap();
    let mut c = ThermalCloud::default();
    c.push([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], 294.15, 0.1, 7);
    c.push([-1.5, 0.25, 2.0], [1.0, 0.0, 0.0], 285.0, 0.0, 1);
    let p = dir.path().join("c.ply");
    write_cloud_ply(&p, &c, "test", &[("surface_id", &[3, -1])]).unwrap();
    let text = std::fs::read(&p).unwrap();
    let header = String::from_utf8_lossy(
        &text[..text.windows(10).position(|w| w == b"end_header").unwrap()],
    );
    for prop in [
        "float x",
        "float nx",
        "float temperature_c",
        "float temperature_std",
        "int observations",
        "uchar red",
        "int surface_id",
    ] {
        assert!(header.contains(prop), "{header}");
    }
    let back = read_cloud_ply(&p).unwrap();
    assert_eq!(back.cloud.positions, c.positions);
    assert_eq!(back.cloud.observations, c.observations);
    assert!((back.cloud.temperature_k[0] - 294.15).abs() < 1e-3);
    assert_eq!(back.extra, vec![("surface_id".to_string(), vec![3, -1])]);
    std::fs::write(&p, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n").unwrap();
    assert!(
        read_cloud_ply(&p)
            .unwrap_err()
            .to_string()
            .contains("no 'temperature_c' property")
    );
}
