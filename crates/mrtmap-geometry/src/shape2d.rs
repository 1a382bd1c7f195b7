//! Small 2D shape tools: convex hull, minimum-area rectangle, line intersection, polygon
//! simplification, clipping.

use nalgebra::{Point2, Vector2};

/// Convex hull (Andrew's monotone chain), counter-clockwise, without collinear points.
pub fn convex_hull(points: &[Point2<f64>]) -> Vec<Point2<f64>> {
    let mut p: Vec<Point2<f64>> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>| (a - o).perp(&(b - o));
    let mut lower: Vec<Point2<f64>> = Vec::new();
    for q in &p {
        while lower.len() >= 2 && cross(&lower[lower.len() - 2], &lower[lower.len() - 1], q) <= 0.0
        {
            lower.pop();
        }
        lower.push(*q);
    }
    let mut upper: Vec<Point2<f64>> = Vec::new();
    for q in p.iter().rev() {
        while upper.len() >= 2 && cross(&upper[upper.len() - 2], &upper[upper.len() - 1], q) <= 0.0
        {
            upper.pop();
        }
        upper.push(*q);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

/// The minimum-area rectangle enclosing `points` (rotating an edge of the hull), as four corners
/// counter-clockwise, and its area.
pub fn min_area_rectangle(points: &[Point2<f64>]) -> Option<([Point2<f64>; 4], f64)> {
    let hull = convex_hull(points);
    if hull.len() < 3 {
        return None;
    }
    let mut best: Option<([Point2<f64>; 4], f64)> = None;
    for i in 0..hull.len() {
        let e = hull[(i + 1) % hull.len()] - hull[i];
        let Some(u) = e.try_normalize(1e-12) else {
            continue;
        };
        let v = Vector2::new(-u.y, u.x);
        let (mut u0, mut u1, mut v0, mut v1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for p in &hull {
            let (a, b) = (p.coords.dot(&u), p.coords.dot(&v));
            u0 = u0.min(a);
            u1 = u1.max(a);
            v0 = v0.min(b);
            v1 = v1.max(b);
        }
        let area = (u1 - u0) * (v1 - v0);
        if best.is_none_or(|b| area < b.1) {
            let c = |a: f64, b: f64| Point2::from(u * a + v * b);
            best = Some(([c(u0, v0), c(u1, v0), c(u1, v1), c(u0, v1)], area));
        }
    }
    best
}

/// Intersection of the lines through `p` along `d` and through `q` along `e`, or `None` when
/// (nearly) parallel.
pub fn line_intersection(
    p: &Point2<f64>,
    d: &Vector2<f64>,
    q: &Point2<f64>,
    e: &Vector2<f64>,
) -> Option<Point2<f64>> {
    let den = d.perp(e);
    if den.abs() < 1e-9 * d.norm() * e.norm() {
        return None;
    }
    Some(p + d * ((q - p).perp(e) / den))
}

/// Douglas–Peucker simplification of a closed polygon with tolerance `tol`.
pub fn simplify_closed(poly: &[Point2<f64>], tol: f64) -> Vec<Point2<f64>> {
    if poly.len() <= 4 {
        return poly.to_vec();
    }
    // Split at the two mutually farthest-ish vertices: 0 and the farthest from it.
    let far = (0..poly.len())
        .max_by(|&a, &b| {
            (poly[a] - poly[0])
                .norm()
                .total_cmp(&(poly[b] - poly[0]).norm())
        })
        .unwrap_or(0);
    let mut a: Vec<Point2<f64>> = poly[..=far].to_vec();
    let mut b: Vec<Point2<f64>> = poly[far..].to_vec();
    b.push(poly[0]);
    a = dp(&a, tol);
    b = dp(&b, tol);
    a.pop();
    b.pop();
    a.extend(b);
    a
}

fn dp(pts: &[Point2<f64>], tol: f64) -> Vec<Point2<f64>> {
    if pts.len() < 3 {
        return pts.to_vec();
    }
    let (a, b) = (pts[0], pts[pts.len() - 1]);
    let (k, d) = pts[1..pts.len() - 1]
        .iter()
        .enumerate()
        .map(|(k, p)| (k + 1, crate::polygon::point_segment_distance(p, &a, &b)))
        .fold((0, -1.0), |m, x| if x.1 > m.1 { x } else { m });
    if d <= tol {
        return vec![a, b];
    }
    let mut left = dp(&pts[..=k], tol);
    let right = dp(&pts[k..], tol);
    left.pop();
    left.extend(right);
    left
}

/// One Sutherland–Hodgman step: the part of polygon `p` where `side(q) ≥ 0` (`side` linear, such
/// as a signed distance to a line).
pub fn clip_half_plane(p: &[Point2<f64>], side: impl Fn(&Point2<f64>) -> f64) -> Vec<Point2<f64>> {
    let mut out = Vec::with_capacity(p.len() + 1);
    for k in 0..p.len() {
        let (c, d) = (p[k], p[(k + 1) % p.len()]);
        let (sc, sd) = (side(&c), side(&d));
        if sc >= 0.0 {
            out.push(c);
        }
        if (sc >= 0.0) != (sd >= 0.0) {
            out.push(c + (d - c) * (sc / (sc - sd)));
        }
    }
    out
}

/// Polygon `p` clipped to the convex polygon `clip` (both counter-clockwise; Sutherland–Hodgman).
pub fn clip_convex(p: &[Point2<f64>], clip: &[Point2<f64>]) -> Vec<Point2<f64>> {
    let mut out = p.to_vec();
    for i in 0..clip.len() {
        let (a, b) = (clip[i], clip[(i + 1) % clip.len()]);
        out = clip_half_plane(&out, |q| (b - a).perp(&(q - a)));
        if out.is_empty() {
            break;
        }
    }
    out
}
