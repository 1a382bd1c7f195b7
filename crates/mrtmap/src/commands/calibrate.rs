//! `mrtmap calibrate` and `mrtmap simulate-board`.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mrtmap_calib::report::{draw_corners, overlay, png};
use mrtmap_calib::rig::{rig_toml, updated_rig};
use mrtmap_calib::synth::{SynthOptions, SynthRig, render_pairs};
use mrtmap_calib::{
    Board, DetectOptions, Detection, DistortionModel, Gray, MonoResult, PairInput, PairStatus,
    StereoOptions, StereoResult, calibrate_mono, calibrate_stereo, detect, find_pairs, list_images,
};
use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_io::{PoseFile, Rig, encode_png16, write_atomic};
use rayon::prelude::*;
use serde_json::json;

use crate::cli::{CalibrateArgs, DistortionArg, SimulateBoardArgs};
use crate::output::json;

fn model(d: DistortionArg) -> DistortionModel {
    match d {
        DistortionArg::None => DistortionModel::None,
        DistortionArg::Radial => DistortionModel::Radial,
        DistortionArg::RadialTangential => DistortionModel::RadialTangential,
        DistortionArg::Full => DistortionModel::Full,
    }
}

/// An image read and searched, or why not.
struct Seen {
    gray: Option<Gray>,
    det: Option<Detection>,
    problem: Option<String>,
}

fn see(path: &Path, board: &Board, size: Option<(u32, u32)>) -> Seen {
    match Gray::read(path) {
        Err(e) => Seen {
            gray: None,
            det: None,
            problem: Some(e.to_string()),
        },
        Ok(g) => {
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
            let det = detect(&g, (board.cols, board.rows), &DetectOptions::default());
            Seen {
                gray: Some(g),
                det,
                problem: None,
            }
        }
    }
}

