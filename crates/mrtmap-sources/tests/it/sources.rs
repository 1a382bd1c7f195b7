//! Bags (ROS 1, ROS 2 SQLite), MCAP files and RTAB-Map databases built with this crate's writers (and the same
//! `mcap`, `bzip2`, `lz4_flex`, `rusqlite` crates), read back through the same path `convert`
//! takes: every frame, pose and camera must come back; broken files must give errors with offsets.

use std::path::Path;

use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use mrtmap_io::{
    FileErrorKind, Image16, Recording, RgbCamera, Rig, ThermalEncoding, encode_png_rgb8,
    encode_png16, read_image16,
};
use mrtmap_sources::ros::bag::{BagWriter, Compression};
use mrtmap_sources::ros::msg::{Wire, encode};
use mrtmap_sources::ros::{self, Container, RosOptions, RosWriteOptions, names};
use mrtmap_sources::rtabmap::{self, Schema};
use nalgebra::{Isometry3, Vector3};

fn rig() -> Rig {
    let mut thermal = PinholeCamera::new(16, 12, 14.7, 14.7, 7.5, 5.5);
    thermal.distortion = BrownConrady::from_array([-0.1, 0.05, 0.0, 0.0, 0.0]);
    let depth = PinholeCamera::new(20, 15, 19.0, 19.0, 9.5, 7.0);
    Rig {
        depth,
        depth_scale: 1000.0,
        thermal,
        thermal_encoding: ThermalEncoding::Centikelvin,
        thermal_accuracy_k: None,
        thermal_time_offset_s: None,
        depth_from_thermal: Isometry3::new(
            Vector3::new(0.04, -0.02, 0.005),
            Vector3::new(0.0, 0.02, 0.01),
        ),
        rgb: Some(RgbCamera {
            camera: depth,
            depth_from_rgb: Isometry3::identity(),
        }),
    }
}

fn pose_at(t: f64) -> Isometry3<f64> {
    Isometry3::new(
        Vector3::new(0.3 * t, -0.1 * t, 0.05 * t * t),
        Vector3::new(0.1 * t, 0.4 * t, -0.2 * t),
    )
}

