//! Built-in RGB-D tracking: poses for a recording that has colour and depth but no pose source.
//!
//! ```text
//!  colour frame ─ FAST-9 corners (imageproc), spread over a grid ─ BRIEF-256 (fixed test pairs)
//!      │ depth frame nearest in time → z-buffer in the colour image → 3D of each corner
//!      │ match to the reference keyframe: guided by the constant-velocity prediction
//!      │   (or, failing that, over the whole image), mutual best with a ratio test
//!      │ RANSAC on 3D–3D triples (Kabsch), inliers by reprojection → Gauss–Newton on the
//!      │   reprojection error (Huber)                           = the frame's pose
//!      │ keyframe when the inliers thin out or the camera moved / turned enough
//!      └ loop closure: each new keyframe against older ones nearby (descriptors + RANSAC),
//!        pose graph over keyframes (tiny-solver), frames follow their keyframes
//! ```
//!
//! The depth frame was taken at its own time: its points are moved to the colour frame's time with
//! the camera's current velocity. Results are deterministic (fixed BRIEF pairs, RANSAC seeded per
//! frame) and do not depend on the number of threads (features are computed in parallel, tracking
//! is sequential).

use std::collections::BTreeMap;
use std::time::Instant;

use imageproc::binary_descriptors::brief::{TestPair, brief};
use imageproc::corners::corners_fast9;
use imageproc::point::Point;
use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::icp::kabsch;
use mrtmap_geometry::nalgebra::{
    Isometry3, Matrix6, Point2, Point3, Translation3, UnitQuaternion, Vector3, Vector6,
};
use mrtmap_io::{Recording, Trajectory};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use mrtmap_geometry::icp::{IcpParams, IcpTarget, icp_point_to_plane};

use crate::pose_graph::{Edge, optimise};
use mrtmap_io::depth::{DepthPoints, DepthSampling, RayTable, depth_points};

/// Tracking settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TrackParams {
    /// FAST-9 threshold (grey levels).
    pub fast_threshold: u8,
    /// A cell without any corner at `fast_threshold` takes its corners at this lower one
    /// (ORB-SLAM's rule: low-contrast surfaces still get corners where nothing stronger is).
    pub min_fast_threshold: u8,
    /// Corners are spread over cells of this size (px)…
    pub cell_px: u32,
    /// …keeping at most this many (the strongest) per cell.
    pub per_cell: usize,
    /// A match's Hamming distance (of 256 bits) at most this.
    pub max_hamming: u32,
    /// Lowe's ratio: best distance below this fraction of the second best.
    pub ratio: f64,
    /// Guided matching: search radius around the predicted pixel (px).
    pub search_radius_px: f64,
    /// Reprojection error of an inlier (px).
    pub inlier_px: f64,
    /// A pose needs this many inliers.
    pub min_inliers: usize,
    /// RANSAC hypotheses.
    pub ransac_iterations: usize,
    /// A new keyframe when the inliers fall below this fraction of the keyframe's corners with depth…
    pub keyframe_inlier_ratio: f64,
    /// …or the camera moved this far from it (m)…
    pub keyframe_move_m: f64,
    /// …or turned this much (degrees).
    pub keyframe_turn_deg: f64,
    /// Corners farther than this have no 3D point (the depth noise grows with z²).
    pub max_depth_m: f64,
    /// Largest time between a colour frame and its depth frame (s).
    pub sync_tolerance_s: f64,
    /// Look for loop closures.
    pub loop_closure: bool,
    /// Predict each frame's rotation from the gyro (imu.txt) where the recording has one.
    pub use_imu: bool,
    /// A loop joins keyframes at least this many keyframes apart…
    pub loop_min_separation: usize,
    /// …whose estimated positions lie within this distance (m)…
    pub loop_radius_m: f64,
    /// …with at least this many inliers.
    pub loop_min_inliers: usize,
}

impl Default for TrackParams {
    fn default() -> Self {
        Self {
            fast_threshold: 12,
            min_fast_threshold: 7,
            cell_px: 32,
            per_cell: 6,
            max_hamming: 70,
            ratio: 0.85,
            search_radius_px: 40.0,
            inlier_px: 2.5,
            min_inliers: 25,
            ransac_iterations: 200,
            keyframe_inlier_ratio: 0.35,
            keyframe_move_m: 0.4,
            keyframe_turn_deg: 20.0,
            max_depth_m: 3.5,
            sync_tolerance_s: 0.02,
            loop_closure: true,
            use_imu: true,
            loop_min_separation: 12,
            loop_radius_m: 1.5,
            loop_min_inliers: 40,
        }
    }
}

/// What tracking did.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrackReport {
    /// Colour frames.
    pub frames: usize,
    /// Frames with a pose.
    pub tracked: usize,
    /// Frames without a depth frame near enough in time.
    pub unsynced: usize,
    /// Frames whose pose could not be found (lost).
    pub lost: usize,
    /// Frames found again against an older keyframe after being lost or off the reference.
    pub relocalised: usize,
    /// Frames placed by their depth alone (too few corners matched): point-to-plane ICP on the
    /// keyframe's depth from the constant-velocity prediction.
    pub depth_only: usize,
    /// Keyframes.
    pub keyframes: usize,
    /// Loop closures tried (candidate keyframe pairs) and accepted.
    pub loops_tried: usize,
    /// Accepted loop closures.
    pub loops_accepted: usize,
    /// Gyro samples the prediction drew on (0: no imu.txt, or not used).
    #[serde(default)]
    pub gyro_samples: usize,
    /// Mean corners per frame.
    pub mean_corners: f64,
    /// Mean inliers per tracked frame.
    pub mean_inliers: f64,
    /// Mean inlier reprojection error (px).
    pub mean_reprojection_px: f64,
    /// Pose graph: weighted squared error before and after (0 without loops).
    pub graph_cost_before: f64,
    /// After.
    pub graph_cost_after: f64,
    /// Wall time (s).
    pub seconds: f64,
    /// Against the recording's true poses (groundtruth.txt), when it has them.
    pub accuracy: Option<TrajectoryError>,
    /// Colour frames left out because their size is not the rig's colour camera's (a frame of
    /// another stream or camera mode recorded among them): how many, and the first one's file
    /// and size.
    #[serde(default)]
    pub wrong_size: usize,
    /// The first wrong-size frame: its file and its width and height.
    #[serde(default)]
    pub wrong_size_first: Option<(String, u32, u32)>,
}

impl TrackReport {
    /// What the user must know: frames lost, frames left out for their size.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.lost > 0 {
            out.push(format!(
                "tracking lost {} of {} colour frames",
                self.lost, self.frames
            ));
        }
        if let Some((path, w, h)) = &self.wrong_size_first {
            out.push(format!(
                "{} colour frame(s) left out because their size is not the rig's colour camera's, the first {path} ({w}×{h}); check rig.toml's [colour] width and height or remove those frames from rgb.txt",
                self.wrong_size
            ));
        }
        out
    }
}

