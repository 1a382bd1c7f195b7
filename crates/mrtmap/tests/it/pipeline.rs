//! The pipeline from the command line: run (stages, reuse, resume), report (numbers match the
//! CSV; renders in headless Chromium), validate, demo. One small simulated scan is shared.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use mrtmap_pipeline::export::ExportFormat;
use mrtmap_pipeline::settings::Quantity;
use mrtmap_pipeline::{DemoLayout, RunLayout};
use serde_json::Value;

use crate::{mrtmap, ok};

/// A 20 s noise-free office scan at 160×120 depth (the accuracy under noise is tested in
/// mrtmap-scan), simulated once for all tests here.
pub fn recording() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap().keep();
        let rec = dir.join("scan");
        ok(&[
            "simulate",
            "--room",
            "office",
            "--out",
            rec.to_str().unwrap(),
            "--seconds",
            "20",
            "--depth-size",
            "160x120",
            "--noise",
            "none",
            "--truth-rays",
            "1000",
        ]);
        rec
    })
}

pub(crate) fn read_json(p: &Path) -> Value {
    serde_json::from_str(
        &std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display())),
    )
    .unwrap()
}

/// Each of `paths` (a layout's) is there.
fn assert_exist(paths: &[PathBuf]) {
    for p in paths {
        assert!(p.exists(), "{} missing", p.display());
    }
}

/// `dir` holds nothing but `known` (a layout's paths).
fn assert_only(dir: &Path, known: &[PathBuf]) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        assert!(
            known.contains(&p),
            "{} is not a RunLayout path",
            p.display()
        );
    }
}

/// Each stage of the run in `out` (run.json), and whether it was reused.
pub(crate) fn stages_skipped(out: &Path) -> Vec<(String, bool)> {
    read_json(&out.join("run.json"))["stages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            (
                s["stage"].as_str().unwrap().to_string(),
                s["skipped"].as_bool().unwrap(),
            )
        })
        .collect()
}

