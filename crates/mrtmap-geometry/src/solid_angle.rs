//! Solid angles of triangles and planar polygons seen from a point (Van Oosterom & Strackee 1983).
//!
//! The view factor from a small sphere to a surface is its solid angle over 4π.

use nalgebra::{Point3, Vector3};

/// Signed solid angle (sr) of triangle ABC seen from `p`: positive when a·(b×c) > 0 with
/// a = A − p etc., i.e. when `p` lies behind the right-hand normal (B − A)×(C − A) and ABC winds
/// clockwise as seen from `p`.
///
/// tan(Ω/2) = a·(b×c) / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|), evaluated with atan2 so
/// that Ω covers the whole range (−2π, 2π).
pub fn triangle_solid_angle(
    p: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> f64 {
    let (a, b, c) = (a - p, b - p, c - p);
    let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
    let num = a.dot(&b.cross(&c));
    let den = la * lb * lc + a.dot(&b) * lc + a.dot(&c) * lb + b.dot(&c) * la;
    2.0 * num.atan2(den)
}

/// Signed solid angle (sr) of a planar polygon seen from `p`: the fan of signed triangles from the
/// first vertex, which is exact for any simple planar polygon, convex or not. Its sign follows the
/// winding as seen from `p`; the magnitude is the solid angle.
pub fn polygon_solid_angle(p: &Point3<f64>, vertices: &[Point3<f64>]) -> f64 {
    if vertices.len() < 3 {
        return 0.0;
    }
    let v0 = &vertices[0];
    vertices
        .windows(2)
        .skip(1)
        .map(|w| triangle_solid_angle(p, v0, &w[0], &w[1]))
        .sum()
}

/// View factor from a small sphere at `p` to a planar polygon: |Ω| / 4π.
pub fn sphere_view_factor(p: &Point3<f64>, vertices: &[Point3<f64>]) -> f64 {
    polygon_solid_angle(p, vertices).abs() / (4.0 * std::f64::consts::PI)
}

/// The part of a planar polygon on the side of the plane through `p` that `n` points to (the
/// half-space n·(x − p) ≥ 0), by Sutherland–Hodgman clipping.
pub fn clip_polygon_to_halfspace(
    vertices: &[Point3<f64>],
    p: &Point3<f64>,
    n: &Vector3<f64>,
) -> Vec<Point3<f64>> {
    let side = |v: &Point3<f64>| n.dot(&(v - p));
    let mut out = Vec::with_capacity(vertices.len() + 2);
    for (i, a) in vertices.iter().enumerate() {
        let b = &vertices[(i + 1) % vertices.len()];
        let (da, db) = (side(a), side(b));
        if da >= 0.0 {
            out.push(*a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            out.push(a + (b - a) * t);
        }
    }
    out
}

/// View factor from a small plane element at `p` with unit normal `n` to a planar polygon (the
/// cosine-weighted share of the element's hemisphere it covers), exact by Lambert's contour
/// integral F = (1/2π) |Σₖ θₖ n·ĝₖ| over the part of the polygon in front of the element
/// (θₖ the angle between the rays to vertices k and k + 1, ĝₖ the unit normal of their plane).
pub fn plane_view_factor(p: &Point3<f64>, n: &Vector3<f64>, vertices: &[Point3<f64>]) -> f64 {
    let front = clip_polygon_to_halfspace(vertices, p, n);
    if front.len() < 3 {
        return 0.0;
    }
    let sum: f64 = (0..front.len())
        .map(|k| {
            let a = front[k] - p;
            let b = front[(k + 1) % front.len()] - p;
            let g = a.cross(&b);
            let gn = g.norm();
            if gn < 1e-300 {
                return 0.0;
            }
            let theta = gn.atan2(a.dot(&b));
            theta * n.dot(&g) / gn
        })
        .sum();
    sum.abs() / (2.0 * std::f64::consts::PI)
}
