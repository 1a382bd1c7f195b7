//! Real thermal images of a heated, coded checkerboard (`shared/data/thermal-checkerboard`:
//! 60 8-bit LWIR frames, 382×288, up to 11×9 inner corners of 50.5 mm, an ArUco marker hiding
//! the centre 4×4 squares). The data are read in place: `MRTMAP_DATA_DIR` overrides the default
//! `../shared/data` beside the repository.

use std::path::PathBuf;

use mrtmap_calib::{
    Board, DetectOptions, DistortionModel, Gray, calibrate_mono, detect, list_images,
};

pub fn data_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("MRTMAP_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    dir.join("thermal-checkerboard/imageDataset")
        .is_dir()
        .then_some(dir)
}

#[test]
fn real_thermal_board_intrinsics() {
    let Some(dir) = data_dir() else {
        println!("skipped: shared/data/thermal-checkerboard not found (set MRTMAP_DATA_DIR)");
        return;
    };
    let board = Board::new(11, 9, 0.0505).expect("board");
    let images = list_images(&dir.join("thermal-checkerboard/imageDataset")).expect("list");
    assert_eq!(images.len(), 60);
    let dets: Vec<_> = images
        .iter()
        .map(|p| {
            let g = Gray::read(p).expect("image");
            assert_eq!((g.width, g.height), (382, 288));
            detect(&g, (board.cols, board.rows), &DetectOptions::default())
        })
        .collect();
    let found = dets.iter().filter(|d| d.is_some()).count();
    let corners: usize = dets.iter().flatten().map(|d| d.corners.len()).sum();
    let r = calibrate_mono(&board, 382, 288, &dets, DistortionModel::RadialTangential)
        .expect("calibration");
    let used = r.view_errors.iter().flatten().count();
    println!(
        "found the board in {found}/60 frames ({corners} corners); {used} used, rejected {:?}; fx {:.2} fy {:.2} cx {:.2} cy {:.2} {:?}; MRE {:.3} px, RMS {:.3} px",
        r.rejected,
        r.camera.fx,
        r.camera.fy,
        r.camera.cx,
        r.camera.cy,
        r.camera.distortion,
        r.error.mean_px,
        r.error.rms_px
    );
    assert!(found >= 55, "board found in only {found} of 60 frames");
    assert!(used >= 50, "only {used} frames used");
    assert!(r.error.mean_px < 0.3, "MRE {:.3} px", r.error.mean_px);
}

