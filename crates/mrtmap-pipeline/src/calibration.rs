//! Calibration runs behind `mrtmap calibrate`: every image of a folder read and searched for the
//! board in parallel, the fit, rig.toml, and the report folder (corners drawn on every image,
//! thermal-over-colour overlays, `calibration.json`, `index.html`).

use std::path::{Path, PathBuf};

use mrtmap_calib::report::{draw_corners, overlay, png};
use mrtmap_calib::rig::{rig_toml, updated_rig};
/// The calibration's inputs and results (mrtmap-calib's types).
pub use mrtmap_calib::synth::SynthOptions;
pub(crate) use mrtmap_calib::{
    Board, DistortionModel, GridSize, MonoResult, StereoOptions, StereoResult,
};
use mrtmap_calib::{
    DetectOptions, Detection, Gray, ImagePair, PairInput, ViewError, calibrate_mono,
    calibrate_stereo, detect_variants, find_pairs, list_images,
};
pub(crate) use mrtmap_calib::{PairStatus, plausibility};
/// A camera's intrinsics.
pub(crate) use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_io::{FileError, PoseFile, Rig, write_atomic};
use rayon::prelude::*;
use serde_json::json;

use crate::cache::write_json;
use crate::error::{Error, Result};

/// An image read and searched, or why not.
pub(crate) struct Seen {
    /// The image in grey (absent when it could not be read or had the wrong size).
    pub gray: Option<Gray>,
    /// The board's corners, when found.
    pub det: Option<Detection>,
    /// Why the image was left out.
    pub problem: Option<String>,
}

fn see(path: &Path, board: &Board, size: Option<(u32, u32)>) -> Seen {
    let variants = match Gray::read_variants(path) {
        Err(e) => {
            return Seen {
                gray: None,
                det: None,
                problem: Some(e.to_string()),
            };
        }
        Ok(v) => v,
    };
    let g = variants[0].clone();
    if let Some((w, h)) = size
        && (g.width, g.height) != (w, h)
    {
        return Seen {
            problem: Some(format!(
                "{}: image is {}×{} pixels but the first image of this camera is {w}×{h}",
                path.display(),
                g.width,
                g.height
            )),
            gray: None,
            det: None,
        };
    }
    let det = detect_variants(
        &variants,
        (board.cols, board.rows),
        &DetectOptions::default(),
    )
    .map(|(_, d)| d);
    Seen {
        gray: Some(g),
        det,
        problem: None,
    }
}

/// Reads and searches images in parallel; all must share the first readable image's size.
pub(crate) fn see_all(paths: &[PathBuf], board: &Board) -> (Vec<Seen>, Option<(u32, u32)>) {
    let size = paths.iter().find_map(|p| {
        image::ImageReader::open(p)
            .ok()?
            .with_guessed_format()
            .ok()?
            .into_dimensions()
            .ok()
    });
    let seen = paths.par_iter().map(|p| see(p, board, size)).collect();
    (seen, size)
}

/// Every image of a folder searched for the board.
pub(crate) struct ImageDetections {
    /// The images.
    pub paths: Vec<PathBuf>,
    /// What was seen in each.
    pub seen: Vec<Seen>,
    /// Their size.
    pub size: (u32, u32),
}

impl ImageDetections {
    /// Images in which the board was found.
    pub fn found(&self) -> usize {
        self.seen.iter().filter(|s| s.det.is_some()).count()
    }
}

/// Reads the images in `dir` and searches each for the board.
pub(crate) fn detect_images(dir: &Path, board: &Board) -> Result<ImageDetections> {
    let paths = list_images(dir)?;
    if paths.is_empty() {
        return Err(Error::source(dir, "holds no PNG, JPEG or TIFF images"));
    }
    let (seen, size) = see_all(&paths, board);
    let Some(size) = size else {
        return Err(Error::source(dir, "no image in it could be read"));
    };
    Ok(ImageDetections { paths, seen, size })
}