#[test]
fn run_produces_every_output_and_reuses_unchanged_stages() {
    let dir = tempfile::tempdir().unwrap();
    // Its own copy (files hard-linked): a frame is replaced below.
    let rec = dir.path().join("scan");
    crate::refusals::linked_copy(recording(), &rec);
    let out = dir.path().join("run");
    let o = out.to_str().unwrap();
    let r = rec.to_str().unwrap();
    let text = ok(&[
        "run",
        r,
        "--out",
        o,
        "--grid",
        "8x6",
        "--mark",
        "P=0.2,0.5,1.0",
    ]);
    assert!(text.contains("report:"), "{text}");
    for f in [
        "fuse/cloud.ply",
        "fuse/fusion.json",
        "fuse/poses.txt",
        "segment/scene.json",
        "segment/segments.ply",
        "segment/segment.json",
        "map-1.10m/mrt_grid.csv",
        "map-1.10m/mrt_map.png",
        "map-1.10m/summary.json",
        "report.html",
        "run.json",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    // RunLayout names each file the run wrote, and nothing else is there.
    let l = RunLayout::new(&out);
    let (fuse, segment, map) = (l.fuse(), l.segment(), l.map(1.1));
    let fuse_files = [fuse.outputs(), vec![fuse.stage_json()]].concat();
    let segment_files = [segment.outputs(), vec![segment.stage_json()]].concat();
    let map_files = [map.outputs(), vec![map.stage_json(), map.mrt_map_svg()]].concat();
    for (dir, files) in [
        (fuse.dir(), &fuse_files),
        (segment.dir(), &segment_files),
        (map.dir(), &map_files),
    ] {
        assert_exist(files);
        assert_only(dir, files);
    }
    let top = [
        l.fuse_dir(),
        l.segment_dir(),
        l.map_dir(1.1),
        l.report_html(),
        l.run_json(),
        l.made_list(),
    ];
    assert_exist(&top);
    assert_only(&out, &top);
    assert_eq!(
        (l.cloud_ply(), l.scene_json(), l.mrt_grid_csv(1.1)),
        (fuse.cloud_ply(), segment.scene_json(), map.mrt_grid_csv())
    );
    assert!(stages_skipped(&out).iter().all(|s| !s.1));
    // Unchanged: everything reused.
    ok(&[
        "run",
        r,
        "--out",
        o,
        "--grid",
        "8x6",
        "--mark",
        "P=0.2,0.5,1.0",
    ]);
    assert!(
        stages_skipped(&out).iter().all(|s| s.1),
        "{:?}",
        stages_skipped(&out)
    );
    // A new height: only that map is computed.
    // The same run at two heights, asked again below.
    let two_heights = [
        "run",
        r,
        "--out",
        o,
        "--grid",
        "8x6",
        "--mark",
        "P=0.2,0.5,1.0",
        "--height",
        "1.1",
        "--height",
        "1.7",
    ];
    ok(&two_heights);
    assert_exist(&RunLayout::new(&out).map(1.7).outputs());
    let st = stages_skipped(&out);
    assert_eq!(
        st,
        vec![
            ("fuse".into(), true),
            ("segment".into(), true),
            ("map at 1.10 m".into(), true),
            ("map at 1.70 m".into(), false)
        ]
    );
    // An interrupted run resumes: remove segment's fingerprint, as if it stopped mid-stage.
    std::fs::remove_file(out.join("segment/stage.json")).unwrap();
    ok(&two_heights);
    let st = stages_skipped(&out);
    assert!(st[0].1 && !st[1].1, "{st:?}");
    // A thermal frame replaced behind an unchanged thermal.txt: fusion runs again (issue 54's
    // campaign: fusion was reused over new images).
    let first = std::fs::read_to_string(rec.join("thermal.txt"))
        .unwrap()
        .lines()
        .find(|l| !l.starts_with('#') && !l.trim().is_empty())
        .and_then(|l| l.split_whitespace().nth(1).map(str::to_string))
        .unwrap();
    let frame = rec.join(&first);
    let other = std::fs::read(&frame).unwrap();
    std::fs::remove_file(&frame).unwrap();
    std::fs::write(&frame, [other.as_slice(), b"\0"].concat()).unwrap();
    ok(&two_heights);
    let st = stages_skipped(&out);
    assert!(!st[0].1, "fusion reused over a replaced frame: {st:?}");
    // --force reruns all.
    ok(&["run", r, "--out", o, "--grid", "8x6", "--force"]);
    assert!(stages_skipped(&out).iter().all(|s| !s.1));
    // A project file with an unknown key is refused with its name and line.
    let cfg = dir.path().join("p.toml");
    std::fs::write(&cfg, "[map]\ngrid = [8, 6]\nhieghts_m = [1.1]\n").unwrap();
    let e = mrtmap(&["run", r, "--out", o, "--config", cfg.to_str().unwrap()]);
    assert!(!e.status.success());
    let err = String::from_utf8_lossy(&e.stderr);
    assert!(
        err.contains("p.toml:3") && err.contains("hieghts_m"),
        "{err}"
    );
    // [export] writes the room for other tools beside the report (stages reused).
    std::fs::write(
        &cfg,
        "[map]\ngrid = [8, 6]\n[export]\nformats = [\"hbjson\", \"gltf\"]\nmax_points = 500\n",
    )
    .unwrap();
    let said = ok(&["run", r, "--out", o, "--config", cfg.to_str().unwrap()]);
    assert!(
        said.contains("room.hbjson (hbjson,") && said.contains("room.glb (gltf,"),
        "{said}"
    );
    let hb: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("export/room.hbjson")).unwrap())
            .unwrap();
    let scene = read_json(&out.join("segment/scene.json"));
    assert_eq!(
        hb["rooms"][0]["faces"].as_array().unwrap().len(),
        scene["surfaces"].as_array().unwrap().len()
    );
    let glb = std::fs::read(out.join("export/room.glb")).unwrap();
    assert_eq!(&glb[..4], b"glTF");
    assert!(!out.join("export/room.xml").exists());
    assert_exist(&[
        l.export_file(ExportFormat::Hbjson),
        l.export_file(ExportFormat::Gltf),
    ]);
    assert!(!l.export_file(ExportFormat::Gbxml).exists());
}