/// A 1 s recording: depth at 10 Hz, thermal at 5 Hz, colour at 5 Hz, poses at 50 Hz.
fn recording(dir: &Path) -> Recording {
    let r = rig();
    for sub in ["depth", "thermal", "rgb"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    std::fs::write(dir.join("rig.toml"), r.to_toml()).unwrap();
    let t0 = 1_700_000_000.0;
    let mut lists = [String::new(), String::new(), String::new()];
    for i in 0..10 {
        let t = t0 + 0.1 * i as f64 + 0.003;
        let d = Image16 {
            width: 20,
            height: 15,
            data: (0..300)
                .map(|k| {
                    if k % 7 == 0 {
                        0
                    } else {
                        1000 + k as u16 + 13 * i
                    }
                })
                .collect(),
        };
        std::fs::write(
            dir.join(format!("depth/{i}.png")),
            encode_png16(&d).unwrap(),
        )
        .unwrap();
        lists[0] += &format!("{t:.6} depth/{i}.png\n");
        if i % 2 == 0 {
            let th = Image16 {
                width: 16,
                height: 12,
                data: (0..192).map(|k| 29_315 + k as u16 * 3 + i).collect(),
            };
            std::fs::write(
                dir.join(format!("thermal/{i}.png")),
                encode_png16(&th).unwrap(),
            )
            .unwrap();
            lists[1] += &format!("{:.6} thermal/{i}.png\n", t + 0.01);
            let rgb: Vec<u8> = (0..300 * 3).map(|k| (k * 7 + i as usize) as u8).collect();
            std::fs::write(
                dir.join(format!("rgb/{i}.png")),
                encode_png_rgb8(20, 15, &rgb).unwrap(),
            )
            .unwrap();
            lists[2] += &format!("{t:.6} rgb/{i}.png\n");
        }
    }
    std::fs::write(dir.join("depth.txt"), &lists[0]).unwrap();
    std::fs::write(dir.join("thermal.txt"), &lists[1]).unwrap();
    std::fs::write(dir.join("rgb.txt"), &lists[2]).unwrap();
    let traj = mrtmap_io::Trajectory {
        stamps: (0..=50).map(|i| t0 + 0.02 * i as f64).collect(),
        poses: (0..=50).map(|i| pose_at(0.02 * i as f64)).collect(),
    };
    std::fs::write(dir.join("trajectory.txt"), traj.to_tum("test")).unwrap();
    Recording::open(dir).unwrap()
}

/// 16-bit pixels as little-endian bytes (a ROS image's data).
fn le16(img: &Image16) -> Vec<u8> {
    img.data.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A recording's thermal frames as mono16 images on `topic` (frame "lepton").
fn write_thermal(w: &mut BagWriter, rec: &Recording, topic: &str) {
    for e in &rec.thermal {
        let img = rec.read_thermal(e).unwrap();
        let (width, height) = (img.width, img.height);
        let m = encode::image(
            Wire::Ros1,
            e.t,
            "lepton",
            width,
            height,
            "mono16",
            2 * width,
            &le16(&img),
        );
        w.write(topic, "sensor_msgs/Image", e.t, &m);
    }
}

fn same_pose(a: &Isometry3<f64>, b: &Isometry3<f64>, tol: f64) -> bool {
    (a.translation.vector - b.translation.vector).norm() < tol
        && a.rotation.angle_to(&b.rotation) < tol
}

/// The converted folder holds the same frames, poses and rig as the original.
fn assert_same(orig: &Recording, conv: &Recording, pose_tol: f64) {
    assert_eq!(conv.depth.len(), orig.depth.len());
    assert_eq!(conv.thermal.len(), orig.thermal.len());
    assert_eq!(conv.rgb.len(), orig.rgb.len());
    for (a, b) in orig.depth.iter().zip(&conv.depth) {
        assert!((a.t - b.t).abs() < 1e-6);
        assert_eq!(orig.read_depth(a).unwrap(), conv.read_depth(b).unwrap());
    }
    for (a, b) in orig.thermal.iter().zip(&conv.thermal) {
        assert!((a.t - b.t).abs() < 1e-6);
        assert_eq!(orig.read_thermal(a).unwrap(), conv.read_thermal(b).unwrap());
    }
    for (a, b) in orig.rgb.iter().zip(&conv.rgb) {
        let x = image::open(orig.path_of(a)).unwrap().to_rgb8();
        let y = image::open(conv.path_of(b)).unwrap().to_rgb8();
        assert_eq!(x, y);
    }
    assert_eq!(conv.trajectory.len(), orig.trajectory.len());
    for (p, q) in orig.trajectory.poses.iter().zip(&conv.trajectory.poses) {
        assert!(same_pose(p, q, pose_tol), "{p} vs {q}");
    }
    assert_eq!(conv.rig.depth, orig.rig.depth);
    assert_eq!(conv.rig.thermal, orig.rig.thermal);
    assert!(same_pose(
        &conv.rig.depth_from_thermal,
        &orig.rig.depth_from_thermal,
        1e-12
    ));
}

#[test]
fn bags_and_mcap_files_round_trip_with_every_compression() {
    let dir = tempfile::tempdir().unwrap();
    let orig = recording(&dir.path().join("scan"));
    for (container, compression) in [
        (Container::Bag, Compression::None),
        (Container::Bag, Compression::Bz2),
        (Container::Bag, Compression::Lz4),
        (Container::Mcap, Compression::None),
        (Container::Mcap, Compression::Bz2),
        (Container::Mcap, Compression::Lz4),
        (Container::Db3, Compression::None),
    ] {
        let bytes =
            ros::write_ros(&orig, &RosWriteOptions::t265_like(container, compression)).unwrap();
        let s = ros::survey(container, &bytes).unwrap();
        assert!(!s.unfinished);
        assert_eq!(s.topics[names::DEPTH].count, 10);
        assert_eq!(s.topics[names::THERMAL].encoding, "mono16");
        assert!((s.topics[names::DEPTH].rate_hz() - 10.0).abs() < 1e-3);
        let p = ros::plan(&s, &RosOptions::default());
        assert!(p.missing.is_empty(), "{:?}", p.missing);
        let out = dir.path().join(format!("{container:?}-{compression:?}"));
        let rep = ros::export(Path::new("x"), &bytes, &s, &p, &out).unwrap();
        assert_eq!(
            (rep.depth, rep.thermal, rep.rgb, rep.poses, rep.skipped),
            (10, 5, 5, 51, 0)
        );
        // The T265-style pose frame is carried back to the depth camera through /tf_static.
        assert_same(&orig, &Recording::open(&out).unwrap(), 1e-9);
    }
}

#[test]
fn poses_from_tf_and_a_missing_thermal_calibration() {
    let dir = tempfile::tempdir().unwrap();
    let orig = recording(&dir.path().join("scan"));
    let r = rig();
    let base_from_depth =
        Isometry3::new(Vector3::new(0.1, 0.0, 0.2), Vector3::new(-1.2, 1.2, -1.2));
    let mut w = BagWriter::new(Compression::Lz4, 4096);
    let t0 = orig.trajectory.stamps[0];
    w.write(
        "/tf_static",
        "tf2_msgs/TFMessage",
        t0,
        &encode::tf_message(
            Wire::Ros1,
            &[
                (t0, "base_link", "cam_optical", base_from_depth),
                (t0, "cam_optical", "lepton", r.depth_from_thermal),
            ],
        ),
    );
    w.write(
        "/cam/camera_info",
        "sensor_msgs/CameraInfo",
        t0,
        &encode::camera_info(Wire::Ros1, t0, "cam_optical", &r.depth),
    );
    for (t, p) in orig.trajectory.stamps.iter().zip(&orig.trajectory.poses) {
        let world_from_base = p * base_from_depth.inverse();
        w.write(
            "/tf",
            "tf2_msgs/TFMessage",
            *t,
            &encode::tf_message(Wire::Ros1, &[(*t, "map", "base_link", world_from_base)]),
        );
    }
    for e in &orig.depth {
        let img = orig.read_depth(e).unwrap();
        let le = le16(&img);
        w.write(
            "/cam/depth",
            "sensor_msgs/Image",
            e.t,
            &encode::image(Wire::Ros1, e.t, "cam_optical", 20, 15, "16UC1", 40, &le),
        );
    }
    write_thermal(&mut w, &orig, "/lepton/image");
    let bag = w.finish().unwrap();
    let s = ros::survey(Container::Bag, &bag).unwrap();
    // No thermal CameraInfo: the plan says so, and a rig supplies it.
    let p = ros::plan(
        &s,
        &RosOptions {
            depth_topic: Some("/cam/depth".into()),
            ..Default::default()
        },
    );
    assert_eq!(p.thermal.as_deref(), Some("/lepton/image"));
    assert!(
        p.missing.iter().any(|m| m.contains("thermal intrinsics")),
        "{:?}",
        p.missing
    );
    assert!(ros::export(Path::new("b.bag"), &bag, &s, &p, &dir.path().join("no")).is_err());
    assert!(
        !dir.path().join("no").exists(),
        "nothing written on failure"
    );
    let p = ros::plan(
        &s,
        &RosOptions {
            depth_topic: Some("/cam/depth".into()),
            rig: Some(r),
            ..Default::default()
        },
    );
    assert!(p.missing.is_empty(), "{:?}", p.missing);
    assert_eq!(
        p.poses,
        Some(ros::PoseSource::Tf("map".into(), "base_link".into()))
    );
    let out = dir.path().join("tf");
    ros::export(Path::new("b.bag"), &bag, &s, &p, &out).unwrap();
    let conv = Recording::open(&out).unwrap();
    for (a, b) in orig.trajectory.poses.iter().zip(&conv.trajectory.poses) {
        assert!(same_pose(a, b, 1e-9), "{a} vs {b}");
    }
    // A topic named but absent.
    let p = ros::plan(
        &s,
        &RosOptions {
            thermal_topic: Some("/nope".into()),
            ..Default::default()
        },
    );
    assert!(p.missing.iter().any(|m| m.contains("/nope")));
}

#[test]
fn broken_bags_and_mcap_files_name_the_offset() {
    let dir = tempfile::tempdir().unwrap();
    let orig = recording(&dir.path().join("scan"));
    let bag = ros::write_ros(
        &orig,
        &RosWriteOptions::t265_like(Container::Bag, Compression::Bz2),
    )
    .unwrap();
    // Corrupt bytes inside the first chunk's compressed data.
    let mut bad = bag.clone();
    let at = ros::bag::MAGIC.len() + 4096 + 120;
    for b in &mut bad[at..at + 32] {
        *b = !*b;
    }
    let e = ros::survey(Container::Bag, &bad).unwrap_err();
    assert!(e.to_string().contains("chunk"), "{e}");
    assert!(e.offset >= (ros::bag::MAGIC.len() + 4096) as u64, "{e}");
    // A chunk header that claims 3 GB decompressed is refused before anything is allocated.
    let mut w = BagWriter::new(Compression::None, 1 << 20);
    w.write("/a", "std_msgs/String", 1.0, b"abc");
    let mut big = w.finish().unwrap();
    let pos = big.windows(5).position(|x| x == b"size=").unwrap() + 5;
    big[pos..pos + 4].copy_from_slice(&3_000_000_000u32.to_le_bytes());
    let e = ros::survey(Container::Bag, &big).unwrap_err();
    assert!(e.what.contains("more than"), "{e}");
    // MCAP cut short: an error with an offset, or the part before the cut flagged unfinished.
    let mcap = ros::write_ros(
        &orig,
        &RosWriteOptions::t265_like(Container::Mcap, Compression::None),
    )
    .unwrap();
    for cut in [9, 100, mcap.len() / 3, mcap.len() - 20] {
        match ros::survey(Container::Mcap, &mcap[..cut]) {
            Err(e) => assert!(e.offset <= cut as u64, "{e}"),
            Ok(s) => assert!(s.unfinished),
        }
    }
    // A depth message whose data is shorter than its size says is skipped, counted and named.
    let mut w = BagWriter::new(Compression::None, 1 << 20);
    let info = encode::camera_info(Wire::Ros1, 1.0, "c", &rig().depth);
    w.write(names::DEPTH_INFO, "sensor_msgs/CameraInfo", 1.0, &info);
    w.write(
        names::DEPTH,
        "sensor_msgs/Image",
        1.0,
        &encode::image(Wire::Ros1, 1.0, "c", 20, 15, "16UC1", 40, &[0; 100]),
    );
    let s = ros::survey(Container::Bag, &w.finish().unwrap()).unwrap();
    assert_eq!(s.topics[names::DEPTH].undecodable, 1);
    let p = ros::plan(&s, &RosOptions::default());
    assert!(
        p.notes
            .iter()
            .any(|n| n.contains("do not decode") && n.contains("20×15")),
        "{:?}",
        p.notes
    );
}

#[test]
fn rtabmap_databases_of_both_schemas_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let orig = recording(&dir.path().join("scan"));
    for schema in [Schema::Current, Schema::Legacy] {
        let db = dir.path().join(format!("{schema:?}.db"));
        let n = rtabmap::write_recording(&orig, &db, schema).unwrap();
        assert_eq!(n, 5);
        let s = rtabmap::summarize(&db).unwrap();
        assert_eq!((s.nodes, s.images, s.depths), (5, 5, 5));
        assert_eq!(s.rvl, if schema == Schema::Current { 5 } else { 0 });
        assert_eq!(s.optimised, if schema == Schema::Current { 5 } else { 0 });
        assert!(s.poses.starts_with(if schema == Schema::Current {
            "optimised"
        } else {
            "odometry"
        }));
        let cal = s.calibration.unwrap();
        assert_eq!(cal.camera, rig().depth);
        let mut nodes = Vec::new();
        let bad = rtabmap::for_each_node(&db, None, &mut |n| {
            nodes.push(n);
            Ok(())
        })
        .unwrap();
        assert!(bad.is_empty());
        let limits = mrtmap_io::InterpolationLimits::default();
        // The graph: odometry poses (drifting 1 cm per node), 4 neighbour links and a loop
        // closure, with their information.
        let (odom, links, unread) = rtabmap::graph(&db).unwrap();
        assert!(unread.is_empty());
        assert_eq!(odom.len(), 5);
        let kinds: Vec<i64> = links.iter().map(|l| l.kind).collect();
        assert_eq!(kinds, [0, 0, 0, 0, 1]);
        assert_eq!((links[4].from, links[4].to), (5, 1));
        assert!((links[0].information[0] - 1e4).abs() < 1e-6 && links[0].information[1] == 0.0);
        for (i, (node, e)) in nodes.iter().zip(&orig.rgb).enumerate() {
            let want = orig.trajectory.interpolate(e.t, &limits).unwrap();
            let drift = Isometry3::translation(0.01 * i as f64, 0.0, 0.0);
            assert!(same_pose(
                &(odom[&node.id] * cal.local),
                &(drift * want),
                1e-5
            ));
            // Saved optimised poses are the recording's; without them, the odometry.
            let want = if schema == Schema::Current {
                want
            } else {
                drift * want
            };
            // f32 blobs: 1e-6 relative.
            assert!(
                same_pose(&(node.pose * cal.local), &want, 1e-5),
                "{schema:?}"
            );
            let d = orig
                .depth
                .iter()
                .find(|d| (d.t - e.t).abs() < 0.02)
                .unwrap();
            assert_eq!(node.depth.as_ref().unwrap(), &orig.read_depth(d).unwrap());
        }
    }
}

#[test]
fn broken_rtabmap_databases_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let orig = recording(&dir.path().join("scan"));
    let db = dir.path().join("a.db");
    rtabmap::write_recording(&orig, &db, Schema::Current).unwrap();
    {
        let c = rusqlite::Connection::open(&db).unwrap();
        c.execute("UPDATE Node SET pose = x'0011' WHERE id = 2", [])
            .unwrap();
        c.execute(
            "UPDATE Data SET depth = substr(depth, 1, 40) WHERE id = 3",
            [],
        )
        .unwrap();
    }
    let mut ok = 0;
    let bad = rtabmap::for_each_node(&db, None, &mut |_| {
        ok += 1;
        Ok(())
    })
    .unwrap();
    assert_eq!(ok, 3);
    assert_eq!(bad.len(), 2);
    assert_eq!(bad[0].0, 2);
    assert!(bad[0].1.contains("2 bytes, expected 48"), "{}", bad[0].1);
    assert!(bad[1].1.contains("RVL"), "{}", bad[1].1);
    // An old schema and a non-database are refused with one sentence.
    {
        let c = rusqlite::Connection::open(&db).unwrap();
        c.execute("UPDATE Admin SET version = '0.17.6'", [])
            .unwrap();
    }
    let e = rtabmap::summarize(&db).unwrap_err();
    assert!(e.to_string().contains("older than 0.18"), "{e}");
    let not = dir.path().join("x.db");
    std::fs::write(&not, b"SQLite format 3\0garbage").unwrap();
    let e = rtabmap::summarize(&not).unwrap_err();
    assert!(matches!(e.kind, FileErrorKind::Syntax(_)), "{e}");
    assert!(read_image16(&not).is_err());
}

