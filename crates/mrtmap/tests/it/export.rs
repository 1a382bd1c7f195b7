//! `mrtmap export`: each format, and Honeybee models read back as scenes.

use crate::{fails_with, mrtmap, ok_json};

#[test]
fn export_writes_each_format_and_a_honeybee_export_maps_back_the_same() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["room.hbjson", "room.xml", "room.glb", "room.rad"] {
        let p = dir.path().join(name);
        let out = mrtmap(&["export", "--out", p.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8_lossy(&out.stdout).contains("6 surfaces, 7 features"));
        assert!(std::fs::metadata(&p).unwrap().len() > 1000, "{name}");
    }
    let hb = dir.path().join("room.hbjson");
    let at = ["--at", "0.6,1.8,1.1", "--at", "3.8,0.9,1.1", "--json"];
    let a = ok_json(&[&["mrt", "--scene", hb.to_str().unwrap()][..], &at].concat());
    let b = ok_json(&[&["mrt"][..], &at].concat());
    for k in 0..2 {
        let (x, y) = (&a["points"][k]["mrt_c"], &b["points"][k]["mrt_c"]);
        assert!(
            (x.as_f64().unwrap() - y.as_f64().unwrap()).abs() < 0.01,
            "{x} vs {y}"
        );
    }
    fails_with(
        &[
            "export",
            "--to",
            "gltf",
            "--out",
            dir.path().to_str().unwrap(),
        ],
        "is a folder: name the file to write in it",
    );
    // gbXML into a file named .hbjson was written, and then read back as "not JSON".
    fails_with(
        &["export", "--to", "gbxml", "--out", hb.to_str().unwrap()],
        "the file's extension names hbjson",
    );
    let obj = dir.path().join("room.obj");
    fails_with(
        &["export", "--out", obj.to_str().unwrap()],
        "does not tell the format",
    );
    let csv = dir.path().join("t.csv");
    std::fs::write(&csv, "identifier,temperature_c\nwall-9,20\n").unwrap();
    fails_with(
        &[
            "mrt",
            "--at",
            "1,1,1",
            "--scene",
            hb.to_str().unwrap(),
            "--temperatures",
            csv.to_str().unwrap(),
        ],
        "t.csv:2: `wall-9` is not a face",
    );
    let sj = dir.path().join("scene.json");
    std::fs::write(&sj, mrtmap_pipeline_example()).unwrap();
    fails_with(
        &[
            "mrt",
            "--at",
            "1,1,1",
            "--scene",
            sj.to_str().unwrap(),
            "--temperatures",
            csv.to_str().unwrap(),
        ],
        "are for a Honeybee model",
    );
}

#[test]
fn export_takes_a_room_only_from_a_honeybee_model() {
    let dir = tempfile::tempdir().unwrap();
    let sj = dir.path().join("scene.json");
    std::fs::write(&sj, mrtmap_pipeline_example()).unwrap();
    let out = dir.path().join("x.glb");
    let (sj, out) = (sj.to_str().unwrap(), out.to_str().unwrap());
    fails_with(
        &["export", sj, "--room", "R", "--out", out],
        "are for a Honeybee model",
    );
    let hb = dir.path().join("x.hbjson");
    let hb = hb.to_str().unwrap();
    let done = mrtmap(&["export", sj, "--out", hb]);
    assert!(done.status.success());
    fails_with(
        &["export", hb, "--room", "Kitchen", "--out", out],
        "no room `Kitchen`; the model's rooms are room",
    );
}

fn mrtmap_pipeline_example() -> Vec<u8> {
    mrtmap(&["example-scene"]).stdout
}