/// The report is self-contained, its numbers match the CSV, and it renders in headless Chromium.
#[test]
fn report_numbers_match_the_csv_and_it_renders() {
    let rec = recording();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    ok(&[
        "run",
        rec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--grid",
        "10x8",
        "--mark",
        "P=0.2,0.5,1.0",
        "--quantity",
        "mrt_seated",
        "--quantity",
        "pmv",
        "--air-c",
        "21",
    ]);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    // A person's comfort: its maps, the floor by category, the marked point's values.
    assert!(html.contains("<h2>Comfort of a person</h2>"));
    assert!(html.contains("floor by ISO 7730 PMV category"));
    assert!(html.contains("<h3>PMV (ISO 7730) of a seated person"));
    assert!(out.join("comfort/pmv.csv").exists() && out.join("comfort/comfort.json").exists());
    let l = RunLayout::new(&out);
    let comfort = l.comfort();
    let mut comfort_files = vec![comfort.stage_json(), comfort.comfort_json()];
    for q in [Quantity::MrtSeated, Quantity::Pmv] {
        comfort_files.extend([l.comfort_png(q), l.comfort_svg(q), l.comfort_csv(q)]);
    }
    assert_exist(&comfort_files);
    assert_only(&l.comfort_dir(), &comfort_files);
    assert!(
        html.contains("data:image/png;base64,") && !html.contains("src=\"map-"),
        "images are embedded"
    );
    // Provenance and the room frame a person measures from.
    assert!(
        html.contains(&format!(
            " UTC by mrtmap {}: mrtmap run ",
            env!("CARGO_PKG_VERSION")
        )),
        "date, version and command"
    );
    assert!(html.contains("<h2>Room coordinates</h2>") && html.contains("<td>wall-1</td>"));
    assert!(!html.contains("<th></th>"), "no empty header cells");
    let value = |id: &str| -> f64 {
        let key = format!("id=\"{id}\">");
        let i = html
            .find(&key)
            .unwrap_or_else(|| panic!("{id} not in the report"))
            + key.len();
        html[i..].split('<').next().unwrap().parse().unwrap()
    };
    let csv = std::fs::read_to_string(out.join("map-1.10m/mrt_grid.csv")).unwrap();
    let mrt: Vec<f64> = csv
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').nth(3)?.parse().ok())
        .collect();
    assert!(!mrt.is_empty());
    // The ± in its five parts, which make the total.
    assert!(csv.starts_with(
        "x,y,z,mrt_c,std_error_k,i,j,u_m,v_m,sampling_std_error_k,temperature_std_error_k,placement_std_error_k,unseen_std_error_k,level_std_error_k,note"
    ));
    for l in csv.lines().skip(1) {
        let v: Vec<f64> = l.split(',').filter_map(|x| x.parse().ok()).collect();
        if v.len() == 14 {
            let parts = v[9..14].iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((parts - v[4]).abs() < 3e-4, "{l}");
        }
    }
    assert!(html.contains("its parts, the largest of each on the map"));
    assert!(html.contains("unseen areas that matter most for the map"));
    assert!(html.contains("What the scan saw of each surface") && html.contains("<svg"));
    assert!(html.contains("<figcaption>floor: "));
    let (min, max) = mrt
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let mean = mrt.iter().sum::<f64>() / mrt.len() as f64;
    assert!((value("map-1.10-min") - min).abs() <= 0.005 + 1e-9);
    assert!((value("map-1.10-max") - max).abs() <= 0.005 + 1e-9);
    assert!((value("map-1.10-mean") - mean).abs() <= 0.005 + 1e-9);
    let summary = read_json(&out.join("map-1.10m/summary.json"));
    assert!(
        (value("point-P") - summary["marks"][0]["mrt_c"].as_f64().unwrap()).abs() <= 0.005 + 1e-9
    );
    let Some(chrome) = Chrome::find(dir.path()) else {
        return;
    };
    let url = format!("file://{}", out.join("report.html").display());
    let chrome = |args: &[&str]| chrome.run(args);
    let dom = chrome(&["--dump-dom", &url]);
    let dom = String::from_utf8_lossy(&dom.stdout);
    assert!(
        dom.contains("Mean radiant temperature at 1.10 m") && dom.contains("id=\"map-1.10-min\""),
        "Chromium did not render the report: {}",
        &dom[..dom.len().min(300)]
    );
    let shot = dir.path().join("report.png");
    let s = chrome(&[
        "--window-size=1200,1600",
        &format!("--screenshot={}", shot.display()),
        &url,
    ]);
    assert!(s.status.success());
    assert!(
        std::fs::metadata(&shot).unwrap().len() > 20_000,
        "a blank screenshot"
    );
    // The 3D view alone (report.html#3d), drawn by WebGL (SwiftShader without a GPU).
    let shot3d = dir.path().join("view3d.png");
    let view = ["--window-size=1000,800", "--virtual-time-budget=5000"];
    let s = chrome(
        &[
            &view[..],
            &[
                &format!("--screenshot={}", shot3d.display()),
                &format!("{url}#3d"),
            ],
        ]
        .concat(),
    );
    assert!(s.status.success());
    assert_view3d_drawn(&shot3d);
    // A click in the middle of the view names what is there, with its temperature and area.
    let dom = chrome(
        &[
            &view[..],
            &["--dump-dom", &format!("{url}#3d&pick=0.5,0.5")],
        ]
        .concat(),
    );
    let dom = String::from_utf8_lossy(&dom.stdout);
    let said = dom
        .split("<p id=\"view3d-info\">")
        .nth(1)
        .and_then(|r| r.split('<').next())
        .unwrap_or_default();
    let scene = read_json(&out.join("segment/scene.json"));
    let ids: Vec<&str> = scene["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|s| {
            std::iter::once(&s["id"]).chain(
                s["features"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .map(|f| &f["id"]),
            )
        })
        .chain(
            scene["occluders"]
                .as_array()
                .into_iter()
                .flatten()
                .map(|o| &o["id"]),
        )
        .filter_map(Value::as_str)
        .collect();
    assert!(
        said.contains(" °C") && said.contains(" m²") && ids.iter().any(|id| said.starts_with(id)),
        "the click named nothing: {said:?}"
    );
}

/// A 1000×800 screenshot of the 3D view is not blank, the room fills its middle, and both the
/// cold window and the warm room show in their colours.
/// Headless Chromium (CI installs Debian's chromium and sets MRTMAP_REQUIRE_CHROMIUM), with its
/// own profile folder.
pub struct Chrome {
    program: &'static str,
    profile: PathBuf,
}

