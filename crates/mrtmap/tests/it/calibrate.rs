//! `mrtmap simulate-board` + `mrtmap calibrate` end to end: the rig it writes against the truth,
//! an outlier pair rejected and reported, an existing rig updated, bad input, the real thermal
//! board images (when `shared/data` is present).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use mrtmap_io::Rig;
use serde_json::Value;

use crate::{mrtmap, ok};

fn fails(args: &[&str]) -> String {
    let o = mrtmap(args);
    assert!(!o.status.success(), "mrtmap {args:?} should fail");
    String::from_utf8(o.stderr).unwrap()
}

/// 12 simulated pairs (2 with the board partly out of view), made once.
fn boards() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap().keep().join("boards");
        let d = dir.to_str().unwrap();
        ok(&[
            "simulate-board",
            "--out",
            d,
            "--pairs",
            "12",
            "--partial",
            "2",
            "--seed",
            "3",
        ]);
        dir
    })
}

fn copy_dir(from: &Path, to: &Path) {
    for sub in ["rgb", "thermal"] {
        std::fs::create_dir_all(to.join(sub)).unwrap();
        for e in std::fs::read_dir(from.join(sub)).unwrap() {
            let e = e.unwrap();
            std::fs::copy(e.path(), to.join(sub).join(e.file_name())).unwrap();
        }
    }
}

fn truth() -> Value {
    serde_json::from_str(&std::fs::read_to_string(boards().join("truth.json")).unwrap()).unwrap()
}

#[test]
fn calibrate_writes_a_rig_matching_the_truth_and_a_report() {
    let tmp = tempfile::tempdir().unwrap();
    let rig_path = tmp.path().join("rig.toml");
    let report = tmp.path().join("report");
    let out = ok(&[
        "calibrate",
        "--pairs",
        boards().to_str().unwrap(),
        "--board",
        "8x6",
        "--square-m",
        "0.06",
        "--out",
        rig_path.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(
        out.contains("found in 12 colour (640×480) and 12 thermal (160×120) images"),
        "{out}"
    );
    assert!(out.contains("joint fit over 12 of 12 pairs"), "{out}");
    let rig = Rig::read(&rig_path).unwrap();
    let t = truth();
    let rel = |a: f64, b: &Value| (a - b.as_f64().unwrap()).abs() / b.as_f64().unwrap();
    assert!(rel(rig.thermal.fx, &t["thermal"]["fx"]) < 0.005);
    assert!(rel(rig.thermal.fy, &t["thermal"]["fy"]) < 0.005);
    let rgb = rig.rgb.unwrap().camera;
    assert!(rel(rgb.fx, &t["rgb"]["fx"]) < 0.005);
    let tt: Vec<f64> = t["rgb_from_thermal"]["translation"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let d = rig.depth_from_thermal.translation.vector;
    let err = ((d.x - tt[0]).powi(2) + (d.y - tt[1]).powi(2) + (d.z - tt[2]).powi(2)).sqrt();
    assert!(err < 0.002, "translation off by {:.2} mm", err * 1e3);
    // rig.toml carries the errors; the report has every image and the overlays.
    let text = std::fs::read_to_string(&rig_path).unwrap();
    assert!(text.contains("[calibration]") && text.contains("thermal_mre_px"));
    let cal: Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("calibration.json")).unwrap())
            .unwrap();
    assert_eq!(cal["pairs"].as_array().unwrap().len(), 12);
    let mre = cal["thermal_error"]["mean_px"].as_f64().unwrap();
    assert!(mre > 0.0 && mre < 0.2, "thermal MRE {mre}");
    for f in [
        "index.html",
        "0000_rgb.png",
        "0000_thermal.png",
        "0000_overlay.png",
    ] {
        assert!(report.join(f).is_file(), "{f} missing");
    }
}

#[test]
fn a_mismatched_pair_is_rejected_and_named() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("pairs");
    copy_dir(boards(), &dir);
    // Pair 0005 gets the thermal image of pair 0008: its board pose disagrees with the colour one.
    std::fs::copy(dir.join("thermal/0008.png"), dir.join("thermal/0005.png")).unwrap();
    let out = ok(&[
        "calibrate",
        "--pairs",
        dir.to_str().unwrap(),
        "--board",
        "8x6",
        "--square-m",
        "0.06",
    ]);
    let line = out.lines().find(|l| l.starts_with("0005")).unwrap();
    assert!(line.contains("rejected"), "{out}");
    assert!(out.contains("joint fit over 11 of 12 pairs"), "{out}");
}

