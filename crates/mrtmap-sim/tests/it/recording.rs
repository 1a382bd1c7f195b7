use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Vector3};
use mrtmap_geometry::polygon::{self, Containment, PlaneFrame};
use mrtmap_geometry::{BvhRayCaster, RayCaster};
use mrtmap_io::masks::{labels_path, read_mask_labels};
use mrtmap_io::{InterpolationLimits, Recording, read_image16};
use mrtmap_physics::ZERO_CELSIUS_K;
use mrtmap_radiation::RadiantScene;
use mrtmap_sim::{NoiseLevel, Truth, preset};

use crate::common::quick;

fn pose(t: &mrtmap_io::PoseFile) -> Isometry3<f64> {
    let q = mrtmap_io::unit_quaternion(t.rotation_xyzw).unwrap();
    Isometry3::from_parts(
        mrtmap_geometry::nalgebra::Translation3::new(
            t.translation[0],
            t.translation[1],
            t.translation[2],
        ),
        q,
    )
}

fn truth(dir: &std::path::Path) -> Truth {
    serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).unwrap()).unwrap()
}

/// Distance from a point to a planar polygon (3D): off the plane, and beyond the outline.
fn distance_to_polygon(f: &PlaneFrame, poly2: &[Point2<f64>], p: &Point3<f64>) -> f64 {
    let q = f.to_2d(p);
    let off = f.signed_distance(p).abs();
    let outside = if polygon::point_in_polygon(&q, poly2, 0.0) == Containment::Outside {
        (0..poly2.len())
            .map(|i| polygon::point_segment_distance(&q, &poly2[i], &poly2[(i + 1) % poly2.len()]))
            .fold(f64::INFINITY, f64::min)
    } else {
        0.0
    };
    off.hypot(outside)
}

/// Distance from a point to the nearest surface or furniture face of the truth scene (world).
fn distance_to_scene(scene: &RadiantScene, p: &Point3<f64>) -> f64 {
    let mut best = f64::INFINITY;
    for s in &scene.surfaces {
        best = best.min(distance_to_polygon(&s.frame, &s.polygon_2d, p));
    }
    for o in &scene.occluders {
        for tri in o.triangles().chunks(2) {
            let quad = [tri[0][0], tri[0][1], tri[0][2], tri[1][2]];
            let f = PlaneFrame::of_polygon(&quad).unwrap();
            let q2: Vec<Point2<f64>> = quad.iter().map(|v| f.to_2d(v)).collect();
            best = best.min(distance_to_polygon(&f, &q2, p));
        }
    }
    best
}

/// Noise-free depth back-projected through the true poses lies on the room's surfaces within 1 mm.
#[test]
fn noise_free_depth_lies_on_the_surfaces() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scan");
    quick("office", NoiseLevel::None, 3.0, &out);
    let rec = Recording::open(&out).unwrap();
    let gt = rec.groundtruth.clone().unwrap();
    let scene = RadiantScene::new(&truth(&out).scene).unwrap();
    let cam = rec.rig.depth;
    let lim = InterpolationLimits::default();
    let (mut n, mut worst) = (0usize, 0.0f64);
    for e in rec.depth.iter().step_by(7) {
        let img = rec.read_depth(e).unwrap();
        let world_from_depth = gt.interpolate(e.t, &lim).unwrap();
        for v in (0..cam.height).step_by(3) {
            for u in (0..cam.width).step_by(3) {
                let raw = img.get(u, v);
                assert!(raw > 0, "noise-free depth has no invalid pixels");
                let z = raw as f64 / rec.rig.depth_scale;
                let p = world_from_depth
                    * Point3::from(cam.unproject(&Point2::new(u as f64, v as f64)) * z);
                let d = distance_to_scene(&scene, &p);
                worst = worst.max(d);
                n += 1;
            }
        }
    }
    assert!(n > 10_000, "{n}");
    println!(
        "noise-free depth: {n} points, worst distance to the surfaces {:.3} mm",
        worst * 1e3
    );
    assert!(worst < 1e-3, "worst distance {worst} m");
}