/// The real foil-board pairs (`thermal-rgb-pairs`: a ZED 2i 1280×720 and a Lepton 3.5 in ironbow,
/// 120×160, 4×6 inner corners of 55 mm). OpenCV 5 on the same images (`bench/calib_real_peer.py`:
/// `findChessboardCorners` with adaptive threshold and normalisation, `cornerSubPix`, thermal
/// upscaled ×4, `calibrateCamera` and `stereoCalibrate` with the intrinsics fixed, k3 fixed)
/// finds the board in 35 colour and 34 thermal images; thermal fx 152.3, fy 149.9 px; stereo RMS
/// 1.189 px; the thermal camera at (−73.5, 33.3, −47.6) mm from the colour camera, and at
/// (−69.9, 30.4, 3.2) mm when views whose own error is more than twice the median are dropped
/// (its colour corners slide 6–9 px along foil glare in seven images, and its colour focal
/// length goes from 847 to 895–902 px without them).
#[test]
fn real_foil_board_pairs_calibrate_like_opencv() {
    use mrtmap_calib::{PairInput, StereoOptions, calibrate_stereo, plausibility};
    use mrtmap_geometry::nalgebra::Vector3;
    let Some(dir) = data_dir() else {
        println!("skipped: shared/data not found (set MRTMAP_DATA_DIR)");
        return;
    };
    let pairs = dir.join("thermal-rgb-pairs");
    if !pairs.is_dir() {
        println!("skipped: shared/data/thermal-rgb-pairs not found");
        return;
    }
    let board = Board {
        cols: 4,
        rows: 6,
        square_m: 0.055,
    };
    let detect_all = |sub: &str| {
        let images = list_images(&pairs.join(sub)).expect("list");
        assert_eq!(images.len(), 35, "{sub}");
        images
            .iter()
            .map(|p| {
                let g = Gray::read(p).expect("image");
                detect(&g, (4, 6), &DetectOptions::default())
            })
            .collect::<Vec<_>>()
    };
    let (rgb, thermal) = (detect_all("rgb"), detect_all("thermal"));
    let found = |d: &[Option<_>]| d.iter().filter(|x| x.is_some()).count();
    assert!(found(&rgb) >= 35, "colour: {} of 35", found(&rgb));
    assert!(found(&thermal) >= 34, "thermal: {} of 35", found(&thermal));
    let inputs: Vec<PairInput> = rgb
        .iter()
        .zip(&thermal)
        .map(|(r, t)| PairInput {
            rgb: r.as_ref(),
            thermal: t.as_ref(),
        })
        .collect();
    let r = calibrate_stereo(
        &board,
        (1280, 720),
        (120, 160),
        &inputs,
        &StereoOptions::default(),
    )
    .expect("calibration");
    let c = r.rgb_from_thermal.translation.vector * 1e3;
    println!(
        "thermal fx {:.1} fy {:.1} cx {:.1} cy {:.1}; colour fx {:.1}; centre ({:.1}, {:.1}, {:.1}) mm, {:.2}°; std {:?}",
        r.thermal.fx,
        r.thermal.fy,
        r.thermal.cx,
        r.thermal.cy,
        r.rgb.fx,
        c.x,
        c.y,
        c.z,
        r.rgb_from_thermal.rotation.angle().to_degrees(),
        r.std.as_ref().map(|s| s[18..].to_vec())
    );
    let used = r
        .pairs
        .iter()
        .filter(|p| p.status == mrtmap_calib::PairStatus::Used)
        .count();
    assert!(used >= 25, "only {used} of 35 pairs used");
    // Thermal focal length within 5 % of OpenCV's, each axis within 3 %, square pixels.
    assert!(
        (r.thermal.fx / 152.3 - 1.0).abs() < 0.03,
        "fx {}",
        r.thermal.fx
    );
    assert!(
        (r.thermal.fy / 149.9 - 1.0).abs() < 0.03,
        "fy {}",
        r.thermal.fy
    );
    assert!((r.thermal.fx / r.thermal.fy - 1.0).abs() < 0.03);
    // Stereo RMS (both cameras' corners) no worse than 1.05 × OpenCV's.
    let (a, b) = (r.rgb_error, r.thermal_error);
    let stereo = ((a.rms_px.powi(2) * a.corners as f64 + b.rms_px.powi(2) * b.corners as f64)
        / (a.corners + b.corners) as f64)
        .sqrt();
    assert!(stereo <= 1.05 * 1.189, "stereo RMS {stereo:.3} px");
    // Within 2.5 cm of OpenCV's pose once its bad colour views are dropped.
    let careful = Vector3::new(-69.9, 30.4, 3.2);
    assert!((c - careful).norm() < 25.0, "centre {c:?}");
    // The stated uncertainty covers plain OpenCV's pose too (within 3 σ per axis), and the pose is
    // flagged as poorly constrained: these views do not fix it to a centimetre.
    let std = r.std.as_ref().expect("std");
    let plain = Vector3::new(-73.5, 33.3, -47.6);
    for k in 0..3 {
        assert!(
            (c[k] - plain[k]).abs() < 3.0 * std[21 + k] * 1e3,
            "axis {k}: {:.1} mm off OpenCV's, ± {:.1} mm stated",
            c[k] - plain[k],
            std[21 + k] * 1e3
        );
    }
    let w = plausibility(&r);
    assert!(w.iter().any(|w| w.contains("poorly constrained")), "{w:?}");
}
