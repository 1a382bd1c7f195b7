//! `mrtmap calibrate`: one camera's intrinsics, or the rig (both cameras and the thermal
//! camera's pose) into rig.toml.

use std::path::Path;

use anyhow::bail;
use mrtmap_pipeline::calibration::PinholeCamera;
use mrtmap_pipeline::calibration::{Board, MonoResult, PairStatus, StereoOptions, StereoResult};
use mrtmap_pipeline::calibration::{
    ImageDetections, Seen, board, calibrate_images, calibrate_pairs, detect_images, detect_pairs,
    error_cell, found, status_text, write_mono_report, write_rig, write_stereo_report,
};

use crate::cli::CalibrateArgs;

fn describe(name: &str, c: &PinholeCamera, m: &MonoResult, std: Option<&[f64]>) -> String {
    let d = c.distortion.to_array();
    let pm = |k: usize| std.map_or(String::new(), |s| format!(" ± {:.2}", s[k]));
    format!(
        "{name:<8} {}×{}  fx {:.2}{}  fy {:.2}{}  cx {:.2}{}  cy {:.2}{}  k1 {:.4} k2 {:.4} p1 {:.5} p2 {:.5} k3 {:.4}  (alone: MRE {:.3} px over {} views)",
        c.width,
        c.height,
        c.fx,
        pm(0),
        c.fy,
        pm(1),
        c.cx,
        pm(2),
        c.cy,
        pm(3),
        d[0],
        d[1],
        d[2],
        d[3],
        d[4],
        m.error.mean_px,
        m.view_errors.iter().flatten().count()
    )
}

fn print_problems<'a>(seen: impl Iterator<Item = &'a Seen>) {
    for s in seen {
        if let Some(p) = &s.problem {
            eprintln!("skipped: {p}");
        }
    }
}