/// Noise-free thermal pixels equal the temperature of the surface point their centre ray sees
/// through the rig extrinsic, feature borders included, checked by an independent BVH trace of the
/// truth scene (a room without gradients, so the scene's temperatures are exact).
#[test]
fn noise_free_thermal_equals_the_surface_seen() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scan");
    quick("l-shaped", NoiseLevel::None, 3.0, &out);
    let rec = Recording::open(&out).unwrap();
    let gt = rec.groundtruth.clone().unwrap();
    let scene = RadiantScene::new(&truth(&out).scene).unwrap();
    // Independent tracer: triangles of surfaces and furniture, owners, features by polygon.
    let mut tris = Vec::new();
    let mut owner: Vec<(Option<usize>, f64)> = Vec::new();
    for (si, s) in scene.surfaces.iter().enumerate() {
        for t in polygon::triangulate(&s.polygon_2d).unwrap() {
            tris.push([s.polygon[t[0]], s.polygon[t[1]], s.polygon[t[2]]]);
            owner.push((Some(si), s.temperature.celsius()));
        }
    }
    for o in &scene.occluders {
        for t in o.triangles() {
            tris.push(t);
            owner.push((None, o.temperature.celsius()));
        }
    }
    let caster = BvhRayCaster::new(&tris);
    let cam = rec.rig.thermal;
    let lim = InterpolationLimits::default();
    let (mut n, mut border, mut worst) = (0usize, 0usize, 0.0f64);
    for e in rec.thermal.iter().step_by(3) {
        let img = rec.read_thermal(e).unwrap();
        let world_from_thermal = gt.interpolate(e.t, &lim).unwrap() * rec.rig.depth_from_thermal;
        for v in 0..cam.height {
            for u in 0..cam.width {
                let d = (world_from_thermal.rotation
                    * cam.unproject(&Point2::new(u as f64, v as f64)))
                .normalize();
                let o = Point3::from(world_from_thermal.translation.vector);
                let hit = caster.cast(&o, &d, f64::INFINITY).unwrap();
                let (surface, mut t_c) = owner[hit.triangle as usize];
                let p = o + d * hit.t;
                let mut near_edge = false;
                if let Some(si) = surface {
                    let s = &scene.surfaces[si];
                    let q = s.frame.to_2d(&p);
                    for f in &s.features {
                        match polygon::point_in_polygon(&q, &f.polygon_2d, 1e-4) {
                            Containment::Inside => t_c = f.temperature.celsius(),
                            Containment::Boundary => near_edge = true,
                            Containment::Outside => {}
                        }
                    }
                }
                if near_edge {
                    continue; // within 0.1 mm of a border: f32 rays may fall either side
                }
                let got = rec.rig.thermal_encoding.kelvin(img.get(u, v)) - ZERO_CELSIUS_K;
                let neighbours_differ =
                    [(1i32, 0i32), (-1, 0), (0, 1), (0, -1)]
                        .iter()
                        .any(|(du, dv)| {
                            let (uu, vv) = (u as i32 + du, v as i32 + dv);
                            uu >= 0
                                && vv >= 0
                                && (uu as u32) < cam.width
                                && (vv as u32) < cam.height
                                && img.get(uu as u32, vv as u32).abs_diff(img.get(u, v)) > 50
                        });
                border += neighbours_differ as usize;
                worst = worst.max((got - t_c).abs());
                n += 1;
            }
        }
    }
    assert!(n > 100_000, "{n}");
    assert!(
        border > 200,
        "the frames must include feature and furniture borders: {border}"
    );
    println!(
        "noise-free thermal: {n} pixels ({border} at borders), worst |T − truth| {worst:.4} K"
    );
    assert!(
        worst <= 0.0051,
        "worst |T − truth| = {worst} K (quantisation is 0.005 K)"
    );
}

