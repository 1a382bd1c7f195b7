use std::path::Path;

use serde_json::Value;

use crate::mrtmap;

fn ok_json(args: &[&str]) -> Value {
    let out = mrtmap(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn fails_with(args: &[&str], needle: &str) {
    let out = mrtmap(args);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(needle), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn globe_converts_both_ways_and_names_the_formula() {
    let v = ok_json(&["globe", "--tg", "25", "--ta", "22", "--json"]);
    assert!((v["mrt_c"].as_f64().unwrap() - 26.543).abs() < 2e-3);
    assert_eq!(v["formula"], "iso_natural");
    let v = ok_json(&[
        "globe",
        "--tg",
        "25",
        "--ta",
        "22",
        "--method",
        "iso-closed-form",
        "--json",
    ]);
    assert!((v["mrt_c"].as_f64().unwrap() - 26.479).abs() < 1e-3);
    let v = ok_json(&[
        "globe",
        "--tg",
        "25",
        "--ta",
        "22",
        "--va",
        "0.1",
        "--method",
        "iso-closed-form",
        "--json",
    ]);
    assert!((v["mrt_c"].as_f64().unwrap() - 26.761).abs() < 1e-3);
    assert_eq!(v["formula"], "iso_closed_form_forced");
    let v = ok_json(&[
        "globe",
        "--tg",
        "25.42",
        "--ta",
        "26.10",
        "--va",
        "0.1931",
        "--diameter",
        "0.1",
        "--method",
        "mixed",
        "--json",
    ]);
    assert!((v["mrt_c"].as_f64().unwrap() - 24.2).abs() < 0.1);
    let v = ok_json(&["globe", "--tr", "26.543", "--ta", "22", "--json"]);
    assert!((v["globe_c"].as_f64().unwrap() - 25.0).abs() < 2e-3);
    let text = String::from_utf8(mrtmap(&["globe", "--tg", "25", "--ta", "22"]).stdout).unwrap();
    assert!(
        text.starts_with("MRT 26.54 °C") && text.contains("ISO 7726 general formula"),
        "{text}"
    );
    fails_with(
        &[
            "globe",
            "--tg",
            "25",
            "--ta",
            "22",
            "--method",
            "mixed",
            "--diameter",
            "0.3",
        ],
        "outside the valid range",
    );
    fails_with(&["globe", "--ta", "22"], "required");
}

#[test]
fn mrt_exact_and_montecarlo_agree_on_the_example() {
    let ex = ok_json(&[
        "mrt",
        "--at",
        "2.1,1.8,1.1",
        "--at",
        "3.8,0.6,1.1",
        "--json",
    ]);
    let mc = ok_json(&[
        "mrt",
        "--at",
        "2.1,1.8,1.1",
        "--at",
        "3.8,0.6,1.1",
        "--method",
        "montecarlo",
        "--rays",
        "40000",
        "--seed",
        "3",
        "--json",
    ]);
    assert_eq!(ex["points"].as_array().unwrap().len(), 2);
    for k in 0..2 {
        let (a, b) = (&ex["points"][k], &mc["points"][k]);
        assert!((a["view_factor_sum"].as_f64().unwrap() - 1.0).abs() < 1e-9);
        let se = b["std_error_k"].as_f64().unwrap();
        assert!(se > 0.0 && se < 0.05, "{se}");
        let d = (a["mrt_c"].as_f64().unwrap() - b["mrt_c"].as_f64().unwrap()).abs();
        assert!(d < 4.0 * se + 1e-3, "exact vs MC: {d} K, se {se}");
        // The table names every surface and feature.
        let table = a["view_factors"].as_array().unwrap();
        assert_eq!(table.len(), 13);
        assert!(
            table.iter().any(|r| r["id"] == "window-1"
                && r["label"] == "window"
                && r["host"] == "wall-east")
        );
        assert!(
            table
                .iter()
                .all(|r| r["F"].as_f64().is_some() && r["temperature_c"].as_f64().is_some())
        );
    }
}

fn scene_with_desk(dir: &Path) -> String {
    let mut v: Value = serde_json::from_str(mrtmap_radiation::EXAMPLE_OFFICE_JSON).unwrap();
    v["occluders"] = serde_json::json!([
        { "id": "desk-1", "label": "desk", "temperature_c": 21.0, "box": { "min": [1.0, 1.0, 0.0], "max": [2.2, 1.8, 0.75] } }
    ]);
    let p = dir.join("desk.json");
    std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
    p.display().to_string()
}

#[test]
fn occluders_need_montecarlo_and_auto_picks_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_with_desk(dir.path());
    fails_with(
        &[
            "mrt", "--scene", &scene, "--at", "2,2,1.1", "--method", "exact",
        ],
        "occluder(s) (first: 'desk-1')",
    );
    let v = ok_json(&[
        "mrt",
        "--scene",
        &scene,
        "--at",
        "1.6,1.4,1.1",
        "--rays",
        "20000",
        "--json",
    ]);
    assert_eq!(v["method"]["engine"], "monte_carlo");
    let desk = v["points"][0]["view_factors"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["id"] == "desk-1")
        .cloned()
        .unwrap();
    // Right above the desk, it fills much of the lower view.
    assert!(desk["F"].as_f64().unwrap() > 0.1, "{desk}");
    fails_with(
        &[
            "mrt",
            "--scene",
            &scene,
            "--at",
            "1.5,1.5,0.5",
            "--rays",
            "1000",
        ],
        "inside occluder 'desk-1'",
    );
}

#[test]
fn bad_scene_files_get_one_clear_sentence() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.json");
    let mut v: Value = serde_json::from_str(mrtmap_radiation::EXAMPLE_OFFICE_JSON).unwrap();
    v["surfaces"][2]["temperature_c"] = serde_json::json!(400.0);
    std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
    let path = p.display().to_string();
    fails_with(
        &["mrt", "--scene", &path, "--at", "1,1,1"],
        &format!("{path}: surface 'wall-east': temperature 400 °C is outside −60…200 °C"),
    );
    std::fs::write(
        &p,
        "{ \"format\": \"mrtmap-scene/1\",\n \"surfaces\": [ oops ] }",
    )
    .unwrap();
    fails_with(
        &[
            "map",
            "--scene",
            &path,
            "--out",
            dir.path().join("o").to_str().unwrap(),
        ],
        "line 2",
    );
    assert!(
        !dir.path().join("o").exists(),
        "a failed run writes nothing"
    );
    fails_with(
        &["mrt", "--scene", "/nonexistent.json", "--at", "1,1,1"],
        "/nonexistent.json: cannot read the file",
    );
    fails_with(&["mrt", "--at", "1,1"], "expected X,Y,Z");
}

#[test]
fn map_writes_csv_png_svg_and_a_summary_that_agree() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("map");
    let o = mrtmap(&[
        "map",
        "--grid",
        "12x10",
        "--height",
        "1.1",
        "--mark",
        "A=1.0,1.8",
        "--mark",
        "B=3.6,1.8,1.1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("mrt_grid.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 120);
    assert!(csv.starts_with("x,y,z,mrt_c,std_error_k,"));
    let vals: Vec<f64> = rows.iter().map(|r| r[3].parse().unwrap()).collect();
    assert!(
        rows.iter()
            .all(|r| (r[2].parse::<f64>().unwrap() - 1.1).abs() < 1e-9)
    );
    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let min = vals.iter().cloned().fold(f64::INFINITY, f64::min);
    let max = vals.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    assert!((s["min"]["mrt_c"].as_f64().unwrap() - min).abs() < 1e-4);
    assert!((s["max"]["mrt_c"].as_f64().unwrap() - max).abs() < 1e-4);
    assert!(
        (s["mean_c"].as_f64().unwrap() - vals.iter().sum::<f64>() / vals.len() as f64).abs() < 1e-4
    );
    assert_eq!(s["grid"], serde_json::json!([12, 10]));
    assert_eq!(s["marks"].as_array().unwrap().len(), 2);
    // B is by the cold window: cooler than A.
    assert!(
        s["marks"][1]["mrt_c"].as_f64().unwrap() < s["marks"][0]["mrt_c"].as_f64().unwrap() - 1.0
    );
    let png = std::fs::read(out.join("mrt_map.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let svg = std::fs::read_to_string(out.join("mrt_map.svg")).unwrap();
    assert!(
        svg.contains("<svg") && svg.contains("Mean radiant temperature at 1.10 m above the floor")
    );
    assert!(
        svg.contains("\nwindow 11.5°\n") && svg.contains("\nA\n"),
        "features and marks are named"
    );
    // No temporary files are left behind.
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 4, "{names:?}");
}

#[test]
fn example_scene_round_trips_through_map() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.json");
    assert!(
        mrtmap(&["example-scene", "--out", scene.to_str().unwrap()])
            .status
            .success()
    );
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    assert!(
        mrtmap(&["map", "--out", a.to_str().unwrap()])
            .status
            .success()
    );
    assert!(
        mrtmap(&[
            "map",
            "--scene",
            scene.to_str().unwrap(),
            "--out",
            b.to_str().unwrap()
        ])
        .status
        .success()
    );
    assert_eq!(
        std::fs::read_to_string(a.join("mrt_grid.csv")).unwrap(),
        std::fs::read_to_string(b.join("mrt_grid.csv")).unwrap()
    );
}
