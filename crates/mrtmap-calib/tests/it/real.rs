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

/// The hand-made foil board of `thermal-rgb-pairs` (ZED 2i colour 1280×720, Lepton 3.5 ironbow
/// 120×160, 4×6 inner corners): the board is found in 34 of the 35 colour images (20 before large
/// images were also tried at half and a third of their size) and 32 of the 35 thermal ones.
/// OpenCV finds it in every image; the pose is not yet within its bounds (issue 14).
#[test]
fn real_foil_board_pairs_are_detected() {
    let Some(dir) = data_dir() else {
        println!("skipped: shared/data not found (set MRTMAP_DATA_DIR)");
        return;
    };
    let pairs = dir.join("thermal-rgb-pairs");
    if !pairs.is_dir() {
        println!("skipped: shared/data/thermal-rgb-pairs not found");
        return;
    }
    let count = |sub: &str| {
        let images = list_images(&pairs.join(sub)).expect("list");
        assert_eq!(images.len(), 35, "{sub}");
        images
            .iter()
            .filter(|p| {
                let g = Gray::read(p).expect("image");
                detect(&g, (4, 6), &DetectOptions::default()).is_some()
            })
            .count()
    };
    let (rgb, thermal) = (count("rgb"), count("thermal"));
    assert!(rgb >= 34, "colour: {rgb} of 35");
    assert!(thermal >= 32, "thermal: {thermal} of 35");
}
