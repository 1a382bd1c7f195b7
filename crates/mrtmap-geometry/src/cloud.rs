//! Point-cloud basics: voxel downsampling and normals from neighbours.

use rustc_hash::FxHashMap;

use nalgebra::{Matrix3, Point3, Vector3};

/// The integer voxel of a point.
pub fn voxel_key(p: &Point3<f64>, voxel_m: f64) -> [i32; 3] {
    [
        (p.x / voxel_m).floor() as i32,
        (p.y / voxel_m).floor() as i32,
        (p.z / voxel_m).floor() as i32,
    ]
}

/// Downsamples to one point per voxel: the mean of the points in it (as Open3D's
/// `voxel_down_sample`), in order of first occurrence. Voxels are aligned to the world origin; see
/// [`voxel_downsample_from`] for another grid origin.
pub fn voxel_downsample(points: &[Point3<f64>], voxel_m: f64) -> Vec<Point3<f64>> {
    voxel_downsample_from(points, voxel_m, &Point3::origin())
}

/// [`voxel_downsample`] with voxels aligned to `origin` (Open3D aligns them to the cloud's minimum
/// bound minus half a voxel).
pub fn voxel_downsample_from(
    points: &[Point3<f64>],
    voxel_m: f64,
    origin: &Point3<f64>,
) -> Vec<Point3<f64>> {
    let mut index: FxHashMap<[i32; 3], usize> = FxHashMap::default();
    let mut sums: Vec<(Vector3<f64>, u32)> = Vec::new();
    for p in points {
        let k = voxel_key(&Point3::from(p - origin), voxel_m);
        let i = *index.entry(k).or_insert_with(|| {
            sums.push((Vector3::zeros(), 0));
            sums.len() - 1
        });
        sums[i].0 += p.coords;
        sums[i].1 += 1;
    }
    sums.into_iter()
        .map(|(s, n)| Point3::from(s / n as f64))
        .collect()
}

/// The centroid of points and their scatter matrix Σ (p − c)(p − c)ᵀ (the covariance times the
/// count), the input of every PCA fit here.
pub fn centroid_and_scatter(points: &[Point3<f64>]) -> (Point3<f64>, Matrix3<f64>) {
    let c = points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / points.len().max(1) as f64;
    let mut scatter = Matrix3::zeros();
    for p in points {
        let d = p.coords - c;
        scatter += d * d.transpose();
    }
    (Point3::from(c), scatter)
}

/// Unit normal of a set of points by PCA (the eigenvector of the smallest eigenvalue of their
/// covariance), or `None` for fewer than 3 points or no plane. The sign is arbitrary.
pub fn pca_normal(points: &[Point3<f64>]) -> Option<Vector3<f64>> {
    if points.len() < 3 {
        return None;
    }
    let (_, scatter) = centroid_and_scatter(points);
    let eig = nalgebra::SymmetricEigen::new(scatter);
    let (k, _) = eig
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    let n = eig.eigenvectors.column(k).into_owned();
    (n.norm() > 0.5).then(|| n.normalize())
}
