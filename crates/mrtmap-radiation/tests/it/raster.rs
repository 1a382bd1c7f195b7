//! Temperature rasters: a rastered surface radiates as its texels would as surfaces of their own.

use mrtmap_geometry::nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use mrtmap_radiation::{Method, MrtEngine, RadiantScene, RasterFile, SceneFile};

use crate::common::*;

const H: f64 = 2.7;

/// Wall-s (y = 0, 4 m × 2.7 m) stratified: 0.8 K/m about 18 °C at mid-height, in 0.3 m rows.
fn stratified(z: f64) -> f64 {
    18.0 + 0.8 * (z - H / 2.0)
}

fn raster() -> RasterFile {
    let (cols, rows) = (14, 9);
    RasterFile {
        texel_m: 0.3,
        origin: [0.0, 0.0, 0.0],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 0.0, 1.0],
        cols,
        rows,
        temperature_c: (0..cols * rows)
            .map(|i| Some(stratified((i / cols) as f64 * 0.3 + 0.15)))
            .collect(),
        filled: vec![],
    }
}

fn with_raster() -> SceneFile {
    let mut f = box_room(4.0, 3.0, H, [20.0, 21.0, 18.0, 20.5, 20.5, 19.5]);
    f.surfaces[2].raster = Some(raster());
    f
}

/// The same room with wall-s cut into its raster's rows, each a wall at the row's temperature.
fn with_strips() -> SceneFile {
    let mut f = box_room(4.0, 3.0, H, [20.0, 21.0, 18.0, 20.5, 20.5, 19.5]);
    f.surfaces.remove(2);
    for r in 0..9 {
        let (z0, z1) = (r as f64 * 0.3, (r as f64 * 0.3 + 0.3).min(H));
        f.surfaces.push(surface(
            &format!("strip-{r}"),
            "wall",
            vec![[0., 0., z0], [4., 0., z0], [4., 0., z1], [0., 0., z1]],
            stratified(z0 + 0.15),
        ));
    }
    f
}

fn mrt(s: &RadiantScene, p: Point3<f64>) -> f64 {
    MrtEngine::new(s, Method::Exact)
        .unwrap()
        .at(&p, 0)
        .unwrap()
        .mrt
        .celsius()
}

#[test]
fn a_stratified_wall_radiates_as_its_rows() {
    let (a, b) = (scene(&with_raster()), scene(&with_strips()));
    let uniform = scene(&box_room(4.0, 3.0, H, [20.0, 21.0, 18.0, 20.5, 20.5, 19.5]));
    for p in [
        Point3::new(2.0, 0.4, 0.3),
        Point3::new(2.0, 0.4, 2.4),
        Point3::new(1.0, 1.5, 1.1),
        Point3::new(3.5, 2.5, 1.7),
    ] {
        let (ta, tb) = (mrt(&a, p), mrt(&b, p));
        assert!((ta - tb).abs() < 1e-9, "{p:?}: raster {ta} vs strips {tb}");
        // Near the wall the stratification matters: low points see its cold bottom.
        if p.y < 1.0 {
            let tu = mrt(&uniform, p);
            assert!((ta - tu).abs() > 0.05, "{p:?}: raster {ta} vs uniform {tu}");
            assert_eq!(ta < tu, p.z < H / 2.0, "{p:?}: raster {ta} vs uniform {tu}");
        }
    }
}

#[test]
fn a_uniform_raster_changes_nothing_and_rasters_round_trip_and_move_with_the_scene() {
    let mut f = with_raster();
    let plain = scene(&box_room(4.0, 3.0, H, [20.0, 21.0, 18.0, 20.5, 20.5, 19.5]));
    for t in f.surfaces[2]
        .raster
        .as_mut()
        .unwrap()
        .temperature_c
        .iter_mut()
    {
        *t = Some(18.0);
    }
    let p = Point3::new(1.2, 0.7, 0.9);
    assert!((mrt(&scene(&f), p) - mrt(&plain, p)).abs() < 1e-9);
    // Round trip through the file.
    let s = scene(&with_raster());
    let again = RadiantScene::new(&s.to_file()).unwrap();
    assert!((mrt(&s, p) - mrt(&again, p)).abs() < 1e-12);
    // Turned and moved, the raster goes with its wall.
    let iso = Isometry3::from_parts(
        Translation3::new(5.0, -2.0, 1.0),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.7),
    );
    let moved = RadiantScene::new(&with_raster().transformed(&iso)).unwrap();
    assert!((mrt(&s, p) - mrt(&moved, iso * p)).abs() < 1e-9);
}

#[test]
fn a_bad_raster_is_refused_with_the_surface_and_the_rule() {
    type Spoil = fn(&mut RasterFile);
    let cases: [(&str, Spoil); 5] = [
        ("cols × rows is 126", |r| {
            r.temperature_c.pop();
        }),
        ("in the surface's plane", |r| r.v = [0.0, 1.0, 0.0]),
        ("outside -60…200 °C", |r| {
            r.temperature_c[3] = Some(500.0);
        }),
        ("filled names texel 999", |r| r.filled = vec![999]),
        ("off the surface's plane", |r| r.origin = [0.0, 0.5, 0.0]),
    ];
    for (msg, spoil) in cases {
        let mut f = with_raster();
        spoil(f.surfaces[2].raster.as_mut().unwrap());
        let e = RadiantScene::new(&f).unwrap_err().to_string();
        assert!(
            e.contains("surface 'wall-s': raster") && e.contains(msg),
            "{msg}: {e}"
        );
    }
}