#[test]
fn compressed_depth_and_float_depth_topics() {
    let dir = tempfile::tempdir().unwrap();
    let orig = recording(&dir.path().join("scan"));
    let r = rig();
    for variant in ["compressedDepth", "32FC1"] {
        let mut w = BagWriter::new(Compression::None, 1 << 16);
        let t0 = orig.trajectory.stamps[0];
        w.write(
            "/d/camera_info",
            "sensor_msgs/CameraInfo",
            t0,
            &encode::camera_info(Wire::Ros1, t0, "cam", &r.depth),
        );
        for (t, p) in orig.trajectory.stamps.iter().zip(&orig.trajectory.poses) {
            w.write(
                "/odom",
                "nav_msgs/Odometry",
                *t,
                &encode::odometry(Wire::Ros1, *t, "map", "cam", p),
            );
        }
        for e in &orig.depth {
            let img = orig.read_depth(e).unwrap();
            if variant == "compressedDepth" {
                let mut data = vec![0u8; 12];
                data.extend(encode_png16(&img).unwrap());
                w.write(
                    "/d/image_raw/compressedDepth",
                    "sensor_msgs/CompressedImage",
                    e.t,
                    &encode::compressed_image(
                        Wire::Ros1,
                        e.t,
                        "cam",
                        "16UC1; compressedDepth png",
                        &data,
                    ),
                );
            } else {
                let f: Vec<u8> = img
                    .data
                    .iter()
                    .flat_map(|&v| (v as f32 / 1000.0).to_le_bytes())
                    .collect();
                w.write(
                    "/d/image_raw",
                    "sensor_msgs/Image",
                    e.t,
                    &encode::image(Wire::Ros1, e.t, "cam", 20, 15, "32FC1", 80, &f),
                );
            }
        }
        write_thermal(&mut w, &orig, "/t/image");
        let bag = w.finish().unwrap();
        let s = ros::survey(Container::Bag, &bag).unwrap();
        let p = ros::plan(
            &s,
            &RosOptions {
                rig: Some(r),
                ..Default::default()
            },
        );
        assert!(p.missing.is_empty(), "{variant}: {:?}", p.missing);
        assert!(
            p.depth.as_deref().unwrap().starts_with("/d/image_raw"),
            "{variant}: {:?}",
            p.depth
        );
        let out = dir.path().join(variant);
        let rep = ros::export(Path::new("v.bag"), &bag, &s, &p, &out).unwrap();
        assert_eq!(
            (rep.depth, rep.skipped),
            (10, 0),
            "{variant}: {:?}",
            rep.skipped_reasons
        );
        let conv = Recording::open(&out).unwrap();
        for (a, b) in orig.depth.iter().zip(&conv.depth) {
            assert_eq!(
                orig.read_depth(a).unwrap(),
                conv.read_depth(b).unwrap(),
                "{variant}"
            );
        }
    }
}