/// Reads and searches images in parallel; all must share the first readable image's size.
fn see_all(paths: &[PathBuf], board: &Board) -> (Vec<Seen>, Option<(u32, u32)>) {
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

pub fn run(a: &CalibrateArgs) -> anyhow::Result<()> {
    let Some(board) = Board::new(a.board.cols, a.board.rows, a.square_m) else {
        bail!(
            "--square-m must be a positive number of metres, got {}",
            a.square_m
        );
    };
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
    let paths = list_images(dir)?;
    if paths.is_empty() {
        bail!("{} holds no PNG, JPEG or TIFF images", dir.display());
    }
    let (seen, size) = see_all(&paths, board);
    let Some((w, h)) = size else {
        bail!("no image in {} could be read", dir.display());
    };
    for s in &seen {
        if let Some(p) = &s.problem {
            eprintln!("skipped: {p}");
        }
    }
    let dets: Vec<Option<Detection>> = seen.iter().map(|s| s.det.clone()).collect();
    let found = dets.iter().filter(|d| d.is_some()).count();
    println!(
        "board {}x{} of {} mm squares found in {found} of {} images ({w}×{h})",
        board.cols,
        board.rows,
        board.square_m * 1e3,
        paths.len()
    );
    let r = calibrate_mono(board, w, h, &dets, model(a.distortion))?;
    println!(
        "{}",
        describe("camera", &r.camera, &r, r.std.as_ref().map(|s| &s[..]))
    );
    println!(
        "mean reprojection error {:.3} px (RMS {:.3} px) over {} views, {} corners; rejected: {}",
        r.error.mean_px,
        r.error.rms_px,
        r.view_errors.iter().flatten().count(),
        r.error.corners,
        if r.rejected.is_empty() {
            "none".to_string()
        } else {
            r.rejected
                .iter()
                .map(|k| file_name(&paths[*k]))
                .collect::<Vec<_>>()
                .join(", ")
        }
    );
    if let Some(rep) = &a.report {
        std::fs::create_dir_all(rep).with_context(|| format!("cannot create {}", rep.display()))?;
        let mut views = Vec::new();
        for (k, (p, s)) in paths.iter().zip(&seen).enumerate() {
            let name = file_stem(p);
            if let Some(g) = &s.gray {
                let img = draw_corners(g, s.det.as_ref(), scale_for_report(g.width));
                write_atomic(&rep.join(format!("{name}_corners.png")), &png(&img))?;
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
        write_atomic(&rep.join("calibration.json"), json(&doc)?.as_bytes())?;
        println!("report: {}", rep.display());
    }
    Ok(())
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn file_stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn stereo(a: &CalibrateArgs, board: &Board, dir: &Path) -> anyhow::Result<()> {
    let pairing = find_pairs(dir, a.max_dt)?;
    let pairs = &pairing.pairs;
    if !pairing.unmatched.is_empty() {
        println!(
            "{} image(s) without a partner were left out (first: {})",
            pairing.unmatched.len(),
            pairing.unmatched[0].display()
        );
    }
    let rgb_paths: Vec<PathBuf> = pairs.iter().map(|p| p.rgb.clone()).collect();
    let th_paths: Vec<PathBuf> = pairs.iter().map(|p| p.thermal.clone()).collect();
    let (rgb_seen, rgb_size) = see_all(&rgb_paths, board);
    let (th_seen, th_size) = see_all(&th_paths, board);
    let (Some(rgb_size), Some(th_size)) = (rgb_size, th_size) else {
        bail!(
            "no colour or no thermal image in {} could be read",
            dir.display()
        );
    };
    for s in rgb_seen.iter().chain(&th_seen) {
        if let Some(p) = &s.problem {
            eprintln!("skipped: {p}");
        }
    }
    let n = pairs.len();
    let found_rgb = rgb_seen.iter().filter(|s| s.det.is_some()).count();
    let found_th = th_seen.iter().filter(|s| s.det.is_some()).count();
    println!(
        "{n} pairs; board {}x{} ({} mm squares) found in {found_rgb} colour ({}×{}) and {found_th} thermal ({}×{}) images",
        board.cols,
        board.rows,
        board.square_m * 1e3,
        rgb_size.0,
        rgb_size.1,
        th_size.0,
        th_size.1
    );
    let inputs: Vec<PairInput> = (0..n)
        .map(|k| PairInput {
            rgb: rgb_seen[k].det.as_ref(),
            thermal: th_seen[k].det.as_ref(),
        })
        .collect();
    let opts = StereoOptions {
        model_rgb: model(a.distortion),
        model_thermal: model(a.thermal_distortion),
        common_corners: a.common_corners,
    };
    let r = calibrate_stereo(board, rgb_size, th_size, &inputs, &opts)?;
    print_stereo(&r, pairs.iter().map(|p| p.name.as_str()).collect());
    let names: Vec<String> = pairs.iter().map(|p| p.name.clone()).collect();
    if let Some(out) = &a.out {
        let existing = if out.exists() {
            Some(Rig::read(out).with_context(|| {
                format!("{} exists but is not a rig.toml to update", out.display())
            })?)
        } else {
            None
        };
        let rig = updated_rig(&r, existing.as_ref());
        write_atomic(out, rig_toml(&rig, &r, board, &names).as_bytes())?;
        println!(
            "wrote {} ({})",
            out.display(),
            if existing.is_some() {
                "updated [thermal] and [rgb]; [depth] kept"
            } else {
                "new: the colour camera is taken as the depth camera (depth aligned to colour); check [depth]"
            }
        );
    }
    if let Some(rep) = &a.report {
        write_report(rep, board, &r, pairs, &rgb_seen, &th_seen)?;
        println!("report: {}", rep.join("index.html").display());
    }
    Ok(())
}

fn print_stereo(r: &StereoResult, names: Vec<&str>) {
    let std = r.std.as_deref();
    println!(
        "{}",
        describe("colour", &r.rgb, &r.rgb_alone, std.map(|s| &s[0..9]))
    );
    println!(
        "{}",
        describe(
            "thermal",
            &r.thermal,
            &r.thermal_alone,
            std.map(|s| &s[9..18])
        )
    );
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
    println!(
        "thermal camera in the colour frame: translation ({:.2}, {:.2}, {:.2}) mm{tstd}, rotation {:.3}°{rstd} about ({:.3}, {:.3}, {:.3})",
        t.x,
        t.y,
        t.z,
        angle.to_degrees(),
        axis[0],
        axis[1],
        axis[2]
    );
    let used = r
        .pairs
        .iter()
        .filter(|p| p.status == PairStatus::Used)
        .count();
    println!(
        "joint fit over {used} of {} pairs: mean reprojection error colour {:.3} px (RMS {:.3}), thermal {:.3} px (RMS {:.3})",
        r.pairs.len(),
        r.rgb_error.mean_px,
        r.rgb_error.rms_px,
        r.thermal_error.mean_px,
        r.thermal_error.rms_px
    );
    println!(
        "{:<24} {:>7} {:>8} {:>10} {:>11}  status",
        "pair", "colour", "thermal", "MRE col", "MRE therm"
    );
    for (p, name) in r.pairs.iter().zip(names) {
        let e = |x: Option<mrtmap_calib::ViewError>| {
            x.map_or("—".into(), |e| format!("{:.3}", e.mean_px))
        };
        let status = match &p.status {
            PairStatus::Used => "used".to_string(),
            PairStatus::Rejected(why) => format!("rejected: {why}"),
        };
        println!(
            "{name:<24} {:>7} {:>8} {:>10} {:>11}  {status}",
            p.rgb_corners,
            p.thermal_corners,
            e(p.rgb_error),
            e(p.thermal_error)
        );
    }
}

fn write_report(
    rep: &Path,
    board: &Board,
    r: &StereoResult,
    pairs: &[mrtmap_calib::ImagePair],
    rgb_seen: &[Seen],
    th_seen: &[Seen],
) -> anyhow::Result<()> {
    std::fs::create_dir_all(rep).with_context(|| format!("cannot create {}", rep.display()))?;
    let mut rows = String::new();
    let mut pj = Vec::new();
    for (k, p) in pairs.iter().enumerate() {
        let name = &p.name;
        let safe: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let mut cells = Vec::new();
        if let Some(g) = &rgb_seen[k].gray {
            let f = format!("{safe}_rgb.png");
            write_atomic(
                &rep.join(&f),
                &png(&draw_corners(g, rgb_seen[k].det.as_ref(), 1)),
            )?;
            cells.push(f);
        }
        if let Some(g) = &th_seen[k].gray {
            let f = format!("{safe}_thermal.png");
            let img = draw_corners(g, th_seen[k].det.as_ref(), scale_for_report(g.width));
            write_atomic(&rep.join(&f), &png(&img))?;
            cells.push(f);
        }
        let pose = r.rgb_alone.poses[k];
        if let (Some(cg), Some(tg), Some(pose), PairStatus::Used) = (
            &rgb_seen[k].gray,
            &th_seen[k].gray,
            pose,
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
            write_atomic(&rep.join(&f), &png(&img))?;
            cells.push(f);
        }
        let pr = &r.pairs[k];
        let status = match &pr.status {
            PairStatus::Used => "used".to_string(),
            PairStatus::Rejected(w) => format!("rejected: {w}"),
        };
        let e = |x: Option<mrtmap_calib::ViewError>| {
            x.map_or("—".into(), |e| format!("{:.3}", e.mean_px))
        };
        rows.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n<tr><td colspan=6>{}</td></tr>\n",
            mrtmap_report::esc(name),
            pr.rgb_corners,
            pr.thermal_corners,
            e(pr.rgb_error),
            e(pr.thermal_error),
            mrtmap_report::esc(&status),
            cells
                .iter()
                .map(|f| format!("<img src=\"{f}\" loading=lazy>"))
                .collect::<String>()
        ));
        pj.push(json!({
            "name": name,
            "rgb_path": p.rgb.display().to_string(),
            "thermal_path": p.thermal.display().to_string(),
            "result": pr,
            "rgb_corners": corners_json(rgb_seen[k].det.as_ref()),
            "thermal_corners": corners_json(th_seen[k].det.as_ref()),
            "thermal_corners_tied": r.thermal_labels[k].as_ref().map(|c| c.iter().map(|c| [c.i as f64, c.j as f64, c.x, c.y]).collect::<Vec<_>>()),
        }));
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
        "pairs": pj,
    });
    write_atomic(&rep.join("calibration.json"), json(&doc)?.as_bytes())?;
    let t = r.rgb_from_thermal.translation.vector * 1e3;
    let html = format!(
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
    );
    write_atomic(&rep.join("index.html"), html.as_bytes())?;
    Ok(())
}

pub fn simulate_board(a: &SimulateBoardArgs) -> anyhow::Result<()> {
    let rig = SynthRig::default();
    let o = SynthOptions {
        pairs: a.pairs,
        partial: a.partial.min(a.pairs),
        seed: a.seed,
        thermal_blur_px: a.blur_px,
        thermal_noise_k: a.noise_k,
        ..SynthOptions::default()
    };
    let pairs = render_pairs(&rig, &o);
    if pairs.len() < o.pairs {
        bail!(
            "could only place the board in {} of {} poses",
            pairs.len(),
            o.pairs
        );
    }
    let (rd, td) = (a.out.join("rgb"), a.out.join("thermal"));
    for d in [&rd, &td] {
        std::fs::create_dir_all(d).with_context(|| format!("cannot create {}", d.display()))?;
    }
    for (k, p) in pairs.iter().enumerate() {
        let name = format!("{k:04}.png");
        write_atomic(
            &rd.join(&name),
            &mrtmap_io::encode_png_rgb8(p.rgb.width(), p.rgb.height(), p.rgb.as_raw()),
        )?;
        write_atomic(&td.join(&name), &encode_png16(&p.thermal))?;
    }
    let cam = |c: &PinholeCamera| json!({"width": c.width, "height": c.height, "fx": c.fx, "fy": c.fy, "cx": c.cx, "cy": c.cy, "distortion": c.distortion.to_array()});
    let truth = json!({
        "board": {"cols": o.board.cols, "rows": o.board.rows, "square_m": o.board.square_m},
        "rgb": cam(&rig.rgb),
        "thermal": cam(&rig.thermal),
        "rgb_from_thermal": PoseFile::from_isometry(&rig.rgb_from_thermal),
        "rgb_from_board": pairs.iter().map(|p| PoseFile::from_isometry(&p.rgb_from_board)).collect::<Vec<_>>(),
    });
    write_atomic(&a.out.join("truth.json"), json(&truth)?.as_bytes())?;
    println!(
        "wrote {} pairs to {} (board {}x{}, {} mm squares; truth.json)",
        pairs.len(),
        a.out.display(),
        o.board.cols,
        o.board.rows,
        o.board.square_m * 1e3
    );
    Ok(())
}
