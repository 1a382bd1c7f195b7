use mrtmap_geometry::nalgebra::Point3;
use mrtmap_radiation::{
    GridSpec, MapFrame, Method, MonteCarlo, MrtEngine, MrtError, MrtField, RadiantScene,
    example_office,
};

use crate::common::*;

#[test]
fn example_office_grid_covers_the_floor_in_xy() {
    let s = example_office();
    let e = MrtEngine::new(&s, Method::Exact).unwrap();
    let frame = MapFrame::of_scene(&s).unwrap();
    let field = MrtField::compute(&e, frame, GridSpec::default()).unwrap();
    assert_eq!(field.nodes.len(), 400);
    assert!((field.u[0] - 0.1).abs() < 1e-12 && (field.u[19] - 4.1).abs() < 1e-12);
    assert!((field.v[0] - 0.1).abs() < 1e-12 && (field.v[19] - 3.5).abs() < 1e-12);
    let n = &field.nodes[21];
    assert_eq!((n.i, n.j), (1, 1));
    assert!((n.point - Point3::new(field.u[1], field.v[1], 1.1)).norm() < 1e-12);
    let sum = field.summary().unwrap();
    assert_eq!(sum.nodes, 400);
    // The coldest spot is by the window on the east wall; the warmest away from it.
    assert!(sum.min.xyz[0] > 3.5, "{:?}", sum.min);
    assert!(sum.max.xyz[0] < 2.0, "{:?}", sum.max);
    assert!(sum.min.mrt_c < sum.mean_c && sum.mean_c < sum.max.mrt_c);
}

#[test]
fn l_shaped_floor_leaves_out_the_missing_quadrant() {
    let s = scene(&l_room());
    let e = MrtEngine::new(
        &s,
        Method::MonteCarlo(MonteCarlo {
            rays: 800,
            ..MonteCarlo::default()
        }),
    )
    .unwrap();
    let field = MrtField::compute(
        &e,
        MapFrame::of_scene(&s).unwrap(),
        GridSpec {
            nx: 12,
            ny: 8,
            height_m: 1.1,
            margin_m: 0.1,
        },
    )
    .unwrap();
    assert!(
        field.nodes.len() < 96 && field.nodes.len() > 48,
        "{}",
        field.nodes.len()
    );
    assert!(field.nodes.iter().all(|n| !(n.uv.x > 3.0 && n.uv.y > 2.0)));
    assert!(field.nodes.iter().all(|n| n.result.is_ok()));
}

/// A 4 × 4 × 3 m room with a 21 °C shelf along one wall, x < 1 m up to 2 m.
fn room_with_a_shelf() -> RadiantScene {
    let mut f = box_room(4.0, 4.0, 3.0, [20.0; 6]);
    f.occluders.push(box_occluder(
        "shelf",
        [0.0, 0.0, 0.0],
        [1.0, 4.0, 2.0],
        21.0,
    ));
    scene(&f)
}

/// Monte Carlo with 800 rays.
fn monte_carlo(s: &RadiantScene) -> MrtEngine<'_> {
    MrtEngine::new(
        s,
        Method::MonteCarlo(MonteCarlo {
            rays: 800,
            ..MonteCarlo::default()
        }),
    )
    .unwrap()
}

#[test]
fn nodes_inside_occluders_are_reported_not_computed() {
    let s = room_with_a_shelf();
    let e = monte_carlo(&s);
    let field = MrtField::compute(
        &e,
        MapFrame::of_scene(&s).unwrap(),
        GridSpec {
            nx: 8,
            ny: 8,
            height_m: 1.1,
            margin_m: 0.1,
        },
    )
    .unwrap();
    let inside = field
        .nodes
        .iter()
        .filter(|n| matches!(n.result, Err(MrtError::InsideOccluder { .. })))
        .count();
    assert_eq!(inside, 16, "two columns of 8 lie within x < 1");
    assert_eq!(field.summary().unwrap().skipped, 16);
}

/// A point exactly on a furniture face has no radiant temperature (half its sphere is the
/// furniture's inside): refused like a point inside; a millimetre off the face it is computed.
#[test]
fn a_point_on_a_furniture_face_is_refused_and_one_beside_it_is_not() {
    let s = room_with_a_shelf();
    let e = monte_carlo(&s);
    let on = e.at(&Point3::new(1.0, 2.0, 1.1), 1);
    assert!(matches!(on, Err(MrtError::InsideOccluder { .. })), "{on:?}");
    let beside = e.at(&Point3::new(1.001, 2.0, 1.1), 1).unwrap();
    assert!(beside.mrt.celsius() > 20.0 && beside.mrt.celsius() < 21.0);
}

#[test]
fn map_frame_without_up_uses_the_floor_and_world_axes() {
    let s = scene(&box_room(4.0, 3.0, 2.5, [20.0; 6]));
    let fr = MapFrame::of_scene(&s).unwrap();
    assert!((fr.up().z - 1.0).abs() < 1e-12);
    assert!((fr.plane.u.x - 1.0).abs() < 1e-12 && (fr.plane.v.y - 1.0).abs() < 1e-12);
    let p = Point3::new(1.0, 2.0, 1.1);
    assert!((fr.point(&fr.uv(&p), fr.height(&p)) - p).norm() < 1e-12);
}

#[test]
fn bad_grids_are_refused() {
    let s = example_office();
    let e = MrtEngine::new(&s, Method::Exact).unwrap();
    let bad = |spec| MrtField::compute(&e, MapFrame::of_scene(&s).unwrap(), spec).is_err();
    assert!(bad(GridSpec {
        nx: 0,
        ..GridSpec::default()
    }));
    assert!(bad(GridSpec {
        margin_m: 3.0,
        ..GridSpec::default()
    }));
    assert!(bad(GridSpec {
        height_m: f64::NAN,
        ..GridSpec::default()
    }));
}