/// Every message of a bag or MCAP file, owned: (topic, type, time, data).
fn messages(c: Container, bytes: &[u8]) -> Vec<(String, String, f64, Vec<u8>)> {
    let mut v = Vec::new();
    ros::for_each(c, bytes, &mut |m| {
        v.push((
            m.topic.to_string(),
            m.datatype.to_string(),
            m.time,
            m.data.to_vec(),
        ));
        Ok(())
    })
    .unwrap();
    v
}

#[test]
fn ros2_bag_folders_split_over_files_read_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let orig = recording(&dir.path().join("scan"));
    let mcap = ros::write_ros(
        &orig,
        &RosWriteOptions::t265_like(Container::Mcap, Compression::None),
    )
    .unwrap();
    let all = messages(Container::Mcap, &mcap);
    // Twelve files: `_10` and `_11` sort after `_9` only when the number is read as one.
    let parts = 12;
    let per = all.len().div_ceil(parts);
    for (c, ext) in [(Container::Mcap, "mcap"), (Container::Db3, "db3")] {
        let bag = dir.path().join(format!("rosbag2_{ext}"));
        std::fs::create_dir_all(&bag).unwrap();
        std::fs::write(bag.join("metadata.yaml"), "rosbag2_bagfile_information:\n").unwrap();
        for (i, chunk) in all.chunks(per).enumerate() {
            // Odd files hold each message zstd-compressed, as `ros2 bag record
            // --compression-mode message` writes them.
            let stored = |data: &Vec<u8>| {
                if i % 2 == 1 {
                    zstd::encode_all(&data[..], 3).unwrap()
                } else {
                    data.clone()
                }
            };
            let bytes = if c == Container::Mcap {
                let mut w = ros::mcap::McapWriter::new(None, 1 << 16).unwrap();
                for (topic, ty, t, data) in chunk {
                    w.write(topic, ty, *t, &stored(data)).unwrap();
                }
                w.finish().unwrap()
            } else {
                let mut w = ros::db3::Db3Writer::new().unwrap();
                for (topic, ty, t, data) in chunk {
                    w.write(topic, ty, *t, &stored(data)).unwrap();
                }
                w.finish().unwrap()
            };
            std::fs::write(bag.join(format!("rosbag2_{ext}_{i}.{ext}")), bytes).unwrap();
        }
        let (kind, file) = mrtmap_sources::resolve_source(&bag).unwrap();
        assert_eq!((kind.container(), file.as_path()), (Some(c), bag.as_path()));
        let order: Vec<String> = ros::storage_files(&bag, c)
            .unwrap()
            .iter()
            .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
            .collect();
        let n = all.chunks(per).count();
        assert!(n > 10, "{n} files");
        let expected: Vec<String> = (0..n).map(|i| format!("rosbag2_{ext}_{i}")).collect();
        assert_eq!(order, expected);
        // Read in that order, the messages are the original ones in the original order.
        let mut back = Vec::new();
        ros::for_each(c, bag.as_path(), &mut |m| {
            back.push((m.topic.to_string(), m.time, m.data.to_vec()));
            Ok(())
        })
        .unwrap();
        assert_eq!(back.len(), all.len());
        for (i, (a, b)) in back.iter().zip(&all).enumerate() {
            // Times are f64 seconds: at 1.7e9 s they resolve 0.24 µs, so rewriting rounds them.
            assert!(
                a.0 == b.0 && (a.1 - b.2).abs() < 1e-6 && a.2 == b.3,
                "{ext} message {i}: {} {} / {} {}",
                a.0,
                a.1,
                b.0,
                b.2
            );
        }
        let s = ros::survey(c, bag.as_path()).unwrap();
        let p = ros::plan(&s, &RosOptions::default());
        let out = dir.path().join(format!("from-{ext}"));
        let rep = ros::export(&bag, bag.as_path(), &s, &p, &out).unwrap();
        assert_eq!((rep.depth, rep.thermal, rep.rgb, rep.poses), (10, 5, 5, 51));
        assert_same(&orig, &Recording::open(&out).unwrap(), 1e-9);
        // A broken message in the ninth file is named by file and row.
        let ninth = bag.join(format!("rosbag2_{ext}_8.{ext}"));
        if c == Container::Db3 {
            let db = rusqlite::Connection::open(&ninth).unwrap();
            db.execute("UPDATE messages SET topic_id = 99 WHERE id = 2", [])
                .unwrap();
            drop(db);
            let e = ros::survey(c, bag.as_path()).unwrap_err();
            assert_eq!(
                e.in_file(&bag).to_string(),
                format!(
                    "{}: rosbag2_db3_8.db3, message 2, at byte 0 of its data: topic id 99, which the topics table does not list",
                    bag.display()
                )
            );
        } else {
            // A message record that claims more bytes than the file has.
            std::fs::write(&ninth, b"\x89MCAP0\r\n\x05\xff\xff\0\0\0\0\0\0").unwrap();
            let e = ros::survey(c, bag.as_path()).unwrap_err();
            assert!(
                e.to_string().starts_with("rosbag2_mcap_8.mcap, at byte"),
                "{e}"
            );
        }
    }
    // A folder with no storage file, or one compressed file by file, is refused with the reason.
    let empty = dir.path().join("empty_bag");
    std::fs::create_dir_all(&empty).unwrap();
    std::fs::write(empty.join("metadata.yaml"), "").unwrap();
    let e = mrtmap_sources::resolve_source(&empty)
        .unwrap_err()
        .to_string();
    assert!(e.contains("without .mcap or .db3"), "{e}");
    std::fs::write(empty.join("empty_bag_0.db3.zstd"), b"(\xb5/\xfd").unwrap();
    let e = mrtmap_sources::resolve_source(&empty)
        .unwrap_err()
        .to_string();
    assert!(e.contains("decompress"), "{e}");
}

