//! Planar polygons in 3D: the plane they lie in, a 2D frame on it, and the 2D tests a radiant scene
//! needs (simplicity, containment, overlap, triangulation).

use nalgebra::{Point2, Point3, Unit, Vector3};

use crate::GeometryError;

/// Newell's normal of a polygon: perpendicular to its best-fit plane, with length twice its area,
/// oriented by the winding (right-hand rule). Robust for non-convex and slightly non-planar input.
pub fn newell_normal(vertices: &[Point3<f64>]) -> Vector3<f64> {
    let c = centroid(vertices);
    let mut n = Vector3::zeros();
    for (i, a) in vertices.iter().enumerate() {
        let b = &vertices[(i + 1) % vertices.len()];
        let (a, b) = (a - c, b - c);
        n += a.cross(&b);
    }
    n
}

/// Vertex mean.
pub fn centroid(vertices: &[Point3<f64>]) -> Point3<f64> {
    let n = vertices.len().max(1) as f64;
    let s = vertices
        .iter()
        .fold(Vector3::zeros(), |acc, p| acc + p.coords);
    Point3::from(s / n)
}

/// A plane with an orthonormal 2D frame on it: `p = origin + x·u + y·v`, `normal = u × v`.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneFrame {
    /// A point of the plane, the 2D origin.
    pub origin: Point3<f64>,
    /// First in-plane axis.
    pub u: Unit<Vector3<f64>>,
    /// Second in-plane axis.
    pub v: Unit<Vector3<f64>>,
    /// Plane normal, u × v.
    pub normal: Unit<Vector3<f64>>,
}

impl PlaneFrame {
    /// A frame with the given origin and normal, its u axis as close as possible to `u_hint`
    /// (or any perpendicular direction when the hint is parallel to the normal).
    pub fn new(origin: Point3<f64>, normal: Unit<Vector3<f64>>, u_hint: &Vector3<f64>) -> Self {
        let mut u = u_hint - normal.as_ref() * normal.dot(u_hint);
        if u.norm() < 1e-9 {
            let a = if normal.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            u = a - normal.as_ref() * normal.dot(&a);
        }
        let u = Unit::new_normalize(u);
        let v = Unit::new_normalize(normal.cross(&u));
        Self {
            origin,
            u,
            v,
            normal,
        }
    }

    /// The frame of a polygon: Newell normal (winding's right hand), origin at the vertex mean, u
    /// along the first edge. `None` for a degenerate polygon (zero area).
    pub fn of_polygon(vertices: &[Point3<f64>]) -> Option<Self> {
        if vertices.len() < 3 {
            return None;
        }
        let n = newell_normal(vertices);
        let normal = Unit::try_new(n, 1e-12)?;
        Some(Self::new(
            centroid(vertices),
            normal,
            &(vertices[1] - vertices[0]),
        ))
    }

    /// Signed distance of `p` from the plane along the normal.
    pub fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        self.normal.dot(&(p - self.origin))
    }

    /// In-plane coordinates of `p` (projected along the normal).
    pub fn to_2d(&self, p: &Point3<f64>) -> Point2<f64> {
        let d = p - self.origin;
        Point2::new(self.u.dot(&d), self.v.dot(&d))
    }

    /// The 3D point at in-plane coordinates `q`.
    pub fn to_3d(&self, q: &Point2<f64>) -> Point3<f64> {
        self.origin + self.u.as_ref() * q.x + self.v.as_ref() * q.y
    }
}

/// Largest distance of a vertex from the polygon's Newell plane (m).
pub fn planarity_deviation(vertices: &[Point3<f64>]) -> f64 {
    match PlaneFrame::of_polygon(vertices) {
        Some(f) => vertices
            .iter()
            .map(|p| f.signed_distance(p).abs())
            .fold(0.0, f64::max),
        None => 0.0,
    }
}

/// Area of a planar 3D polygon (m²).
pub fn area_3d(vertices: &[Point3<f64>]) -> f64 {
    newell_normal(vertices).norm() / 2.0
}

/// Signed area of a 2D polygon (positive counter-clockwise).
pub fn signed_area(poly: &[Point2<f64>]) -> f64 {
    let mut s = 0.0;
    for (i, a) in poly.iter().enumerate() {
        let b = &poly[(i + 1) % poly.len()];
        s += a.x * b.y - b.x * a.y;
    }
    s / 2.0
}

