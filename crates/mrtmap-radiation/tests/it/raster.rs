//! Temperature rasters: a rastered surface radiates as its texels would as surfaces of their own.

use mrtmap_geometry::nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use mrtmap_radiation::{
    GridSpec, MapFrame, Method, MrtEngine, MrtField, RadiantScene, RasterFile, SceneFile,
    UnseenPatch,
};

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
        unseen: vec![],
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

/// Wall-s with a 1.2 × 0.9 m patch (columns 5–8, rows 3–5) never seen: its texels are filled at
/// 19 °C, and what was seen around it allows 17…25 °C.
fn with_unseen(range_c: [f64; 2]) -> SceneFile {
    let mut f = with_raster();
    let r = f.surfaces[2].raster.as_mut().unwrap();
    let texels: Vec<usize> = (3..6)
        .flat_map(|row| (5..9).map(move |col| row * 14 + col))
        .collect();
    for &i in &texels {
        r.temperature_c[i] = Some(19.0);
    }
    r.filled = texels.clone();
    r.unseen = vec![UnseenPatch { texels, range_c }];
    f
}

#[test]
fn an_unseen_patch_adds_what_its_range_could_do_to_the_mrt() {
    let p = Point3::new(2.0, 0.8, 1.2);
    let s = scene(&with_unseen([17.0, 25.0]));
    let r = MrtEngine::new(&s, Method::Exact)
        .unwrap()
        .at(&p, 0)
        .unwrap();
    // The truth: the patch at each temperature of its range, evenly; the part is the RMS of what
    // that does to the MRT about the filled map's.
    let at = |t: f64| {
        let mut f = with_unseen([17.0, 25.0]);
        let ras = f.surfaces[2].raster.as_mut().unwrap();
        for &i in &ras.unseen[0].texels.clone() {
            ras.temperature_c[i] = Some(t);
        }
        mrt(&scene(&f), p)
    };
    let n = 400;
    let ms: f64 = (0..n)
        .map(|k| 17.0 + 8.0 * (k as f64 + 0.5) / n as f64)
        .map(|t| (at(t) - r.mrt.celsius()).powi(2))
        .sum::<f64>()
        / n as f64;
    let truth = ms.sqrt();
    assert!(
        (r.unseen_std_error_k - truth).abs() < 0.02 * truth,
        "unseen part {} vs {truth}",
        r.unseen_std_error_k
    );
    assert!(truth > 0.1, "the patch matters here: {truth} K");
    // The parts make the total.
    let total = r
        .sampling_std_error_k
        .hypot(r.temperature_std_error_k)
        .hypot(r.placement_std_error_k)
        .hypot(r.unseen_std_error_k)
        .hypot(r.level_std_error_k);
    assert!((r.std_error_k - total).abs() < 1e-12);
    // A patch whose surroundings pin it to its filled temperature adds nothing; one the point
    // cannot see (behind the wall's plane) neither.
    let pinned = scene(&with_unseen([19.0, 19.0]));
    let r0 = MrtEngine::new(&pinned, Method::Exact)
        .unwrap()
        .at(&p, 0)
        .unwrap();
    assert!(r0.unseen_std_error_k < 1e-12, "{}", r0.unseen_std_error_k);
    // Farther away, it matters less.
    let far = MrtEngine::new(&s, Method::Exact)
        .unwrap()
        .at(&Point3::new(2.0, 2.5, 1.2), 0)
        .unwrap();
    assert!(far.unseen_std_error_k < 0.5 * r.unseen_std_error_k);
    // The camera's level is its own part.
    let mut leveled = with_unseen([17.0, 25.0]);
    leveled.temperature_level_std_k = Some(0.3);
    let rl = MrtEngine::new(&scene(&leveled), Method::Exact)
        .unwrap()
        .at(&p, 0)
        .unwrap();
    assert_eq!(rl.level_std_error_k, 0.3);
    assert!((rl.temperature_std_error_k - r.temperature_std_error_k).abs() < 1e-12);
}

#[test]
fn unseen_patches_that_break_the_rules_are_refused() {
    for (patches, expect) in [
        (
            vec![UnseenPatch {
                texels: vec![3, 500],
                range_c: [18.0, 20.0],
            }],
            "names texel 500",
        ),
        (
            vec![UnseenPatch {
                texels: vec![3],
                range_c: [21.0, 20.0],
            }],
            "low then high",
        ),
        (
            vec![
                UnseenPatch {
                    texels: vec![3, 4],
                    range_c: [18.0, 20.0],
                },
                UnseenPatch {
                    texels: vec![4],
                    range_c: [18.0, 20.0],
                },
            ],
            "texel 4 is in unseen patches 0 and 1",
        ),
    ] {
        let mut f = with_raster();
        f.surfaces[2].raster.as_mut().unwrap().unseen = patches;
        let err = RadiantScene::new(&f).unwrap_err().to_string();
        assert!(err.contains(expect) && err.contains("wall-s"), "{err}");
    }
}

#[test]
fn a_map_lists_the_unseen_patch_where_it_matters_most() {
    let s = scene(&with_unseen([17.0, 25.0]));
    let e = MrtEngine::new(&s, Method::Exact).unwrap();
    let field =
        MrtField::compute(&e, MapFrame::of_scene(&s).unwrap(), GridSpec::default()).unwrap();
    let sum = field.summary().unwrap();
    assert_eq!(sum.unseen_patches.len(), 1, "{:?}", sum.unseen_patches);
    let u = &sum.unseen_patches[0];
    assert_eq!((u.surface_id.as_str(), u.patch), ("wall-s", 0));
    // Columns 5-8 and rows 3-5 of 0.3 m texels: 1.2 × 0.9 m centred at x 2.1, z 1.35.
    assert!((u.area_m2 - 1.08).abs() < 1e-9, "{}", u.area_m2);
    assert!(
        (u.centre[0] - 2.1).abs() < 1e-9
            && u.centre[1].abs() < 1e-9
            && (u.centre[2] - 1.35).abs() < 1e-9,
        "{:?}",
        u.centre
    );
    assert_eq!(u.range_c, [17.0, 25.0]);
    // Its largest part is the largest unseen part of any node (there is one patch), at the node
    // nearest to it.
    let best = field
        .nodes
        .iter()
        .filter_map(|n| n.result.as_ref().ok())
        .max_by(|a, b| a.unseen_std_error_k.total_cmp(&b.unseen_std_error_k))
        .unwrap();
    assert!((u.max_std_error_k - best.unseen_std_error_k).abs() < 1e-12);
    assert_eq!(u.at, [best.point.x, best.point.y, best.point.z]);
    assert!(u.at[1] < 0.3 && (u.at[0] - 2.1).abs() < 0.4, "{:?}", u.at);
    assert!((sum.max_std_error_parts.unseen_k - u.max_std_error_k).abs() < 1e-12);
}
