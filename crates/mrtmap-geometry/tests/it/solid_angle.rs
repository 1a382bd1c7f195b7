use std::f64::consts::PI;

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_geometry::{polygon_solid_angle, sphere_view_factor, triangle_solid_angle};
use proptest::prelude::*;

fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
    Point3::new(x, y, z)
}

fn rect(a: f64, b: f64) -> [Point3<f64>; 4] {
    [
        p(0.0, 0.0, 0.0),
        p(a, 0.0, 0.0),
        p(a, b, 0.0),
        p(0.0, b, 0.0),
    ]
}

/// physics.md: corner-aligned rectangle a × b at distance c: Ω = atan(ab / (c√(a²+b²+c²))).
#[test]
fn corner_aligned_rectangles_published_vectors() {
    for (a, b, c, f) in [
        (1.0, 1.0, 1.0, 0.0416667),
        (2.0, 1.0, 1.0, 0.0544882),
        (3.0, 2.0, 1.5, 0.0634550),
    ] {
        let got = sphere_view_factor(&p(0.0, 0.0, c), &rect(a, b));
        assert!((got - f).abs() < 5e-8, "{a}×{b} at {c}: {got} vs {f}");
        let omega: f64 = (a * b / (c * (a * a + b * b + c * c).sqrt())).atan();
        assert!((got - omega / (4.0 * PI)).abs() < 1e-14);
    }
    // (1, 1, 1) → Ω = π/6 exactly.
    assert!(
        (polygon_solid_angle(&p(0.0, 0.0, 1.0), &rect(1.0, 1.0)).abs() - PI / 6.0).abs() < 1e-14
    );
}

/// Cube centre: each face 1/6.
#[test]
fn cube_centre_faces_are_one_sixth() {
    let c = p(0.5, 0.5, 0.5);
    let faces = [
        [p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.)],
        [p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.)],
        [p(0., 0., 0.), p(1., 0., 0.), p(1., 0., 1.), p(0., 0., 1.)],
        [p(0., 1., 0.), p(1., 1., 0.), p(1., 1., 1.), p(0., 1., 1.)],
        [p(0., 0., 0.), p(0., 1., 0.), p(0., 1., 1.), p(0., 0., 1.)],
        [p(1., 0., 0.), p(1., 1., 0.), p(1., 1., 1.), p(1., 0., 1.)],
    ];
    for f in &faces {
        assert!((sphere_view_factor(&c, f) - 1.0 / 6.0).abs() < 1e-14);
    }
}

/// Disk of radius R on axis at distance h: F = (1 − h/√(h²+R²))/2, by a fine regular polygon
/// (the inscribed n-gon misses a relative area of about (2π/n)²/6).
#[test]
fn disk_formula() {
    for (r, h) in [(1.0, 1.0), (0.5, 2.0), (3.0, 0.2)] {
        let n = 20_000;
        let poly: Vec<_> = (0..n)
            .map(|i| {
                let a = 2.0 * PI * i as f64 / n as f64;
                p(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect();
        let exact = (1.0 - h / (h * h + r * r).sqrt()) / 2.0;
        let got = sphere_view_factor(&p(0.0, 0.0, h), &poly);
        assert!(
            (got - exact).abs() / exact < 1e-7,
            "R {r} h {h}: {got} vs {exact}"
        );
    }
}

/// A triangle seen from just above its interior covers almost a hemisphere; the sign says which
/// side: negative in front of the right-hand normal (here +z), positive behind it.
#[test]
fn signs_and_hemisphere_limit() {
    let (a, b, c) = (p(-10.0, -10.0, 0.0), p(10.0, -10.0, 0.0), p(0.0, 10.0, 0.0));
    let above = triangle_solid_angle(&p(0.0, 0.0, 1e-6), &a, &b, &c);
    let below = triangle_solid_angle(&p(0.0, 0.0, -1e-6), &a, &b, &c);
    assert!((above + 2.0 * PI).abs() < 1e-5, "{above}");
    assert!((above + below).abs() < 1e-9);
    // In the plane: zero.
    assert_eq!(triangle_solid_angle(&p(50.0, 0.0, 0.0), &a, &b, &c), 0.0);
}

/// An L-shaped (non-convex) polygon equals the sum of its two rectangles, both windings.
#[test]
fn non_convex_polygon_is_additive() {
    let l = [
        p(0., 0., 0.),
        p(2., 0., 0.),
        p(2., 1., 0.),
        p(1., 1., 0.),
        p(1., 2., 0.),
        p(0., 2., 0.),
    ];
    let q = p(0.3, 0.4, 0.8);
    let r1 = [p(0., 0., 0.), p(2., 0., 0.), p(2., 1., 0.), p(0., 1., 0.)];
    let r2 = [p(0., 1., 0.), p(1., 1., 0.), p(1., 2., 0.), p(0., 2., 0.)];
    let sum = sphere_view_factor(&q, &r1) + sphere_view_factor(&q, &r2);
    assert!((sphere_view_factor(&q, &l) - sum).abs() < 1e-14);
    let mut rev = l;
    rev.reverse();
    assert!((sphere_view_factor(&q, &rev) - sum).abs() < 1e-14);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha, rng_seed: proptest::test_runner::RngSeed::Fixed(0x736f6c6964), failure_persistence: None, ..ProptestConfig::default() })]
    /// Closed box from any interior point: Σ F = 1 within 1e-9.
    #[test]
    fn closed_box_sums_to_one(x in 0.01f64..0.99, y in 0.01f64..0.99, z in 0.01f64..0.99, sx in 0.5f64..8.0, sy in 0.5f64..8.0, sz in 0.5f64..4.0) {
        let q = p(x * sx, y * sy, z * sz);
        let faces = [
            [p(0., 0., 0.), p(sx, 0., 0.), p(sx, sy, 0.), p(0., sy, 0.)],
            [p(0., 0., sz), p(sx, 0., sz), p(sx, sy, sz), p(0., sy, sz)],
            [p(0., 0., 0.), p(sx, 0., 0.), p(sx, 0., sz), p(0., 0., sz)],
            [p(0., sy, 0.), p(sx, sy, 0.), p(sx, sy, sz), p(0., sy, sz)],
            [p(0., 0., 0.), p(0., sy, 0.), p(0., sy, sz), p(0., 0., sz)],
            [p(sx, 0., 0.), p(sx, sy, 0.), p(sx, sy, sz), p(sx, 0., sz)],
        ];
        let s: f64 = faces.iter().map(|f| sphere_view_factor(&q, f)).sum();
        prop_assert!((s - 1.0).abs() < 1e-9, "{}", s);
    }
}