/// Absolute trajectory error (TUM's definition: poses associated by time, rigidly aligned).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryError {
    /// Poses compared.
    pub poses: usize,
    /// RMSE of the positions after alignment (m).
    pub ate_rmse_m: f64,
    /// Largest position error (m).
    pub ate_max_m: f64,
    /// RMSE of the orientations after the same alignment (degrees; ill-determined on a short,
    /// nearly straight trajectory, whose alignment the positions do not fix).
    pub ate_rotation_rmse_deg: f64,
    /// Relative pose error between consecutive poses (TUM's RPE at one frame): translation RMSE (m)…
    pub rpe_translation_rmse_m: f64,
    /// …and rotation RMSE (degrees).
    pub rpe_rotation_rmse_deg: f64,
    /// The span of the drift figures (s): 1 s, or the whole trajectory if shorter.
    pub drift_span_s: f64,
    /// Drift: the relative pose error over `drift_span_s`, translation RMSE (m)…
    pub drift_translation_rmse_m: f64,
    /// …and rotation RMSE (degrees).
    pub drift_rotation_rmse_deg: f64,
}

/// Why tracking could not run.
#[derive(Debug, thiserror::Error)]
pub enum TrackError {
    /// The recording has no colour stream or no colour camera in its rig.
    #[error("{0}")]
    NoColour(String),
    /// A frame could not be read.
    #[error(transparent)]
    File(#[from] mrtmap_io::FileError),
    /// A colour image could not be decoded.
    #[error("{path}: cannot read the colour image ({why}); re-export the frame as PNG or JPEG")]
    Colour {
        /// The file.
        path: String,
        /// Why.
        why: String,
    },
    /// Too few frames could be tracked.
    #[error("tracking found a pose for only {tracked} of {frames} colour frames: {why}")]
    Failed {
        /// Tracked frames.
        tracked: usize,
        /// Frames.
        frames: usize,
        /// Advice.
        why: String,
    },
}

/// Corners of one frame with descriptors and, where the depth has them, 3D points in the colour
/// camera's frame (see [`Features::moved`]).
#[derive(Clone, Debug, Default)]
struct Features {
    px: Vec<Point2<f64>>,
    /// Normalised image coordinates (distortion removed).
    norm: Vec<Point2<f64>>,
    desc: Vec<[u64; 4]>,
    /// 3D points as the depth frame gives them at the corners' pixels (no motion).
    xyz: Vec<Option<Point3<f64>>>,
    /// The depth frame's z in the colour image (row-major), kept until the points are moved.
    zmap: Option<std::sync::Arc<Vec<f32>>>,
    /// Depth frame time minus colour frame time (s).
    dt: f64,
    /// The depth frame's points and normals in the colour camera's frame (every 4th pixel), for
    /// depth-only tracking where the corners do not suffice.
    cloud: Option<std::sync::Arc<DepthPoints>>,
    /// The frame's size when it is not the rig's colour camera's (the frame is left out).
    wrong_size: Option<(u32, u32)>,
}

impl Features {
    /// The depth cloud moved to the colour frame's time, thinned to about `n` points.
    fn cloud_at(&self, motion: &Isometry3<f64>, n: usize) -> Option<DepthPoints> {
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
    fn moved(
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
                for _ in 0..2 {
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

fn hamming(a: &[u64; 4], b: &[u64; 4]) -> u32 {
    (a[0] ^ b[0]).count_ones()
        + (a[1] ^ b[1]).count_ones()
        + (a[2] ^ b[2]).count_ones()
        + (a[3] ^ b[3]).count_ones()
}

/// BRIEF test pairs, fixed (imageproc draws them from the OS's randomness unless given).
fn test_pairs() -> Vec<TestPair> {
    let mut rng = ChaCha8Rng::seed_from_u64(0x0b71_ef00);
    let mut out = Vec::with_capacity(256);
    while out.len() < 256 {
        // Gaussian around the 31 × 31 patch's centre, σ 6.6 (Calonder et al.'s G II).
        let mut g = || {
            let (u1, u2): (f64, f64) = (rng.random_range(1e-12..1.0), rng.random::<f64>());
            16.0 + 6.6 * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        };
        let (x0, y0, x1, y1) = (g(), g(), g(), g());
        if [x0, y0, x1, y1].iter().all(|v| (0.0..31.0).contains(v)) {
            out.push(TestPair {
                p0: Point::new(x0 as u32, y0 as u32),
                p1: Point::new(x1 as u32, y1 as u32),
            });
        }
    }
    out
}

/// The cameras tracking uses.
#[derive(Clone, Copy)]
struct Cameras {
    colour: PinholeCamera,
    depth: PinholeCamera,
    depth_scale: f64,
    /// p_colour = colour_from_depth · p_depth.
    colour_from_depth: Isometry3<f64>,
}

/// Depth of the colour image's pixels: the depth frame's points moved into the colour camera and
/// z-buffered (nearest wins).
fn depth_in_colour(depth: &mrtmap_io::Image16, cams: &Cameras, rays: &RayTable) -> Vec<f32> {
    let (cw, ch) = (cams.colour.width as usize, cams.colour.height as usize);
    let mut z = vec![f32::INFINITY; cw * ch];
    let same = cams.colour == cams.depth
        && cams.colour_from_depth.translation.vector.norm() < 1e-9
        && cams.colour_from_depth.rotation.angle() < 1e-9;
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

fn features(
    grey: &image::GrayImage,
    depth: Option<(std::sync::Arc<Vec<f32>>, f64)>,
    cams: &Cameras,
    pairs: &[TestPair],
    p: &TrackParams,
) -> Features {
    let (w, h) = grey.dimensions();
    const BORDER: u32 = 17;
    let mut corners = corners_fast9(grey, p.min_fast_threshold.min(p.fast_threshold));
    corners.retain(|c| c.x >= BORDER && c.y >= BORDER && c.x + BORDER < w && c.y + BORDER < h);
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
    let Ok((desc, _)) = brief(grey, &kept, 256, Some(&pairs.to_vec())) else {
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

/// Matches (reference index, current index): guided by `predicted` (current_from_reference) when
/// given, otherwise over the whole image; mutual best with a ratio test.
fn match_features(
    r: &Features,
    r_xyz: &[Option<Point3<f64>>],
    c: &Features,
    predicted: Option<&Isometry3<f64>>,
    cam: &PinholeCamera,
    p: &TrackParams,
) -> Vec<(usize, usize)> {
    let best_for = |i: usize, cands: &mut dyn Iterator<Item = usize>| -> Option<usize> {
        let (mut b, mut bd, mut sd) = (usize::MAX, u32::MAX, u32::MAX);
        for j in cands {
            let d = hamming(&r.desc[i], &c.desc[j]);
            if d < bd {
                (sd, bd, b) = (bd, d, j);
            } else if d < sd {
                sd = d;
            }
        }
        (bd <= p.max_hamming && (bd as f64) < p.ratio * sd as f64).then_some(b)
    };
    let r2 = p.search_radius_px * p.search_radius_px;
    let forward: Vec<Option<usize>> = (0..r.desc.len())
        .map(|i| match predicted {
            Some(t) => {
                let x = r_xyz[i]?;
                let px = cam.project(&(t * x))?;
                let mut near = (0..c.px.len()).filter(|&j| (c.px[j] - px).norm_squared() < r2);
                best_for(i, &mut near)
            }
            None => best_for(i, &mut (0..c.desc.len())),
        })
        .collect();
    // Mutual: the current corner's best among the reference corners that chose it.
    let mut chosen: BTreeMap<usize, (u32, usize)> = BTreeMap::new();
    for (i, j) in forward.iter().enumerate() {
        if let Some(j) = *j {
            let d = hamming(&r.desc[i], &c.desc[j]);
            let e = chosen.entry(j).or_insert((d, i));
            if d < e.0 {
                *e = (d, i);
            }
        }
    }
    chosen.into_iter().map(|(j, (_, i))| (i, j)).collect()
}

/// Reprojection residual (normalised coordinates) of reference point `x` seen at `obs` through
/// current_from_reference `t`.
fn residual(t: &Isometry3<f64>, x: &Point3<f64>, obs: &Point2<f64>) -> Option<(f64, f64)> {
    let y = t * x;
    (y.z > 1e-3).then(|| (y.x / y.z - obs.x, y.y / y.z - obs.y))
}

/// A reference point and where it was seen (normalised image coordinates).
type Projected = (Point3<f64>, Point2<f64>);

/// The Gauss–Newton normal equations of the reprojection error at `t` (Huber at `huber` in
/// normalised units), over a perturbation (ω, v) on the left of `t` (in the current camera's frame).
fn normal_equations(
    t: &Isometry3<f64>,
    pts: &[Projected],
    huber: f64,
) -> (Matrix6<f64>, Vector6<f64>) {
    let mut hmat = Matrix6::<f64>::zeros();
    let mut g = Vector6::<f64>::zeros();
    for (x, obs) in pts {
        let y = t * x;
        if y.z < 1e-3 {
            continue;
        }
        let (iz, iz2) = (1.0 / y.z, 1.0 / (y.z * y.z));
        let e = [y.x * iz - obs.x, y.y * iz - obs.y];
        let norm = (e[0] * e[0] + e[1] * e[1]).sqrt();
        let w = if norm <= huber { 1.0 } else { huber / norm };
        // d(x/z, y/z)/dY, and dY/d(ω, v) = [−[Y]×, I].
        let jp = [[iz, 0.0, -y.x * iz2], [0.0, iz, -y.y * iz2]];
        for (k, row) in jp.iter().enumerate() {
            let jy = Vector3::new(row[0], row[1], row[2]);
            let jw = y.coords.cross(&jy); // row of jy · (−[Y]×) = (Y × jy)ᵀ
            let j = Vector6::new(jw.x, jw.y, jw.z, jy.x, jy.y, jy.z);
            hmat += w * j * j.transpose();
            g += w * j * e[k];
        }
    }
    (hmat, g)
}

/// Gauss–Newton on the reprojection error (Huber at `huber` in normalised units).
fn refine(mut t: Isometry3<f64>, pts: &[Projected], huber: f64) -> Isometry3<f64> {
    for _ in 0..10 {
        let (hmat, g) = normal_equations(&t, pts, huber);
        let Some(step) = hmat.cholesky().map(|c| c.solve(&(-g))) else {
            break;
        };
        let dw = Vector3::new(step[0], step[1], step[2]);
        let dv = Vector3::new(step[3], step[4], step[5]);
        let delta =
            Isometry3::from_parts(Translation3::from(dv), UnitQuaternion::from_scaled_axis(dw));
        t = renormalised(&(delta * t));
        if dv.norm() < 1e-6 && dw.norm() < 1e-7 {
            break;
        }
    }
    t
}

/// The information of reference_from_current found by [`refine`], for the pose graph: its
/// Hessian at the solution, reordered to the graph's (translation, rotation) and scaled to a
/// nominal reprojection error of [`GRAPH_SIGMA_PX`]. The edge's residual at the truth is minus
/// the current frame's perturbation, so the Hessian carries over; a view that pins a direction
/// weakly (a distant flat wall: turning and sliding look alike) pins the graph weakly there too.
fn information(t: &Isometry3<f64>, pts: &[Projected], huber: f64, fx: f64) -> Matrix6<f64> {
    let (h, _) = normal_equations(t, pts, huber);
    // (ω, v) → (v, ω).
    let map = [3, 4, 5, 0, 1, 2];
    Matrix6::from_fn(|i, j| h[(map[i], map[j])]) * (fx / GRAPH_SIGMA_PX).powi(2)
}

/// The reprojection error (px) an edge's information is scaled to. Only the ratios between edges
/// matter to the optimum; a nominal error of a few pixels keeps the numbers moderate.
const GRAPH_SIGMA_PX: f64 = 10.0;

/// A pose found from matches.
struct Found {
    /// current_from_reference.
    pose: Isometry3<f64>,
    /// Its information for the pose graph (see [`information`]).
    information: Matrix6<f64>,
    inliers: usize,
    reprojection_px: f64,
}

/// A frame's corners as pose estimation sees them: normalised coordinates and 3D points.
#[derive(Clone, Copy)]
struct Seen<'a> {
    norm: &'a [Point2<f64>],
    xyz: &'a [Option<Point3<f64>>],
}

/// A match: the reference's 3D point, the current corner and its own 3D point.
type Observation = (Point3<f64>, Point2<f64>, Option<Point3<f64>>);

/// current_from_reference from matched corners: RANSAC on 3D–3D triples, scored by reprojection,
/// then Gauss–Newton on the inliers' reprojection errors.
fn estimate(
    r_xyz: &[Option<Point3<f64>>],
    c: Seen<'_>,
    matches: &[(usize, usize)],
    prior: Option<&Isometry3<f64>>,
    fx: f64,
    p: &TrackParams,
    seed: u64,
) -> Option<Found> {
    let obs: Vec<Observation> = matches
        .iter()
        .filter_map(|&(i, j)| Some((r_xyz[i]?, c.norm[j], c.xyz[j])))
        .collect();
    if obs.len() < p.min_inliers {
        return None;
    }
    let tol = p.inlier_px / fx;
    let count = |t: &Isometry3<f64>| -> usize {
        obs.iter()
            .filter(|(x, o, _)| residual(t, x, o).is_some_and(|(a, b)| a * a + b * b < tol * tol))
            .count()
    };
    let both: Vec<usize> = (0..obs.len()).filter(|&k| obs[k].2.is_some()).collect();
    let mut best: Option<(usize, Isometry3<f64>)> = prior.map(|t| (count(t), *t));
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    if both.len() >= 3 {
        for _ in 0..p.ransac_iterations {
            let k: [usize; 3] = std::array::from_fn(|_| both[rng.random_range(0..both.len())]);
            if k[0] == k[1] || k[1] == k[2] || k[0] == k[2] {
                continue;
            }
            let a: Vec<Point3<f64>> = k.iter().map(|&i| obs[i].0).collect();
            let b: Vec<Point3<f64>> = k.iter().filter_map(|&i| obs[i].2).collect();
            // A degenerate triple (nearly collinear or tiny) gives no pose.
            let area = (a[1] - a[0]).cross(&(a[2] - a[0])).norm();
            if area < 1e-3 {
                continue;
            }
            let Some(t) = kabsch(&a, &b) else { continue };
            let n = count(&t);
            if best.as_ref().is_none_or(|(m, _)| n > *m) {
                best = Some((n, t));
            }
        }
    }
    let (_, mut t) = best?;
    for round in 0..2 {
        let huber = if round == 0 { 2.0 * tol } else { tol };
        let inl: Vec<Projected> = obs
            .iter()
            .filter(|(x, o, _)| {
                residual(&t, x, o).is_some_and(|(a, b)| a * a + b * b < 4.0 * tol * tol)
            })
            .map(|(x, o, _)| (*x, *o))
            .collect();
        if inl.len() < p.min_inliers {
            return None;
        }
        t = refine(t, &inl, huber);
    }
    let (inl, errs): (Vec<Projected>, Vec<f64>) = obs
        .iter()
        .filter_map(|(x, o, _)| {
            let (a, b) = residual(&t, x, o)?;
            let e = (a * a + b * b).sqrt();
            (e < tol).then_some(((*x, *o), e))
        })
        .unzip();
    (inl.len() >= p.min_inliers).then(|| Found {
        pose: t,
        information: information(&t, &inl, tol, fx),
        inliers: inl.len(),
        reprojection_px: fx * errs.iter().sum::<f64>() / errs.len() as f64,
    })
}

/// A keyframe: its corners (3D at the colour frame's time) and world_from_colour.
struct Keyframe {
    feats: Features,
    xyz: Vec<Option<Point3<f64>>>,
    with_depth: usize,
    pose: Isometry3<f64>,
    /// Its depth at its colour frame's time, for depth-only tracking.
    target: Option<IcpTarget>,
}

/// The camera's velocity in its own frame: translation (m/s) and rotation (rad/s, scaled axis).
#[derive(Clone, Copy, Debug, Default)]
struct Twist {
    v: Vector3<f64>,
    w: Vector3<f64>,
}

impl Twist {
    /// From the motion `rel` (earlier_from_later) over `dt` seconds.
    fn from_motion(rel: &Isometry3<f64>, dt: f64) -> Self {
        Self {
            v: rel.translation.vector / dt,
            w: rel.rotation.scaled_axis() / dt,
        }
    }

    /// The motion over `dt` seconds (now_from_later; negative `dt`: now_from_earlier).
    fn over(&self, dt: f64) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::from(self.v * dt),
            UnitQuaternion::from_scaled_axis(self.w * dt),
        )
    }
}

/// The rig's gyro in the colour camera's frame: turns between two times, for the prediction.
struct Gyro {
    t: Vec<f64>,
    w: Vec<Vector3<f64>>,
}

impl Gyro {
    /// From `imu.txt`'s samples (depth camera frame); `None` without samples.
    fn new(imu: &[mrtmap_io::ImuSample], colour_from_depth: &Isometry3<f64>) -> Option<Self> {
        (imu.len() >= 2).then(|| Self {
            t: imu.iter().map(|m| m.t).collect(),
            w: imu
                .iter()
                .map(|m| colour_from_depth.rotation * m.gyro)
                .collect(),
        })
    }

    /// The rotation from `t0` to `t1` as earlier_from_later (the camera at `t0` from the camera
    /// at `t1`; `t1` < `t0` gives the inverse), integrating the rates held from each sample to
    /// the next; `None` when the samples do not cover the interval (a gap over 50 ms).
    fn turn(&self, t0: f64, t1: f64) -> Option<UnitQuaternion<f64>> {
        if t1 < t0 {
            return self.turn(t1, t0).map(|q| q.inverse());
        }
        let n = self.t.len();
        if self.t[0] > t0 + 0.05 || self.t[n - 1] < t1 - 0.05 {
            return None;
        }
        let mut k = self.t.partition_point(|&x| x <= t0).saturating_sub(1);
        let mut q = UnitQuaternion::identity();
        let mut at = t0;
        while at < t1 {
            let next = if k + 1 < n { self.t[k + 1].min(t1) } else { t1 };
            if next - self.t[k].max(at) > 0.05 && k + 1 < n {
                return None;
            }
            q *= UnitQuaternion::from_scaled_axis(self.w[k] * (next - at));
            at = next;
            k += 1;
            if k >= n {
                break;
            }
        }
        Some(q)
    }
}

/// The predicted motion from `t0` to `t1` (earlier_from_later): the velocity's translation and
/// rotation, the rotation from the gyro where there is one.
fn predict(velocity: &Twist, gyro: Option<&Gyro>, t0: f64, t1: f64) -> Isometry3<f64> {
    let m = velocity.over(t1 - t0);
    match gyro.and_then(|g| g.turn(t0, t1)) {
        Some(q) => Isometry3::from_parts(m.translation, q),
        None => m,
    }
}

/// The pose with its quaternion's norm restored (products of many poses drift from 1).
fn renormalised(t: &Isometry3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        t.translation,
        UnitQuaternion::new_normalize(t.rotation.into_inner()),
    )
}

fn rotation_deg(t: &Isometry3<f64>) -> f64 {
    t.rotation.angle().to_degrees()
}

/// Tracks the recording's colour frames; returns world_from_depth at the colour frames' times (the
/// first frame's depth camera is the world) and what was done.
///
/// The frames are read in parallel chunks ([`FrameReader`]) and placed one after another by a
/// [`Tracker`]: against the reference keyframe, else another keyframe (relocalisation), else by
/// depth alone; then, when loops were closed, the keyframe graph is optimised.
pub fn track(
    rec: &Recording,
    params: &TrackParams,
    progress: &dyn Fn(usize, usize),
) -> Result<(Trajectory, TrackReport), TrackError> {
    let t0 = Instant::now();
    let mut tracker = Tracker::new(rec, params)?;
    let reader = FrameReader::new(rec, params, tracker.cams);
    let n = rec.rgb.len();
    let chunk = 16;
    let mut start = 0;
    while start < n {
        let end = (start + chunk).min(n);
        let feats: Vec<Features> = (start..end)
            .into_par_iter()
            .map(|i| reader.read(i))
            .collect::<Result<_, _>>()?;
        for (i, f) in (start..end).zip(feats) {
            progress(i + 1, n);
            tracker.step(i, f);
        }
        start = end;
    }
    tracker.optimise_graph();
    tracker.finish(t0)
}

/// Reads a colour frame's corners with the depth frame nearest in time.
struct FrameReader<'a> {
    rec: &'a Recording,
    params: &'a TrackParams,
    cams: Cameras,
    pairs: Vec<TestPair>,
    depth_t: Vec<f64>,
    rays: RayTable,
    sampling: DepthSampling,
}

impl<'a> FrameReader<'a> {
    fn new(rec: &'a Recording, params: &'a TrackParams, cams: Cameras) -> Self {
        Self {
            rec,
            params,
            cams,
            pairs: test_pairs(),
            depth_t: rec.depth.iter().map(|e| e.t).collect(),
            rays: RayTable::new(&cams.depth),
            sampling: DepthSampling {
                stride: 4,
                max_m: params.max_depth_m,
                ..DepthSampling::default()
            },
        }
    }

    /// The depth frame nearest to time `t`, within the sync tolerance.
    fn nearest_depth(&self, t: f64) -> Option<usize> {
        let depth_t = &self.depth_t;
        let k = depth_t.partition_point(|&x| x < t);
        [k.checked_sub(1), (k < depth_t.len()).then_some(k)]
            .into_iter()
            .flatten()
            .min_by(|&a, &b| (depth_t[a] - t).abs().total_cmp(&(depth_t[b] - t).abs()))
            .filter(|&k| (depth_t[k] - t).abs() <= self.params.sync_tolerance_s)
    }

    /// Colour frame `i`'s corners, their depth and the depth cloud (a frame of another size is
    /// returned empty with `wrong_size`).
    fn read(&self, i: usize) -> Result<Features, TrackError> {
        let (rec, cams) = (self.rec, &self.cams);
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
        let depth = match self.nearest_depth(e.t) {
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
                    self.depth_t[k] - e.t,
                ))
            }
            None => None,
        };
        let mut f = features(&grey, depth, cams, &self.pairs, self.params);
        f.cloud = cloud;
        Ok(f)
    }
}

