//! Reading a colour frame for tracking, with the depth frame nearest in time.
//!
//! 1. The colour image, decoded to grey; a frame of another size than the rig's colour camera's is
//!    returned empty and named.
//! 2. The depth frame nearest in time, within the sync tolerance.
//! 3. Its points and normals (every few pixels) carried into the colour camera's frame, for
//!    depth-only tracking.
//! 4. Its depth z-buffered into the colour image ([`depth_in_colour`]), for the corners' 3D points.
//! 5. The frame's features ([`features`](super::features::features)).

use imageproc::binary_descriptors::brief::TestPair;
use mrtmap_geometry::nalgebra::Point3;
use mrtmap_io::Recording;
use mrtmap_io::depth::{DepthSampling, RayTable, depth_points};

use super::features::{Features, features, test_pairs};
use super::{Cameras, TrackError, TrackParams};

/// The depth cloud keeps every this many pixels along a row and a column.
const CLOUD_STRIDE: u32 = 4;

/// Colour and depth are one camera (the depth used pixel for pixel) when the extrinsic between
/// them moves less than this (m) and turns less than this (rad).
const SAME_CAMERA_TOLERANCE: f64 = 1e-9;

/// Depth of the colour image's pixels: the depth frame's points moved into the colour camera and
/// z-buffered (nearest wins).
fn depth_in_colour(depth: &mrtmap_io::Image16, cams: &Cameras, rays: &RayTable) -> Vec<f32> {
    let (cw, ch) = (cams.colour.width as usize, cams.colour.height as usize);
    let mut z = vec![f32::INFINITY; cw * ch];
    let same = cams.colour == cams.depth
        && cams.colour_from_depth.translation.vector.norm() < SAME_CAMERA_TOLERANCE
        && cams.colour_from_depth.rotation.angle() < SAME_CAMERA_TOLERANCE;
    for v in 0..depth.height {
        for u in 0..depth.width {
            let raw = depth.data[(v * depth.width + u) as usize];
            if raw == 0 {
                continue;
            }
            let d = raw as f64 / cams.depth_scale;
            if same {
                z[v as usize * cw + u as usize] = d as f32;
                continue;
            }
            let p = Point3::from(rays.ray(u, v) * d);
            let q = cams.colour_from_depth * p;
            if let Some(px) = cams.colour.project(&q) {
                let (x, y) = (px.x.round(), px.y.round());
                if x >= 0.0 && y >= 0.0 && (x as usize) < cw && (y as usize) < ch {
                    let k = y as usize * cw + x as usize;
                    z[k] = z[k].min(q.z as f32);
                }
            }
        }
    }
    z
}
/// Reads a colour frame's corners with the depth frame nearest in time.
pub(super) struct FrameReader {
    params: TrackParams,
    cams: Cameras,
    pairs: Vec<TestPair>,
    rays: RayTable,
    sampling: DepthSampling,
}

impl FrameReader {
    pub(super) fn new(params: &TrackParams, cams: Cameras) -> Self {
        Self {
            params: *params,
            cams,
            pairs: test_pairs(),
            rays: RayTable::new(&cams.depth),
            sampling: DepthSampling {
                stride: CLOUD_STRIDE,
                max_m: params.max_depth_m,
                ..DepthSampling::default()
            },
        }
    }

    /// The depth frame nearest to time `t`, within the sync tolerance.
    fn nearest_depth(&self, rec: &Recording, t: f64) -> Option<usize> {
        let depth = &rec.depth;
        let k = depth.partition_point(|x| x.t < t);
        [k.checked_sub(1), (k < depth.len()).then_some(k)]
            .into_iter()
            .flatten()
            .min_by(|&a, &b| (depth[a].t - t).abs().total_cmp(&(depth[b].t - t).abs()))
            .filter(|&k| (depth[k].t - t).abs() <= self.params.sync_tolerance_s)
    }

    /// Colour frame `i`'s corners, their depth and the depth cloud (a frame of another size is
    /// returned empty with `wrong_size`).
    pub(super) fn read(&self, rec: &Recording, i: usize) -> Result<Features, TrackError> {
        let cams = &self.cams;
        let e = &rec.rgb[i];
        let path = rec.path_of(e);
        let grey = image::ImageReader::open(&path)
            .map_err(|e| mrtmap_io::FileError::io(&path, e))?
            .with_guessed_format()
            .map_err(|e| mrtmap_io::FileError::io(&path, e))?
            .decode()
            .map_err(|why| TrackError::Colour {
                path: path.display().to_string(),
                why: why.to_string(),
            })?
            .to_luma8();
        if grey.dimensions() != (cams.colour.width, cams.colour.height) {
            return Ok(Features {
                wrong_size: Some(grey.dimensions()),
                ..Features::default()
            });
        }
        let mut cloud = None;
        let depth = match self.nearest_depth(rec, e.t) {
            Some(k) => {
                let img = rec.read_depth(&rec.depth[k])?;
                let mut pts = depth_points(&img, &self.rays, cams.depth_scale, &self.sampling);
                for (p, n) in pts.points.iter_mut().zip(pts.normals.iter_mut()) {
                    *p = cams.colour_from_depth * *p;
                    *n = cams.colour_from_depth * *n;
                }
                cloud = Some(std::sync::Arc::new(pts));
                Some((
                    std::sync::Arc::new(depth_in_colour(&img, cams, &self.rays)),
                    rec.depth[k].t - e.t,
                ))
            }
            None => None,
        };
        let mut f = features(&grey, depth, cams, &self.pairs, &self.params);
        f.cloud = cloud;
        Ok(f)
    }
}
