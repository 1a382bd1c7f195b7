//! The stages one at a time (`fuse`, `segment`, `map`) against `run`, given the same project.

use std::path::Path;

use serde_json::Value;

use crate::ok;
use crate::pipeline::{read_json, recording};

/// Issue 61: the stages one at a time (`fuse`, `segment --recording`, `map`), each given the
/// same project.toml, give `run`'s scene (every surface's and feature's temperature and label,
/// the masks' labels included) and its grid; `map --config` refuses a scene segmented without the
/// project's [emissivity] rather than ignore it.
#[test]
fn the_stages_one_at_a_time_give_runs_scene_and_map() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let rec = recording().to_str().unwrap();
    std::fs::write(
        dir.path().join("p.toml"),
        "[map]\ngrid = [8, 6]\n\n[emissivity]\nby_label = { window = 0.5 }\n\n[segment]\nraster_m = 0.3\n\n\
         [[references]]\nlabel = \"floor\"\nxyz = [1.5, 1.5, 0.0]\ntemperature_c = 21.0\nstd_k = 0.1\n",
    )
    .unwrap();
    let p = d("p.toml");
    ok(&["run", rec, "--out", &d("run"), "--config", &p]);
    ok(&["fuse", rec, "--out", &d("f"), "--config", &p]);
    ok(&[
        "segment",
        &d("f"),
        "--recording",
        rec,
        "--out",
        &d("s"),
        "--config",
        &p,
    ]);
    let scene = dir.path().join("s/scene.json");
    ok(&[
        "map",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        &d("m"),
        "--config",
        &p,
    ]);
    let elements = |p: &Path| -> Vec<(String, String, f64)> {
        let s = read_json(p);
        let mut v = Vec::new();
        for x in s["surfaces"].as_array().unwrap() {
            let one = |e: &Value| {
                (
                    e["id"].as_str().unwrap().to_string(),
                    e["label"].as_str().unwrap().to_string(),
                    e["temperature_c"].as_f64().unwrap(),
                )
            };
            v.push(one(x));
            for f in x["features"].as_array().into_iter().flatten() {
                v.push(one(f));
            }
        }
        v
    };
    let (a, b) = (
        elements(&dir.path().join("run/segment/scene.json")),
        elements(&scene),
    );
    assert_eq!(a.len(), b.len());
    assert!(
        a.iter().any(|(_, l, _)| l == "door"),
        "the masks' labels: {a:?}"
    );
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((&x.0, &x.1), (&y.0, &y.1));
        assert!((x.2 - y.2).abs() <= 0.01, "{x:?} vs {y:?}");
    }
    let grid = |p: &Path| -> Vec<f64> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(3).unwrap().parse().unwrap())
            .collect()
    };
    let (ga, gb) = (
        grid(&dir.path().join("run/map-1.10m/mrt_grid.csv")),
        grid(&dir.path().join("m/mrt_grid.csv")),
    );
    assert_eq!(ga.len(), 48);
    assert_eq!(ga.len(), gb.len());
    for (x, y) in ga.iter().zip(&gb) {
        assert!((x - y).abs() <= 0.01, "{x} vs {y}");
    }
    // Segmented without the project, the scene's window keeps the table's emissivity: map
    // --config says so instead of mapping it with another.
    ok(&["segment", &d("f"), "--recording", rec, "--out", &d("s0")]);
    let s0 = dir.path().join("s0/scene.json");
    crate::fails_with(
        &[
            "map",
            "--scene",
            s0.to_str().unwrap(),
            "--out",
            &d("m0"),
            "--config",
            &p,
        ],
        "[emissivity] of window-1 = 0.5 differs from the 0.84 the scene",
    );
}