/// How a frame was placed.
enum Placed {
    /// Against the reference keyframe.
    Reference,
    /// Against an older keyframe (the reference was lost).
    Relocalised,
    /// By its depth alone on the reference keyframe's.
    DepthOnly,
}

/// The tracking state over the colour frames, in time order.
struct Tracker<'a> {
    rec: &'a Recording,
    params: &'a TrackParams,
    cams: Cameras,
    gyro: Option<Gyro>,
    /// world_from_colour of each tracked frame.
    poses: Vec<Option<Isometry3<f64>>>,
    /// Each tracked frame's keyframe and keyframe_from_frame, for the pose graph's correction.
    anchor: Vec<Option<(usize, Isometry3<f64>)>>,
    keyframes: Vec<Keyframe>,
    edges: Vec<Edge>,
    /// Motion per second (earlier_from_later over 1 s, body frame).
    velocity: Twist,
    /// The last tracked frame and its pose.
    last: Option<(usize, Isometry3<f64>)>,
    corners_sum: usize,
    inliers_sum: usize,
    reprojection_sum: f64,
    report: TrackReport,
}

impl<'a> Tracker<'a> {
    /// Checks that the recording can be tracked (a colour camera and frames) and sets up.
    fn new(rec: &'a Recording, params: &'a TrackParams) -> Result<Self, TrackError> {
        let Some(rgb) = rec.rig.rgb else {
            return Err(TrackError::NoColour(format!(
                "{}: the rig has no [rgb] camera; tracking needs the colour camera's intrinsics and its pose in the depth camera",
                rec.dir.join("rig.toml").display()
            )));
        };
        if rec.rgb.is_empty() {
            return Err(TrackError::NoColour(format!(
                "{}: no colour frames (rgb.txt); tracking needs them",
                rec.dir.display()
            )));
        }
        let cams = Cameras {
            colour: rgb.camera,
            depth: rec.rig.depth,
            depth_scale: rec.rig.depth_scale,
            colour_from_depth: rgb.depth_from_rgb.inverse(),
        };
        let gyro = params
            .use_imu
            .then(|| Gyro::new(&rec.imu, &cams.colour_from_depth))
            .flatten();
        let n = rec.rgb.len();
        let report = TrackReport {
            frames: n,
            gyro_samples: gyro.as_ref().map_or(0, |g| g.t.len()),
            ..TrackReport::default()
        };
        Ok(Self {
            rec,
            params,
            cams,
            gyro,
            poses: vec![None; n],
            anchor: vec![None; n],
            keyframes: Vec::new(),
            edges: Vec::new(),
            velocity: Twist::default(),
            last: None,
            corners_sum: 0,
            inliers_sum: 0,
            reprojection_sum: 0.0,
            report,
        })
    }