/// Where a point lies relative to a polygon.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Containment {
    /// Strictly inside (farther than the tolerance from every edge).
    Inside,
    /// Within the tolerance of an edge.
    Boundary,
    /// Strictly outside.
    Outside,
}

/// Distance from `q` to segment `ab`.
pub fn point_segment_distance(q: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((q - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (q - (a + ab * t)).norm()
}

/// Whether `q` lies inside `poly` (any winding, convex or not), with a boundary band of `tol`.
pub fn point_in_polygon(q: &Point2<f64>, poly: &[Point2<f64>], tol: f64) -> Containment {
    let n = poly.len();
    let mut inside = false;
    for i in 0..n {
        let a = &poly[i];
        let b = &poly[(i + 1) % n];
        if point_segment_distance(q, a, b) <= tol {
            return Containment::Boundary;
        }
        if (a.y > q.y) != (b.y > q.y) {
            let x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if q.x < x {
                inside = !inside;
            }
        }
    }
    if inside {
        Containment::Inside
    } else {
        Containment::Outside
    }
}

/// Fast inside test without a boundary band (crossing number), for hot loops.
pub fn point_in_polygon_fast(q: &Point2<f64>, poly: &[Point2<f64>]) -> bool {
    let n = poly.len();
    let mut inside = false;
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (&poly[i], &poly[j]);
        if (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y) {
            inside = !inside;
        }
        j = i;
    }
    inside
}

fn orient(a: &Point2<f64>, b: &Point2<f64>, c: &Point2<f64>) -> f64 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

/// Whether segments ab and cd cross properly: each strictly straddles the other's line by more
/// than `tol` (touching and collinear overlap are not proper crossings).
pub fn segments_cross(
    a: &Point2<f64>,
    b: &Point2<f64>,
    c: &Point2<f64>,
    d: &Point2<f64>,
    tol: f64,
) -> bool {
    let lab = (b - a).norm().max(1e-300);
    let lcd = (d - c).norm().max(1e-300);
    let d1 = orient(a, b, c) / lab;
    let d2 = orient(a, b, d) / lab;
    let d3 = orient(c, d, a) / lcd;
    let d4 = orient(c, d, b) / lcd;
    ((d1 > tol && d2 < -tol) || (d1 < -tol && d2 > tol))
        && ((d3 > tol && d4 < -tol) || (d3 < -tol && d4 > tol))
}

/// Whether closed segments ab and cd come within `tol` of each other.
pub fn segments_touch(
    a: &Point2<f64>,
    b: &Point2<f64>,
    c: &Point2<f64>,
    d: &Point2<f64>,
    tol: f64,
) -> bool {
    segments_cross(a, b, c, d, 0.0)
        || point_segment_distance(a, c, d) <= tol
        || point_segment_distance(b, c, d) <= tol
        || point_segment_distance(c, a, b) <= tol
        || point_segment_distance(d, a, b) <= tol
}

/// Why a polygon is not simple.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NotSimple {
    /// Fewer than three vertices.
    TooFewVertices,
    /// Edge `i` has (near) zero length.
    ZeroLengthEdge(usize),
    /// Edges `i` and `j` intersect (or adjacent edges fold back on each other).
    EdgesIntersect(usize, usize),
    /// The polygon encloses (near) zero area.
    ZeroArea,
}

/// Checks that a 2D polygon is simple: at least three vertices, no zero-length edge, no two edges
/// meeting except adjacent ones at their shared vertex, non-zero area. `tol` is a length.
pub fn check_simple(poly: &[Point2<f64>], tol: f64) -> Result<(), NotSimple> {
    let n = poly.len();
    if n < 3 {
        return Err(NotSimple::TooFewVertices);
    }
    for i in 0..n {
        if (poly[(i + 1) % n] - poly[i]).norm() <= tol {
            return Err(NotSimple::ZeroLengthEdge(i));
        }
    }
    for i in 0..n {
        let (a, b) = (&poly[i], &poly[(i + 1) % n]);
        for j in (i + 1)..n {
            let (c, d) = (&poly[j], &poly[(j + 1) % n]);
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            if adjacent {
                // Shared vertex: b == c (j = i+1) or a == d (wrap). Fold-back: the far end of one
                // edge lies on the other.
                let (far_ab, far_cd) = if j == i + 1 { (a, d) } else { (b, c) };
                if point_segment_distance(far_ab, c, d) <= tol
                    || point_segment_distance(far_cd, a, b) <= tol
                {
                    return Err(NotSimple::EdgesIntersect(i, j));
                }
            } else if segments_touch(a, b, c, d, tol) {
                return Err(NotSimple::EdgesIntersect(i, j));
            }
        }
    }
    if signed_area(poly).abs() <= tol * tol {
        return Err(NotSimple::ZeroArea);
    }
    Ok(())
}

