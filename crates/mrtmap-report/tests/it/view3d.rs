use mrtmap_radiation::example_office;
use mrtmap_report::mesh::{PartRole, outward_normal, scene_mesh};
use mrtmap_report::view3d::{GridLayer, MAX_VIEW_POINTS, PatchLayer, view3d};
use mrtmap_report::{ReportData, render_html};
use serde_json::Value;

#[test]
fn the_mesh_covers_every_surface_and_feature_wound_outward() {
    let s = example_office();
    let parts = scene_mesh(&s);
    let n_features: usize = s.surfaces.iter().map(|x| x.features.len()).sum();
    assert_eq!(parts.len(), s.surfaces.len() + n_features);
    for (p, surface) in parts.iter().zip(&s.surfaces) {
        assert_eq!(p.role, PartRole::Surface);
        // The triangles cover the outline less its features.
        let area: f64 = p
            .triangles
            .iter()
            .map(|t| {
                let v = |i: u32| mrtmap_geometry::nalgebra::Point3::from(p.positions[i as usize]);
                let (a, b, c) = (v(t[0]), v(t[1]), v(t[2]));
                let n = (b - a).cross(&(c - a));
                // Wound so its normal points out of the room.
                assert!(n.dot(&outward_normal(&s, surface)) > 0.0, "{}", p.id);
                0.5 * n.norm()
            })
            .sum();
        let holes: f64 = surface
            .features
            .iter()
            .map(|f| mrtmap_geometry::polygon::area_3d(&f.polygon))
            .sum();
        assert!(
            (area - (p.area_m2 - holes)).abs() < 1e-9,
            "{}: {area}",
            p.id
        );
    }
}

#[test]
fn the_view_thins_the_cloud_and_lays_each_map_as_cells() {
    let s = example_office();
    let pos: Vec<[f32; 3]> = (0..100_000).map(|i| [i as f32 * 1e-5, 1.0, 1.0]).collect();
    let t = vec![20.0f32; pos.len()];
    let nodes: Vec<[f64; 4]> = (0..4)
        .flat_map(|j| {
            (0..5).map(move |i| {
                [
                    0.5 + 0.8 * f64::from(i),
                    0.5 + 0.7 * f64::from(j),
                    1.1,
                    20.0 + f64::from(i),
                ]
            })
        })
        .collect();
    let grid = GridLayer {
        height_m: 1.1,
        nodes,
        u: [1.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
    };
    let v: Value =
        serde_json::from_str(&view3d(&s, Some((&pos, &t)), &[grid], &[], None).0).unwrap();
    assert_eq!(
        v["cloud"]["p"].as_array().unwrap().len(),
        3 * MAX_VIEW_POINTS
    );
    assert_eq!(v["grids"][0]["n"].as_array().unwrap().len(), 20);
    let cell: Vec<f64> = serde_json::from_value(v["grids"][0]["cell"].clone()).unwrap();
    assert!(
        (cell[0] - 0.8).abs() < 1e-9 && (cell[1] - 0.7).abs() < 1e-9,
        "{cell:?}"
    );
    let range: Vec<f64> = serde_json::from_value(v["range"].clone()).unwrap();
    assert!(
        (range[0] - 11.5).abs() < 1e-9 && (range[1] - 29.0).abs() < 1e-9,
        "{range:?}"
    );
    // The MRT grid has a palette of its own (viridis), not the surfaces' on another scale.
    assert_eq!(
        v["grids"][0]["bar"][0], "#440154",
        "{}",
        v["grids"][0]["bar"]
    );
    assert_ne!(v["grids"][0]["bar"][0], v["bar"][0]);
    // The camera starts facing the window's wall (outward normal +x).
    assert_eq!(v["look"], serde_json::json!([1.0, 0.0, 0.0]));
}

#[test]
fn the_report_embeds_the_view_safely() {
    let mut f = example_office().to_file();
    f.surfaces[0].label = "</script><b>".into();
    let s = mrtmap_radiation::RadiantScene::new(&f).unwrap();
    let d = ReportData {
        title: "t".into(),
        view3d: Some(view3d(&s, None, &[], &[], None)),
        ..ReportData::default()
    };
    let html = render_html(&d);
    assert!(html.contains("<canvas id=\"view3d\">"));
    // The colour bars lie over the view, not below the fold.
    let stage = html.find("<div id=\"view3d-stage\">").unwrap();
    let bars = html.find("<div id=\"view3d-bars\">").unwrap();
    let info = html.find("<p id=\"view3d-info\">").unwrap();
    assert!(stage < bars && bars < info);
    // No sun, no sunlit-patch button.
    assert!(!html.contains("data-layer=\"sun\""));
    assert!(html.contains("<button data-layer=\"cloud\">"));
    assert!(
        !html.contains("</script><b>"),
        "a label closed the data's script element"
    );
    assert_eq!(html.matches("</script>").count(), 3);
    // Without a scene, no view.
    assert!(!render_html(&ReportData::default()).contains("<canvas"));
}

#[test]
fn the_sunlit_patch_lies_on_the_floor_with_its_own_button() {
    let s = example_office();
    let patch = PatchLayer {
        cells: vec![[2.65, 1.8, 0.0], [2.4, 1.8, 0.0]],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
        cell_m: [0.25, 0.2],
    };
    let view = view3d(&s, None, &[], &[], Some(&patch));
    assert!(view.1.sun);
    let v: Value = serde_json::from_str(&view.0).unwrap();
    let cells: Vec<[f64; 3]> = serde_json::from_value(v["sun"]["cells"].clone()).unwrap();
    // 1 cm above the floor (z = 0), so the floor does not hide it.
    assert_eq!(cells, vec![[2.65, 1.8, 0.01], [2.4, 1.8, 0.01]]);
    assert_eq!(v["sun"]["cell"], serde_json::json!([0.25, 0.2]));
    let html = render_html(&ReportData {
        title: "t".into(),
        view3d: Some(view),
        ..ReportData::default()
    });
    assert!(html.contains("<button data-layer=\"sun\">Sunlit patch</button>"));
    // An empty patch is no layer.
    let empty = PatchLayer {
        cells: Vec::new(),
        ..patch
    };
    let view = view3d(&s, None, &[], &[], Some(&empty));
    assert!(!view.1.sun);
}
