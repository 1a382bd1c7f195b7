//! The sun: SolarCal by itself (`solar-gain`), through a scene's windows (`mrt --sun`), in maps and
//! in globe validation.

use serde_json::Value;

use crate::cli::edited_example;
use crate::pipeline::read_json;
use crate::{fails_with, mrtmap, ok, ok_json};

#[test]
fn solar_gain_equals_solarcal_and_names_a_bad_flag() {
    // grey-and-sun.md, the first vector (pythermalcomfort 4.8.1 solar_gain, unrounded): seated,
    // facing a 1.8 × 1.3 m window 1.55 m away, wholly in a 30° beam.
    let args = [
        "solar-gain",
        "--altitude",
        "30",
        "--sharp",
        "0",
        "--dni",
        "700",
        "--transmittance",
        "0.6",
        "--f-svv",
        "0.04233",
        "--f-bes",
        "1",
    ];
    let v = ok_json(&[&args[..], &["--posture", "sitting", "--json"]].concat());
    assert!(
        (v["erf_w_m2"].as_f64().unwrap() - 68.522).abs() < 0.01,
        "{v}"
    );
    assert!(
        (v["delta_mrt_k"].as_f64().unwrap() - 16.4084).abs() < 0.005,
        "{v}"
    );
    // The inputs come back, with pythermalcomfort's defaults for those not given.
    assert_eq!(v["posture"], "seated");
    assert_eq!(v["asw"], 0.7);
    assert_eq!(v["floor_reflectance"], 0.6);
    assert_eq!(v["f_svv"], 0.04233);
    let text = ok(&args);
    assert!(text.contains("ΔMRT +16.41 K"), "{text}");
    // Out of range: one sentence naming the flag, exit code 1 as any refused input.
    let mut bad = args.to_vec();
    bad[2] = "95";
    let out = mrtmap(&bad);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        err.trim(),
        "error: --altitude 95 is outside 0…90 (the solar altitude in degrees)"
    );
    let mut bad = args.to_vec();
    bad[10] = "NaN";
    fails_with(&bad, "--f-svv NaN is not a finite number");
    fails_with(
        &[&args[..], &["--posture", "lying"]].concat(),
        "invalid value 'lying'",
    );
}

/// Issue 52: the sun through the example office's window (on the +x wall) onto a seated person
/// facing it: ΔMRT beside the MRT, within 10 % of SolarCal for a person wholly in the beam
/// (16.41 K); --sun needs --facing, --dni and --transmittance.
#[test]
fn mrt_adds_the_sun_through_the_window_for_a_person() {
    let v = ok_json(&[
        "mrt",
        "--at",
        "2.65,1.8,0.6",
        "--person",
        "seated",
        "--facing",
        "0",
        "--sun",
        "30,0",
        "--dni",
        "700",
        "--transmittance",
        "0.6",
        "--json",
    ]);
    let p = &v["persons"][0];
    let d = p["delta_mrt_k"].as_f64().unwrap();
    assert!((d - 16.41).abs() < 1.641, "{p}");
    assert!(p["f_bes"].as_f64().unwrap() > 0.95, "{p}");
    assert_eq!(p["sharp_deg"], 0.0);
    let with_sun = p["mrt_with_sun_c"].as_f64().unwrap();
    assert!((with_sun - p["mrt_c"].as_f64().unwrap() - d).abs() < 1e-9);
    fails_with(
        &[
            "mrt",
            "--at",
            "2.65,1.8,0.6",
            "--person",
            "seated",
            "--sun",
            "30,0",
            "--dni",
            "700",
            "--transmittance",
            "0.6",
        ],
        "--facing",
    );
    fails_with(
        &[
            "mrt",
            "--at",
            "2.65,1.8,0.6",
            "--person",
            "seated",
            "--facing",
            "0",
            "--sun",
            "30",
            "--dni",
            "700",
            "--transmittance",
            "0.6",
        ],
        "expected ALT,AZ",
    );
}

