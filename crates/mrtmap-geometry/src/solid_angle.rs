//! Solid angles of triangles and planar polygons seen from a point (Van Oosterom & Strackee 1983).
//!
//! The view factor from a small sphere to a surface is its solid angle over 4π.

use nalgebra::Point3;

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
