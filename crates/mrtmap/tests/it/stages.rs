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

/// The stages a run ran (not reused), by name.
fn ran(out: &Path) -> Vec<(String, bool)> {
    crate::pipeline::stages_skipped(out)
        .into_iter()
        .map(|(n, skipped)| (n, !skipped))
        .collect()
}

/// `path` replaced by `text` (its hard link to the shared recording broken first).
fn replace(path: &Path, text: &str) {
    std::fs::remove_file(path).unwrap();
    std::fs::write(path, text).unwrap();
}

/// Issue 61: replacing a file the recording's settings name re-runs the stages that read it, and
/// only those: references.csv and masks.txt the segmentation (not the fusion), rig.toml the
/// fusion and all after it. (The weather file of `[sun]`: tests/it/sun.rs.)
#[test]
fn replacing_a_file_reruns_the_stages_that_read_it_and_only_those() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("scan");
    crate::refusals::linked_copy(recording(), &rec);
    let refs = rec.join("references.csv");
    std::fs::write(&refs, "label,x,y,z,temperature_c\nfloor,1.5,1.5,0.0,21.0\n").unwrap();
    let out = dir.path().join("run");
    let args = [
        "run",
        rec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--grid",
        "6x5",
    ];
    ok(&args);
    ok(&args);
    assert!(ran(&out).iter().all(|(_, r)| !r), "{:?}", ran(&out));
    let stage = |name: &str| {
        ran(&out)
            .into_iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("no stage {name}: {:?}", ran(&out)))
            .1
    };
    // A reading changed: the level, so the scene and its map.
    replace(&refs, "label,x,y,z,temperature_c\nfloor,1.5,1.5,0.0,21.4\n");
    ok(&args);
    assert!(!stage("fuse") && stage("segment") && stage("map at 1.10 m"));
    let level = read_json(&out.join("segment/level.json"));
    assert!(
        level["references"][0]["reference_c"].as_f64().unwrap() > 21.3,
        "{level}"
    );
    // masks.txt rewritten: segmentation reads it, fusion does not.
    let masks = rec.join("masks.txt");
    let text = std::fs::read_to_string(&masks).unwrap();
    replace(&masks, &format!("{text}# checked again\n"));
    ok(&args);
    assert!(!stage("fuse") && stage("segment"), "{:?}", ran(&out));
    // rig.toml rewritten: the fusion, and what follows it.
    let rig = rec.join("rig.toml");
    let text = std::fs::read_to_string(&rig).unwrap();
    replace(&rig, &format!("{text}\n# checked again\n"));
    ok(&args);
    assert!(stage("fuse") && stage("segment") && stage("map at 1.10 m"));
    // Nothing replaced: nothing runs.
    ok(&args);
    assert!(ran(&out).iter().all(|(_, r)| !r), "{:?}", ran(&out));
    // The weather file [sun] names, rewritten behind the same path with another direct normal
    // irradiance: the comfort maps (the sun) run again, nothing before them (the case:
    // the old mrt_sun map was reused).
    let row = |h: u32, dni: f64| {
        format!(
            "1989,1,15,{h},60,?9?9?9?9E0,1.0,-2.0,80,101000,0,0,250,150,{dni},60,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n"
        )
    };
    let epw = |dni: f64| {
        format!(
            "LOCATION,Berlin,,DEU,IWEC Data,103840,52.47,13.40,1.0,49.0\nDESIGN CONDITIONS,0\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n{}{}",
            row(12, 100.0),
            row(13, dni)
        )
    };
    std::fs::write(dir.path().join("site.epw"), epw(800.0)).unwrap();
    let toml = dir.path().join("sun.toml");
    std::fs::write(
        &toml,
        "[map]\ngrid = [6, 5]\nquantities = [\"mrt_sun\"]\n\n[sun]\nepw = \"site.epw\"\ndate_time = \"2026-01-15T11:00:00Z\"\ntransmittance = 0.6\n",
    )
    .unwrap();
    let sun_args = [&args[..], &["--config", toml.to_str().unwrap()]].concat();
    ok(&sun_args);
    assert!(stage("comfort maps"));
    ok(&sun_args);
    assert!(ran(&out).iter().all(|(_, r)| !r), "{:?}", ran(&out));
    std::fs::write(dir.path().join("site.epw"), epw(200.0)).unwrap();
    ok(&sun_args);
    assert!(
        stage("comfort maps") && !stage("fuse") && !stage("segment") && !stage("map at 1.10 m"),
        "{:?}",
        ran(&out)
    );
}

/// Issue 61: a relocalisation half way through the scan (every pose after 10 s moved by 0.5 m and
/// turned 10°, the frames as they were) is re-anchored by the depth, and the map is the unshifted
/// walk's within 0.1 K.
#[test]
fn a_relocalised_trajectory_is_reanchored_and_maps_as_the_unshifted_walk() {
    use mrtmap_geometry::nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("scan");
    crate::refusals::linked_copy(recording(), &rec);
    let traj = rec.join("trajectory.txt");
    let text = std::fs::read_to_string(&traj).unwrap();
    let shift = Isometry3::from_parts(
        Translation3::new(0.3, -0.4, 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, 10f64.to_radians()),
    );
    let mut t0 = None;
    let mut out = String::new();
    for line in text.lines() {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap_or(f64::NAN))
            .collect();
        if line.starts_with('#') || v.len() != 8 {
            out.push_str(line);
            out.push('\n');
            continue;
        }
        let start = *t0.get_or_insert(v[0]);
        let p = Isometry3::from_parts(
            Translation3::new(v[1], v[2], v[3]),
            UnitQuaternion::from_quaternion(Quaternion::new(v[7], v[4], v[5], v[6])),
        );
        let p = if v[0] - start > 10.0 { shift * p } else { p };
        let (t, q) = (p.translation.vector, p.rotation.coords);
        out.push_str(&format!(
            "{:.9} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9}\n",
            v[0], t.x, t.y, t.z, q.x, q.y, q.z, q.w
        ));
    }
    std::fs::remove_file(&traj).unwrap();
    std::fs::write(&traj, out).unwrap();
    let run = |rec: &Path, name: &str| {
        let out = dir.path().join(name);
        ok(&[
            "run",
            rec.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--grid",
            "8x6",
        ]);
        out
    };
    let (a, b) = (run(recording(), "unshifted"), run(&rec, "relocalised"));
    let fusion = read_json(&b.join("fuse/fusion.json"));
    let jumps = fusion["pose_check"]["jumps"].as_array().unwrap();
    assert_eq!(jumps.len(), 1, "{fusion}");
    assert_eq!(jumps[0]["outcome"]["kind"], "reanchored", "{}", jumps[0]);
    let grid = |p: &Path| -> Vec<f64> {
        std::fs::read_to_string(p.join("map-1.10m/mrt_grid.csv"))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(3).unwrap().parse().unwrap())
            .collect()
    };
    let (ga, gb) = (grid(&a), grid(&b));
    assert_eq!(ga.len(), gb.len());
    let worst = ga
        .iter()
        .zip(&gb)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    println!(
        "relocalised against unshifted: max |diff| {worst:.3} K over {} nodes",
        ga.len()
    );
    assert!(worst <= 0.1, "{worst:.3} K");
}
