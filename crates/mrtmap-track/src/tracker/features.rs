//! A colour frame's features: FAST corners spread over the image, their BRIEF descriptors and,
//! where the depth has them, their 3D points.
//!
//! 1. FAST-9 corners (imageproc) at the lower of the two thresholds, away from the image's edge.
//! 2. Non-maximum suppression over 3 × 3 pixels.
//! 3. Per grid cell the strongest few: only those at the full threshold where the cell has any
//!    (ORB-SLAM's rule), else the weaker ones.
//! 4. BRIEF-256 descriptors with fixed test pairs ([`test_pairs`]), so that results are
//!    deterministic.
//! 5. Each corner's 3D point from the depth z-buffered into the colour image: the pixel's own
//!    depth, else the nearest in its 3 × 3 neighbourhood, up to the largest depth.
//! 6. Later, once the motion over the depth frame's offset in time is predicted
//!    ([`Features::moved`]), the points are moved to the colour frame's time.

use std::collections::BTreeMap;

use imageproc::binary_descriptors::brief::{TestPair, brief};
use imageproc::corners::corners_fast9;
use imageproc::point::Point;
use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Vector3};
use mrtmap_io::depth::DepthPoints;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Cameras, TrackParams};

/// Corners nearer the image's edge than this (px) are dropped: imageproc's BRIEF refuses a corner
/// within 16 px of the edge (its 31 × 31 patch), and one pixel more keeps the 3 × 3
/// neighbourhoods of non-maximum suppression and of the depth look-up inside the image.
const BORDER_PX: u32 = 17;

/// Bits of a BRIEF descriptor (four `u64`s).
const BRIEF_BITS: usize = 256;

/// The side of BRIEF's square patch (px), imageproc's (its radius 15, plus the centre).
const BRIEF_PATCH_PX: u32 = 31;

/// The test pairs' points are drawn around this point of the patch (px), as imageproc draws its
/// own (its patch radius plus one).
const BRIEF_CENTRE_PX: f64 = 16.0;

/// Standard deviation of the test pairs' points around the centre (px): Calonder et al.'s G II,
/// as imageproc draws its own.
const BRIEF_SIGMA_PX: f64 = 6.6;

/// Seed of the fixed BRIEF test pairs (any fixed value makes results deterministic; changing it
/// changes every descriptor).
const BRIEF_SEED: u64 = 0x0b71_ef00;

/// Fixed-point steps that look a corner's depth up where its point was at the depth frame's time
/// ([`Features::moved`]).
const DEPTH_LOOKUP_STEPS: usize = 2;

/// Corners of one frame with descriptors and, where the depth has them, 3D points in the colour
/// camera's frame (see [`Features::moved`]).
#[derive(Clone, Debug, Default)]
pub(super) struct Features {
    /// Corner pixels.
    pub(super) px: Vec<Point2<f64>>,
    /// Normalised image coordinates (distortion removed).
    pub(super) norm: Vec<Point2<f64>>,
    /// BRIEF descriptors (256 bits).
    pub(super) desc: Vec<[u64; 4]>,
    /// 3D points as the depth frame gives them at the corners' pixels (no motion).
    pub(super) xyz: Vec<Option<Point3<f64>>>,
    /// The depth frame's z in the colour image (row-major), kept until the points are moved.
    pub(super) zmap: Option<std::sync::Arc<Vec<f32>>>,
    /// Depth frame time minus colour frame time (s).
    pub(super) dt: f64,
    /// The depth frame's points and normals in the colour camera's frame (every 4th pixel), for
    /// depth-only tracking where the corners do not suffice.
    pub(super) cloud: Option<std::sync::Arc<DepthPoints>>,
    /// The frame's size when it is not the rig's colour camera's (the frame is left out).
    pub(super) wrong_size: Option<(u32, u32)>,
}

impl Features {
    /// The depth cloud moved to the colour frame's time, thinned to about `n` points.
    pub(super) fn cloud_at(&self, motion: &Isometry3<f64>, n: usize) -> Option<DepthPoints> {
        let c = self.cloud.as_deref()?;
        let step = (c.points.len() / n.max(1)).max(1);
        let mut out = DepthPoints::default();
        for (p, nn) in c.points.iter().zip(&c.normals).step_by(step) {
            out.points.push(motion * p);
            out.normals.push(motion * nn);
        }
        Some(out)
    }