    /// The motion from `t0` to `t1` (earlier_from_later) the tracker expects.
    fn predict(&self, t0: f64, t1: f64) -> Isometry3<f64> {
        predict(&self.velocity, self.gyro.as_ref(), t0, t1)
    }

    /// Places colour frame `i`, and makes it a keyframe when it has moved away from its
    /// reference.
    fn step(&mut self, i: usize, f: Features) {
        if let Some((w, h)) = f.wrong_size {
            self.report.wrong_size += 1;
            let rec = self.rec;
            self.report
                .wrong_size_first
                .get_or_insert_with(|| (rec.path_of(&rec.rgb[i]).display().to_string(), w, h));
            return;
        }
        self.corners_sum += f.px.len();
        self.report.unsynced += f.zmap.is_none() as usize;
        let t_now = self.rec.rgb[i].t;
        // The depth's points at the colour frame's time: colour(t) from colour(t + dt).
        let motion = self.predict(t_now, t_now + f.dt);
        let xyz_now = f.moved(&motion, &self.cams.colour, self.params.max_depth_m);
        if self.keyframes.is_empty() {
            self.start(i, f, xyz_now, &motion);
            return;
        }
        let Some((reference, fd)) = self.locate(i, &f, &xyz_now, &motion) else {
            self.report.lost += 1;
            return;
        };
        let kf_from_frame = fd.pose.inverse();
        let world = self.keyframes[reference].pose * kf_from_frame;
        if let Some((k, p)) = self.last {
            let dt = t_now - self.rec.rgb[k].t;
            if dt > 1e-6 {
                self.velocity = Twist::from_motion(&(p.inverse() * world), dt);
            }
        }
        self.poses[i] = Some(world);
        self.anchor[i] = Some((reference, kf_from_frame));
        self.last = Some((i, world));
        self.report.tracked += 1;
        self.inliers_sum += fd.inliers;
        self.reprojection_sum += fd.reprojection_px;
        // A frame placed by depth alone (no inliers) starts a keyframe only by moving away.
        let by_depth = fd.inliers == 0;
        let kref = &self.keyframes[reference];
        let p = self.params;
        let new_kf = (!by_depth
            && (fd.inliers as f64) < p.keyframe_inlier_ratio * kref.with_depth as f64)
            || kf_from_frame.translation.vector.norm() > p.keyframe_move_m
            || rotation_deg(&kf_from_frame) > p.keyframe_turn_deg
            || reference != self.keyframes.len() - 1;
        if new_kf {
            self.add_keyframe(i, f, reference, &fd, world);
        }
    }