impl Chrome {
    /// Chromium when installed; `None` (and a word on stderr) when not, unless
    /// MRTMAP_REQUIRE_CHROMIUM is set.
    #[allow(clippy::print_stderr)]
    pub fn find(dir: &Path) -> Option<Self> {
        let program = ["chromium", "chromium-browser", "google-chrome"]
            .into_iter()
            .find(|c| {
                Command::new(c)
                    .arg("--version")
                    .output()
                    .is_ok_and(|o| o.status.success())
            });
        if program.is_none() {
            assert!(
                std::env::var_os("MRTMAP_REQUIRE_CHROMIUM").is_none(),
                "MRTMAP_REQUIRE_CHROMIUM is set but no chromium was found"
            );
            eprintln!("chromium not installed: the rendering check was not run");
        }
        Some(Chrome {
            program: program?,
            profile: dir.join("chromium-profile"),
        })
    }

    /// Runs it headless with `args`.
    pub fn run(&self, args: &[&str]) -> std::process::Output {
        Command::new(self.program)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
            ])
            .arg(format!("--user-data-dir={}", self.profile.display()))
            .args(args)
            .output()
            .unwrap()
    }
}

pub fn assert_view3d_drawn(png: &Path) {
    let img = image::open(png).unwrap().to_rgb8();
    let background = |p: &image::Rgb<u8>| {
        p.0.iter()
            .zip([245u8, 245, 242])
            .all(|(a, b)| a.abs_diff(b) < 4)
    };
    let (mut n, mut room, mut blue, mut warm, mut centre, mut centre_room) = (0, 0, 0, 0, 0, 0);
    for y in (150..700).step_by(4) {
        for x in (50..950).step_by(4) {
            let p = img.get_pixel(x, y);
            let [r, _, b] = p.0.map(i32::from);
            n += 1;
            room += usize::from(!background(p));
            blue += usize::from(b > r + 60);
            warm += usize::from(r > b + 60);
            if (400..600).contains(&x) && (325..525).contains(&y) {
                centre += 1;
                centre_room += usize::from(!background(p));
            }
        }
    }
    let share = |k: usize, of: usize| k as f64 / of as f64;
    assert!(
        share(room, n) > 0.15,
        "the 3D view is blank: {room} of {n} pixels drawn"
    );
    assert!(
        share(centre_room, centre) > 0.8,
        "the room is not in the middle of the view"
    );
    assert!(
        share(blue, n) > 0.003,
        "no cold (blue) surface in view: {blue} of {n}"
    );
    assert!(
        share(warm, n) > 0.05,
        "no warm surface in view: {warm} of {n}"
    );
}

#[test]
fn validate_compares_globes_with_the_map() {
    let rec = recording();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    ok(&[
        "run",
        rec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--grid",
        "6x5",
    ]);
    // A globe reading consistent with the map at a point: the map's MRT turned into what a
    // standard globe would read there, via the inverse of the ISO formula.
    let scene = out.join("segment/scene.json");
    let p = "0.2,0.5,1.0";
    let m: Value = serde_json::from_str(&ok(&[
        "mrt",
        "--scene",
        scene.to_str().unwrap(),
        "--at",
        p,
        "--rays",
        "200000",
        "--json",
    ]))
    .unwrap();
    let ours = m["points"][0]["mrt_c"].as_f64().unwrap();
    let g: Value = serde_json::from_str(&ok(&[
        "globe",
        "--tr",
        &ours.to_string(),
        "--ta",
        "21",
        "--va",
        "0.1",
        "--json",
    ]))
    .unwrap();
    let tg = g["globe_c"].as_f64().unwrap();
    let csv = dir.path().join("globe.csv");
    std::fs::write(&csv, format!("label,x,y,z,tg_c,ta_c,va_m_s,diameter_m,emissivity\nG1,0.2,0.5,1.0,{tg},21,0.1,0.15,0.95\nG2,0.2,0.5,1.0,{},21,0.1,0.3,0.95\n", tg + 3.0)).unwrap();
    let text = ok(&[
        "validate",
        "--map",
        out.to_str().unwrap(),
        "--globe",
        csv.to_str().unwrap(),
    ]);
    assert!(
        text.contains("G1") && text.contains("meets desired"),
        "{text}"
    );
    let v = read_json(&out.join("validation.json"));
    assert!(
        v[0]["ours_c"].is_f64()
            && v[0]["ours_std_error_k"].is_f64()
            && v[0]["mrt_mixed_note"].is_null()
    );
    assert!(
        v[0]["diff_iso_k"].as_f64().unwrap().abs() < 0.05,
        "{}",
        v[0]
    );
    assert_eq!(v[0]["meets_desired"], true);
    assert!(
        v[1]["mrt_mixed_c"].is_null() && v[1]["mrt_mixed_note"].is_string(),
        "a 0.3 m globe is outside mixed convection's range: {}",
        v[1]
    );
    assert_eq!(v[1]["meets_desired"], false);
    let vcsv = std::fs::read_to_string(out.join("validation.csv")).unwrap();
    assert_eq!(vcsv.lines().count(), 3);
    let l = RunLayout::new(&out);
    assert_exist(&[l.validation_csv(), l.validation_json()]);
    // Run again (every stage reused): the report's 3D view shows the globes with their values.
    ok(&[
        "run",
        rec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--grid",
        "6x5",
    ]);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(
        html.contains("\"kind\":\"globe\",\"text\":\"globe G1: ") && html.contains("(map "),
        "the 3D view lacks the globes"
    );
    std::fs::write(&csv, "label,x,y,z,tg_c,ta_c,va_m_s,diameter_m,emissivity\nG1,0.2,0.5,1.0,warm,21,0.1,0.15,0.95\n").unwrap();
    let e = mrtmap(&[
        "validate",
        "--map",
        out.to_str().unwrap(),
        "--globe",
        csv.to_str().unwrap(),
    ]);
    assert!(
        String::from_utf8_lossy(&e.stderr).contains("globe.csv:2: tg_c 'warm' is not a number")
    );
}

