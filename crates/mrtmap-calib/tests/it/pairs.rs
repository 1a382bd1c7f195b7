//! Pairing colour and thermal images, board sizes, homographies.

use mrtmap_calib::zhang::{apply_homography, fit_homography};
use mrtmap_calib::{GridSize, find_pairs};
use mrtmap_geometry::nalgebra::{Matrix3, Point2};

fn touch(p: &std::path::Path) {
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(p, b"x").unwrap();
}

#[test]
fn subfolders_pair_by_stem_or_nearest_timestamp() {
    let t = tempfile::tempdir().unwrap();
    for n in ["a", "b", "c"] {
        touch(&t.path().join(format!("rgb/{n}.png")));
    }
    for n in ["a", "c", "d"] {
        touch(&t.path().join(format!("thermal/{n}.png")));
    }
    let p = find_pairs(t.path(), 0.05).unwrap();
    let names: Vec<&str> = p.pairs.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["a", "c"]);
    assert_eq!(p.unmatched.len(), 2);

    let t = tempfile::tempdir().unwrap();
    for n in ["100.000", "100.500", "101.000"] {
        touch(&t.path().join(format!("color/{n}.jpg")));
    }
    for n in ["100.020", "100.700", "101.030"] {
        touch(&t.path().join(format!("ir/{n}.png")));
    }
    let p = find_pairs(t.path(), 0.05).unwrap();
    let pairs: Vec<(String, String)> = p
        .pairs
        .iter()
        .map(|p| {
            (
                p.name.clone(),
                p.thermal
                    .file_stem()
                    .unwrap()
                    .to_string_lossy()
                    .into_owned(),
            )
        })
        .collect();
    assert_eq!(
        pairs,
        [
            ("100.000".to_string(), "100.020".to_string()),
            ("101.000".to_string(), "101.030".to_string())
        ]
    );
    // 100.500 has no thermal frame within 50 ms; 100.700 is left over.
    assert_eq!(p.unmatched.len(), 2);
}

#[test]
fn tagged_names_pair_in_one_folder() {
    let t = tempfile::tempdir().unwrap();
    for f in [
        "0001_rgb.png",
        "0001_thermal.tiff",
        "color-0002.png",
        "ir-0002.png",
        "0003_rgb.png",
        "notes.png",
    ] {
        touch(&t.path().join(f));
    }
    let p = find_pairs(t.path(), 0.05).unwrap();
    let names: Vec<&str> = p.pairs.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["0001", "0002"]);
    assert_eq!(p.unmatched.len(), 2);
    let e = find_pairs(&t.path().join("nope"), 0.05)
        .unwrap_err()
        .to_string();
    assert!(e.contains("nope") && e.contains("is not a folder"), "{e}");
    let empty = tempfile::tempdir().unwrap();
    let e = find_pairs(empty.path(), 0.05).unwrap_err().to_string();
    assert!(e.contains("holds no image pairs"), "{e}");
}

#[test]
fn board_sizes_parse() {
    assert_eq!(
        "11x9".parse::<GridSize>().unwrap(),
        GridSize { cols: 11, rows: 9 }
    );
    assert_eq!(
        "8X6".parse::<GridSize>().unwrap(),
        GridSize { cols: 8, rows: 6 }
    );
    for bad in ["8", "1x6", "ax6", "8x6x2", "", "0x0"] {
        assert!(bad.parse::<GridSize>().is_err(), "{bad}");
    }
}

#[test]
fn homography_round_trip() {
    let h = Matrix3::new(310.0, -25.0, 300.0, 12.0, 295.0, 210.0, 0.05, -0.08, 1.0);
    let src: Vec<Point2<f64>> = (0..6)
        .flat_map(|j| (0..8).map(move |i| Point2::new(i as f64 * 0.06, j as f64 * 0.06)))
        .collect();
    let dst: Vec<Point2<f64>> = src.iter().map(|p| apply_homography(&h, p)).collect();
    let g = fit_homography(&src, &dst).unwrap();
    for (s, d) in src.iter().zip(&dst) {
        assert!((apply_homography(&g, s) - d).norm() < 1e-8);
    }
    // Collinear points do not define one.
    let line: Vec<Point2<f64>> = (0..6).map(|i| Point2::new(i as f64, 0.0)).collect();
    assert!(
        fit_homography(&line, &line).is_none() || fit_homography(&line[..3], &line[..3]).is_none()
    );
}