    /// The first frame with enough corners with depth becomes the first keyframe, at the origin.
    fn start(
        &mut self,
        i: usize,
        f: Features,
        xyz_now: Vec<Option<Point3<f64>>>,
        motion: &Isometry3<f64>,
    ) {
        let with_depth = xyz_now.iter().flatten().count();
        if with_depth < self.params.min_inliers {
            // Nothing to start from yet (no depth, or too few corners with depth).
            self.report.lost += 1;
            return;
        }
        self.poses[i] = Some(Isometry3::identity());
        self.anchor[i] = Some((0, Isometry3::identity()));
        let target = f
            .cloud_at(motion, 20_000)
            .map(|c| IcpTarget::new(c.points, c.normals));
        self.keyframes.push(Keyframe {
            feats: Features {
                zmap: None,
                cloud: None,
                ..f
            },
            xyz: xyz_now,
            with_depth,
            pose: Isometry3::identity(),
            target,
        });
        self.last = Some((i, Isometry3::identity()));
        self.report.tracked += 1;
    }

    /// Frame `i`'s pose against a keyframe (keyframe_from... as [`Found`]) and that keyframe:
    /// the reference, guided by the prediction, else over the image; else another keyframe,
    /// newest first; else the depth alone. `None`: lost.
    fn locate(
        &mut self,
        i: usize,
        f: &Features,
        xyz_now: &[Option<Point3<f64>>],
        motion: &Isometry3<f64>,
    ) -> Option<(usize, Found)> {
        let (p, cams, kfs) = (self.params, &self.cams, &self.keyframes);
        let t_now = self.rec.rgb[i].t;
        let newest = kfs.len() - 1;
        let kf = &kfs[newest];
        let predicted_world = self
            .last
            .map(|(k, pose)| pose * self.predict(self.rec.rgb[k].t, t_now));
        let predicted = predicted_world.map(|w| w.inverse() * kf.pose);
        let seen = Seen {
            norm: &f.norm,
            xyz: xyz_now,
        };
        // The pose against keyframe `k`: guided by `guess` when given, else over the image.
        let against = |k: &Keyframe, guess: Option<&Isometry3<f64>>| {
            let m = match_features(&k.feats, &k.xyz, f, guess, &cams.colour, p);
            estimate(&k.xyz, seen, &m, guess, cams.colour.fx, p, i as u64)
        };
        let placed = predicted
            .as_ref()
            .and_then(|pr| against(kf, Some(pr)))
            .or_else(|| against(kf, None))
            .map(|fd| (newest, fd, Placed::Reference))
            .or_else(|| {
                // Lost against the reference: try the other keyframes, newest first. An older
                // keyframe's pose carries the drift since it was made: a frame placed on it is a
                // loop closure and needs a loop's evidence.
                kfs.iter().enumerate().rev().skip(1).find_map(|(k, other)| {
                    against(other, None)
                        .filter(|fd| fd.inliers >= p.loop_min_inliers)
                        .map(|fd| (k, fd, Placed::Relocalised))
                })
            })
            .or_else(|| {
                // No corners to follow (a close-up of a plain surface, motion blur): the depth
                // alone, registered on the reference keyframe's from the prediction.
                predicted
                    .as_ref()
                    .and_then(|pr| depth_only(kf, f, motion, pr))
                    .map(|fd| (newest, fd, Placed::DepthOnly))
            });
        let (k, fd, how) = placed?;
        match how {
            Placed::Reference => {}
            Placed::Relocalised => self.report.relocalised += 1,
            Placed::DepthOnly => self.report.depth_only += 1,
        }
        Some((k, fd))
    }

