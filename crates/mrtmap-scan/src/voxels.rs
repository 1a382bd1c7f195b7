//! Voxel fusion: per voxel the mean position, a normal, the radiant (T⁴) average temperature with
//! the observation weights, its spread, and counts. Memory grows with the surface scanned, not with
//! the number of frames.

use rayon::prelude::*;
use rustc_hash::FxHashMap as HashMap;

use mrtmap_geometry::cloud::pca_normal;
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

/// A frame's contribution, aggregated per voxel before it is merged into the map. Voxels are kept
/// in a vector indexed by a hash map, and the last voxel touched is remembered: neighbouring depth
/// pixels mostly fall into the same voxel, so most points skip the hash lookup.
#[derive(Clone, Debug, Default)]
pub struct FrameVoxels {
    index: HashMap<[i32; 3], u32>,
    voxels: Vec<([i32; 3], Voxel)>,
    last: Option<([i32; 3], u32)>,
}

/// A frame's voxels split by the map's shards, ready to merge.
#[derive(Clone, Debug, Default)]
pub struct ShardedVoxels(Vec<Vec<([i32; 3], Voxel)>>);

impl FrameVoxels {
    /// An empty contribution with room for about `voxels` voxels.
    pub fn with_capacity(voxels: usize) -> Self {
        let mut index = HashMap::default();
        index.reserve(voxels);
        Self {
            index,
            voxels: Vec::with_capacity(voxels),
            last: None,
        }
    }

    /// The voxel of key `k`, created empty when new.
    fn at(&mut self, k: [i32; 3]) -> &mut Voxel {
        let i = match self.last {
            Some((lk, li)) if lk == k => li,
            _ => {
                let next = self.voxels.len() as u32;
                let i = *self.index.entry(k).or_insert(next);
                if i == next {
                    self.voxels.push((k, Voxel::default()));
                }
                self.last = Some((k, i));
                i
            }
        };
        &mut self.voxels[i as usize].1
    }

    /// Adds a geometry point (any depth point) with its normal, in the voxel of key `k`.
    pub fn add_point(&mut self, k: [i32; 3], p: &Point3<f64>, n: &Vector3<f64>) {
        let v = self.at(k);
        v.pos_sum += p.coords;
        v.normal_sum += n;
        v.points += 1;
    }

    /// Adds a temperature observation in the voxel of key `k`.
    pub fn add_temperature(&mut self, k: [i32; 3], t_k: f64, w: f64) {
        self.at(k).temperature.add(Temperature::from_kelvin(t_k), w);
    }

    /// The voxels split by the map's shards.
    pub fn into_shards(self) -> ShardedVoxels {
        let each = self.voxels.len() / SHARDS + 1;
        let mut shards: Vec<Vec<_>> = (0..SHARDS).map(|_| Vec::with_capacity(each)).collect();
        for (k, v) in self.voxels {
            shards[shard(&k)].push((k, v));
        }
        ShardedVoxels(shards)
    }
}

/// Shards of the fused map: frames are merged into the shards in parallel, each voxel's sums still
/// taken in frame order, so the result does not depend on the thread count.
const SHARDS: usize = 8;

/// The shard of a voxel key.
fn shard(k: &[i32; 3]) -> usize {
    let h = (k[0] as u32).wrapping_mul(73_856_093)
        ^ (k[1] as u32).wrapping_mul(19_349_663)
        ^ (k[2] as u32).wrapping_mul(83_492_791);
    (h >> 7) as usize % SHARDS
}

/// The fused map.
#[derive(Clone, Debug)]
pub struct VoxelMap {
    voxel_m: f64,
    shards: Vec<HashMap<[i32; 3], Voxel>>,
}

impl VoxelMap {
    /// An empty map of `voxel_m` voxels.
    pub fn new(voxel_m: f64) -> Self {
        Self {
            voxel_m,
            shards: vec![HashMap::default(); SHARDS],
        }
    }

    /// Voxel size.
    pub fn voxel_m(&self) -> f64 {
        self.voxel_m
    }

    /// Number of voxels with any point.
    pub fn len(&self) -> usize {
        self.shards.iter().map(|m| m.len()).sum()
    }

    /// Whether it is empty.
    pub fn is_empty(&self) -> bool {
        self.shards.iter().all(|m| m.is_empty())
    }

    /// Every voxel with its key, shard after shard.
    fn voxels(&self) -> impl Iterator<Item = (&[i32; 3], &Voxel)> {
        self.shards.iter().flat_map(|m| m.iter())
    }

    /// The voxel of key `k`.
    fn get(&self, k: &[i32; 3]) -> Option<&Voxel> {
        self.shards[shard(k)].get(k)
    }

    /// Merges frames' contributions, in their order.
    pub fn merge(&mut self, frames: &[ShardedVoxels]) {
        self.shards.par_iter_mut().enumerate().for_each(|(s, m)| {
            for f in frames {
                for (k, v) in &f.0[s] {
                    let e = m.entry(*k).or_default();
                    e.pos_sum += v.pos_sum;
                    e.normal_sum += v.normal_sum;
                    e.points += v.points;
                    e.temperature.merge(&v.temperature);
                }
            }
        });
    }

    /// The fused temperature (K) of the voxel of key `k`, when it has at least `min_count`
    /// observations with a spread of at most `max_spread_k`: a reference for self-calibration.
    pub fn reference_k(&self, k: [i32; 3], min_count: u64, max_spread_k: f64) -> Option<f64> {
        let v = self.get(&k)?;
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
        let every = every.max(1);
        let parts: Vec<Vec<(Point3<f64>, Vector3<f64>)>> = self
            .shards
            .par_iter()
            .map(|m| {
                m.iter()
                    .filter(|(k, v)| {
                        v.points >= min_points && k.iter().all(|c| c.rem_euclid(every) == 0)
                    })
                    .filter_map(|(_, v)| {
                        let nn = v.normal_sum.try_normalize(1e-9)?;
                        Some((Point3::from(v.pos_sum / v.points as f64), nn))
                    })
                    .collect()
            })
            .collect();
        parts.into_iter().flatten().unzip()
    }

    /// The thermal cloud: voxels with a temperature, normals refined by PCA over neighbouring
    /// voxel centroids (oriented like the averaged observation normals).
    pub fn to_cloud(&self) -> ThermalCloud {
        let vm = self.voxel_m;
        let centroid = |k: &[i32; 3]| {
            self.get(k)
                .filter(|v| v.points > 0)
                .map(|v| Point3::from(v.pos_sum / v.points as f64))
        };
        let mut keys: Vec<&[i32; 3]> = self.voxels().map(|(k, _)| k).collect();
        keys.sort_unstable();
        let voxels: Vec<_> = keys
            .par_iter()
            .filter_map(|&k| {
                let v = self.get(k)?;
                let t = v.temperature.mean()?;
                let pos = centroid(k).unwrap_or_else(|| {
                    Point3::from(
                        (Vector3::new(k[0] as f64, k[1] as f64, k[2] as f64)
                            + Vector3::repeat(0.5))
                            * vm,
                    )
                });
                let mut neigh = Vec::with_capacity(27);
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            if let Some(c) = centroid(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                                neigh.push(c);
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
                Some((pos, n, t, v))
            })
            .collect();
        let mut cloud = ThermalCloud::default();
        for (pos, n, t, v) in voxels {
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
