use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Point2, Point3, Unit, Vector3};
use mrtmap_geometry::polygon::{
    self, Containment, NotSimple, check_simple, planarity_deviation, point_in_polygon,
    polygon_inside, polygons_overlap, signed_area, triangulate, triangulate_with_holes,
};

fn q(x: f64, y: f64) -> Point2<f64> {
    Point2::new(x, y)
}

fn square(x0: f64, y0: f64, s: f64) -> Vec<Point2<f64>> {
    vec![q(x0, y0), q(x0 + s, y0), q(x0 + s, y0 + s), q(x0, y0 + s)]
}

#[test]
fn plane_frame_round_trips_and_measures_planarity() {
    let pts = [
        Point3::new(4.2, 0.0, 0.0),
        Point3::new(4.2, 3.6, 0.0),
        Point3::new(4.2, 3.6, 2.7),
        Point3::new(4.2, 0.0, 2.7),
    ];
    let f = PlaneFrame::of_polygon(&pts).unwrap();
    assert!((f.normal.x.abs() - 1.0).abs() < 1e-12);
    for p in &pts {
        assert!((f.to_3d(&f.to_2d(p)) - p).norm() < 1e-12);
    }
    assert!(planarity_deviation(&pts) < 1e-12);
    let mut bent = pts;
    bent[2].x += 0.004;
    let dev = planarity_deviation(&bent);
    assert!(dev > 0.0009 && dev < 0.0011, "{dev}");
    assert!((polygon::area_3d(&pts) - 3.6 * 2.7).abs() < 1e-12);
    let g = PlaneFrame::new(
        Point3::origin(),
        Unit::new_normalize(Vector3::z()),
        &Vector3::new(1.0, 1.0, 5.0),
    );
    assert!((g.u.dot(&Vector3::new(1.0, 1.0, 0.0).normalize()) - 1.0).abs() < 1e-12);
}

#[test]
fn containment_with_boundary_band() {
    let l = vec![
        q(0., 0.),
        q(2., 0.),
        q(2., 1.),
        q(1., 1.),
        q(1., 2.),
        q(0., 2.),
    ];
    assert_eq!(
        point_in_polygon(&q(0.5, 0.5), &l, 1e-3),
        Containment::Inside
    );
    assert_eq!(
        point_in_polygon(&q(1.5, 1.5), &l, 1e-3),
        Containment::Outside
    );
    assert_eq!(
        point_in_polygon(&q(1.5, 1.0005), &l, 1e-3),
        Containment::Boundary
    );
    assert!((signed_area(&l) - 3.0).abs() < 1e-12);
}

#[test]
fn simplicity_is_checked() {
    assert_eq!(check_simple(&square(0.0, 0.0, 1.0), 1e-6), Ok(()));
    let bowtie = vec![q(0., 0.), q(1., 1.), q(1., 0.), q(0., 1.)];
    assert!(matches!(
        check_simple(&bowtie, 1e-6),
        Err(NotSimple::EdgesIntersect(_, _))
    ));
    let dup = vec![q(0., 0.), q(1., 0.), q(1., 0.), q(0., 1.)];
    assert_eq!(check_simple(&dup, 1e-6), Err(NotSimple::ZeroLengthEdge(1)));
    let spike = vec![q(0., 0.), q(2., 0.), q(1., 0.), q(1., 1.)];
    assert!(check_simple(&spike, 1e-6).is_err());
    assert_eq!(
        check_simple(&[q(0., 0.), q(1., 0.)], 1e-6),
        Err(NotSimple::TooFewVertices)
    );
}

#[test]
fn inside_and_overlap() {
    let wall = square(0.0, 0.0, 4.0);
    let window = square(1.0, 1.0, 1.0);
    assert!(polygon_inside(&window, &wall, 1e-3));
    assert!(
        polygon_inside(&square(0.0, 0.0, 1.0), &wall, 1e-3),
        "touching the border is allowed"
    );
    assert!(!polygon_inside(&square(3.5, 1.0, 1.0), &wall, 1e-3));
    // A notch: every vertex inside the L's hull, but an edge crosses the reflex corner.
    let l = vec![
        q(0., 0.),
        q(2., 0.),
        q(2., 1.),
        q(1., 1.),
        q(1., 2.),
        q(0., 2.),
    ];
    assert!(!polygon_inside(
        &[q(0.5, 0.5), q(1.8, 0.5), q(0.5, 1.8)],
        &l,
        1e-3
    ));
    assert!(polygons_overlap(&window, &square(1.5, 1.5, 1.0), 1e-3));
    assert!(
        polygons_overlap(&window, &window, 1e-3),
        "identical polygons overlap"
    );
    assert!(
        !polygons_overlap(&window, &square(2.0, 1.0, 1.0), 1e-3),
        "sharing an edge is not overlap"
    );
    assert!(
        polygons_overlap(&wall, &window, 1e-3),
        "containment is overlap"
    );
}

#[test]
fn triangulation_covers_the_area() {
    let l = vec![
        q(0., 0.),
        q(2., 0.),
        q(2., 1.),
        q(1., 1.),
        q(1., 2.),
        q(0., 2.),
    ];
    let tris = triangulate(&l).unwrap();
    assert_eq!(tris.len(), 4);
    let area: f64 = tris
        .iter()
        .map(|t| signed_area(&[l[t[0]], l[t[1]], l[t[2]]]).abs())
        .sum();
    assert!((area - 3.0).abs() < 1e-12);
}

#[test]
fn triangulation_with_a_hole_covers_the_outline_less_the_hole() {
    let outline = [q(0.0, 0.0), q(4.0, 0.0), q(4.0, 3.0), q(0.0, 3.0)];
    let hole = vec![q(1.0, 1.0), q(2.5, 1.0), q(2.5, 2.0), q(1.0, 2.0)];
    let all: Vec<Point2<f64>> = outline.iter().chain(hole.iter()).copied().collect();
    let tris = triangulate_with_holes(&outline, std::slice::from_ref(&hole)).unwrap();
    let area: f64 = tris
        .iter()
        .map(|t| signed_area(&[all[t[0]], all[t[1]], all[t[2]]]).abs())
        .sum();
    assert!((area - (12.0 - 1.5)).abs() < 1e-9, "area {area}");
    // No triangle's centroid lies in the hole.
    for t in &tris {
        let c = Point2::from((all[t[0]].coords + all[t[1]].coords + all[t[2]].coords) / 3.0);
        assert!(!(c.x > 1.0 && c.x < 2.5 && c.y > 1.0 && c.y < 2.0), "{c:?}");
    }
    assert_eq!(triangulate_with_holes(&outline, &[]).unwrap().len(), 2);
}