/// One camera's intrinsics from its images' detections.
pub(crate) fn calibrate_images(
    d: &ImageDetections,
    board: &Board,
    model: DistortionModel,
) -> Result<MonoResult> {
    let dets: Vec<Option<Detection>> = d.seen.iter().map(|s| s.det.clone()).collect();
    Ok(calibrate_mono(board, d.size.0, d.size.1, &dets, model)?)
}

/// Writes a report image as PNG.
fn write_png(path: &Path, img: &image::RgbImage) -> Result<()> {
    let bytes = png(img).map_err(|e| FileError::encode(path, e))?;
    Ok(write_atomic(path, &bytes)?)
}

/// Pixels of a report image per image pixel: small thermal images are enlarged.
fn scale_for_report(w: u32) -> u32 {
    (640 / w.max(1)).clamp(1, 4)
}

fn corners_json(d: Option<&Detection>) -> serde_json::Value {
    d.map_or(serde_json::Value::Null, |d| {
        json!(
            d.corners
                .iter()
                .map(|c| [c.i as f64, c.j as f64, c.x, c.y])
                .collect::<Vec<_>>()
        )
    })
}

/// A file stem for people.
pub(crate) fn file_stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn create_dir(dir: &Path) -> Result<()> {
    Ok(std::fs::create_dir_all(dir).map_err(|e| FileError::io(dir, e))?)
}

/// Writes the corners drawn on every image and `calibration.json` into `rep`.
pub(crate) fn write_mono_report(
    rep: &Path,
    board: &Board,
    d: &ImageDetections,
    r: &MonoResult,
) -> Result<()> {
    create_dir(rep)?;
    let mut views = Vec::new();
    for (k, (p, s)) in d.paths.iter().zip(&d.seen).enumerate() {
        let name = file_stem(p);
        if let Some(g) = &s.gray {
            let img = draw_corners(g, s.det.as_ref(), scale_for_report(g.width));
            write_png(&rep.join(format!("{name}_corners.png")), &img)?;
        }
        views.push(json!({
            "name": name,
            "path": p.display().to_string(),
            "problem": s.problem,
            "corners": corners_json(s.det.as_ref()),
            "error": r.view_errors[k],
            "rejected": r.rejected.contains(&k),
        }));
    }
    let doc = json!({
        "board": board,
        "camera": r.camera,
        "std": r.std,
        "error": r.error,
        "views": views,
    });
    write_json(&rep.join("calibration.json"), &doc)
}

/// Every pair of a folder searched for the board.
pub(crate) struct PairDetections {
    /// The pairs.
    pub pairs: Vec<ImagePair>,
    /// Images without a partner.
    pub unmatched: Vec<PathBuf>,
    /// What was seen in each colour image.
    pub rgb_seen: Vec<Seen>,
    /// What was seen in each thermal image.
    pub thermal_seen: Vec<Seen>,
    /// Colour image size.
    pub rgb_size: (u32, u32),
    /// Thermal image size.
    pub thermal_size: (u32, u32),
}

/// Images of `seen` in which the board was found.
pub(crate) fn found(seen: &[Seen]) -> usize {
    seen.iter().filter(|s| s.det.is_some()).count()
}

/// Pairs the images in `dir` and searches each for the board.
pub(crate) fn detect_pairs(dir: &Path, board: &Board, max_dt: f64) -> Result<PairDetections> {
    let pairing = find_pairs(dir, max_dt)?;
    let rgb_paths: Vec<PathBuf> = pairing.pairs.iter().map(|p| p.rgb.clone()).collect();
    let th_paths: Vec<PathBuf> = pairing.pairs.iter().map(|p| p.thermal.clone()).collect();
    let (rgb_seen, rgb_size) = see_all(&rgb_paths, board);
    let (thermal_seen, th_size) = see_all(&th_paths, board);
    let (Some(rgb_size), Some(thermal_size)) = (rgb_size, th_size) else {
        return Err(Error::source(
            dir,
            "no colour or no thermal image in it could be read",
        ));
    };
    Ok(PairDetections {
        pairs: pairing.pairs,
        unmatched: pairing.unmatched,
        rgb_seen,
        thermal_seen,
        rgb_size,
        thermal_size,
    })
}

