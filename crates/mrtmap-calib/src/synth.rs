//! Synthetic calibration pairs with exact truth: a heated checkerboard (black polyethylene squares
//! hot, aluminium-foil squares reflecting a cooler room, so the thermal contrast is the colour
//! image's inverted) rendered by a distorted colour camera and a distorted 160×120 thermal camera
//! (supersampled, blurred, with noise), at random poses, some partly out of the thermal view.

use image::RgbImage;
use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use mrtmap_geometry::nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use mrtmap_io::{Image16, ThermalEncoding, gaussian_blur};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::board::Board;

/// The true rig.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SynthRig {
    /// Colour camera.
    pub rgb: PinholeCamera,
    /// Thermal camera.
    pub thermal: PinholeCamera,
    /// p_in_rgb = rgb_from_thermal · p_in_thermal.
    pub rgb_from_thermal: Isometry3<f64>,
}

impl Default for SynthRig {
    /// A RealSense-like colour camera and a Lepton-3.5-like thermal camera 45 mm to its side,
    /// turned by about 2°.
    fn default() -> Self {
        let mut rgb = PinholeCamera::new(640, 480, 612.0, 610.0, 322.5, 238.0);
        rgb.distortion = BrownConrady::from_array([0.09, -0.18, 0.0012, -0.0008, 0.0]);
        let mut thermal = PinholeCamera::new(160, 120, 146.0, 145.2, 81.3, 58.4);
        thermal.distortion = BrownConrady::from_array([-0.28, 0.12, 0.001, 0.0015, 0.0]);
        let rgb_from_thermal = Isometry3::from_parts(
            Translation3::new(0.045, -0.012, 0.004),
            UnitQuaternion::from_euler_angles(0.012, -0.03, 0.006),
        );
        Self {
            rgb,
            thermal,
            rgb_from_thermal,
        }
    }
}

/// What to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SynthOptions {
    /// The board.
    pub board: Board,
    /// Number of pairs.
    pub pairs: usize,
    /// Of those, how many show the board only partly in the thermal image.
    pub partial: usize,
    /// Thermal blur (Gaussian σ, thermal pixels).
    pub thermal_blur_px: f64,
    /// Thermal noise (K, standard deviation).
    pub thermal_noise_k: f64,
    /// Random seed.
    pub seed: u64,
}

impl Default for SynthOptions {
    fn default() -> Self {
        Self {
            board: Board {
                cols: 8,
                rows: 6,
                square_m: 0.06,
            },
            pairs: 20,
            partial: 3,
            thermal_blur_px: 0.7,
            thermal_noise_k: 0.05,
            seed: 7,
        }
    }
}

/// One rendered pair and its truth.
pub struct SynthPair {
    /// Colour image.
    pub rgb: RgbImage,
    /// Thermal image, centikelvin.
    pub thermal: Image16,
    /// rgb_from_board.
    pub rgb_from_board: Isometry3<f64>,
}

/// The board's "material" at a point of its plane: Some(true) black polyethylene, Some(false)
/// foil, None off the squares (the board's margin within half a square, else background).
fn material(board: &Board, x: f64, y: f64) -> Surface {
    let s = board.square_m;
    let (a, b) = ((x / s).floor() as i64 + 1, (y / s).floor() as i64 + 1);
    let inside = a >= 0 && b >= 0 && a <= board.cols as i64 && b <= board.rows as i64;
    if inside {
        return if (a + b) % 2 == 0 {
            Surface::Black
        } else {
            Surface::Foil
        };
    }
    let m = 0.5 * s;
    let on_board =
        x > -s - m && y > -s - m && x < board.cols as f64 * s + m && y < board.rows as f64 * s + m;
    if on_board {
        Surface::Margin
    } else {
        Surface::Background
    }
}

#[derive(Clone, Copy)]
enum Surface {
    Black,
    Foil,
    Margin,
    Background,
}

/// Rays (z = 1) of a camera's supersampled pixels, `n`×`n` per pixel.
fn rays(cam: &PinholeCamera, n: u32) -> Vec<Vector3<f64>> {
    let mut out = Vec::with_capacity((cam.width * cam.height * n * n) as usize);
    for v in 0..cam.height {
        for u in 0..cam.width {
            for sy in 0..n {
                for sx in 0..n {
                    let px = mrtmap_geometry::nalgebra::Point2::new(
                        u as f64 - 0.5 + (sx as f64 + 0.5) / n as f64,
                        v as f64 - 0.5 + (sy as f64 + 0.5) / n as f64,
                    );
                    out.push(cam.unproject(&px));
                }
            }
        }
    }
    out
}

/// Renders, per pixel, the mean of `value` over the supersampled rays.
fn render<F: Fn(Surface) -> f64>(
    cam: &PinholeCamera,
    rays: &[Vector3<f64>],
    n: u32,
    cam_from_board: &Isometry3<f64>,
    board: &Board,
    value: F,
) -> Vec<f64> {
    let inv = cam_from_board.inverse();
    let o = inv * Point3::origin();
    let per = (n * n) as usize;
    (0..(cam.width * cam.height) as usize)
        .map(|p| {
            let mut acc = 0.0;
            for r in &rays[p * per..(p + 1) * per] {
                let d = inv * r;
                let s = -o.z / d.z;
                let surf = if s > 0.0 {
                    material(board, o.x + s * d.x, o.y + s * d.y)
                } else {
                    Surface::Background
                };
                acc += value(surf);
            }
            acc / per as f64
        })
        .collect()
}

