use mrtmap_geometry::nalgebra::Isometry3;
use mrtmap_io::Recording;
use mrtmap_scan::refined_poses;
use mrtmap_scan::segment::{MaskInput, SegmentParams, TextureInput, segment_textured};
use mrtmap_sim::{Drift, NoiseLevel, SceneScore, Truth, score_scene};

use crate::common::*;

/// Simulates, fuses and segments (with masks) a scan; scores the scene against the truth.
fn run(
    room: &str,
    noise: NoiseLevel,
    seconds: f64,
) -> (SceneScore, mrtmap_scan::segment::SegmentReport) {
    let (s, r, _) = run_seeded(room, noise, seconds, 1);
    (s, r)
}

/// [`run`] with the walk of `seed`; also the segmented room's frame in the simulated room's
/// (sim_room_from_room).
fn run_seeded(
    room: &str,
    noise: NoiseLevel,
    seconds: f64,
    seed: u64,
) -> (
    SceneScore,
    mrtmap_scan::segment::SegmentReport,
    Isometry3<f64>,
) {
    run_at(room, noise, seconds, seed, 0.5, true)
}

/// [`run_seeded`] with the depth camera's resolution scaled by `depth_scale` (every pixel at
/// half the resolution, every second pixel at full resolution, as `mrtmap fuse` by default).
fn run_at(
    room: &str,
    noise: NoiseLevel,
    seconds: f64,
    seed: u64,
    depth_scale: f64,
    field_effects: bool,
) -> (
    SceneScore,
    mrtmap_scan::segment::SegmentReport,
    Isometry3<f64>,
) {
    let dir = tempfile::tempdir().unwrap();
    let rec_dir = dir.path().join("scan");
    scan_glass(
        room,
        noise,
        Drift::NONE,
        seconds,
        depth_scale,
        seed,
        field_effects,
        &rec_dir,
    );
    let rec = Recording::open(&rec_dir).unwrap();
    let mut p = params(true);
    p.depth.stride = if depth_scale < 1.0 { 1 } else { 2 };
    let fused = mrtmap_scan::fuse(&rec, &p, &|_, _| {});
    let poses = fused.trajectory();
    let pose_fn = refined_poses(&rec, &poses);
    let masks = MaskInput {
        recording: &rec,
        world_from_depth: &pose_fn,
    };
    let cams: Vec<Isometry3<f64>> = poses.poses.clone();
    // As `mrtmap run` does: the thermal frames cast onto the room model fill what the depth
    // camera did not see (glass).
    let texture = TextureInput {
        recording: &rec,
        frames: &fused.frames,
        vignetting_k: fused.report.radiometric.vignetting_k,
    };
    let seg = segment_textured(
        &fused.cloud,
        &cams,
        Some(&masks),
        Some(&texture),
        &SegmentParams::default(),
    )
    .unwrap();
    let truth: Truth =
        serde_json::from_str(&std::fs::read_to_string(rec_dir.join("truth.json")).unwrap())
            .unwrap();
    let sim_room_from_room =
        truth_world_from_room(&rec_dir).inverse() * seg.scene.world_from_room.unwrap();
    (
        score_scene(&seg.scene, &truth).unwrap(),
        seg.report,
        sim_room_from_room,
    )
}

fn check_noise_free(room: &str, s: &SceneScore) {
    for x in &s.surfaces {
        assert!(x.id.is_some(), "{room}: surface {} not found", x.truth_id);
        assert!(
            x.angle_deg < 1.0 && x.offset_m < 0.02,
            "{room}: plane {} off by {:.3}° {:.1} mm",
            x.truth_id,
            x.angle_deg,
            x.offset_m * 1e3
        );
        assert!(
            x.temperature_error_k.abs() < 0.1,
            "{room}: surface {} ΔT {:.3} K",
            x.truth_id,
            x.temperature_error_k
        );
    }
    assert!(
        s.corner_max_error_m < 0.03,
        "{room}: corners off by {:.1} mm",
        s.corner_max_error_m * 1e3
    );
    mrt_within(room, s, 0.2);
}

/// The MRT at every validation point within `tol_k` of the truth.
fn mrt_within(room: &str, s: &SceneScore, tol_k: f64) {
    for p in &s.points {
        assert!(
            p.error_k.abs() < tol_k,
            "{room}: MRT at {} off by {:.3} K",
            p.name,
            p.error_k
        );
    }
}

/// How many walls segmentation found.
fn walls(report: &mrtmap_scan::segment::SegmentReport) -> usize {
    report
        .surfaces
        .iter()
        .filter(|x| x.kind == mrtmap_radiation::SurfaceKind::Wall)
        .count()
}