/// Both cameras and the thermal camera's pose from the pairs' detections.
pub(crate) fn calibrate_pairs(
    d: &PairDetections,
    board: &Board,
    opts: &StereoOptions,
) -> Result<StereoResult> {
    let inputs: Vec<PairInput> = d
        .rgb_seen
        .iter()
        .zip(&d.thermal_seen)
        .map(|(c, t)| PairInput {
            rgb: c.det.as_ref(),
            thermal: t.det.as_ref(),
        })
        .collect();
    Ok(calibrate_stereo(
        board,
        d.rgb_size,
        d.thermal_size,
        &inputs,
        opts,
    )?)
}

/// Writes the result into the rig.toml `out`, updating an existing one (its `[depth]` is kept);
/// returns whether one existed.
pub(crate) fn write_rig(
    out: &Path,
    board: &Board,
    d: &PairDetections,
    r: &StereoResult,
) -> Result<bool> {
    let existing = if out.exists() {
        Some(Rig::read(out).map_err(|e| {
            Error::source(out, format!("exists but is not a rig.toml to update: {e}"))
        })?)
    } else {
        None
    };
    let names: Vec<String> = d.pairs.iter().map(|p| p.name.clone()).collect();
    let rig = updated_rig(r, existing.as_ref());
    write_atomic(out, rig_toml(&rig, r, board, &names).as_bytes())?;
    Ok(existing.is_some())
}