/// The recording reads back through the layout reader with no warnings; timestamps, rates,
/// quaternions and the world frame are as documented.
#[test]
fn recording_reads_back_consistently() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scan");
    let (cfg, s) = quick("radiant-ceiling", NoiseLevel::Realistic, 4.0, &out);
    assert!(!dir.path().join("scan.partial").exists());
    let rec = Recording::open(&out).unwrap();
    assert!(rec.warnings.is_empty(), "{:?}", rec.warnings);
    assert_eq!(
        (
            rec.depth.len(),
            rec.thermal.len(),
            rec.rgb.len(),
            rec.masks.len()
        ),
        (s.depth_frames, s.thermal_frames, s.rgb_frames, s.rgb_frames)
    );
    // Rates: 30 / 8.7 / 5 Hz over 4 s.
    for (list, hz) in [
        (&rec.depth, cfg.depth_hz),
        (&rec.thermal, cfg.thermal_hz),
        (&rec.rgb, cfg.rgb_hz),
    ] {
        let span = list.last().unwrap().t - list[0].t;
        let rate = (list.len() - 1) as f64 / span;
        assert!((rate - hz).abs() / hz < 0.02, "{rate} vs {hz}");
        assert!(list.windows(2).all(|w| w[1].t > w[0].t));
    }
    // Streams on their own clocks: thermal frames do not coincide with depth frames.
    let min_gap = rec
        .thermal
        .iter()
        .map(|e| {
            rec.depth
                .iter()
                .map(|d| (d.t - e.t).abs())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    assert!(min_gap > 1e-3, "{min_gap}");
    let gt = rec.groundtruth.as_ref().unwrap();
    assert_eq!(gt.len(), rec.trajectory.len());
    assert!((gt.stamps[1] - gt.stamps[0] - 1.0 / cfg.pose_hz).abs() < 1e-6);
    assert!(
        gt.poses
            .iter()
            .all(|p| (p.rotation.quaternion().norm() - 1.0).abs() < 1e-9)
    );
    assert!(
        gt.poses[0].translation.vector.norm() < 1e-9 && gt.poses[0].rotation.angle() < 1e-9,
        "world = first camera frame"
    );
    assert_eq!(gt.poses, rec.trajectory.poses, "no drift asked");
    // The world frame is neither the room frame nor z-up.
    let t = truth(&out);
    let up = Vector3::from(t.up_world);
    assert!(up.z.abs() < 0.99 && (up.norm() - 1.0).abs() < 1e-9, "{up}");
    assert!(pose(&t.world_from_room).rotation.angle() > 0.1);
    // Masks: every id in a mask PNG has a label in its JSON.
    for e in rec.masks.iter().take(5) {
        let png = rec.path_of(e);
        let labels = read_mask_labels(&labels_path(&png)).unwrap();
        let img = read_image16(&png).unwrap();
        assert!(img.data.iter().all(|&i| i == 0 || labels.contains_key(&i)));
    }
}

/// A 3 s noise-free office walk at 80×60 depth with `drift`.
fn noise_free_office(drift: mrtmap_sim::Drift, out: &std::path::Path) -> Recording {
    let room = preset("office").unwrap().unwrap();
    let mut cfg = mrtmap_sim::SimConfig {
        seconds: 3.0,
        noise: NoiseLevel::None,
        truth_rays: 1000,
        drift,
        ..Default::default()
    };
    cfg.depth_camera = cfg.depth_camera.scaled(0.125);
    mrtmap_sim::simulate(&room, &cfg, out, &|_, _| {}).unwrap();
    Recording::open(out).unwrap()
}

#[test]
fn drift_separates_trajectory_from_groundtruth() {
    let dir = tempfile::tempdir().unwrap();
    let rec = noise_free_office(mrtmap_sim::Drift::ODOMETRY, &dir.path().join("scan"));
    let gt = rec.groundtruth.unwrap();
    let err = |k: usize| {
        (rec.trajectory.poses[k].translation.vector - gt.poses[k].translation.vector).norm()
    };
    assert_eq!(err(0), 0.0);
    let last = gt.len() - 1;
    assert!(err(last) > 1e-3 && err(last) < 0.1, "{}", err(last));
}

/// imu.txt: the gyro integrated between two true poses gives their relative rotation, and the
/// accelerometer, turned into the world, reads gravity (the walk's own acceleration averages out).
#[test]
fn the_simulated_gyro_integrates_to_the_true_rotation_and_the_accelerometer_reads_gravity() {
    let dir = tempfile::tempdir().unwrap();
    let rec = noise_free_office(mrtmap_sim::Drift::NONE, &dir.path().join("scan"));
    let gt = rec.groundtruth.unwrap();
    assert_eq!(rec.imu.len(), gt.len());
    let (a, b) = (100, 500); // 0.5 s and 2.5 s
    let mut q = mrtmap_geometry::nalgebra::UnitQuaternion::identity();
    for m in &rec.imu[a..b] {
        q *= mrtmap_geometry::nalgebra::UnitQuaternion::from_scaled_axis(m.gyro * 0.005);
    }
    let truth = gt.poses[a].rotation.inverse() * gt.poses[b].rotation;
    assert!(
        truth.angle() > 0.1,
        "the walk turns: {:.3} rad",
        truth.angle()
    );
    let off = q.angle_to(&truth).to_degrees();
    assert!(off < 0.5, "gyro off by {off:.3}° over 2 s");
    let mean: Vector3<f64> = rec
        .imu
        .iter()
        .zip(&gt.poses)
        .map(|(m, p)| p.rotation * m.accel)
        .sum::<Vector3<f64>>()
        / rec.imu.len() as f64;
    assert!((mean.norm() - 9.807).abs() < 0.3, "{mean:?}");
}