#[test]
fn db3_files_are_told_from_rtabmap_databases_and_bad_messages_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let orig = recording(&dir.path().join("scan"));
    let db3 = ros::write_ros(
        &orig,
        &RosWriteOptions::t265_like(Container::Db3, Compression::None),
    )
    .unwrap();
    let f = dir.path().join("scan.db3");
    std::fs::write(&f, &db3).unwrap();
    assert_eq!(
        mrtmap_sources::source_kind(&f).unwrap(),
        mrtmap_sources::SourceKind::Db3
    );
    let rt = dir.path().join("rtabmap.db");
    rtabmap::write_recording(&orig, &rt, Schema::Current).unwrap();
    assert_eq!(
        mrtmap_sources::source_kind(&rt).unwrap(),
        mrtmap_sources::SourceKind::RtabMap
    );
    // Cut the data of the third depth message: it is skipped, counted and named by its row.
    let db = rusqlite::Connection::open(&f).unwrap();
    let id: i64 = db
        .query_row(
            "SELECT m.id FROM messages m JOIN topics t ON m.topic_id = t.id WHERE t.name = ?1 ORDER BY m.timestamp LIMIT 1 OFFSET 2",
            [names::DEPTH],
            |r| r.get(0),
        )
        .unwrap();
    db.execute(
        "UPDATE messages SET data = substr(data, 1, 100) WHERE id = ?1",
        [id],
    )
    .unwrap();
    drop(db);
    let s = ros::survey(Container::Db3, f.as_path()).unwrap();
    assert_eq!(s.topics[names::DEPTH].undecodable, 1);
    let first = s.topics[names::DEPTH].first_error.clone().unwrap();
    assert!(
        first.starts_with(&format!("message {id}, at byte ")),
        "{first}"
    );
    let p = ros::plan(&s, &RosOptions::default());
    let rep = ros::export(&f, f.as_path(), &s, &p, &dir.path().join("out")).unwrap();
    assert_eq!((rep.depth, rep.skipped), (9, 1));
    assert!(
        rep.skipped_reasons[0].starts_with(&format!("{} message {id}: ", names::DEPTH)),
        "{:?}",
        rep.skipped_reasons
    );
}

