//! Voxel fusion: per voxel the mean position, a normal, the radiant (T⁴) average temperature with
//! the observation weights, its spread, and counts. Memory grows with the surface scanned, not with
//! the number of frames.

use rustc_hash::FxHashMap as HashMap;

use mrtmap_geometry::cloud::{pca_normal, voxel_key};
use mrtmap_geometry::nalgebra::{Point3, Vector3};
use mrtmap_io::ThermalCloud;
use mrtmap_physics::{RadiantAverage, Temperature};

/// What a voxel has gathered.
#[derive(Clone, Debug, Default)]
pub struct Voxel {
    pos_sum: Vector3<f64>,
    normal_sum: Vector3<f64>,
    points: u32,
    temperature: RadiantAverage,
}

/// A frame's contribution, aggregated per voxel before it is merged into the map.
#[derive(Clone, Debug, Default)]
pub struct FrameVoxels {
    map: HashMap<[i32; 3], Voxel>,
}

impl FrameVoxels {
    /// Adds a geometry point (any depth point) with its normal.
    pub fn add_point(&mut self, voxel_m: f64, p: &Point3<f64>, n: &Vector3<f64>) {
        let v = self.map.entry(voxel_key(p, voxel_m)).or_default();
        v.pos_sum += p.coords;
        v.normal_sum += n;
        v.points += 1;
    }

    /// Adds a temperature observation at a point.
    pub fn add_temperature(&mut self, voxel_m: f64, p: &Point3<f64>, t_k: f64, w: f64) {
        self.map
            .entry(voxel_key(p, voxel_m))
            .or_default()
            .temperature
            .add(Temperature::from_kelvin(t_k), w);
    }
}

/// The fused map.
#[derive(Clone, Debug)]
pub struct VoxelMap {
    voxel_m: f64,
    map: HashMap<[i32; 3], Voxel>,
}

impl VoxelMap {
    /// An empty map of `voxel_m` voxels.
    pub fn new(voxel_m: f64) -> Self {
        Self {
            voxel_m,
            map: HashMap::default(),
        }
    }

    /// Voxel size.
    pub fn voxel_m(&self) -> f64 {
        self.voxel_m
    }

    /// Number of voxels with any point.
    pub fn len(&self) -> usize {
        self.map.len()
    }

    /// Whether it is empty.
    pub fn is_empty(&self) -> bool {
        self.map.is_empty()
    }

    /// Merges a frame's contribution.
    pub fn merge(&mut self, f: FrameVoxels) {
        for (k, v) in f.map {
            let e = self.map.entry(k).or_default();
            e.pos_sum += v.pos_sum;
            e.normal_sum += v.normal_sum;
            e.points += v.points;
            e.temperature.merge(&v.temperature);
        }
    }

    /// The fused temperature (K) of the voxel holding `p`, when it has at least `min_count`
    /// observations with a spread of at most `max_spread_k`: a reference for self-calibration.
    pub fn reference_k(&self, p: &Point3<f64>, min_count: u64, max_spread_k: f64) -> Option<f64> {
        let v = self.map.get(&voxel_key(p, self.voxel_m))?;
        if v.temperature.count() < min_count
            || v.temperature.std_dev_k().is_none_or(|s| s > max_spread_k)
        {
            return None;
        }
        v.temperature.mean().map(|t| t.kelvin())
    }

    /// Centroids and averaged unit normals of voxels with at least `min_points` points, keeping
    /// one voxel in `every`³ (those whose keys are multiples of `every`): the ICP target.
    pub fn surface(&self, min_points: u32, every: i32) -> (Vec<Point3<f64>>, Vec<Vector3<f64>>) {
        let mut p = Vec::new();
        let mut n = Vec::new();
        let every = every.max(1);
        for (k, v) in &self.map {
            if v.points >= min_points
                && k.iter().all(|c| c.rem_euclid(every) == 0)
                && let Some(nn) = v.normal_sum.try_normalize(1e-9)
            {
                p.push(Point3::from(v.pos_sum / v.points as f64));
                n.push(nn);
            }
        }
        (p, n)
    }

    /// The thermal cloud: voxels with a temperature, normals refined by PCA over neighbouring
    /// voxel centroids (oriented like the averaged observation normals).
    pub fn to_cloud(&self) -> ThermalCloud {
        let vm = self.voxel_m;
        let mut cloud = ThermalCloud::default();
        let centroids: HashMap<[i32; 3], Point3<f64>> = self
            .map
            .iter()
            .filter(|(_, v)| v.points > 0)
            .map(|(k, v)| (*k, Point3::from(v.pos_sum / v.points as f64)))
            .collect();
        let mut keys: Vec<&[i32; 3]> = self.map.keys().collect();
        keys.sort_unstable();
        for k in keys {
            let v = &self.map[k];
            let Some(t) = v.temperature.mean() else {
                continue;
            };
            let pos = match centroids.get(k) {
                Some(p) => *p,
                None => Point3::from(
                    (Vector3::new(k[0] as f64, k[1] as f64, k[2] as f64) + Vector3::repeat(0.5))
                        * vm,
                ),
            };
            let mut neigh = Vec::with_capacity(27);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(c) = centroids.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                            neigh.push(*c);
                        }
                    }
                }
            }
            let avg = v
                .normal_sum
                .try_normalize(1e-9)
                .unwrap_or_else(Vector3::zeros);
            let n = match pca_normal(&neigh) {
                Some(pn) if neigh.len() >= 5 => {
                    if pn.dot(&avg) < 0.0 {
                        -pn
                    } else {
                        pn
                    }
                }
                _ => avg,
            };
            cloud.push(
                [pos.x as f32, pos.y as f32, pos.z as f32],
                [n.x as f32, n.y as f32, n.z as f32],
                t.kelvin() as f32,
                v.temperature.std_dev_k().unwrap_or(0.0) as f32,
                v.temperature.count() as u32,
            );
        }
        cloud
    }
}
