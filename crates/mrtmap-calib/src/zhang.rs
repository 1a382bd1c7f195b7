//! Closed-form starting values: plane-to-image homographies (normalised DLT), focal lengths from
//! the homographies with the principal point at the image centre (as OpenCV initialises), and each
//! view's board pose.

use mrtmap_geometry::nalgebra::{
    DMatrix, Isometry3, Matrix3, Point2, Rotation3, Translation3, UnitQuaternion, Vector3,
};

/// Hartley normalisation: centroid to the origin, mean distance √2.
fn normaliser(p: &[Point2<f64>]) -> Matrix3<f64> {
    let n = p.len().max(1) as f64;
    let c = p
        .iter()
        .fold(Vector3::zeros(), |a, q| a + Vector3::new(q.x, q.y, 0.0))
        / n;
    let d = p.iter().map(|q| (q.x - c.x).hypot(q.y - c.y)).sum::<f64>() / n;
    let s = if d > 1e-12 { 2f64.sqrt() / d } else { 1.0 };
    Matrix3::new(s, 0.0, -s * c.x, 0.0, s, -s * c.y, 0.0, 0.0, 1.0)
}

/// Maps a point through a homography.
pub fn apply_homography(h: &Matrix3<f64>, p: &Point2<f64>) -> Point2<f64> {
    let v = h * Vector3::new(p.x, p.y, 1.0);
    Point2::new(v.x / v.z, v.y / v.z)
}

/// The homography taking `src` to `dst` (least squares, normalised DLT); `None` for fewer than
/// four points or a degenerate (collinear) set.
pub fn fit_homography(src: &[Point2<f64>], dst: &[Point2<f64>]) -> Option<Matrix3<f64>> {
    if src.len() < 4 || src.len() != dst.len() {
        return None;
    }
    let (ts, td) = (normaliser(src), normaliser(dst));
    let mut a = DMatrix::<f64>::zeros(2 * src.len(), 9);
    for (k, (s, d)) in src.iter().zip(dst).enumerate() {
        let s = apply_homography(&ts, s);
        let d = apply_homography(&td, d);
        let r = 2 * k;
        let row0 = [s.x, s.y, 1.0, 0.0, 0.0, 0.0, -d.x * s.x, -d.x * s.y, -d.x];
        let row1 = [0.0, 0.0, 0.0, s.x, s.y, 1.0, -d.y * s.x, -d.y * s.y, -d.y];
        for c in 0..9 {
            a[(r, c)] = row0[c];
            a[(r + 1, c)] = row1[c];
        }
    }
    let ata = a.transpose() * &a;
    let eig = ata.symmetric_eigen();
    let (imin, _) = eig
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))?;
    let v = eig.eigenvectors.column(imin);
    let hn = Matrix3::new(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]);
    let h = td.try_inverse()? * hn * ts;
    let h = h / h[(2, 2)];
    h.iter().all(|x| x.is_finite()).then_some(h)
}

/// Focal lengths from plane homographies (board metres → pixels) with the principal point at
/// (cx, cy): each view's two constraints (orthogonal, equal-length rotation columns) solved by
/// least squares for 1/fx², 1/fy². `None` when the views do not constrain them (fronto-parallel
/// boards only).
pub fn init_focal(homographies: &[Matrix3<f64>], cx: f64, cy: f64) -> Option<(f64, f64)> {
    let mut ata = mrtmap_geometry::nalgebra::Matrix2::<f64>::zeros();
    let mut atb = mrtmap_geometry::nalgebra::Vector2::<f64>::zeros();
    for h in homographies {
        let t = Matrix3::new(1.0, 0.0, -cx, 0.0, 1.0, -cy, 0.0, 0.0, 1.0);
        let h = t * h;
        let h1: Vector3<f64> = h.column(0).into();
        let h2: Vector3<f64> = h.column(1).into();
        let d1 = (h1.normalize() + h2.normalize()) * 0.5;
        let d2 = (h1.normalize() - h2.normalize()) * 0.5;
        let (a, b) = (h1.normalize(), h2.normalize());
        for (u, v) in [(a, b), (d1.normalize(), d2.normalize())] {
            let row = mrtmap_geometry::nalgebra::Vector2::new(u.x * v.x, u.y * v.y);
            let rhs = -u.z * v.z;
            ata += row * row.transpose();
            atb += row * rhs;
        }
    }
    let f = ata.try_inverse()? * atb;
    if f.x <= 0.0 || f.y <= 0.0 || !f.x.is_finite() || !f.y.is_finite() {
        return None;
    }
    Some(((1.0 / f.x).sqrt(), (1.0 / f.y).sqrt()))
}

/// The board's pose in the camera (camera_from_board) from a homography H = K [r1 r2 t].
pub fn pose_from_homography(h: &Matrix3<f64>, k: &Matrix3<f64>) -> Option<Isometry3<f64>> {
    let m = k.try_inverse()? * h;
    let (m1, m2, m3): (Vector3<f64>, Vector3<f64>, Vector3<f64>) =
        (m.column(0).into(), m.column(1).into(), m.column(2).into());
    let mut lambda = 2.0 / (m1.norm() + m2.norm());
    if m3.z * lambda < 0.0 {
        lambda = -lambda;
    }
    let r1 = m1 * lambda;
    let r2 = m2 * lambda;
    let r3 = r1.cross(&r2);
    let r = Matrix3::from_columns(&[r1, r2, r3]);
    let svd = r.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut rot = u * vt;
    if rot.determinant() < 0.0 {
        rot = -rot;
    }
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(rot));
    let t = m3 * lambda;
    Some(Isometry3::from_parts(Translation3::from(t), q))
}