/// Noise-free office: planes within 2 cm and 1°, corners within 3 cm, every feature found with
/// IoU ≥ 0.8, the right label by mask votes and its temperature within 0.1 K; MRT at A–D within 0.2 K;
/// the desk found as furniture.
#[test]
fn noise_free_office_scene_matches_the_truth() {
    let (s, report) = run("office", NoiseLevel::None, 20.0);
    check_noise_free("office", &s);
    for f in &s.features {
        let (_, label) = f
            .found
            .clone()
            .unwrap_or_else(|| panic!("feature {} not found", f.truth_id));
        assert!(f.iou >= 0.8, "{}: IoU {:.3}", f.truth_id, f.iou);
        assert_eq!(label, f.truth_label, "{}", f.truth_id);
        assert!(
            f.temperature_error_k.unwrap().abs() < 0.1,
            "{}: {:?}",
            f.truth_id,
            f.temperature_error_k
        );
    }
    assert!(s.spurious_features.is_empty(), "{:?}", s.spurious_features);
    assert!(
        report
            .features
            .iter()
            .all(|f| f.label_source == "masks" && f.votes.as_ref().is_some_and(|v| v.share > 0.9))
    );
    assert!(
        report.furniture.iter().any(|f| f.label == "desk"),
        "{:?}",
        report.furniture
    );
    println!("office: {s:?}");
}

/// Noise-free L-shaped room: the re-entrant corner is found, the outline closes with six walls.
#[test]
fn noise_free_l_shaped_room_closes_its_outline() {
    let (s, report) = run("l-shaped", NoiseLevel::None, 30.0);
    assert_eq!(walls(&report), 6);
    check_noise_free("l-shaped", &s);
    // Window and radiator under it are told apart; the painting is only 0.4 K warmer than its wall.
    for label in ["window", "radiator", "recessed light", "painting"] {
        let f = s.features.iter().find(|f| f.truth_label == label).unwrap();
        assert!(f.iou >= 0.8, "{label}: {f:?}");
    }
}

/// Realistic noise: the office's MRT at A–D stays within 0.2 K.
#[test]
fn realistic_office_mrt_within_tolerance() {
    let (s, _) = run("office", NoiseLevel::Realistic, 20.0);
    mrt_within("office", &s, 0.2);
    println!("realistic office points: {:?}", s.points);
}

/// Two walks through the office that start in different places give the same room frame (as
/// placed in the simulated room), and in it every corner lies at x, y ≥ 0 on the floor (z = 0).
#[test]
fn the_room_frame_does_not_depend_on_where_the_walk_started() {
    let (_, r1, a) = run_seeded("office", NoiseLevel::None, 20.0, 1);
    let (_, r5, b) = run_seeded("office", NoiseLevel::None, 20.0, 5);
    let d = a.inverse() * b;
    assert!(
        d.translation.vector.norm() < 0.03 && d.rotation.angle().to_degrees() < 1.0,
        "seed 1 {a:?}, seed 5 {b:?}"
    );
    for r in [&r1, &r5] {
        assert_eq!(r.floor_corners[0], [0.0, 0.0, 0.0]);
        for c in &r.floor_corners {
            assert!(c[0] > -0.03 && c[1] > -0.03 && c[2].abs() < 1e-6, "{c:?}");
        }
        assert!(!r.room.chosen && r.room.origin_corner == 1);
    }
}

/// A walk that broke the outline before it was found from cells on the floor plan (L-shaped room,
/// seed 5: "the walls do not close"), with realistic depth and thermal noise on the idealised rig
/// (panes that return depth, thermal frames stamped on time, no bolometer lag): every wall found
/// from its own points, corners within 5 cm, MRT at A–D within 0.2 K. With the field effects
/// the window wall keeps too few points (47 mm and 1.75° off, corners 140 mm; with glass alone
/// off, point C is 0.205 K off): docs/segmentation.md's known limits.
#[test]
fn a_realistic_walk_of_another_seed_closes_the_l_shaped_outline() {
    let (s, report, _) = run_at("l-shaped", NoiseLevel::Realistic, 30.0, 5, 0.5, false);
    closes_within("l-shaped, seed 5", &s, &report, 6);
    println!("l-shaped seed 5: {:?}", s.points);
}

/// The outline has `n` walls, all seen, corners within 5 cm, MRT at A–D within 0.2 K.
fn closes_within(
    what: &str,
    s: &SceneScore,
    report: &mrtmap_scan::segment::SegmentReport,
    n: usize,
) {
    assert_eq!(walls(report), n, "{what}: {report:?}");
    assert!(report.inferred_walls.is_empty(), "{what}: {report:?}");
    assert!(
        s.corner_max_error_m < 0.05,
        "{what}: corners off by {:.1} mm",
        s.corner_max_error_m * 1e3
    );
    mrt_within(what, s, 0.2);
}

/// A room with no preset: the bay window of bench/rooms (slanted 0.78 m walls at 50°, a 1 m
/// front wall 0.6 m out holding a 9.5 °C window), a 30 s realistic walk at the depth camera's
/// full resolution: the bay closes with its three walls (its slanted walls' spread and the floor
/// seen beyond its front wall cut it off before), corners within 5 cm, MRT at A–D within 0.2 K.
/// (At half resolution, whose depth noise is twice as thick, the outline does not hold yet.)
/// On the idealised rig (panes that return depth, no clock or bolometer lag). With glass the
/// bay's front wall, half of it window, is not seen as a wall and is inferred at the floor's
/// edge; with the bolometer's time constant alone the wall's texels beside the window blur and
/// the window becomes the wall's background (MRT at B 0.38 K off): docs/segmentation.md's known
/// limits.
#[test]
fn a_bay_window_closes_with_its_three_walls() {
    let (s, report, _) = run_at("bay.toml", NoiseLevel::Realistic, 30.0, 1, 1.0, false);
    closes_within("bay window", &s, &report, 8);
    println!("bay window: {:?}", s.points);
}