/// Issue 63: a seated person 0.1 m from the window's wall with the sun behind that wall (azimuth
/// 100°) was lit "through window-1" (+3.07 K): the body's rectangle reached out through the wall.
/// Now no beam: f_bes 0, no window, and only the sky and its floor reflection (no floor-reflected
/// beam, as none enters the room) — well under the 3 K. A skylight in the ceiling lets the sun in
/// as a window there would (issue 61), and a scene without glazing says so.
#[test]
fn no_sun_through_a_wall_and_every_glazing_lets_it_in() {
    let sun_at = |scene: Option<&str>, at: &str, sun: &str| {
        let mut args = vec![
            "mrt",
            "--at",
            at,
            "--person",
            "seated",
            "--facing",
            "0",
            "--sun",
            sun,
            "--dni",
            "700",
            "--transmittance",
            "0.6",
            "--json",
        ];
        if let Some(s) = scene {
            args.extend(["--scene", s]);
        }
        ok_json(&args)
    };
    let v = sun_at(None, "4.1,1.8,0.6", "30,100");
    let p = &v["persons"][0];
    assert_eq!(p["f_bes"], 0.0, "{p}");
    assert_eq!(p["beam_windows"].as_array().map(Vec::len), Some(0), "{p}");
    // SolarCal's sky and its floor reflection alone: no beam on the body, none on the floor.
    let f_svv = p["f_svv"].as_f64().unwrap();
    let (f_eff, i_diff) = (0.696, 0.2 * 700.0);
    let erf = f_eff * f_svv * 0.5 * 0.6 * (i_diff + i_diff * 0.6) * (0.7 / 0.95);
    let d = p["delta_mrt_k"].as_f64().unwrap();
    assert!((d - erf / (6.0 * f_eff)).abs() < 1e-9, "{p}");
    assert!(d < 1.5, "{p}");
    let dir = tempfile::tempdir().unwrap();
    let sky = edited_example(dir.path(), "skylight.json", |v| {
        v["surfaces"][1]["features"][1]["label"] = Value::from("skylight");
    });
    let win = edited_example(dir.path(), "ceiling-window.json", |v| {
        v["surfaces"][1]["features"][1]["label"] = Value::from("window");
    });
    let (a, b) = (
        sun_at(Some(&sky), "2.24,1.0,0.6", "70,0"),
        sun_at(Some(&win), "2.24,1.0,0.6", "70,0"),
    );
    let (a, b) = (&a["persons"][0], &b["persons"][0]);
    assert!(a["f_bes"].as_f64().unwrap() > 0.05, "{a}");
    assert_eq!(a["f_bes"], b["f_bes"]);
    assert_eq!(a["delta_mrt_k"], b["delta_mrt_k"]);
    assert_eq!(a["beam_windows"][0], "light-2");
    let closed = edited_example(dir.path(), "closed.json", |v| {
        v["surfaces"][2]["features"][0]["label"] = Value::from("painting");
    });
    let text = ok(&[
        "mrt",
        "--at",
        "2.65,1.8,0.6",
        "--person",
        "seated",
        "--facing",
        "0",
        "--sun",
        "30,0",
        "--dni",
        "700",
        "--transmittance",
        "0.6",
        "--scene",
        &closed,
    ]);
    assert!(text.contains("warning: the scene has no glazing"), "{text}");
    // A map with the sun says so too.
    let project = dir.path().join("sun.toml");
    std::fs::write(&project, SUNNY_PROJECT).unwrap();
    let text = ok(&[
        "map",
        "--scene",
        &closed,
        "--config",
        project.to_str().unwrap(),
        "--quantity",
        "mrt_sun",
        "--grid",
        "3x3",
        "--out",
        dir.path().join("m").to_str().unwrap(),
    ]);
    assert!(text.contains("warning: the scene has no glazing"), "{text}");
}

/// The example office's window is on the +x wall; `[sun]` 30° high due +x puts a globe in front
/// of it (2.65, 1.8, 1.1) in the beam and one at y = 0.3 in the shade.
const SUNNY_PROJECT: &str =
    "[sun]\naltitude_deg = 30.0\nazimuth_deg = 0.0\ndni_w_m2 = 700\ntransmittance = 0.6\n";

#[test]
fn validate_flags_a_globe_in_the_sun_and_does_not_judge_it() {
    let dir = tempfile::tempdir().unwrap();
    edited_example(dir.path(), "scene.json", |_| {});
    let globe = dir.path().join("globe.csv");
    std::fs::write(
        &globe,
        "label,x,y,z,tg_c,ta_c,va_m_s,diameter_m,emissivity\n\
         lit,2.65,1.8,1.1,30.0,21.0,0.1,0.15,0.95\n\
         shade,2.65,0.3,1.1,22.0,21.0,0.1,0.15,0.95\n",
    )
    .unwrap();
    let project = dir.path().join("project.toml");
    std::fs::write(&project, SUNNY_PROJECT).unwrap();
    let (d, g, p) = (
        dir.path().to_str().unwrap(),
        globe.to_str().unwrap(),
        project.to_str().unwrap(),
    );
    let text = ok(&["validate", "--map", d, "--globe", g, "--config", p]);
    assert!(
        text.contains("in sun: its reading includes short-wave the long-wave map does not"),
        "{text}"
    );
    let v: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("validation.json")).unwrap())
            .unwrap();
    assert!(v[0]["in_sun"].is_string(), "{v}");
    assert!(v[0]["meets_required"].is_null(), "{v}");
    assert!(
        v[0]["diff_iso_k"].is_number(),
        "the difference is still shown: {v}"
    );
    assert!(v[1].get("in_sun").is_none(), "{v}");
    assert!(v[1]["meets_required"].is_boolean(), "{v}");
    let csv = std::fs::read_to_string(dir.path().join("validation.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].ends_with(",in_sun"), "{csv}");
    assert!(!lines[1].ends_with(','), "{csv}");
    assert!(lines[2].ends_with(','), "{csv}");
    // Without the project, the same globe is judged.
    ok(&["validate", "--map", d, "--globe", g]);
    let v: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("validation.json")).unwrap())
            .unwrap();
    assert!(v[0]["meets_required"].is_boolean(), "{v}");
    fails_with(
        &[
            "validate",
            "--map",
            d,
            "--globe",
            g,
            "--config",
            p,
            "--calibrate-with",
            "lit",
        ],
        "--calibrate-with lit names a globe in the sun",
    );
}