/// Random board poses (rgb_from_board): 0.65–1.25 m away, tilted up to 35°, rolled up to 25°
/// (one in four a quarter turn further), the first `partial` pushed partly out of the thermal view
/// (and maybe the colour view).
pub fn board_poses(rig: &SynthRig, o: &SynthOptions) -> Vec<Isometry3<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(o.seed);
    let b = &o.board;
    let centre = Vector3::new(
        (b.cols - 1) as f64 * b.square_m / 2.0,
        (b.rows - 1) as f64 * b.square_m / 2.0,
        0.0,
    );
    let thermal_from_rgb = rig.rgb_from_thermal.inverse();
    let mut out = Vec::new();
    let mut tries = 0;
    while out.len() < o.pairs && tries < 100_000 {
        tries += 1;
        let partial = out.len() < o.partial;
        let z = rng.random_range(0.65..1.25);
        let spread = if partial { 0.45 } else { 0.12 };
        let (x, y) = (
            rng.random_range(-spread..spread) * z,
            rng.random_range(-spread..spread) * z * 0.75,
        );
        let mut roll = rng.random_range(-0.45..0.45);
        if rng.random_range(0..4) == 0 {
            roll += std::f64::consts::FRAC_PI_2;
        }
        let rot = UnitQuaternion::from_euler_angles(
            rng.random_range(-0.6..0.6),
            rng.random_range(-0.6..0.6),
            roll,
        );
        let pose = Isometry3::from_parts(Translation3::new(x, y, z), rot)
            * Isometry3::translation(-centre.x, -centre.y, 0.0);
        let corners: Vec<Point3<f64>> = (0..b.rows as i32)
            .flat_map(|j| (0..b.cols as i32).map(move |i| (i, j)))
            .map(|(i, j)| b.point(i, j))
            .collect();
        let inside = |cam: &PinholeCamera, p: &Isometry3<f64>, margin: f64| {
            corners
                .iter()
                .filter(|c| {
                    cam.project(&(p * *c)).is_some_and(|px| {
                        px.x > margin
                            && px.y > margin
                            && px.x < cam.width as f64 - 1.0 - margin
                            && px.y < cam.height as f64 - 1.0 - margin
                    })
                })
                .count()
        };
        let n = corners.len();
        let in_rgb = inside(&rig.rgb, &pose, 12.0);
        let in_th = inside(&rig.thermal, &(thermal_from_rgb * pose), 4.0);
        let ok = if partial {
            in_rgb >= n / 3 && in_th >= n / 3 && in_th <= n * 3 / 4
        } else {
            in_rgb == n && in_th == n
        };
        if ok {
            out.push(pose);
        }
    }
    out
}

/// Renders the pairs of [`board_poses`].
pub fn render_pairs(rig: &SynthRig, o: &SynthOptions) -> Vec<SynthPair> {
    use rayon::prelude::*;
    let poses = board_poses(rig, o);
    let (nr, nt) = (2, 4);
    let rgb_rays = rays(&rig.rgb, nr);
    let th_rays = rays(&rig.thermal, nt);
    let thermal_from_rgb = rig.rgb_from_thermal.inverse();
    poses
        .par_iter()
        .enumerate()
        .map(|(k, pose)| {
            let mut rng =
                ChaCha8Rng::seed_from_u64(o.seed.wrapping_mul(1000).wrapping_add(k as u64));
            let grey = render(&rig.rgb, &rgb_rays, nr, pose, &o.board, |s| match s {
                Surface::Black => 28.0,
                Surface::Foil | Surface::Margin => 205.0,
                Surface::Background => 120.0,
            });
            let (w, h) = (rig.rgb.width as usize, rig.rgb.height as usize);
            let grey = gaussian_blur(&grey, w, h, 0.5);
            let cn = Normal::new(0.0, 1.5).unwrap_or_else(|_| unreachable!());
            let rgb = RgbImage::from_fn(rig.rgb.width, rig.rgb.height, |x, y| {
                let g = grey[y as usize * w + x as usize] + cn.sample(&mut rng);
                let c = |f: f64| (g * f).round().clamp(0.0, 255.0) as u8;
                image::Rgb([c(1.0), c(0.97), c(0.92)])
            });
            let kelvin = render(
                &rig.thermal,
                &th_rays,
                nt,
                &(thermal_from_rgb * pose),
                &o.board,
                |s| match s {
                    Surface::Black => 318.0,
                    Surface::Foil => 299.0,
                    Surface::Margin => 305.0,
                    Surface::Background => 296.5,
                },
            );
            let (tw, th) = (rig.thermal.width as usize, rig.thermal.height as usize);
            let kelvin = gaussian_blur(&kelvin, tw, th, o.thermal_blur_px);
            let tn =
                Normal::new(0.0, o.thermal_noise_k.max(0.0)).unwrap_or_else(|_| unreachable!());
            let thermal = Image16 {
                width: rig.thermal.width,
                height: rig.thermal.height,
                data: kelvin
                    .iter()
                    .map(|k| ThermalEncoding::Centikelvin.raw(k + tn.sample(&mut rng)))
                    .collect(),
            };
            SynthPair {
                rgb,
                thermal,
                rgb_from_board: *pose,
            }
        })
        .collect()
}