#[test]
fn demo_prints_the_papers_table_and_grid_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    let text = ok(&[
        "demo",
        "--out",
        out.to_str().unwrap(),
        "--seconds",
        "20",
        "--depth-size",
        "160x120",
        "--noise",
        "none",
    ]);
    assert!(
        text.contains("black globe (ISO)") && text.contains("over the 20×20 grid"),
        "{text}"
    );
    let d = read_json(&out.join("demo.json"));
    let points = d["points"].as_array().unwrap();
    assert_eq!(points.len(), 4);
    for p in points {
        assert!(p["diff_k"].as_f64().unwrap().abs() < 0.5, "{p}");
    }
    assert!(d["grid"]["nodes"].as_u64().unwrap() > 300);
    assert!(out.join("run/report.html").exists());
    let l = DemoLayout::new(&out);
    assert_exist(&[l.simulate_json(), l.truth_json(), l.demo_json()]);
    assert_exist(&[l.run().report_html(), l.run().scene_json()]);
    let top = [
        l.simulate_json(),
        l.recording_dir(),
        l.run().root().to_path_buf(),
        l.demo_json(),
    ];
    assert_only(&out, &top);
    let html = std::fs::read_to_string(out.join("run/report.html")).unwrap();
    assert!(html.contains("Against the truth") && html.contains("id=\"grid-rmse\""));
}

