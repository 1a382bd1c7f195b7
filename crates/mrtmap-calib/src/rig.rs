//! Writing the result into rig.toml (docs/recording.md): the `[thermal]` and `[rgb]`
//! sections with `depth_from_thermal`, and a `[calibration]` table with the errors (readers of
//! rig.toml ignore it).

use mrtmap_geometry::nalgebra::Isometry3;
use mrtmap_io::{RgbCamera, Rig, ThermalEncoding};
use serde::Serialize;

use crate::board::Board;
use crate::calibrate::{PairStatus, StereoResult};

/// The rig with the calibration applied. An existing rig keeps its depth camera, its thermal
/// encoding and its depth_from_rgb (the thermal pose is chained through it); without one, the
/// colour camera is the depth camera (a RealSense whose depth is aligned to colour, 1000 raw
/// units per metre).
pub fn updated_rig(r: &StereoResult, existing: Option<&Rig>) -> Rig {
    let depth_from_rgb = existing
        .and_then(|e| e.rgb.map(|c| c.depth_from_rgb))
        .unwrap_or_else(Isometry3::identity);
    let mut depth = r.rgb;
    depth.distortion = Default::default();
    Rig {
        depth: existing.map_or(depth, |e| e.depth),
        depth_scale: existing.map_or(1000.0, |e| e.depth_scale),
        thermal: r.thermal,
        thermal_encoding: existing.map_or(ThermalEncoding::Centikelvin, |e| e.thermal_encoding),
        thermal_accuracy_k: existing.and_then(|e| e.thermal_accuracy_k),
        thermal_time_offset_s: existing.and_then(|e| e.thermal_time_offset_s),
        depth_from_thermal: depth_from_rgb * r.rgb_from_thermal,
        rgb: Some(RgbCamera {
            camera: r.rgb,
            depth_from_rgb,
        }),
    }
}

#[derive(Serialize)]
struct PairRow {
    name: String,
    status: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<String>,
    rgb_corners: usize,
    thermal_corners: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    rgb_mre_px: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    thermal_mre_px: Option<f64>,
}

#[derive(Serialize)]
struct CalibrationTable {
    board: String,
    square_m: f64,
    pairs_used: usize,
    pairs_rejected: usize,
    rgb_mre_px: f64,
    rgb_rms_px: f64,
    thermal_mre_px: f64,
    thermal_rms_px: f64,
    pairs: Vec<PairRow>,
}

#[derive(Serialize)]
struct Wrapper {
    calibration: CalibrationTable,
}

fn round(x: f64, digits: i32) -> f64 {
    let f = 10f64.powi(digits);
    (x * f).round() / f
}

/// rig.toml text: the rig, then the `[calibration]` table (per-pair and mean reprojection errors).
pub fn rig_toml(rig: &Rig, r: &StereoResult, board: &Board, names: &[String]) -> String {
    let used = r
        .pairs
        .iter()
        .filter(|p| p.status == PairStatus::Used)
        .count();
    let table = CalibrationTable {
        board: format!("{}x{}", board.cols, board.rows),
        square_m: board.square_m,
        pairs_used: used,
        pairs_rejected: r.pairs.len() - used,
        rgb_mre_px: round(r.rgb_error.mean_px, 4),
        rgb_rms_px: round(r.rgb_error.rms_px, 4),
        thermal_mre_px: round(r.thermal_error.mean_px, 4),
        thermal_rms_px: round(r.thermal_error.rms_px, 4),
        pairs: r
            .pairs
            .iter()
            .zip(names)
            .map(|(p, n)| PairRow {
                name: n.clone(),
                status: match p.status {
                    PairStatus::Used => "used",
                    PairStatus::Rejected(_) => "rejected",
                },
                reason: match &p.status {
                    PairStatus::Used => None,
                    PairStatus::Rejected(why) => Some(why.clone()),
                },
                rgb_corners: p.rgb_corners,
                thermal_corners: p.thermal_corners,
                rgb_mre_px: p.rgb_error.map(|e| round(e.mean_px, 4)),
                thermal_mre_px: p.thermal_error.map(|e| round(e.mean_px, 4)),
            })
            .collect(),
    };
    let extra = toml::to_string(&Wrapper { calibration: table }).unwrap_or_default();
    format!(
        "# Written by mrtmap calibrate: thermal and colour intrinsics, depth_from_thermal.\n{}\n{}",
        rig.to_toml(),
        extra
    )
}