#[test]
fn map_draws_the_mrt_with_the_sun_from_the_projects_sun() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("map");
    let o = out.to_str().unwrap();
    fails_with(
        &["map", "--grid", "4x3", "--quantity", "mrt_sun", "--out", o],
        "[sun]",
    );
    let project = dir.path().join("project.toml");
    std::fs::write(&project, SUNNY_PROJECT).unwrap();
    let text = ok(&[
        "map",
        "--grid",
        "4x3",
        "--quantity",
        "mrt_sun",
        "--config",
        project.to_str().unwrap(),
        "--mark",
        "lit=2.65,1.8",
        "--out",
        o,
    ]);
    assert!(text.contains("mrt_sun"), "{text}");
    assert!(text.contains("the beam reaches the person on"), "{text}");
    let csv = std::fs::read_to_string(out.join("mrt_sun.csv")).unwrap();
    assert_eq!(csv.lines().count(), 13, "{csv}");
    let c: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("comfort.json")).unwrap()).unwrap();
    let lit = &c["marks"][0][1];
    let d = lit["sun"]["delta_mrt_k"].as_f64().unwrap();
    let share = c["sun"]["sunlit_share"].as_f64().unwrap();
    assert!(
        share > 0.0 && share < 1.0,
        "part of the floor is in the beam: {share}"
    );
    assert!(c["sun"]["max_delta_mrt_k"].as_f64().unwrap() > 10.0, "{c}");
    assert!(d > 10.0, "{lit}");
    let m = lit["mrt_sun"][0].as_f64().unwrap();
    let lw = lit["sun"]["mrt_long_wave_c"].as_f64().unwrap();
    assert!((m - lw - d).abs() < 1e-6, "{lit}");
}

/// `simulate --sun`: truth.json gets SolarCal on its grid for a seated person facing the sun. The
/// office's window is on the +x wall (y 0.9…2.7, z 0.9…2.2); with the sun 30° high due +x a
/// person at (2.65, 1.8) sits in the beam (SolarCal by hand: 16.4 K with the whole body lit), one
/// at y ≈ 0.3 beside it gets sky and floor only; a body centre inside the desk (x 2.5…3.8, y
/// 0.25…1.05, up to 0.75 m) has no value.
#[test]
fn simulate_with_the_sun_writes_solarcal_into_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("sunny");
    let args = |sun: &str, dni: &str, tau: &str| -> Vec<String> {
        [
            "simulate",
            "--room",
            "office",
            "--out",
            rec.to_str().unwrap(),
            "--seconds",
            "3",
            "--depth-size",
            "80x60",
            "--noise",
            "none",
            "--truth-rays",
            "500",
            "--sun",
            sun,
            "--dni",
            dni,
            "--transmittance",
            tau,
        ]
        .map(String::from)
        .to_vec()
    };
    for (a, needle) in [
        (args("30,0", "700", "1.6"), "--transmittance = 1.6"),
        (args("-5,0", "700", "0.6"), "--sun altitude = -5"),
    ] {
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let out = mrtmap(&a);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(needle), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let good = args("30,0", "700", "0.6");
    let good: Vec<&str> = good.iter().map(String::as_str).collect();
    ok(&good);
    let truth = read_json(&rec.join("truth.json"));
    let sun = &truth["sun"];
    assert_eq!(sun["inputs"]["dni_w_m2"], 700.0);
    assert_eq!(sun["posture"], "seated");
    let nodes = sun["nodes"].as_array().unwrap();
    assert_eq!(
        nodes.len(),
        truth["grid"]["nodes"].as_array().unwrap().len()
    );
    let nearest = |x: f64, y: f64| {
        nodes
            .iter()
            .min_by(|a, b| {
                let d = |n: &Value| {
                    (n["xyz_room"][0].as_f64().unwrap() - x)
                        .hypot(n["xyz_room"][1].as_f64().unwrap() - y)
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    };
    let lit = nearest(2.65, 1.8);
    let d_lit = lit["delta_mrt_k"].as_f64().unwrap();
    assert!((d_lit - 16.4).abs() < 1.64, "{lit}");
    assert!(lit["f_bes"].as_f64().unwrap() > 0.9, "{lit}");
    let in_desk = nearest(2.65, 0.3);
    assert!(in_desk["delta_mrt_k"].is_null(), "{in_desk}");
    assert_eq!(in_desk["note"], "inside desk");
    let beside = nearest(2.0, 0.3);
    assert!(
        (beside["xyz_room"][1].as_f64().unwrap() - 0.3).abs() < 0.1,
        "{beside}"
    );
    let d_beside = beside["delta_mrt_k"].as_f64().unwrap();
    assert!(d_beside < d_lit / 4.0, "{beside}");
    assert!(
        beside["f_svv"].as_f64().unwrap() > 0.0,
        "sky through the window: {beside}"
    );
    assert_eq!(beside["f_bes"], 0.0);
}