/// Triangulates a simple 2D polygon (ear clipping, earcut): vertex index triples.
pub fn triangulate(poly: &[Point2<f64>]) -> Result<Vec<[usize; 3]>, GeometryError> {
    let flat: Vec<f64> = poly.iter().flat_map(|p| [p.x, p.y]).collect();
    let idx = earcutr::earcut(&flat, &[], 2).map_err(|_| GeometryError::Triangulation {
        vertices: poly.len(),
    })?;
    if idx.len() != 3 * (poly.len() - 2) {
        return Err(GeometryError::Triangulation {
            vertices: poly.len(),
        });
    }
    Ok(idx.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
}

/// Triangulates a simple 2D polygon with holes (each hole simple, inside it, the holes apart):
/// vertex index triples into the outline followed by each hole's vertices in order.
pub fn triangulate_with_holes(
    outline: &[Point2<f64>],
    holes: &[Vec<Point2<f64>>],
) -> Result<Vec<[usize; 3]>, GeometryError> {
    if holes.is_empty() {
        return triangulate(outline);
    }
    let mut flat: Vec<f64> = outline.iter().flat_map(|p| [p.x, p.y]).collect();
    let mut starts = Vec::with_capacity(holes.len());
    for h in holes {
        starts.push(flat.len() / 2);
        flat.extend(h.iter().flat_map(|p| [p.x, p.y]));
    }
    let vertices = flat.len() / 2;
    let idx = earcutr::earcut(&flat, &starts, 2)
        .map_err(|_| GeometryError::Triangulation { vertices })?;
    if idx.is_empty() || idx.len() % 3 != 0 {
        return Err(GeometryError::Triangulation { vertices });
    }
    Ok(idx.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
}

fn sample_points(poly: &[Point2<f64>]) -> Vec<Point2<f64>> {
    // Edge midpoints and triangle centroids: interior witnesses for containment and overlap.
    let n = poly.len();
    let mut pts: Vec<Point2<f64>> = (0..n)
        .map(|i| nalgebra::center(&poly[i], &poly[(i + 1) % n]))
        .collect();
    if let Ok(tris) = triangulate(poly) {
        pts.extend(tris.iter().map(|t| {
            Point2::from((poly[t[0]].coords + poly[t[1]].coords + poly[t[2]].coords) / 3.0)
        }));
    }
    pts
}

/// Whether `inner` lies inside `outer` (touching its boundary is allowed within `tol`).
pub fn polygon_inside(inner: &[Point2<f64>], outer: &[Point2<f64>], tol: f64) -> bool {
    let outside = |q: &Point2<f64>| point_in_polygon(q, outer, tol) == Containment::Outside;
    if inner.iter().any(outside) || sample_points(inner).iter().any(outside) {
        return false;
    }
    !edges_cross(inner, outer, tol)
}

fn edges_cross(a: &[Point2<f64>], b: &[Point2<f64>], tol: f64) -> bool {
    let (na, nb) = (a.len(), b.len());
    (0..na).any(|i| {
        (0..nb).any(|j| segments_cross(&a[i], &a[(i + 1) % na], &b[j], &b[(j + 1) % nb], tol))
    })
}

/// Whether the interiors of two polygons overlap (sharing only boundary within `tol` does not count).
pub fn polygons_overlap(a: &[Point2<f64>], b: &[Point2<f64>], tol: f64) -> bool {
    if edges_cross(a, b, tol) {
        return true;
    }
    let strictly_in =
        |q: &Point2<f64>, p: &[Point2<f64>]| point_in_polygon(q, p, tol) == Containment::Inside;
    a.iter()
        .chain(sample_points(a).iter())
        .any(|q| strictly_in(q, b))
        || b.iter()
            .chain(sample_points(b).iter())
            .any(|q| strictly_in(q, a))
}