/// A simulated camera with a unit offset, gain error, frequent flat-field corrections, drift and
/// vignetting: self-calibration tracks the frames' offsets and the vignetting, two reference
/// readings fix the level and the gain, and without them the stated ± covers the error.
#[test]
fn camera_errors_are_self_calibrated_and_anchored_by_references() {
    let dir = tempfile::tempdir().unwrap();
    let sim = |name: &str, refs: &str| {
        let rec = dir.path().join(name);
        ok(&[
            "simulate",
            "--room",
            "office",
            "--out",
            rec.to_str().unwrap(),
            "--seconds",
            "20",
            "--depth-size",
            "160x120",
            "--noise",
            "none",
            "--truth-rays",
            "1000",
            "--camera-errors",
            "realistic",
            "--ffc-interval-s",
            "5,8",
            "--references",
            refs,
        ]);
        rec
    };
    let with = sim("with", "2");
    let run = dir.path().join("run");
    ok(&[
        "run",
        with.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
        "--grid",
        "8x6",
    ]);
    // The frames' offsets against the truth's, up to one constant.
    let fusion = read_json(&run.join("fuse/fusion.json"));
    let truth = read_json(&with.join("radiometric_truth.json"));
    let r = &fusion["radiometric"];
    let vig = r["vignetting_k"].as_f64().unwrap();
    assert!((vig + 0.6).abs() < 0.15, "vignetting {vig}");
    let est: Vec<f64> = r["offsets_k"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x[1].as_f64().unwrap())
        .collect();
    let tru: Vec<f64> = truth["frame_offsets_k"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x[1].as_f64().unwrap())
        .collect();
    assert!(truth["camera"]["ffc"].as_array().unwrap().len() >= 3);
    assert_eq!(est.len(), tru.len(), "every frame fused");
    // Skip the first frames (no map to compare with yet). The estimate must explain most of the
    // offsets' variation (FFC jumps of several tenths of a kelvin, drift).
    let sd = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
    };
    let d: Vec<f64> = est.iter().zip(&tru).skip(20).map(|(e, t)| e - t).collect();
    let t_sd = sd(&tru[20..]);
    assert!(t_sd > 0.2, "the truth's offsets vary: {t_sd}");
    assert!(
        sd(&d) < 0.4 * t_sd,
        "offsets track the truth's: sd {} vs {t_sd}",
        sd(&d)
    );
    // Two readings fix offset and gain.
    let level = read_json(&run.join("segment/level.json"));
    assert_eq!(level["basis"], "references (offset and gain)", "{level}");
    let beta = level["beta"].as_f64().unwrap();
    assert!((beta - 1.02).abs() < 0.01, "gain {beta}");
    // segment.json's tables (the report's Surfaces table) are at scene.json's level (issue 41:
    // they showed the camera's uncorrected temperatures).
    let seg = read_json(&run.join("segment/segment.json"));
    let sc = read_json(&run.join("segment/scene.json"));
    let floor_of = |v: &Value| {
        v["surfaces"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["id"] == "floor")
            .and_then(|s| s["temperature_c"].as_f64())
            .unwrap()
    };
    let (a, b) = (floor_of(&seg), floor_of(&sc));
    assert!(
        (a - b).abs() < 1e-6,
        "segment.json floor {a} °C, scene.json {b} °C"
    );
    // The thermal cloud the report draws and the glTF carries is at the same level (issue 54: it
    // carried the camera's raw level, ~2 K above the floor surface on one colour scale).
    let (scene, _) = mrtmap_pipeline::maps::load_scene(&mrtmap_pipeline::maps::SceneSource {
        scene: Some(run.join("segment/scene.json")),
        ..Default::default()
    })
    .unwrap();
    let cloud = mrtmap_pipeline::export::run_cloud(&run, &scene).unwrap();
    let mut on_floor: Vec<f32> = cloud
        .positions
        .iter()
        .zip(&cloud.temperature_c)
        .filter(|(p, _)| p[2].abs() < 0.03 && p[0] > 0.5 && p[1] > 0.5)
        .map(|(_, t)| *t)
        .collect();
    on_floor.sort_by(f32::total_cmp);
    let median = f64::from(on_floor[on_floor.len() / 2]);
    assert!(
        (median - b).abs() < 0.3,
        "cloud on the floor {median:.2} °C, floor surface {b:.2} °C ({} points)",
        on_floor.len()
    );
    // The same readings in the room's frame (references.csv's default: what a tape measures),
    // placed after segmentation: the camera's readings there are the same.
    use mrtmap_geometry::nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};
    let w = &sc["world_from_room"];
    let f = |k: &str, i: usize| w[k][i].as_f64().unwrap();
    let world_from_room = Isometry3::from_parts(
        Translation3::new(
            f("translation", 0),
            f("translation", 1),
            f("translation", 2),
        ),
        UnitQuaternion::from_quaternion(Quaternion::new(
            f("rotation_xyzw", 3),
            f("rotation_xyzw", 0),
            f("rotation_xyzw", 1),
            f("rotation_xyzw", 2),
        )),
    );
    let csv = std::fs::read_to_string(with.join("references.csv")).unwrap();
    // A black room's readings say so: the camera reads them as they are.
    assert!(csv.contains(",frame,emissivity\n"), "{csv}");
    let mut room_csv = String::from("label,x,y,z,temperature_c,std_k\n");
    for line in csv.lines().filter(|l| l.ends_with(",scan,1")) {
        let c: Vec<&str> = line.split(',').collect();
        let p: Vec<f64> = c[1..4].iter().map(|v| v.parse().unwrap()).collect();
        let q = world_from_room.inverse() * Point3::new(p[0], p[1], p[2]);
        room_csv += &format!("{},{},{},{},{},{}\n", c[0], q.x, q.y, q.z, c[4], c[5]);
    }
    let room_refs = dir.path().join("room-references.csv");
    std::fs::write(&room_refs, room_csv).unwrap();
    let again = dir.path().join("segment-room");
    ok(&[
        "segment",
        run.join("fuse").to_str().unwrap(),
        "--recording",
        with.to_str().unwrap(),
        "--references",
        room_refs.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
    ]);
    let room_level = read_json(&again.join("level.json"));
    let refs = level["references"].as_array().unwrap();
    assert_eq!(refs.len(), 2);
    for (x, y) in refs
        .iter()
        .zip(room_level["references"].as_array().unwrap())
    {
        let (cx, cy) = (
            x["camera_c"].as_f64().unwrap(),
            y["camera_c"].as_f64().unwrap(),
        );
        assert!((cx - cy).abs() < 1e-6, "{x} vs {y}");
    }
    // MRT at the validation points against the truth.
    let t = read_json(&with.join("truth.json"));
    let scene = run.join("segment/scene.json");
    let errors = |scene: &Path, t: &Value| -> Vec<(f64, f64)> {
        t["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                let w = p["xyz_world"].as_array().unwrap();
                let at = format!("{},{},{}", w[0], w[1], w[2]);
                let v: Value = serde_json::from_str(&ok(&[
                    "mrt",
                    "--scene",
                    scene.to_str().unwrap(),
                    "--at",
                    &at,
                    "--frame",
                    "scan",
                    "--json",
                ]))
                .unwrap();
                let q = &v["points"][0];
                (
                    q["mrt_c"].as_f64().unwrap() - p["mrt_c"].as_f64().unwrap(),
                    q["std_error_k"].as_f64().unwrap(),
                )
            })
            .collect()
    };
    for (e, se) in errors(&scene, &t) {
        assert!(e.abs() < 0.3, "with references: {e:+.3} K");
        assert!(
            se > 0.05 && se < 0.3,
            "the level's uncertainty is in the ±: {se}"
        );
    }
    // Without references: the camera's level, off by the unit's offset, and a ± that says so.
    let without = sim("without", "0");
    let run2 = dir.path().join("run2");
    ok(&[
        "run",
        without.to_str().unwrap(),
        "--out",
        run2.to_str().unwrap(),
        "--grid",
        "8x6",
    ]);
    let level = read_json(&run2.join("segment/level.json"));
    assert_eq!(level["basis"], "camera");
    let errs = errors(
        &run2.join("segment/scene.json"),
        &read_json(&without.join("truth.json")),
    );
    for (e, se) in &errs {
        assert!(e.abs() > 1.0 && e.abs() < 2.0 * se, "{e:+.3} K ± {se}");
    }
    // … while its differences between points stay right.
    let first = errs[0].0;
    for (e, _) in &errs {
        assert!((e - first).abs() < 0.15, "relative: {:+.3} K", e - first);
    }
    let html = std::fs::read_to_string(run.join("report.html")).unwrap();
    assert!(html.contains("<h2>What the temperatures rest on</h2>"));
    // The gain: fixed by the two readings; without them the report says what it could stretch.
    assert!(!html.contains("differences between places"));
    let html = std::fs::read_to_string(run2.join("report.html")).unwrap();
    assert!(
        html.contains("differences between places")
            && html.contains("each 1 % of gain error stretches the map"),
        "the report says the gain is unknown"
    );
}