    /// The 3D points at the colour frame's time: `motion` is colour(t)_from_colour(t + dt), the
    /// camera's motion over the depth frame's offset. The depth image saw each surface point at
    /// another pixel than the colour image: a corner's depth is looked up where its point was
    /// at the depth frame's time (two fixed-point steps), then moved.
    pub(super) fn moved(
        &self,
        motion: &Isometry3<f64>,
        cam: &PinholeCamera,
        max_depth_m: f64,
    ) -> Vec<Option<Point3<f64>>> {
        let Some(z) = self.zmap.as_deref() else {
            return self.xyz.clone();
        };
        let (w, h) = (cam.width as i64, cam.height as i64);
        let at = |px: &Point2<f64>| -> Option<f64> {
            let (x, y) = (px.x.round() as i64, px.y.round() as i64);
            (x >= 0 && y >= 0 && x < w && y < h)
                .then(|| z[(y * w + x) as usize])
                .filter(|v| v.is_finite())
                .map(f64::from)
        };
        let back = motion.inverse();
        self.xyz
            .iter()
            .zip(&self.norm)
            .map(|(p0, n)| {
                let mut p = (*p0)?;
                let ray = Vector3::new(n.x, n.y, 1.0);
                for _ in 0..DEPTH_LOOKUP_STEPS {
                    let then = back * p;
                    let px = cam.project(&then)?;
                    let zz = at(&px)?;
                    let seen = motion * Point3::from(cam.unproject(&px) * zz);
                    p = Point3::from(ray * seen.z);
                }
                (p.z <= max_depth_m).then_some(p)
            })
            .collect()
    }
}

/// BRIEF test pairs, fixed (imageproc draws them from the OS's randomness unless given).
pub(super) fn test_pairs() -> Vec<TestPair> {
    let mut rng = ChaCha8Rng::seed_from_u64(BRIEF_SEED);
    let mut out = Vec::with_capacity(BRIEF_BITS);
    while out.len() < BRIEF_BITS {
        // Gaussian around the 31 × 31 patch's centre, σ 6.6 (Calonder et al.'s G II).
        let mut g = || {
            let (u1, u2): (f64, f64) = (rng.random_range(1e-12..1.0), rng.random::<f64>());
            BRIEF_CENTRE_PX
                + BRIEF_SIGMA_PX * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        };
        let (x0, y0, x1, y1) = (g(), g(), g(), g());
        if [x0, y0, x1, y1]
            .iter()
            .all(|v| (0.0..BRIEF_PATCH_PX as f64).contains(v))
        {
            out.push(TestPair {
                p0: Point::new(x0 as u32, y0 as u32),
                p1: Point::new(x1 as u32, y1 as u32),
            });
        }
    }
    out
}