mod plane_element {
    use mrtmap_geometry::nalgebra::{Point3, Vector3};
    use mrtmap_geometry::plane_view_factor;

    fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    /// comfort-person.md §3: element normal +z at the origin; a rectangle in the plane y = c with a
    /// corner at the foot, side a along x (parallel to the element), side b along the normal.
    #[test]
    fn perpendicular_corner_rectangles() {
        let n = Vector3::z();
        for (a, b, c, f) in [
            (1.0, 1.0, 1.0, 0.0557342),
            (2.0, 1.0, 1.0, 0.0686973),
            (1.0, 2.0, 1.0, 0.0950679),
        ] {
            let rect = [p(0.0, c, 0.0), p(a, c, 0.0), p(a, c, b), p(0.0, c, b)];
            let got = plane_view_factor(&Point3::origin(), &n, &rect);
            assert!((got - f).abs() < 1e-7, "({a}, {b}): {got}");
            // The same rectangle extended below the element: only the front half counts.
            let through = [p(0.0, c, -b), p(a, c, -b), p(a, c, b), p(0.0, c, b)];
            let got = plane_view_factor(&Point3::origin(), &n, &through);
            assert!((got - f).abs() < 1e-7, "clipped ({a}, {b}): {got}");
        }
    }

    #[test]
    fn parallel_corner_rectangles() {
        let n = Vector3::z();
        for (a, b, c, f) in [(2.0, 1.0, 1.0, 0.1673750), (3.0, 2.0, 1.5, 0.1880837)] {
            let rect = [p(0.0, 0.0, c), p(a, 0.0, c), p(a, b, c), p(0.0, b, c)];
            let got = plane_view_factor(&Point3::origin(), &n, &rect);
            assert!((got - f).abs() < 1e-7, "({a}, {b}, {c}): {got}");
            // Behind the element it sees nothing.
            let below: Vec<_> = rect.iter().map(|q| p(q.x, q.y, -q.z)).collect();
            assert_eq!(plane_view_factor(&Point3::origin(), &n, &below), 0.0);
        }
    }

    /// Cube of side 2, element at the centre facing a face: 0.5541264 to it, 0.1114684 to each side.
    #[test]
    fn cube_from_its_centre() {
        let n = Vector3::z();
        let top = [
            p(-1.0, -1.0, 1.0),
            p(1.0, -1.0, 1.0),
            p(1.0, 1.0, 1.0),
            p(-1.0, 1.0, 1.0),
        ];
        let side = [
            p(1.0, -1.0, -1.0),
            p(1.0, 1.0, -1.0),
            p(1.0, 1.0, 1.0),
            p(1.0, -1.0, 1.0),
        ];
        let o = Point3::origin();
        let ft = plane_view_factor(&o, &n, &top);
        let fs = plane_view_factor(&o, &n, &side);
        assert!((ft - 0.5541264).abs() < 1e-7, "{ft}");
        assert!((fs - 0.1114684).abs() < 1e-7, "{fs}");
        assert!(
            (ft + 4.0 * fs - 1.0).abs() < 1e-12,
            "the hemisphere is covered once"
        );
    }
}