#[test]
fn an_existing_rig_keeps_its_depth_camera() {
    let tmp = tempfile::tempdir().unwrap();
    let rig_path = tmp.path().join("rig.toml");
    std::fs::write(
        &rig_path,
        "[depth]\nwidth = 848\nheight = 480\nfx = 420.0\nfy = 420.0\ncx = 424.0\ncy = 240.0\ndepth_scale = 1000.0\n\n[thermal]\nwidth = 160\nheight = 120\nfx = 100.0\nfy = 100.0\ncx = 80.0\ncy = 60.0\nencoding = \"centikelvin\"\ndepth_from_thermal = { translation = [0.0, 0.0, 0.0], rotation_xyzw = [0.0, 0.0, 0.0, 1.0] }\n\n[rgb]\nwidth = 640\nheight = 480\nfx = 600.0\nfy = 600.0\ncx = 320.0\ncy = 240.0\ndepth_from_rgb = { translation = [0.015, 0.0, 0.0], rotation_xyzw = [0.0, 0.0, 0.0, 1.0] }\n",
    )
    .unwrap();
    ok(&[
        "calibrate",
        "--pairs",
        boards().to_str().unwrap(),
        "--board",
        "8x6",
        "--square-m",
        "0.06",
        "--out",
        rig_path.to_str().unwrap(),
    ]);
    let rig = Rig::read(&rig_path).unwrap();
    assert_eq!((rig.depth.width, rig.depth.fx), (848, 420.0));
    // depth_from_thermal = depth_from_rgb · rgb_from_thermal: the 15 mm offset is carried.
    let tx = truth()["rgb_from_thermal"]["translation"][0]
        .as_f64()
        .unwrap();
    let d = rig.depth_from_thermal.translation.vector.x;
    assert!((d - (tx + 0.015)).abs() < 0.002, "x {d}");
}

#[test]
fn bad_input_gets_one_clear_sentence() {
    let b = boards().to_str().unwrap();
    let e = fails(&[
        "calibrate",
        "--pairs",
        b,
        "--board",
        "1x6",
        "--square-m",
        "0.06",
    ]);
    assert!(e.contains("is not COLSxROWS"), "{e}");
    let e = fails(&["calibrate", "--pairs", b, "--board", "8x6", "--square-m=-1"]);
    assert!(e.contains("--square-m must be a positive"), "{e}");
    let e = fails(&[
        "calibrate",
        "--pairs",
        "/nonexistent/x",
        "--board",
        "8x6",
        "--square-m",
        "0.06",
    ]);
    assert!(
        e.contains("/nonexistent/x") && e.contains("is not a folder"),
        "{e}"
    );
    // A corrupt image is skipped and named; the rest still calibrate.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("pairs");
    copy_dir(boards(), &dir);
    std::fs::write(dir.join("thermal/0004.png"), b"not a png").unwrap();
    let o = mrtmap(&[
        "calibrate",
        "--pairs",
        dir.to_str().unwrap(),
        "--board",
        "8x6",
        "--square-m",
        "0.06",
    ]);
    assert!(o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("thermal/0004.png"), "{err}");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("no board found in the thermal image"), "{out}");
}

#[test]
fn real_thermal_board_images() {
    let dir = std::env::var_os("MRTMAP_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
        .join("thermal-checkerboard/imageDataset");
    if !dir.is_dir() {
        println!("skipped: {} not found (set MRTMAP_DATA_DIR)", dir.display());
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let rep = tmp.path().join("r");
    let out = ok(&[
        "calibrate",
        "--images",
        dir.to_str().unwrap(),
        "--board",
        "11x9",
        "--square-m",
        "0.0505",
        "--report",
        rep.to_str().unwrap(),
    ]);
    println!("{out}");
    assert!(out.contains("found in 60 of 60 images (382×288)"), "{out}");
    let cal: Value =
        serde_json::from_str(&std::fs::read_to_string(rep.join("calibration.json")).unwrap())
            .unwrap();
    let mre = cal["error"]["mean_px"].as_f64().unwrap();
    assert!(mre < 0.3, "MRE {mre}");
}