/// Issue 52: real rooms are grey. A grey office (window glass 0.84 mirroring the operator, the rest
/// 0.90–0.95), a camera with a unit offset and a 2 % gain, two contact readings of true surface
/// temperatures, one on the glass. The readings are turned into what the camera should read before
/// the level is fitted (the glass's helps fix the gain), the map matches the grey enclosure's
/// truth, the window's surface temperature its true 11.5 °C, and texturing left out the pixels
/// that could mirror the operator.
#[test]
fn grey_rooms_map_radiosities_and_give_true_surface_temperatures() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("grey");
    ok(&[
        "simulate",
        "--room",
        "office",
        "--out",
        rec.to_str().unwrap(),
        "--seconds",
        "20",
        "--depth-size",
        "160x120",
        "--noise",
        "none",
        "--glass",
        "on",
        "--surfaces",
        "grey",
        "--truth-rays",
        "1000",
        "--camera-errors",
        "realistic",
        "--ffc-interval-s",
        "5,8",
        "--references",
        "2",
    ]);
    let truth = read_json(&rec.join("truth.json"));
    assert_eq!(truth["scene"]["temperatures"], "radiant");
    let true_window = truth["scene"]["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|s| s["features"].as_array().cloned().unwrap_or_default())
        .find(|f| f["label"] == "window")
        .unwrap();
    let (true_radiant, true_surface) = (
        true_window["temperature_c"].as_f64().unwrap(),
        true_window["surface_temperature_c"].as_f64().unwrap(),
    );
    assert!(
        (true_surface - 11.5).abs() < 1e-9 && true_radiant > true_surface + 1.0,
        "the camera sees the window warmer than it is: {true_radiant} vs {true_surface}"
    );
    let run = dir.path().join("run");
    ok(&[
        "run",
        rec.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
        "--grid",
        "8x6",
    ]);
    // The reading on the glass was compared with what the camera should read there, and used.
    let level = read_json(&run.join("segment/level.json"));
    assert_eq!(level["basis"], "references (offset and gain)", "{level}");
    let window = level["references"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["label"] == "window")
        .unwrap();
    assert_eq!(window["used"], true, "{window}");
    assert_eq!(window["emissivity"], 0.84);
    let expected = window["radiant_c"].as_f64().unwrap();
    assert!(
        (expected - true_radiant).abs() < 0.3,
        "the camera should read {expected} °C on the glass; the truth's radiosity is {true_radiant} °C"
    );
    let beta = level["beta"].as_f64().unwrap();
    assert!((beta - 1.02).abs() < 0.015, "gain {beta}");
    // scene.json: radiant temperatures, emissivities, and the window's true temperature.
    let scene = read_json(&run.join("segment/scene.json"));
    assert_eq!(scene["temperatures"], "radiant");
    let found = scene["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|s| s["features"].as_array().cloned().unwrap_or_default())
        .find(|f| f["label"] == "window")
        .unwrap();
    assert_eq!(found["emissivity"], 0.84);
    let radiant = found["temperature_c"].as_f64().unwrap();
    let surface = found["surface_temperature_c"].as_f64().unwrap();
    let surface_sd = found["surface_temperature_std_k"].as_f64().unwrap();
    assert!(
        (radiant - true_radiant).abs() < 0.3,
        "window radiant {radiant} °C, truth {true_radiant} °C (the operator's reflection left out)"
    );
    assert!(
        (surface - 11.5).abs() < 0.5 && (surface - 11.5).abs() < 3.0 * surface_sd,
        "window surface temperature {surface} ± {surface_sd} K, truth 11.5 °C"
    );
    let seg = read_json(&run.join("segment/segment.json"));
    let mirrored = seg["texture"]["pixels_mirroring_operator"]
        .as_u64()
        .unwrap();
    assert!(
        mirrored > 1000,
        "pixels left out as mirrors of the operator: {mirrored}"
    );
    // The report names both temperatures.
    let html = std::fs::read_to_string(run.join("report.html")).unwrap();
    assert!(html.contains("radiant T (°C)") && html.contains("surface T (°C, ± K)"));
    // The map against the grey enclosure's truth, within the ± it states.
    for p in truth["points"].as_array().unwrap() {
        let w = p["xyz_world"].as_array().unwrap();
        let at = format!("{},{},{}", w[0], w[1], w[2]);
        let v: Value = serde_json::from_str(&ok(&[
            "mrt",
            "--scene",
            run.join("segment/scene.json").to_str().unwrap(),
            "--at",
            &at,
            "--frame",
            "scan",
            "--json",
        ]))
        .unwrap();
        let q = &v["points"][0];
        let e = q["mrt_c"].as_f64().unwrap() - p["mrt_c"].as_f64().unwrap();
        let se = q["std_error_k"].as_f64().unwrap();
        assert!(
            e.abs() < 0.25 && e.abs() < 3.0 * se,
            "{}: {e:+.3} K ± {se}",
            p["name"]
        );
    }
    // The same readings taken as black (emissivity 1 in references.csv): the glass's reading then
    // disagrees with the camera by its reflection, and the gain it implies is refused.
    let csv = std::fs::read_to_string(rec.join("references.csv")).unwrap();
    let black: String = csv
        .lines()
        .map(|l| {
            if l.ends_with(",scan,") {
                format!("{l}1\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let black_refs = dir.path().join("black.csv");
    std::fs::write(&black_refs, black).unwrap();
    let again = dir.path().join("segment-black");
    ok(&[
        "segment",
        run.join("fuse").to_str().unwrap(),
        "--recording",
        rec.to_str().unwrap(),
        "--references",
        black_refs.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
    ]);
    let black_level = read_json(&again.join("level.json"));
    let black_beta = black_level["beta"].as_f64().unwrap();
    assert!(
        (black_beta - 1.02).abs() > 0.05 || black_level["basis"] == "references (offset)",
        "taken as black, the glass's reading misleads the gain: {black_level}"
    );
}

/// `mrtmap coverage`: a coarse run judged by what the scan controls. The 20 s office walk saw
/// every wall; its verdict follows what it did not see against the target asked for.
#[test]
fn coverage_says_whether_a_scan_is_good_enough_and_where_to_look() {
    let out = tempfile::tempdir().unwrap();
    let keep = out.path().join("cov");
    let text = ok(&[
        "coverage",
        recording().to_str().unwrap(),
        "--out",
        keep.to_str().unwrap(),
        "--json",
    ]);
    let c: Value = serde_json::from_str(&text).unwrap();
    let surfaces = c["surfaces"].as_array().unwrap();
    assert_eq!(surfaces.len(), 6, "{text}");
    for s in surfaces {
        let sum = s["seen_with_depth"].as_f64().unwrap()
            + s["textured_only"].as_f64().unwrap()
            + s["unseen"].as_f64().unwrap();
        assert!((sum - 1.0).abs() < 1e-9, "{s}");
        assert_eq!(s["inferred"], false);
    }
    let unseen = c["max_unseen_k"].as_f64().unwrap();
    assert_eq!(
        c["good_enough"].as_bool().unwrap(),
        c["reasons"].as_array().unwrap().is_empty()
    );
    if 2.0 * unseen > 0.2 {
        assert_eq!(c["good_enough"], false, "{text}");
    }
    // The coarse run is kept where asked: a 10 × 10 grid at 1.1 m.
    let summary = read_json(&keep.join("map-1.10m/summary.json"));
    assert_eq!(summary["grid"], serde_json::json!([10, 10]));
    assert!((summary["max_std_error_parts"]["unseen_k"].as_f64().unwrap() - unseen).abs() < 1e-12);
    // A target tighter than what was not seen allows: not good enough, and says why and where.
    assert!(
        unseen > 0.0,
        "the walk leaves something unseen (under the desk): {text}"
    );
    let target = format!("{}", unseen);
    let strict: Value = serde_json::from_str(&ok(&[
        "coverage",
        recording().to_str().unwrap(),
        "--out",
        keep.to_str().unwrap(),
        "--target-k",
        &target,
        "--json",
    ]))
    .unwrap();
    assert_eq!(strict["good_enough"], false);
    assert!(
        strict["reasons"][0]
            .as_str()
            .unwrap()
            .contains("what the scan did not see"),
        "{strict}"
    );
    assert!(
        !strict["look_at"].as_array().unwrap().is_empty(),
        "{strict}"
    );
    // Text for people, and a nonsense target refused.
    let words = ok(&[
        "coverage",
        recording().to_str().unwrap(),
        "--target-k",
        &target,
    ]);
    assert!(
        words.contains("not good enough for a ±") && words.contains("where to point the camera"),
        "{words}"
    );
    let o = mrtmap(&[
        "coverage",
        recording().to_str().unwrap(),
        "--target-k",
        "-1",
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--target-k -1"));
}
