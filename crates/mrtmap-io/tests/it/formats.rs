use std::path::Path;

use mrtmap_geometry::nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use mrtmap_io::masks::{InstanceInfo, MaskLabels, mask_labels_json, read_mask_labels};
use mrtmap_io::{
    FileErrorKind, Image16, InterpolationLimits, Rig, Trajectory, encode_png16, parse_stream_list,
    read_image16,
};

const RIG: &str = r#"
[depth]
width = 640
height = 480
fx = 385.0
fy = 385.0
cx = 319.5
cy = 239.5
depth_scale = 1000.0

[thermal]
width = 160
height = 120
fx = 147.4
fy = 147.4
cx = 79.5
cy = 59.5
distortion = [0.0, 0.0, 0.0, 0.0, 0.0]
encoding = "centikelvin"
depth_from_thermal = { translation = [0.04, -0.02, 0.005], rotation_xyzw = [0.0, 0.0174524, 0.0, 0.9998477] }

[rgb]
width = 640
height = 480
fx = 615.0
fy = 615.0
cx = 319.5
cy = 239.5
depth_from_rgb = { translation = [0.0, 0.0, 0.0], rotation_xyzw = [0.0, 0.0, 0.0, 1.0] }
"#;

#[test]
fn the_spec_rig_parses_and_round_trips() {
    let p = Path::new("rig.toml");
    let rig = Rig::parse(RIG, p).unwrap();
    assert_eq!((rig.depth.width, rig.thermal.height), (640, 120));
    assert!((rig.depth_from_thermal.rotation.angle().to_degrees() - 2.0).abs() < 1e-3);
    assert_eq!(rig.rgb.unwrap().camera.fx, 615.0);
    let again = Rig::parse(&rig.to_toml(), p).unwrap();
    assert_eq!(again.depth, rig.depth);
    assert!(
        (again.depth_from_thermal.translation.vector - rig.depth_from_thermal.translation.vector)
            .norm()
            < 1e-15
    );
}

#[test]
fn rig_errors_name_the_file_and_what() {
    let p = Path::new("scan/rig.toml");
    let e = Rig::parse(&RIG.replace("\"centikelvin\"", "\"celsius\""), p).unwrap_err();
    assert_eq!(
        e.to_string(),
        "scan/rig.toml: [thermal] unknown encoding 'celsius' (supported: centikelvin)"
    );
    let e = Rig::parse(&RIG.replace("0.9998477", "0.5"), p).unwrap_err();
    assert!(
        e.to_string().contains("depth_from_thermal")
            && e.to_string().contains("not a unit quaternion"),
        "{e}"
    );
    let e = Rig::parse(&RIG.replace("fx = 385.0", "fx = -1.0"), p).unwrap_err();
    assert!(e.to_string().contains("focal lengths must be positive"));
    let e = Rig::parse(&RIG.replace("depth_scale = 1000.0", ""), p).unwrap_err();
    assert!(e.to_string().contains("missing field `depth_scale`"), "{e}");
    // Distortion that folds the image over is refused (it fused 4 % of the points, silently);
    // a real lens's (TUM freiburg1's Kinect, strongly distorted) and a Lepton's are read.
    let d = |v: &str| RIG.replace("distortion = [0.0, 0.0, 0.0, 0.0, 0.0]", v);
    let e = Rig::parse(&d("distortion = [500.0, -1e6, 3.0, 3.0, 1e9]"), p).unwrap_err();
    assert!(
        e.to_string().contains("folds or stretches the image"),
        "{e}"
    );
    let e = Rig::parse(&d("distortion = [-3.0, 0.0, 0.0, 0.0, 0.0]"), p).unwrap_err();
    assert!(e.to_string().contains("[thermal] distortion"), "{e}");
    Rig::parse(
        &d("distortion = [0.2624, -0.9531, -0.0054, 0.0026, 1.1633]"),
        p,
    )
    .unwrap();
    Rig::parse(&d("distortion = [-0.12, 0.06, 0.0005, -0.0008, 0.0]"), p).unwrap();
}