/// A D435i-style source without odometry but with its IMU: it converts (no trajectory.txt: the
/// recording is tracked), and imu.txt comes back in the depth camera's axes through /tf_static.
#[test]
fn a_source_without_poses_converts_with_its_imu_in_the_depth_cameras_axes() {
    let dir = tempfile::tempdir().unwrap();
    let scan = dir.path().join("scan");
    recording(&scan);
    std::fs::remove_file(scan.join("trajectory.txt")).unwrap();
    let samples: Vec<mrtmap_io::ImuSample> = (0..200)
        .map(|k| {
            let t = 1_700_000_000.0 + 0.005 * k as f64;
            mrtmap_io::ImuSample {
                t,
                gyro: Vector3::new(0.3, -0.1 * (k as f64 * 0.05).sin(), 0.05),
                accel: Vector3::new(0.2, -9.7, 0.4 + 0.001 * k as f64),
            }
        })
        .collect();
    std::fs::write(scan.join("imu.txt"), mrtmap_io::imu_text(&samples, "test")).unwrap();
    let orig = Recording::open(&scan).unwrap();
    assert!(orig.trajectory.is_empty() && orig.imu.len() == 200);
    for container in [Container::Bag, Container::Mcap, Container::Db3] {
        let bytes = ros::write_ros(
            &orig,
            &RosWriteOptions::t265_like(container, Compression::None),
        )
        .unwrap();
        let s = ros::survey(container, &bytes).unwrap();
        let p = ros::plan(&s, &RosOptions::default());
        assert!(p.missing.is_empty(), "{:?}", p.missing);
        assert!(p.poses.is_none());
        assert!(
            p.notes.iter().any(|n| n.contains("tracks the camera")),
            "{:?}",
            p.notes
        );
        assert_eq!(p.gyro.as_deref(), Some(names::IMU));
        let out = dir.path().join(format!("{container:?}"));
        let rep = ros::export(Path::new("x"), &bytes, &s, &p, &out).unwrap();
        assert_eq!((rep.poses, rep.imu), (0, 200));
        assert!(!out.join("trajectory.txt").exists());
        let conv = Recording::open(&out).unwrap();
        assert!(
            conv.warnings
                .contains(&mrtmap_io::RecordingWarning::NoTrajectory)
        );
        assert_eq!(conv.imu.len(), 200);
        for (a, b) in orig.imu.iter().zip(&conv.imu) {
            assert!((a.t - b.t).abs() < 1e-6);
            assert!(
                (a.gyro - b.gyro).norm() < 1e-6,
                "{:?} vs {:?}",
                a.gyro,
                b.gyro
            );
            assert!(
                (a.accel - b.accel).norm() < 1e-4,
                "{:?} vs {:?}",
                a.accel,
                b.accel
            );
        }
    }
    // Without colour either (the colour topic named is not there), the poses are missing.
    let bytes = ros::write_ros(
        &orig,
        &RosWriteOptions::t265_like(Container::Bag, Compression::None),
    )
    .unwrap();
    let s = ros::survey(Container::Bag, &bytes).unwrap();
    let o = RosOptions {
        rgb_topic: Some("/no/colour".into()),
        ..RosOptions::default()
    };
    let p = ros::plan(&s, &o);
    assert!(
        p.missing
            .iter()
            .any(|m| m.starts_with("poses:") && m.contains("nor colour images")),
        "{:?}",
        p.missing
    );
}
