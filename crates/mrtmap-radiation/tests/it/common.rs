//! Scene builders shared by the tests.

use mrtmap_radiation::{
    FeatureFile, OccluderFile, RadiantScene, SCENE_FORMAT, SceneFile, SurfaceFile,
};
use proptest::test_runner::{Config, RngAlgorithm, RngSeed};

/// Deterministic proptest settings: a fixed seed so a "within k standard errors" property cannot
/// flicker between runs.
pub fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0x6d72_746d_6170),
        failure_persistence: None,
        ..Config::default()
    }
}

pub fn surface(id: &str, kind: &str, polygon: Vec<[f64; 3]>, t: f64) -> SurfaceFile {
    SurfaceFile {
        id: id.into(),
        kind: kind.into(),
        label: String::new(),
        polygon,
        temperature_c: t,
        emissivity: 1.0,
        temperature_std_k: None,
        surface_temperature_c: None,
        surface_temperature_std_k: None,
        observed_fraction: None,
        features: Vec::new(),
        raster: None,
    }
}

pub fn feature(id: &str, polygon: Vec<[f64; 3]>, t: f64) -> FeatureFile {
    FeatureFile {
        id: id.into(),
        label: "window".into(),
        polygon,
        temperature_c: t,
        emissivity: 1.0,
        temperature_std_k: None,
        surface_temperature_c: None,
        surface_temperature_std_k: None,
    }
}

pub fn box_occluder(id: &str, min: [f64; 3], max: [f64; 3], t: f64) -> OccluderFile {
    OccluderFile {
        id: id.into(),
        label: "box".into(),
        temperature_c: t,
        emissivity: 1.0,
        box_: Some(mrtmap_radiation::BoxFile { min, max }),
        vertices: None,
        triangles: None,
    }
}

/// A closed box room [0, sx] × [0, sy] × [0, sz] with temperatures (floor, ceiling, -y, +x, +y, -x).
pub fn box_room(sx: f64, sy: f64, sz: f64, t: [f64; 6]) -> SceneFile {
    SceneFile {
        format: SCENE_FORMAT.into(),
        up: None,
        world_from_room: None,
        temperature_level_std_k: None,
        temperatures: None,
        surfaces: vec![
            surface(
                "floor",
                "floor",
                vec![[0., 0., 0.], [sx, 0., 0.], [sx, sy, 0.], [0., sy, 0.]],
                t[0],
            ),
            surface(
                "ceiling",
                "ceiling",
                vec![[0., 0., sz], [sx, 0., sz], [sx, sy, sz], [0., sy, sz]],
                t[1],
            ),
            surface(
                "wall-s",
                "wall",
                vec![[0., 0., 0.], [sx, 0., 0.], [sx, 0., sz], [0., 0., sz]],
                t[2],
            ),
            surface(
                "wall-e",
                "wall",
                vec![[sx, 0., 0.], [sx, sy, 0.], [sx, sy, sz], [sx, 0., sz]],
                t[3],
            ),
            surface(
                "wall-n",
                "wall",
                vec![[sx, sy, 0.], [0., sy, 0.], [0., sy, sz], [sx, sy, sz]],
                t[4],
            ),
            surface(
                "wall-w",
                "wall",
                vec![[0., sy, 0.], [0., 0., 0.], [0., 0., sz], [0., sy, sz]],
                t[5],
            ),
        ],
        occluders: Vec::new(),
    }
}

/// An L-shaped room: [0, 6] × [0, 4] minus [3, 6] × [2, 4], height 2.5.
pub fn l_room() -> SceneFile {
    let plan = [[0., 0.], [6., 0.], [6., 2.], [3., 2.], [3., 4.], [0., 4.]];
    let h = 2.5;
    let mut surfaces = vec![
        surface(
            "floor",
            "floor",
            plan.iter().map(|p| [p[0], p[1], 0.0]).collect(),
            20.0,
        ),
        surface(
            "ceiling",
            "ceiling",
            plan.iter().map(|p| [p[0], p[1], h]).collect(),
            24.0,
        ),
    ];
    for i in 0..plan.len() {
        let (a, b) = (plan[i], plan[(i + 1) % plan.len()]);
        surfaces.push(surface(
            &format!("wall-{i}"),
            "wall",
            vec![
                [a[0], a[1], 0.0],
                [b[0], b[1], 0.0],
                [b[0], b[1], h],
                [a[0], a[1], h],
            ],
            18.0 + i as f64,
        ));
    }
    SceneFile {
        format: SCENE_FORMAT.into(),
        up: None,
        world_from_room: None,
        temperature_level_std_k: None,
        temperatures: None,
        surfaces,
        occluders: Vec::new(),
    }
}

pub fn scene(file: &SceneFile) -> RadiantScene {
    RadiantScene::new(file).unwrap()
}