#[test]
fn trajectory_parses_with_errors_at_their_line() {
    let p = Path::new("trajectory.txt");
    let ok =
        "# header\n1.0 0 0 0 0 0 0 1\n\n2.0 1 0 0 0 0 0.7071068 0.7071068\n2.0 5 5 5 0 0 0 1\n";
    let t = Trajectory::parse(ok, p).unwrap();
    assert_eq!(t.len(), 2, "the duplicate timestamp keeps the first pose");
    let back = Trajectory::parse(&t.to_tum("test"), p).unwrap();
    assert_eq!(back.stamps, t.stamps);
    assert!((back.poses[1].rotation.angle() - t.poses[1].rotation.angle()).abs() < 1e-9);

    let e = Trajectory::parse("1.0 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n", p).unwrap_err();
    assert_eq!(
        e.to_string(),
        "trajectory.txt:2: timestamp 0.5 goes backwards (the previous line has 1)"
    );
    let e = Trajectory::parse("1.0 0 0 0 0 0 0 2\n", p).unwrap_err();
    assert!(matches!(e.kind, FileErrorKind::BadQuaternion { .. }) && e.line == Some(1));
    let e = Trajectory::parse("1.0 0 0 0 nan 0 0 1\n", p).unwrap_err();
    assert!(e.to_string().starts_with("trajectory.txt:1:"));
    let e = Trajectory::parse("1.0 0 0 0 0 0 1\n", p).unwrap_err();
    assert!(e.to_string().contains("expected 8 numbers"));
}

#[test]
fn interpolation_is_linear_and_slerp_and_never_extrapolates_far() {
    let a = Isometry3::from_parts(Translation3::new(0.0, 0.0, 0.0), UnitQuaternion::identity());
    let b = Isometry3::from_parts(
        Translation3::new(2.0, 0.0, 0.0),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 90f64.to_radians()),
    );
    let t = Trajectory {
        stamps: vec![10.0, 11.0, 20.0],
        poses: vec![a, b, b],
    };
    let lim = InterpolationLimits {
        max_gap_secs: 2.0,
        max_extrapolation_secs: 0.05,
    };
    let m = t.interpolate(10.25, &lim).unwrap();
    assert!((m.translation.vector.x - 0.5).abs() < 1e-12);
    assert!((m.rotation.angle().to_degrees() - 22.5).abs() < 1e-9);
    assert!(t.interpolate(9.97, &lim).is_some());
    assert!(t.interpolate(9.9, &lim).is_none());
    assert!(t.interpolate(15.0, &lim).is_none(), "9 s gap");
    assert!(t.interpolate(20.04, &lim).is_some() && t.interpolate(20.2, &lim).is_none());
}

#[test]
fn stream_lists_parse_and_refuse_backwards_time() {
    let p = Path::new("depth.txt");
    let l = parse_stream_list("# c\n0.1 depth/a.png\n0.2 depth/b.png extra\n", p).unwrap();
    assert_eq!(l.len(), 2);
    assert_eq!(l[1].line, 3);
    let e = parse_stream_list("0.2 a.png\n0.1 b.png\n", p).unwrap_err();
    assert_eq!(e.line, Some(2));
    assert!(
        parse_stream_list("zero a.png\n", p)
            .unwrap_err()
            .to_string()
            .contains("'zero' is not a timestamp")
    );
    assert!(parse_stream_list("0.1\n", p).is_err());
    // A byte-order mark (Excel's "CSV UTF-8") is read past: it was "'\u{feff}#' is not a
    // timestamp", the mark invisible in the message.
    let l = parse_stream_list("\u{feff}# c\n0.1 depth/a.png\n", p).unwrap();
    assert_eq!((l.len(), l[0].line), (1, 2));
    let l = parse_stream_list("\u{feff}0.1 depth/a.png\n", p).unwrap();
    assert_eq!(l[0].t, 0.1);
}

#[test]
fn png16_round_trip_and_size_check() {
    let dir = tempfile::tempdir().unwrap();
    let mut img = Image16::zeros(7, 5);
    for (k, v) in img.data.iter_mut().enumerate() {
        *v = (k as u16) * 1000 + 3;
    }
    let p = dir.path().join("x.png");
    std::fs::write(&p, encode_png16(&img).unwrap()).unwrap();
    let back = read_image16(&p).unwrap();
    assert_eq!(back, img);
    let e = back.check_size(&p, 8, 5).unwrap_err();
    assert!(
        e.to_string()
            .ends_with("image is 7×5 pixels but the rig says 8×5")
    );
    std::fs::write(&p, b"not a png").unwrap();
    assert!(
        read_image16(&p)
            .unwrap_err()
            .to_string()
            .contains("cannot decode")
    );
}

#[test]
fn mask_labels_round_trip_and_checks() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = MaskLabels::new();
    m.insert(
        3,
        InstanceInfo {
            label: "window".into(),
            score: 0.9,
        },
    );
    let p = dir.path().join("m.json");
    std::fs::write(&p, mask_labels_json(&m)).unwrap();
    assert_eq!(read_mask_labels(&p).unwrap(), m);
    std::fs::write(&p, r#"{"0": {"label": "x", "score": 0.5}}"#).unwrap();
    assert!(read_mask_labels(&p).is_err());
    std::fs::write(&p, r#"{"2": {"label": "x", "score": 1.5}}"#).unwrap();
    assert!(
        read_mask_labels(&p)
            .unwrap_err()
            .to_string()
            .contains("score 1.5")
    );
}