    /// Frame `i`, placed at `world` on keyframe `reference` by `fd`, becomes a keyframe (when
    /// its depth allows), linked to its reference, and loops are closed.
    fn add_keyframe(
        &mut self,
        i: usize,
        f: Features,
        reference: usize,
        fd: &Found,
        world: Isometry3<f64>,
    ) {
        let t_now = self.rec.rgb[i].t;
        // The motion model now holds this frame's velocity: move its depth again.
        let motion = self.predict(t_now, t_now + f.dt);
        let xyz = f.moved(&motion, &self.cams.colour, self.params.max_depth_m);
        let with_depth = xyz.iter().flatten().count();
        let target = f
            .cloud_at(&motion, 20_000)
            .map(|c| IcpTarget::new(c.points, c.normals));
        if with_depth < self.params.min_inliers && target.as_ref().is_none_or(|t| t.len() < 500) {
            return;
        }
        let id = self.keyframes.len();
        self.edges.push(Edge {
            from: reference as i64,
            to: id as i64,
            measured: fd.pose.inverse(),
            information: fd.information,
        });
        self.anchor[i] = Some((id, Isometry3::identity()));
        self.keyframes.push(Keyframe {
            feats: Features {
                zmap: None,
                cloud: None,
                ..f
            },
            xyz,
            with_depth,
            pose: world,
            target,
        });
        if self.params.loop_closure {
            close_loops(
                &mut self.keyframes,
                &mut self.edges,
                &self.cams,
                self.params,
                &mut self.report,
            );
        }
    }

    /// The pose graph over the keyframes, when loops were closed; every frame follows its
    /// keyframe.
    fn optimise_graph(&mut self) {
        if self.report.loops_accepted == 0 {
            return;
        }
        let initial: BTreeMap<i64, Isometry3<f64>> = self
            .keyframes
            .iter()
            .enumerate()
            .map(|(k, kf)| (k as i64, kf.pose))
            .collect();
        let Ok(opt) = optimise(&initial, &self.edges) else {
            return;
        };
        self.report.graph_cost_before = opt.cost_before;
        self.report.graph_cost_after = opt.cost_after;
        for (k, kf) in self.keyframes.iter_mut().enumerate() {
            if let Some(p) = opt.poses.get(&(k as i64)) {
                kf.pose = *p;
            }
        }
        for (pose, a) in self.poses.iter_mut().zip(&self.anchor) {
            if let (Some(p), Some((k, rel))) = (pose.as_mut(), a) {
                *p = self.keyframes[*k].pose * rel;
            }
        }
    }

    /// The trajectory of the depth camera (the first tracked frame's is the world) and the
    /// report; an error when too few frames were tracked.
    fn finish(mut self, t0: Instant) -> Result<(Trajectory, TrackReport), TrackError> {
        let n = self.rec.rgb.len();
        let report = &mut self.report;
        report.keyframes = self.keyframes.len();
        report.mean_corners = self.corners_sum as f64 / n.max(1) as f64;
        report.mean_inliers = self.inliers_sum as f64 / report.tracked.max(1) as f64;
        report.mean_reprojection_px = self.reprojection_sum / report.tracked.max(1) as f64;
        let mut traj = Trajectory::default();
        for (i, p) in self.poses.iter().enumerate() {
            if let Some(p) = p {
                traj.stamps.push(self.rec.rgb[i].t);
                // world_from_depth = world_from_colour · colour_from_depth.
                traj.poses
                    .push(renormalised(&(p * self.cams.colour_from_depth)));
            }
        }
        // The first tracked frame's depth camera is the world.
        if let Some(first) = traj.poses.first().copied() {
            let inv = first.inverse();
            for p in &mut traj.poses {
                *p = renormalised(&(inv * *p));
            }
        }
        report.seconds = t0.elapsed().as_secs_f64();
        if let Some(gt) = &self.rec.groundtruth {
            report.accuracy = trajectory_error(&traj, gt);
        }
        if report.tracked < 2 || report.tracked * 2 < n {
            return Err(TrackError::Failed {
                tracked: report.tracked,
                frames: n,
                why: "too few corners or matches (a textureless view, motion blur, or colour and depth out of step); scan more slowly over textured surfaces, or record poses".into(),
            });
        }
        Ok((traj, self.report))
    }
}

/// A depth-only link's information in the units of [`information`]: as a weakly matched visual
/// link (about 8 mm and 0.17° at the nominal error; the median visual link of a simulated walk is
/// pinned to about 4.5 mm and 0.09° there).
fn depth_only_information() -> Matrix6<f64> {
    let (st, sr) = (0.008, 0.17f64.to_radians());
    let d = 1.0 / (st * st);
    let r = 1.0 / (sr * sr);
    Matrix6::from_diagonal(&Vector6::new(d, d, d, r, r, r))
}