/// A pair's name made safe for file names.
fn safe_name(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Writes pair `k`'s images (corners on each, the overlay of a used pair); returns their names.
fn pair_images(
    rep: &Path,
    board: &Board,
    d: &PairDetections,
    r: &StereoResult,
    k: usize,
) -> Result<Vec<String>> {
    let safe = safe_name(&d.pairs[k].name);
    let (rgb, th) = (&d.rgb_seen[k], &d.thermal_seen[k]);
    let mut cells = Vec::new();
    if let Some(g) = &rgb.gray {
        let f = format!("{safe}_rgb.png");
        write_png(&rep.join(&f), &draw_corners(g, rgb.det.as_ref(), 1))?;
        cells.push(f);
    }
    if let Some(g) = &th.gray {
        let f = format!("{safe}_thermal.png");
        let img = draw_corners(g, th.det.as_ref(), scale_for_report(g.width));
        write_png(&rep.join(&f), &img)?;
        cells.push(f);
    }
    if let (Some(cg), Some(tg), Some(pose), PairStatus::Used) = (
        &rgb.gray,
        &th.gray,
        r.rgb_alone.poses[k],
        &r.pairs[k].status,
    ) {
        let f = format!("{safe}_overlay.png");
        let img = overlay(
            cg,
            tg,
            &r.rgb,
            &r.thermal,
            &pose,
            &r.rgb_from_thermal,
            board,
        );
        write_png(&rep.join(&f), &img)?;
        cells.push(f);
    }
    Ok(cells)
}

/// A reprojection error for a table cell.
pub(crate) fn error_cell(x: Option<ViewError>) -> String {
    x.map_or("—".into(), |e| format!("{:.3}", e.mean_px))
}

/// A pair's status in words.
pub(crate) fn status_text(s: &PairStatus) -> String {
    match s {
        PairStatus::Used => "used".to_string(),
        PairStatus::Rejected(why) => format!("rejected: {why}"),
    }
}

/// Pair `k`'s two rows of the report's table.
fn pair_rows(d: &PairDetections, r: &StereoResult, k: usize, cells: &[String]) -> String {
    let pr = &r.pairs[k];
    format!(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n<tr><td colspan=6>{}</td></tr>\n",
        mrtmap_report::esc(&d.pairs[k].name),
        pr.rgb_corners,
        pr.thermal_corners,
        error_cell(pr.rgb_error),
        error_cell(pr.thermal_error),
        mrtmap_report::esc(&status_text(&pr.status)),
        cells
            .iter()
            .map(|f| format!("<img src=\"{f}\" loading=lazy>"))
            .collect::<String>()
    )
}

/// Pair `k` in calibration.json.
fn pair_json(d: &PairDetections, r: &StereoResult, k: usize) -> serde_json::Value {
    let p = &d.pairs[k];
    json!({
        "name": p.name,
        "rgb_path": p.rgb.display().to_string(),
        "thermal_path": p.thermal.display().to_string(),
        "result": r.pairs[k],
        "rgb_corners": corners_json(d.rgb_seen[k].det.as_ref()),
        "thermal_corners": corners_json(d.thermal_seen[k].det.as_ref()),
        "thermal_corners_tied": r.thermal_labels[k].as_ref().map(|c| c.iter().map(|c| [c.i as f64, c.j as f64, c.x, c.y]).collect::<Vec<_>>()),
    })
}

/// The report page around the pairs' table rows.
fn index_html(board: &Board, r: &StereoResult, rows: &str) -> String {
    let t = r.rgb_from_thermal.translation.vector * 1e3;
    format!(
        "<!doctype html><html><head><meta charset=utf-8><title>mrtmap calibrate</title><style>body{{font-family:sans-serif;margin:1.5em}}td{{padding:2px 8px}}img{{max-width:32%;margin:2px;image-rendering:pixelated}}</style></head><body>\n<h1>Rig calibration</h1>\n<p>Board {}x{} inner corners, {} mm squares. Colour {}×{} fx {:.2} fy {:.2}; thermal {}×{} fx {:.2} fy {:.2}. Thermal camera in the colour frame at ({:.1}, {:.1}, {:.1}) mm, turned {:.2}°.</p>\n<p>Mean reprojection error: colour {:.3} px, thermal {:.3} px. Each pair: corners drawn (rows coloured, the (0,0) corner circled twice), and the thermal image laid over the colour image on the board's plane through the result: the thermal squares should sit on the colour squares.</p>\n<table><tr><th>pair</th><th>colour corners</th><th>thermal corners</th><th>MRE colour px</th><th>MRE thermal px</th><th>status</th></tr>\n{rows}</table></body></html>\n",
        board.cols,
        board.rows,
        board.square_m * 1e3,
        r.rgb.width,
        r.rgb.height,
        r.rgb.fx,
        r.rgb.fy,
        r.thermal.width,
        r.thermal.height,
        r.thermal.fx,
        r.thermal.fy,
        t.x,
        t.y,
        t.z,
        r.rgb_from_thermal.rotation.angle().to_degrees(),
        r.rgb_error.mean_px,
        r.thermal_error.mean_px,
    )
}

/// Writes the report folder `rep`: every pair's images, calibration.json and index.html.
pub(crate) fn write_stereo_report(
    rep: &Path,
    board: &Board,
    d: &PairDetections,
    r: &StereoResult,
) -> Result<()> {
    create_dir(rep)?;
    let mut rows = String::new();
    let mut pairs = Vec::new();
    for k in 0..d.pairs.len() {
        let cells = pair_images(rep, board, d, r, k)?;
        rows.push_str(&pair_rows(d, r, k, &cells));
        pairs.push(pair_json(d, r, k));
    }
    let doc = json!({
        "board": board,
        "rgb": r.rgb,
        "thermal": r.thermal,
        "rgb_from_thermal": PoseFile::from_isometry(&r.rgb_from_thermal),
        "std": r.std,
        "rgb_error": r.rgb_error,
        "thermal_error": r.thermal_error,
        "rgb_alone": r.rgb_alone,
        "thermal_alone": r.thermal_alone,
        "pairs": pairs,
        "warnings": plausibility(r),
        "model_choice": r.model_choice,
    });
    write_json(&rep.join("calibration.json"), &doc)?;
    write_atomic(
        &rep.join("index.html"),
        index_html(board, r, &rows).as_bytes(),
    )?;
    Ok(())
}

/// Checks a board's square size.
pub(crate) fn board(cols: u32, rows: u32, square_m: f64) -> Result<Board> {
    Board::new(cols, rows, square_m).ok_or_else(|| {
        Error::setting(
            "--square-m",
            format!("must be a positive number of metres, got {square_m}"),
        )
    })
}

/// Renders synthetic board pairs of the default synthetic rig into `out` (rgb/, thermal/ as
/// 16-bit centikelvin, truth.json); returns how many were written.
pub fn simulate_boards(out: &Path, o: &SynthOptions) -> Result<usize> {
    use mrtmap_calib::synth::{SynthRig, render_pairs};
    use mrtmap_geometry::camera::PinholeCamera;
    let rig = SynthRig::default();
    let pairs = render_pairs(&rig, o);
    if pairs.len() < o.pairs {
        return Err(Error::setting(
            format!("{} board poses", o.pairs),
            format!(
                "are too many: the board fits in only {} of them",
                pairs.len()
            ),
        ));
    }
    let (rd, td) = (out.join("rgb"), out.join("thermal"));
    for (k, p) in pairs.iter().enumerate() {
        let name = format!("{k:04}.png");
        write_png(&rd.join(&name), &p.rgb)?;
        let (path, thermal) = (td.join(&name), mrtmap_io::encode_png16(&p.thermal));
        write_atomic(&path, &thermal.map_err(|e| FileError::encode(&path, e))?)?;
    }
    let cam = |c: &PinholeCamera| json!({"width": c.width, "height": c.height, "fx": c.fx, "fy": c.fy, "cx": c.cx, "cy": c.cy, "distortion": c.distortion.to_array()});
    let truth = json!({
        "board": {"cols": o.board.cols, "rows": o.board.rows, "square_m": o.board.square_m},
        "rgb": cam(&rig.rgb),
        "thermal": cam(&rig.thermal),
        "rgb_from_thermal": PoseFile::from_isometry(&rig.rgb_from_thermal),
        "rgb_from_board": pairs.iter().map(|p| PoseFile::from_isometry(&p.rgb_from_board)).collect::<Vec<_>>(),
    });
    write_json(&out.join("truth.json"), &truth)?;
    Ok(pairs.len())
}

/// One camera's intrinsics in a line: size, focal lengths, principal point and distortion with
/// their standard deviations (`std`, when known), and its own fit's error.
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

/// What a one-camera calibration found, in lines: the camera and the fit's error, with the
/// images left out by name.
pub(crate) fn mono_lines(d: &ImageDetections, r: &MonoResult) -> Vec<String> {
    let mut lines = Vec::new();
    lines.push(describe(
        "camera",
        &r.camera,
        r,
        r.std.as_ref().map(|s| &s[..]),
    ));
    let rejected = if r.rejected.is_empty() {
        "none".to_string()
    } else {
        r.rejected
            .iter()
            .map(|k| {
                d.paths[*k]
                    .file_name()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    lines.push(format!(
        "mean reprojection error {:.3} px (RMS {:.3} px) over {} views, {} corners; rejected: {rejected}",
        r.error.mean_px,
        r.error.rms_px,
        r.view_errors.iter().flatten().count(),
        r.error.corners,
    ));
    lines
}

/// The thermal camera's pose in the colour frame, with its standard deviations.
fn extrinsic_line(r: &StereoResult) -> String {
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
    format!(
        "thermal camera in the colour frame: translation ({:.2}, {:.2}, {:.2}) mm{tstd}, rotation {:.3}°{rstd} about ({:.3}, {:.3}, {:.3})",
        t.x,
        t.y,
        t.z,
        angle.to_degrees(),
        axis[0],
        axis[1],
        axis[2]
    )
}

/// What a rig calibration found, in lines: both cameras, the extrinsic, how the model was
/// chosen, plausibility warnings, the joint fit's errors and a table of the pairs.
pub(crate) fn stereo_lines<'a>(
    r: &StereoResult,
    names: impl Iterator<Item = &'a str>,
) -> Vec<String> {
    let mut lines = Vec::new();
    let std = r.std.as_deref();
    lines.push(describe(
        "colour",
        &r.rgb,
        &r.rgb_alone,
        std.map(|s| &s[0..9]),
    ));
    lines.push(describe(
        "thermal",
        &r.thermal,
        &r.thermal_alone,
        std.map(|s| &s[9..18]),
    ));
    lines.push(extrinsic_line(r));
    lines.push(format!("model: {}", r.model_choice));
    for w in plausibility(r) {
        lines.push(format!("warning: {w}"));
    }
    let used = r
        .pairs
        .iter()
        .filter(|p| p.status == PairStatus::Used)
        .count();
    lines.push(format!(
        "joint fit over {used} of {} pairs: mean reprojection error colour {:.3} px (RMS {:.3}), thermal {:.3} px (RMS {:.3})",
        r.pairs.len(),
        r.rgb_error.mean_px,
        r.rgb_error.rms_px,
        r.thermal_error.mean_px,
        r.thermal_error.rms_px
    ));
    lines.push(format!(
        "{:<24} {:>7} {:>8} {:>10} {:>11}  status",
        "pair", "colour", "thermal", "MRE col", "MRE therm"
    ));
    for (p, name) in r.pairs.iter().zip(names) {
        lines.push(format!(
            "{name:<24} {:>7} {:>8} {:>10} {:>11}  {}",
            p.rgb_corners,
            p.thermal_corners,
            error_cell(p.rgb_error),
            error_cell(p.thermal_error),
            status_text(&p.status)
        ));
    }
    lines
}

/// `mrtmap calibrate`: the flags.
#[derive(Debug, Clone, clap::Args)]
#[command(after_long_help = "Examples:
  mrtmap simulate-board --out boards
  mrtmap calibrate --pairs boards --board 8x6 --square-m 0.06 --out rig.toml --report calib-report
  mrtmap calibrate --images thermal-shots --board 11x9 --square-m 0.0505 --report r

The pairs folder holds rgb/ and thermal/ sub-folders (images paired by file stem, or by the nearest
timestamp when the stems are numbers), or files tagged like 0001_rgb.png + 0001_thermal.png.
Thermal images may be 16-bit radiometric (any scale: they are stretched) or 8-bit grey or
colour-mapped. At least one pair must show all inner corners in both images; other pairs may show
part of the board.")]
pub struct CalibrateArgs {
    /// Folder of colour + thermal image pairs.
    #[arg(long, value_name = "DIR", conflicts_with = "images")]
    pub(crate) pairs: Option<PathBuf>,
    /// Folder of one camera's images: its intrinsics only.
    #[arg(long, value_name = "DIR")]
    pub(crate) images: Option<PathBuf>,
    /// Inner corners per row and column, COLSxROWS (a board of 9×7 squares has 8x6).
    #[arg(long, value_name = "COLSxROWS")]
    pub(crate) board: GridSize,
    /// Side of one square (m).
    #[arg(long, value_name = "M")]
    pub(crate) square_m: f64,
    /// rig.toml to write. An existing one keeps its [depth] section and encoding; a new one takes
    /// the colour camera as the depth camera (a RealSense with depth aligned to colour).
    #[arg(long, value_name = "FILE")]
    pub(crate) out: Option<PathBuf>,
    /// Report folder: corners drawn on every image, thermal-over-colour overlays, index.html,
    /// calibration.json.
    #[arg(long, value_name = "DIR")]
    pub(crate) report: Option<PathBuf>,
    /// Distortion model of the colour camera (or of the --images camera).
    #[arg(long, value_enum, default_value = "auto")]
    pub(crate) distortion: DistortionModel,
    /// Distortion model of the thermal camera.
    #[arg(long, value_enum, default_value = "auto")]
    pub(crate) thermal_distortion: DistortionModel,
    /// Largest time difference (s) when pairing images by timestamp.
    #[arg(long, default_value_t = 0.05, value_name = "S")]
    pub(crate) max_dt: f64,
    /// Fit only the corners found in both images of a pair (as OpenCV's stereoCalibrate).
    #[arg(long)]
    pub(crate) common_corners: bool,
}

/// The images searched for the board, before the fit ([`CalibrateArgs::detect`]).
pub struct Detected {
    board: Board,
    images: Images,
}

/// One camera's images, or colour + thermal pairs.
enum Images {
    Mono(ImageDetections),
    Stereo(PairDetections),
}

impl CalibrateArgs {
    /// `mrtmap calibrate`, first step: the board checked, and the images of `--images` or the
    /// pairs of `--pairs` read and searched for it.
    pub fn detect(&self) -> Result<Detected> {
        detect(self)
    }
}

/// [`CalibrateArgs::detect`].
fn detect(a: &CalibrateArgs) -> Result<Detected> {
    let board = board(a.board.cols, a.board.rows, a.square_m)?;
    let images = match (&a.pairs, &a.images) {
        (Some(dir), None) => Images::Stereo(detect_pairs(dir, &board, a.max_dt)?),
        (None, Some(dir)) => {
            if a.out.is_some() {
                return Err(Error::setting(
                    "--out",
                    "writes a rig.toml, which needs --pairs (colour + thermal); with --images the result goes to the screen and --report",
                ));
            }
            Images::Mono(detect_images(dir, &board)?)
        }
        _ => {
            return Err(Error::setting(
                "give",
                "--pairs DIR (colour + thermal pairs) or --images DIR (one camera's intrinsics)",
            ));
        }
    };
    Ok(Detected { board, images })
}

impl Detected {
    /// Why images were left out, one line each.
    pub fn problems(&self) -> Vec<String> {
        let seen: Vec<&Seen> = match &self.images {
            Images::Mono(d) => d.seen.iter().collect(),
            Images::Stereo(d) => d.rgb_seen.iter().chain(&d.thermal_seen).collect(),
        };
        seen.iter().filter_map(|s| s.problem.clone()).collect()
    }

    /// What was found, as `mrtmap calibrate` prints it before the fit.
    pub fn lines(&self) -> Vec<String> {
        let b = &self.board;
        match &self.images {
            Images::Mono(d) => vec![format!(
                "board {}x{} of {} mm squares found in {} of {} images ({}×{})",
                b.cols,
                b.rows,
                b.square_m * 1e3,
                d.found(),
                d.paths.len(),
                d.size.0,
                d.size.1
            )],
            Images::Stereo(d) => {
                let mut lines = Vec::new();
                if let Some(first) = d.unmatched.first() {
                    lines.push(format!(
                        "{} image(s) without a partner were left out (first: {})",
                        d.unmatched.len(),
                        first.display()
                    ));
                }
                lines.push(format!(
                    "{} pairs; board {}x{} ({} mm squares) found in {} colour ({}×{}) and {} thermal ({}×{}) images",
                    d.pairs.len(),
                    b.cols,
                    b.rows,
                    b.square_m * 1e3,
                    found(&d.rgb_seen),
                    d.rgb_size.0,
                    d.rgb_size.1,
                    found(&d.thermal_seen),
                    d.thermal_size.0,
                    d.thermal_size.1
                ));
                lines
            }
        }
    }

    /// `mrtmap calibrate`, second step: the fit, rig.toml (`--out`) and the report folder
    /// (`--report`) written; gives what the CLI prints.
    pub fn calibrate(&self, a: &CalibrateArgs) -> Result<Vec<String>> {
        let board = &self.board;
        match &self.images {
            Images::Mono(d) => {
                let r = calibrate_images(d, board, a.distortion)?;
                let mut lines = mono_lines(d, &r);
                if let Some(rep) = &a.report {
                    write_mono_report(rep, board, d, &r)?;
                    lines.push(format!("report: {}", rep.display()));
                }
                Ok(lines)
            }
            Images::Stereo(d) => {
                let opts = StereoOptions {
                    model_rgb: a.distortion,
                    model_thermal: a.thermal_distortion,
                    common_corners: a.common_corners,
                };
                let r = calibrate_pairs(d, board, &opts)?;
                let mut lines = stereo_lines(&r, d.pairs.iter().map(|p| p.name.as_str()));
                if let Some(out) = &a.out {
                    let updated = write_rig(out, board, d, &r)?;
                    lines.push(format!(
                        "wrote {} ({})",
                        out.display(),
                        if updated {
                            "updated [thermal] and [rgb]; [depth] kept"
                        } else {
                            "new: the colour camera is taken as the depth camera (depth aligned to colour); check [depth]"
                        }
                    ));
                }
                if let Some(rep) = &a.report {
                    write_stereo_report(rep, board, d, &r)?;
                    lines.push(format!("report: {}", rep.join("index.html").display()));
                }
                Ok(lines)
            }
        }
    }
}