pub fn run(a: &CalibrateArgs) -> anyhow::Result<()> {
    let board = board(a.board.cols, a.board.rows, a.square_m)?;
    match (&a.pairs, &a.images) {
        (Some(dir), None) => stereo(a, &board, dir),
        (None, Some(dir)) => mono(a, &board, dir),
        _ => bail!(
            "give --pairs DIR (colour + thermal pairs) or --images DIR (one camera's intrinsics)"
        ),
    }
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn print_mono(d: &ImageDetections, r: &MonoResult) {
    outln!(
        "{}",
        describe("camera", &r.camera, r, r.std.as_ref().map(|s| &s[..]))
    );
    let rejected = if r.rejected.is_empty() {
        "none".to_string()
    } else {
        r.rejected
            .iter()
            .map(|k| file_name(&d.paths[*k]))
            .collect::<Vec<_>>()
            .join(", ")
    };
    outln!(
        "mean reprojection error {:.3} px (RMS {:.3} px) over {} views, {} corners; rejected: {rejected}",
        r.error.mean_px,
        r.error.rms_px,
        r.view_errors.iter().flatten().count(),
        r.error.corners,
    );
}

fn mono(a: &CalibrateArgs, board: &Board, dir: &Path) -> anyhow::Result<()> {
    if a.out.is_some() {
        bail!(
            "--out writes a rig.toml, which needs --pairs (colour + thermal); with --images the result goes to the screen and --report"
        );
    }
    let d = detect_images(dir, board)?;
    print_problems(d.seen.iter());
    outln!(
        "board {}x{} of {} mm squares found in {} of {} images ({}×{})",
        board.cols,
        board.rows,
        board.square_m * 1e3,
        d.found(),
        d.paths.len(),
        d.size.0,
        d.size.1
    );
    let r = calibrate_images(&d, board, a.distortion)?;
    print_mono(&d, &r);
    if let Some(rep) = &a.report {
        write_mono_report(rep, board, &d, &r)?;
        outln!("report: {}", rep.display());
    }
    Ok(())
}

fn stereo(a: &CalibrateArgs, board: &Board, dir: &Path) -> anyhow::Result<()> {
    let d = detect_pairs(dir, board, a.max_dt)?;
    if let Some(first) = d.unmatched.first() {
        outln!(
            "{} image(s) without a partner were left out (first: {})",
            d.unmatched.len(),
            first.display()
        );
    }
    print_problems(d.rgb_seen.iter().chain(&d.thermal_seen));
    outln!(
        "{} pairs; board {}x{} ({} mm squares) found in {} colour ({}×{}) and {} thermal ({}×{}) images",
        d.pairs.len(),
        board.cols,
        board.rows,
        board.square_m * 1e3,
        found(&d.rgb_seen),
        d.rgb_size.0,
        d.rgb_size.1,
        found(&d.thermal_seen),
        d.thermal_size.0,
        d.thermal_size.1
    );
    let opts = StereoOptions {
        model_rgb: a.distortion,
        model_thermal: a.thermal_distortion,
        common_corners: a.common_corners,
    };
    let r = calibrate_pairs(&d, board, &opts)?;
    print_stereo(&r, d.pairs.iter().map(|p| p.name.as_str()));
    if let Some(out) = &a.out {
        let updated = write_rig(out, board, &d, &r)?;
        outln!(
            "wrote {} ({})",
            out.display(),
            if updated {
                "updated [thermal] and [rgb]; [depth] kept"
            } else {
                "new: the colour camera is taken as the depth camera (depth aligned to colour); check [depth]"
            }
        );
    }
    if let Some(rep) = &a.report {
        write_stereo_report(rep, board, &d, &r)?;
        outln!("report: {}", rep.join("index.html").display());
    }
    Ok(())
}

/// The thermal camera's pose in the colour frame, with its standard deviations.
fn print_extrinsic(r: &StereoResult) {
    let std = r.std.as_deref();
    let t = r.rgb_from_thermal.translation.vector * 1e3;
    let (axis, angle) = r
        .rgb_from_thermal
        .rotation
        .axis_angle()
        .map_or(([0.0; 3], 0.0), |(ax, an)| ([ax.x, ax.y, ax.z], an));
    let tstd = std.map_or(String::new(), |s| {
        format!(
            " ± ({:.2}, {:.2}, {:.2})",
            s[21] * 1e3,
            s[22] * 1e3,
            s[23] * 1e3
        )
    });
    let rstd = std.map_or(String::new(), |s| {
        format!(
            " ± {:.3}°",
            (s[18] * s[18] + s[19] * s[19] + s[20] * s[20])
                .sqrt()
                .to_degrees()
        )
    });
    outln!(
        "thermal camera in the colour frame: translation ({:.2}, {:.2}, {:.2}) mm{tstd}, rotation {:.3}°{rstd} about ({:.3}, {:.3}, {:.3})",
        t.x,
        t.y,
        t.z,
        angle.to_degrees(),
        axis[0],
        axis[1],
        axis[2]
    );
}

fn print_stereo<'a>(r: &StereoResult, names: impl Iterator<Item = &'a str>) {
    let std = r.std.as_deref();
    outln!(
        "{}",
        describe("colour", &r.rgb, &r.rgb_alone, std.map(|s| &s[0..9]))
    );
    outln!(
        "{}",
        describe(
            "thermal",
            &r.thermal,
            &r.thermal_alone,
            std.map(|s| &s[9..18])
        )
    );
    print_extrinsic(r);
    outln!("model: {}", r.model_choice);
    for w in mrtmap_pipeline::calibration::plausibility(r) {
        outln!("warning: {w}");
    }
    let used = r
        .pairs
        .iter()
        .filter(|p| p.status == PairStatus::Used)
        .count();
    outln!(
        "joint fit over {used} of {} pairs: mean reprojection error colour {:.3} px (RMS {:.3}), thermal {:.3} px (RMS {:.3})",
        r.pairs.len(),
        r.rgb_error.mean_px,
        r.rgb_error.rms_px,
        r.thermal_error.mean_px,
        r.thermal_error.rms_px
    );
    outln!(
        "{:<24} {:>7} {:>8} {:>10} {:>11}  status",
        "pair",
        "colour",
        "thermal",
        "MRE col",
        "MRE therm"
    );
    for (p, name) in r.pairs.iter().zip(names) {
        outln!(
            "{name:<24} {:>7} {:>8} {:>10} {:>11}  {}",
            p.rgb_corners,
            p.thermal_corners,
            error_cell(p.rgb_error),
            error_cell(p.thermal_error),
            status_text(&p.status)
        );
    }
}
