//! `mrtmap calibrate`: one camera's intrinsics, or the rig (both cameras and the thermal
//! camera's pose) into rig.toml.

use std::path::Path;

use anyhow::bail;
use mrtmap_pipeline::calibration::{
    Board, Seen, StereoOptions, board, calibrate_images, calibrate_pairs, detect_images,
    detect_pairs, found, mono_lines, stereo_lines, write_mono_report, write_rig,
    write_stereo_report,
};

use crate::cli::CalibrateArgs;
use crate::output::print_lines;

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
    print_lines(mono_lines(&d, &r));
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
    print_lines(stereo_lines(&r, d.pairs.iter().map(|p| p.name.as_str())));
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