/// Frame features from the grey image and, when there is one, the depth frame's z-buffer in the
/// colour image with its time offset (depth time minus colour time, s).
pub(super) fn features(
    grey: &image::GrayImage,
    depth: Option<(std::sync::Arc<Vec<f32>>, f64)>,
    cams: &Cameras,
    pairs: &[TestPair],
    p: &TrackParams,
) -> Features {
    let (w, h) = grey.dimensions();
    let mut corners = corners_fast9(grey, p.min_fast_threshold.min(p.fast_threshold));
    corners.retain(|c| {
        c.x >= BORDER_PX && c.y >= BORDER_PX && c.x + BORDER_PX < w && c.y + BORDER_PX < h
    });
    // Non-maximum suppression (3 × 3) and the strongest few per cell.
    let mut score = vec![0f32; (w * h) as usize];
    for c in &corners {
        score[(c.y * w + c.x) as usize] = c.score;
    }
    corners.retain(|c| {
        let s = c.score;
        (-1i32..=1).all(|dy| {
            (-1i32..=1).all(|dx| {
                let (x, y) = ((c.x as i32 + dx) as u32, (c.y as i32 + dy) as u32);
                let o = score[(y * w + x) as usize];
                o < s || (o == s && (dy, dx) >= (0, 0))
            })
        })
    });
    let cells_x = w.div_ceil(p.cell_px);
    let mut cells: BTreeMap<u32, Vec<(f32, u32, u32)>> = BTreeMap::new();
    for c in &corners {
        cells
            .entry((c.y / p.cell_px) * cells_x + c.x / p.cell_px)
            .or_default()
            .push((c.score, c.y, c.x));
    }
    let mut kept: Vec<Point<u32>> = Vec::new();
    let strong = p.fast_threshold as f32;
    for list in cells.values_mut() {
        list.sort_by(|a, b| b.0.total_cmp(&a.0).then((a.1, a.2).cmp(&(b.1, b.2))));
        // A cell with corners at the full threshold keeps only those.
        if list.first().is_some_and(|c| c.0 >= strong) {
            list.retain(|c| c.0 >= strong);
        }
        kept.extend(
            list.iter()
                .take(p.per_cell)
                .map(|&(_, y, x)| Point::new(x, y)),
        );
    }
    let Ok((desc, _)) = brief(grey, &kept, BRIEF_BITS, Some(&pairs.to_vec())) else {
        return Features::default();
    };
    let mut f = Features {
        dt: depth.as_ref().map_or(0.0, |d| d.1),
        ..Features::default()
    };
    for d in desc {
        let (x, y) = (d.corner.x, d.corner.y);
        let px = Point2::new(x as f64, y as f64);
        let ray = cams.colour.unproject(&px);
        let xyz = depth.as_ref().and_then(|(z, _)| {
            // The nearest valid depth in the 3 × 3 neighbourhood: a corner often sits on an edge.
            let mut best = f32::INFINITY;
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    let k = ((y as i32 + dy) as u32 * w + (x as i32 + dx) as u32) as usize;
                    best = best.min(z[k]);
                }
            }
            let zc = z[(y * w + x) as usize];
            // Prefer the pixel's own depth; a neighbour's only when the pixel has none.
            let zz = if zc.is_finite() { zc } else { best };
            (zz.is_finite() && (zz as f64) <= p.max_depth_m).then(|| Point3::from(ray * zz as f64))
        });
        let b = &d.bits;
        f.desc.push([
            b[0] as u64,
            (b[0] >> 64) as u64,
            b.get(1).map_or(0, |v| *v as u64),
            b.get(1).map_or(0, |v| (*v >> 64) as u64),
        ]);
        f.px.push(px);
        f.norm.push(Point2::new(ray.x, ray.y));
        f.xyz.push(xyz);
    }
    f.zmap = depth.map(|d| d.0);
    f
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn brief_pairs_are_fixed_and_inside_the_patch() {
        let a = test_pairs();
        assert_eq!(a.len(), 256);
        assert!(a == test_pairs());
        assert!(
            a.iter()
                .all(|p| p.p0.x < 31 && p.p0.y < 31 && p.p1.x < 31 && p.p1.y < 31)
        );
    }

    #[test]
    fn low_contrast_cells_take_corners_at_the_lower_threshold_and_strong_cells_only_strong_ones() {
        // 4-px blocks of random grey: ±60 levels on the left half, ±8 on the right (a dim,
        // low-contrast surface: hardly a corner reaches the full threshold of 12 there).
        let (w, h) = (256u32, 128u32);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let blocks: Vec<f64> = (0..(w / 4) * (h / 4))
            .map(|_| rng.random::<f64>() - 0.5)
            .collect();
        let grey = image::GrayImage::from_fn(w, h, |x, y| {
            let r = blocks[((y / 4) * (w / 4) + x / 4) as usize];
            // A flat band between them: no corner there sees both halves.
            let amp = match x {
                0..128 => 120.0,
                128..136 => 0.0,
                _ => 16.0,
            };
            image::Luma([(128.0 + amp * r).round() as u8])
        });
        let cam = PinholeCamera {
            width: w,
            height: h,
            fx: 200.0,
            fy: 200.0,
            cx: 127.5,
            cy: 63.5,
            distortion: Default::default(),
        };
        let cams = Cameras {
            colour: cam,
            depth: cam,
            depth_scale: 1000.0,
            colour_from_depth: Isometry3::identity(),
        };
        let pairs = test_pairs();
        let side = |f: &Features| {
            let left: Vec<_> = f.px.iter().filter(|p| p.x < 128.0).copied().collect();
            (left, f.px.len())
        };
        let strict = TrackParams {
            min_fast_threshold: 12,
            ..TrackParams::default()
        };
        let (left_strict, all_strict) = side(&features(&grey, None, &cams, &pairs, &strict));
        let (left, all) = side(&features(
            &grey,
            None,
            &cams,
            &pairs,
            &TrackParams::default(),
        ));
        // The strong half keeps exactly the corners it had; the dim half gains some.
        assert!(left_strict.len() > 50, "{}", left_strict.len());
        assert_eq!(left, left_strict);
        let (dim_strict, dim) = (all_strict - left_strict.len(), all - left.len());
        assert!(dim_strict <= 3, "dim half at 12: {dim_strict}");
        assert!(dim > 40, "dim half: {dim}");
    }
}