/// current_from_keyframe by point-to-plane ICP of the frame's depth on the keyframe's, from the
/// prediction; `None` when the fit is poor or leaves a direction unconstrained.
fn depth_only(
    kf: &Keyframe,
    f: &Features,
    motion: &Isometry3<f64>,
    predicted: &Isometry3<f64>,
) -> Option<Found> {
    let target = kf.target.as_ref()?;
    let src = f.cloud_at(motion, 2_000)?;
    if src.points.len() < 300 {
        return None;
    }
    let icp = IcpParams {
        max_correspondence_m: 0.08,
        max_iterations: 30,
        converged_translation_m: 1e-4,
        converged_rotation_rad: 1e-4,
        ..IcpParams::default()
    };
    // ICP gives keyframe_from_frame; the prediction is frame_from_keyframe.
    let reg = icp_point_to_plane(&src.points, target, &predicted.inverse(), &icp);
    // Far from the prediction is a wrong minimum (a wall slid along a wall), not a fast camera.
    let moved = predicted * reg.target_from_source;
    let near = moved.translation.vector.norm() < 0.05 && rotation_deg(&moved) < 3.0;
    (near && reg.fitness >= 0.7 && reg.inlier_plane_rmse_m <= 0.015 && reg.degenerate_dofs == 0)
        .then(|| Found {
            pose: reg.target_from_source.inverse(),
            information: depth_only_information(),
            inliers: 0,
            reprojection_px: 0.0,
        })
}

/// Tries to join the newest keyframe to older ones nearby; adds accepted loops as edges.
fn close_loops(
    kfs: &mut [Keyframe],
    edges: &mut Vec<Edge>,
    cams: &Cameras,
    p: &TrackParams,
    report: &mut TrackReport,
) {
    let Some((new, older)) = kfs.split_last() else {
        return;
    };
    let id = older.len();
    if id < p.loop_min_separation {
        return;
    }
    // Candidates: far enough back in the sequence, near in space and looking the same way.
    let mut cands: Vec<(f64, usize)> = older[..id - p.loop_min_separation]
        .iter()
        .enumerate()
        .filter_map(|(k, o)| {
            let rel = o.pose.inverse() * new.pose;
            let d = rel.translation.vector.norm();
            (d < p.loop_radius_m && rotation_deg(&rel) < 35.0).then_some((d, k))
        })
        .collect();
    cands.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(_, k) in cands.iter().take(2) {
        report.loops_tried += 1;
        let o = &older[k];
        let m = match_features(&o.feats, &o.xyz, &new.feats, None, &cams.colour, p);
        let Some(fd) = estimate(
            &o.xyz,
            Seen {
                norm: &new.feats.norm,
                xyz: &new.xyz,
            },
            &m,
            None,
            cams.colour.fx,
            p,
            0x100 + id as u64,
        ) else {
            continue;
        };
        if fd.inliers < p.loop_min_inliers {
            continue;
        }
        report.loops_accepted += 1;
        edges.push(Edge {
            from: k as i64,
            to: id as i64,
            measured: fd.pose.inverse(),
            information: fd.information,
        });
    }
}

/// Each estimated pose with the true pose interpolated at its time: (time, estimated, true).
fn paired(est: &Trajectory, truth: &Trajectory) -> Vec<(f64, Isometry3<f64>, Isometry3<f64>)> {
    let limits = mrtmap_io::InterpolationLimits::default();
    est.stamps
        .iter()
        .zip(&est.poses)
        .filter_map(|(&t, p)| Some((t, *p, truth.interpolate(t, &limits)?)))
        .collect()
}

/// The rigid transform (Horn/Kabsch on the positions) that carries the pairs' estimated poses
/// onto the true ones; `None` below three pairs.
fn align_pairs(pairs: &[(f64, Isometry3<f64>, Isometry3<f64>)]) -> Option<Isometry3<f64>> {
    if pairs.len() < 3 {
        return None;
    }
    let (a, b): (Vec<Point3<f64>>, Vec<Point3<f64>>) = pairs
        .iter()
        .map(|(_, p, q)| {
            (
                Point3::from(p.translation.vector),
                Point3::from(q.translation.vector),
            )
        })
        .unzip();
    kabsch(&a, &b)
}

/// truth_world_from_est_world: the rigid transform (Horn/Kabsch on the positions, poses paired by
/// time) that carries an estimated trajectory onto the true one; `None` below three pairs.
pub fn align(est: &Trajectory, truth: &Trajectory) -> Option<Isometry3<f64>> {
    align_pairs(&paired(est, truth))
}

/// `est` carried into `reference`'s world frame by [`align`] (a re-tracked recording keeps the
/// frame its references and points are given in); `None` below three poses paired in time.
pub fn expressed_in(est: &Trajectory, reference: &Trajectory) -> Option<Trajectory> {
    let w = align(est, reference)?;
    Some(Trajectory {
        stamps: est.stamps.clone(),
        poses: est.poses.iter().map(|p| renormalised(&(w * p))).collect(),
    })
}

