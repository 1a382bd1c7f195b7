use mrtmap_radiation::{RadiantScene, SceneError, SurfaceKind, example_office};

use crate::common::*;

fn err(file: &mrtmap_radiation::SceneFile) -> SceneError {
    RadiantScene::new(file).unwrap_err()
}

#[test]
fn example_office_is_valid_and_round_trips() {
    let s = example_office();
    assert_eq!(s.surfaces.len(), 6);
    assert_eq!(
        s.surfaces.iter().map(|s| s.features.len()).sum::<usize>(),
        7
    );
    let again = RadiantScene::from_json(&s.to_json()).unwrap();
    assert_eq!(again.to_file(), s.to_file());
    // Saved by a Windows editor with a byte-order mark: read past, as every text file is (it
    // was "not a valid scene file: expected value (line 1, column 1)").
    let bom = RadiantScene::from_json(&format!("\u{feff}{}", s.to_json())).unwrap();
    assert_eq!(bom.to_file(), s.to_file());
}

#[test]
fn up_defaults_to_floor_normal_into_the_room() {
    let s = scene(&box_room(4.0, 3.0, 2.5, [20.0; 6]));
    assert!((s.up().unwrap().z - 1.0).abs() < 1e-12);
    // Reverse the floor's winding: up is still into the room.
    let mut f = box_room(4.0, 3.0, 2.5, [20.0; 6]);
    f.surfaces[0].polygon.reverse();
    assert!((scene(&f).up().unwrap().z - 1.0).abs() < 1e-12);
    assert_eq!(scene(&f).floor().unwrap().kind, SurfaceKind::Floor);
}

#[test]
fn every_rule_of_the_spec_is_enforced_with_the_id() {
    let base = || box_room(4.0, 3.0, 2.5, [20.0; 6]);

    let mut f = base();
    f.format = "mrtmap-scene/2".into();
    assert!(matches!(err(&f), SceneError::Format { .. }));

    let mut f = base();
    f.surfaces[1].id = "floor".into();
    assert_eq!(err(&f).to_string(), "duplicate id 'floor'");

    let mut f = base();
    f.surfaces[2].kind = "roof".into();
    assert_eq!(
        err(&f).to_string(),
        "surface 'wall-s': unknown kind 'roof' (expected floor, ceiling, wall or other)"
    );

    let mut f = base();
    // One corner of a quad 8 mm out of plane: the best-fit plane leaves ±2 mm at every corner.
    f.surfaces[3].polygon[2][0] += 0.008;
    let e = err(&f);
    assert!(
        matches!(e, SceneError::NonPlanar { ref id, deviation_mm, .. } if id == "wall-e" && (deviation_mm - 2.0).abs() < 0.01),
        "{e}"
    );
    assert!(e.to_string().contains("not planar") && e.to_string().contains("mm"));

    let mut f = base();
    f.surfaces[0].polygon = vec![[0., 0., 0.], [4., 3., 0.], [4., 0., 0.], [0., 3., 0.]];
    assert!(
        err(&f)
            .to_string()
            .starts_with("surface 'floor': polygon is not simple")
    );

    let mut f = base();
    f.surfaces[0].polygon.truncate(2);
    assert!(matches!(
        err(&f),
        SceneError::TooFewVertices { count: 2, .. }
    ));

    let mut f = base();
    f.surfaces[4].temperature_c = 250.0;
    assert_eq!(
        err(&f).to_string(),
        "surface 'wall-n': temperature 250 °C is outside −60…200 °C"
    );

    let mut f = base();
    f.surfaces[4].temperature_c = f64::NAN;
    assert!(matches!(err(&f), SceneError::NotFinite { .. }));

    let mut f = base();
    f.surfaces[4].emissivity = 0.0;
    assert!(matches!(err(&f), SceneError::Emissivity { .. }));

    let mut f = base();
    f.up = Some([0.0, 0.0, 0.0]);
    assert!(matches!(err(&f), SceneError::BadUp { .. }));

    let mut f = base();
    f.surfaces[3].features.push(feature(
        "win",
        vec![
            [4.0, 0.5, 0.5],
            [4.0, 1.5, 0.5],
            [4.0, 1.5, 1.5],
            [4.0, 0.5, 1.5],
        ],
        12.0,
    ));
    assert!(RadiantScene::new(&f).is_ok());
    let mut g = f.clone();
    g.surfaces[3].features[0].polygon[0][0] = 3.9;
    assert!(matches!(err(&g), SceneError::FeatureOffPlane { ref id, .. } if id == "win"));
    let mut g = f.clone();
    g.surfaces[3].features[0].polygon = vec![
        [4.0, 2.5, 0.5],
        [4.0, 3.5, 0.5],
        [4.0, 3.5, 1.5],
        [4.0, 2.5, 1.5],
    ];
    assert_eq!(
        err(&g).to_string(),
        "feature 'win' is not inside the polygon of its host surface 'wall-e'"
    );
    let mut g = f.clone();
    g.surfaces[3].features.push(feature(
        "win2",
        vec![
            [4.0, 1.0, 1.0],
            [4.0, 2.0, 1.0],
            [4.0, 2.0, 2.0],
            [4.0, 1.0, 2.0],
        ],
        12.0,
    ));
    assert_eq!(
        err(&g).to_string(),
        "features 'win' and 'win2' of surface 'wall-e' overlap"
    );
    let mut g = f.clone();
    g.surfaces[3].features[0].id = "wall-n".into();
    assert!(matches!(err(&g), SceneError::DuplicateId { .. }));

    let mut f = base();
    f.occluders.push(box_occluder(
        "desk",
        [1.0, 1.0, 0.0],
        [0.5, 2.0, 0.75],
        21.0,
    ));
    assert!(err(&f).to_string().starts_with("occluder 'desk': box min"));
    let mut f = base();
    let mut o = box_occluder("mesh", [0.0; 3], [1.0; 3], 21.0);
    o.box_ = None;
    o.vertices = Some(vec![[1.0, 1.0, 0.5], [2.0, 1.0, 0.5], [1.0, 2.0, 0.5]]);
    o.triangles = Some(vec![[0, 1, 3]]);
    f.occluders.push(o);
    assert!(
        err(&f)
            .to_string()
            .contains("refers to a vertex beyond the 3 given")
    );
}

#[test]
fn json_errors_name_line_and_column() {
    let e = RadiantScene::from_json("{\n  \"format\": \"mrtmap-scene/1\",\n  \"surfaces\": [ }\n")
        .unwrap_err();
    match e {
        SceneError::Json { line, .. } => assert_eq!(line, 3),
        other => panic!("{other}"),
    }
    let e = RadiantScene::from_json(
        r#"{"format": "mrtmap-scene/1", "surfaces": [{"id": "a", "kind": "wall"}]}"#,
    )
    .unwrap_err();
    assert!(e.to_string().contains("missing field `polygon`"), "{e}");
}

#[test]
fn load_error_names_the_file() {
    let e = RadiantScene::load(std::path::Path::new("/nonexistent/scene.json")).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("/nonexistent/scene.json: cannot read the file")
    );
}