/// TUM's absolute trajectory error: each estimated pose against the true pose interpolated at its
/// time, after the rigid alignment (Horn) that minimises the position errors.
pub fn trajectory_error(est: &Trajectory, truth: &Trajectory) -> Option<TrajectoryError> {
    let pairs = paired(est, truth);
    let align = align_pairs(&pairs)?;
    let (mut se, mut max, mut sr) = (0.0, 0.0f64, 0.0);
    for (_, p, q) in &pairs {
        let a = align * p;
        let e = (a.translation.vector - q.translation.vector).norm();
        se += e * e;
        max = max.max(e);
        sr += (a.rotation.inverse() * q.rotation)
            .angle()
            .to_degrees()
            .powi(2);
    }
    let n = pairs.len() as f64;
    // Relative pose errors between pose k and the first pose at least `span` seconds later.
    let rpe = |span: f64| -> (f64, f64) {
        let (mut st, mut sr, mut m) = (0.0, 0.0, 0usize);
        let mut j = 0;
        for k in 0..pairs.len() {
            j = j.max(k + 1);
            while j < pairs.len() && pairs[j].0 - pairs[k].0 < span - 1e-9 {
                j += 1;
            }
            if j >= pairs.len() {
                break;
            }
            let de = pairs[k].1.inverse() * pairs[j].1;
            let dg = pairs[k].2.inverse() * pairs[j].2;
            let e = dg.inverse() * de;
            st += e.translation.vector.norm_squared();
            sr += e.rotation.angle().to_degrees().powi(2);
            m += 1;
        }
        let m = m.max(1) as f64;
        ((st / m).sqrt(), (sr / m).sqrt())
    };
    let (rt, rr) = rpe(0.0);
    let span = (pairs[pairs.len() - 1].0 - pairs[0].0).min(1.0);
    let (dt, dr) = rpe(span);
    Some(TrajectoryError {
        poses: pairs.len(),
        ate_rmse_m: (se / n).sqrt(),
        ate_max_m: max,
        ate_rotation_rmse_deg: (sr / n).sqrt(),
        rpe_translation_rmse_m: rt,
        rpe_rotation_rmse_deg: rr,
        drift_span_s: span,
        drift_translation_rmse_m: dt,
        drift_rotation_rmse_deg: dr,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn pose(t: [f64; 3], axis_angle: [f64; 3]) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(t[0], t[1], t[2]),
            UnitQuaternion::from_scaled_axis(Vector3::from(axis_angle)),
        )
    }

    #[test]
    fn a_distant_flat_view_pins_turning_against_sliding_weakly() {
        // Corners on a 40°-wide patch of a wall, seen exactly; with a second wall nearer.
        let grid = |z: f64| -> Vec<Projected> {
            let mut v = Vec::new();
            for i in -6..=6 {
                for j in -4..=4 {
                    let x = Point3::new(i as f64 * 0.06 * z, j as f64 * 0.06 * z, z);
                    v.push((x, Point2::new(x.x / x.z, x.y / x.z)));
                }
            }
            v
        };
        let id = Isometry3::identity();
        // (t, θ) order: sliding right by 3 m·θ while turning by −θ about y keeps a wall at 3 m
        // nearly in place.
        let coupled = Vector6::new(1.0, 0.0, 0.0, 0.0, -1.0 / 3.0, 0.0).normalize();
        let slide = Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let ratio = |info: &Matrix6<f64>| {
            (coupled.transpose() * info * coupled)[0] / (slide.transpose() * info * slide)[0]
        };
        let flat = information(&id, &grid(3.0), 1.0, 600.0);
        let mut deep_pts = grid(3.0);
        deep_pts.extend(grid(1.0));
        let deep = information(&id, &deep_pts, 1.0, 600.0);
        assert!((flat - flat.transpose()).norm() < 1e-6 * flat.norm() && flat.cholesky().is_some());
        assert!(ratio(&flat) < 0.05, "flat wall: {}", ratio(&flat));
        assert!(
            ratio(&deep) > 5.0 * ratio(&flat),
            "deep {} flat {}",
            ratio(&deep),
            ratio(&flat)
        );
        // Nearer points pin the translation harder (as 1/z²).
        let near = information(&id, &grid(1.0), 1.0, 600.0);
        let r = near[(0, 0)] / flat[(0, 0)];
        assert!(
            (r - 9.0).abs() < 0.5,
            "near/far translation information {r}"
        );
    }

    #[test]
    fn a_twist_gives_back_the_motion_it_came_from_and_scales_with_time() {
        let rel = pose([0.02, 0.0, -0.01], [0.0, 0.012, 0.003]);
        let v = Twist::from_motion(&rel, 1.0 / 30.0);
        let back = v.over(1.0 / 30.0);
        assert!((back.translation.vector - rel.translation.vector).norm() < 1e-12);
        assert!((back.rotation.inverse() * rel.rotation).angle() < 1e-12);
        let half = v.over(0.5 / 30.0);
        assert!((half.rotation.angle() - rel.rotation.angle() / 2.0).abs() < 1e-12);
        // Backwards in time: the inverse motion (to first order in the rotation: 0.3 mm here).
        let before = v.over(-1.0 / 30.0) * back;
        assert!(before.translation.vector.norm() < 5e-4 && before.rotation.angle() < 1e-9);
    }

    #[test]
    fn the_trajectory_error_ignores_the_world_frame_and_sees_a_bent_path() {
        let truth = Trajectory {
            stamps: (0..40).map(|k| k as f64 * 0.1).collect(),
            poses: (0..40)
                .map(|k| {
                    let s = k as f64 * 0.1;
                    pose([s, (s * 2.0).sin(), 0.3 * s], [0.0, 0.0, 0.2 * s])
                })
                .collect(),
        };
        // The same path in another world frame: no error.
        let w = pose([1.0, 2.0, -0.5], [0.2, 0.1, 1.0]);
        let moved = Trajectory {
            stamps: truth.stamps.clone(),
            poses: truth.poses.iter().map(|p| w * p).collect(),
        };
        let e = trajectory_error(&moved, &truth).unwrap();
        assert_eq!(e.poses, 40);
        // Carried back into the truth's frame: the truth.
        let back = expressed_in(&moved, &truth).unwrap();
        assert!(back.poses.iter().zip(&truth.poses).all(|(a, b)| {
            (a.translation.vector - b.translation.vector).norm() < 1e-9
                && a.rotation.angle_to(&b.rotation) < 1e-9
        }));
        assert!(
            e.ate_rmse_m < 1e-9 && e.rpe_translation_rmse_m < 1e-9,
            "{e:?}"
        );
        assert!(e.ate_rotation_rmse_deg < 1e-6, "{e:?}");
        assert!(e.drift_rotation_rmse_deg < 1e-6, "{e:?}");
        assert!((e.drift_span_s - 1.0).abs() < 1e-9);
        // A path that drifts 1 cm per pose along x: seen by the ATE and by the relative errors.
        let drifted = Trajectory {
            stamps: truth.stamps.clone(),
            poses: truth
                .poses
                .iter()
                .enumerate()
                .map(|(k, p)| pose([0.01 * k as f64, 0.0, 0.0], [0.0, 0.0, 0.0]) * p)
                .collect(),
        };
        let e = trajectory_error(&drifted, &truth).unwrap();
        assert!(e.ate_rmse_m > 0.005, "{e:?}");
        assert!((e.drift_translation_rmse_m - 0.1).abs() < 0.02, "{e:?}");
    }

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

    #[test]
    fn the_gyro_turn_integrates_the_rates_and_refuses_a_gap() {
        // 0.5 rad/s about y, then about x after t = 1 s; 200 Hz, a gap from 1.5 to 1.6 s.
        let imu: Vec<mrtmap_io::ImuSample> = (0..400)
            .map(|k| k as f64 * 0.005)
            .filter(|t| !(1.5..1.6).contains(t))
            .map(|t| mrtmap_io::ImuSample {
                t,
                gyro: if t < 1.0 {
                    Vector3::new(0.0, 0.5, 0.0)
                } else {
                    Vector3::new(0.5, 0.0, 0.0)
                },
                accel: Vector3::new(0.0, -9.81, 0.0),
            })
            .collect();
        let g = Gyro::new(&imu, &Isometry3::identity()).unwrap();
        let q = g.turn(0.2, 0.6).unwrap();
        let want = UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.2, 0.0));
        assert!(q.angle_to(&want) < 1e-9, "{q:?}");
        // Backwards: the inverse; across the change of axis: y then x.
        assert!(g.turn(0.6, 0.2).unwrap().angle_to(&want.inverse()) < 1e-9);
        let both = UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.05, 0.0))
            * UnitQuaternion::from_scaled_axis(Vector3::new(0.05, 0.0, 0.0));
        assert!(g.turn(0.9, 1.1).unwrap().angle_to(&both) < 1e-9);
        assert!(g.turn(1.4, 1.7).is_none(), "a 100 ms gap");
        assert!(g.turn(2.5, 2.6).is_none(), "beyond the samples");
        // In the colour camera's frame: a camera turned 90° about z sees the y rate about x.
        let turned = Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2)),
        );
        let g = Gyro::new(&imu, &turned).unwrap();
        let q = g.turn(0.2, 0.6).unwrap();
        let want = UnitQuaternion::from_scaled_axis(Vector3::new(-0.2, 0.0, 0.0));
        assert!(q.angle_to(&want) < 1e-9, "{q:?}");
    }
}
