//! Checkerboard inner corners in one image.
//!
//! The ChESS corner detector and grid labelling of `calib-targets` find the corners; small images
//! (a 160×120 thermal camera) are first upsampled so that a square spans enough pixels for the
//! detector's ring, then tried at smaller factors; large ones are also tried at a half … a fifth
//! of their size; a histogram-equalised copy when no scale finds the whole board; the try with
//! the most corners wins. Saddle points do not care which squares are bright, so thermal images with
//! inverted contrast need no special case. On images that were not upsampled each corner is
//! refined by the gradient-orthogonality method (as OpenCV's `cornerSubPix`); corners that
//! disagree with a homography fitted to the rest are dropped.

use calib_targets::chessboard::ChessboardParams;
use calib_targets::detect::{default_chess_config, detect_chessboard_all};
use mrtmap_geometry::nalgebra::{Matrix2, Point2, Vector2};
use serde::{Deserialize, Serialize};

use crate::gray::Gray;
use crate::zhang::{apply_homography, fit_homography};

/// One detected inner corner.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Corner {
    /// Grid column label.
    pub i: i32,
    /// Grid row label.
    pub j: i32,
    /// Pixel x (centre of the first pixel at 0).
    pub x: f64,
    /// Pixel y.
    pub y: f64,
}

/// The corners found in one image. Labels start at (0, 0) and are consistent within the image; a
/// partly visible board gets labels relative to what is visible.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Detection {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Median square side in pixels.
    pub cell_px: f64,
    /// The corners.
    pub corners: Vec<Corner>,
    /// Corners dropped as disagreeing with the others.
    pub dropped: usize,
}

impl Detection {
    /// Columns and rows spanned by the labels.
    pub fn extent(&self) -> (i32, i32) {
        let span = |f: fn(&Corner) -> i32| {
            let lo = self.corners.iter().map(f).min().unwrap_or(0);
            let hi = self.corners.iter().map(f).max().unwrap_or(-1);
            hi - lo + 1
        };
        (span(|c| c.i), span(|c| c.j))
    }
}

/// Detector settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetectOptions {
    /// Refine corners by gradient orthogonality on images large enough not to need upsampling
    /// (on upsampled low-resolution images, the ChESS detector's own sub-pixel positions measured
    /// better: 0.20 px MRE against 0.32–0.50 px on the real thermal board images).
    pub subpixel: bool,
    /// Half-width of the refinement window as a fraction of the square's side.
    pub window: f64,
    /// Fewest corners for a usable view.
    pub min_corners: usize,
}

impl Default for DetectOptions {
    fn default() -> Self {
        Self {
            subpixel: true,
            window: 0.35,
            min_corners: 12,
        }
    }
}

/// Upsampling factor so that the shorter side reaches about 480 pixels (at most 4×).
fn scale_for(img: &Gray) -> u32 {
    let short = img.width.min(img.height).max(1);
    480u32.div_ceil(short).clamp(1, 4)
}

/// The image scales the detector tries: the preferred ones, and those tried when the preferred
/// do not find the whole board. A small image is upsampled to about 480 pixels, then by every
/// smaller whole factor down to its own size; an image of 480 pixels or more is tried at its
/// size, a half and a third, then a quarter and a fifth.
fn search_factors(img: &Gray) -> (Vec<f64>, Vec<f64>) {
    let up = scale_for(img);
    if up > 1 {
        (vec![f64::from(up)], (1..up).rev().map(f64::from).collect())
    } else if img.width.min(img.height) >= 480 {
        (vec![1.0, 0.5, 1.0 / 3.0], vec![0.25, 0.2])
    } else {
        (vec![1.0], Vec::new())
    }
}

/// `base` (the image at its own size) resized by `f`: bicubic up, triangle-filtered down.
fn resized(base: &image::GrayImage, img: &Gray, f: f64) -> image::GrayImage {
    if f == 1.0 {
        return base.clone();
    }
    let (w, h) = (
        ((img.width as f64 * f).round() as u32).max(1),
        ((img.height as f64 * f).round() as u32).max(1),
    );
    let filter = if f > 1.0 {
        image::imageops::FilterType::CatmullRom
    } else {
        image::imageops::FilterType::Triangle
    };
    image::imageops::resize(base, w, h, filter)
}

/// Histogram equalisation of an 8-bit image.
fn equalise(img: &image::GrayImage) -> image::GrayImage {
    let mut hist = [0u64; 256];
    for p in img.pixels() {
        hist[p.0[0] as usize] += 1;
    }
    let n = (img.width() as u64 * img.height() as u64).max(1) as f64;
    let mut map = [0u8; 256];
    let mut acc = 0u64;
    for (k, m) in map.iter_mut().enumerate() {
        acc += hist[k];
        *m = (255.0 * acc as f64 / n).round().clamp(0.0, 255.0) as u8;
    }
    let mut out = img.clone();
    for p in out.pixels_mut() {
        p.0[0] = map[p.0[0] as usize];
    }
    out
}

/// Finds the board in the first of an image's grey `variants` (see [`Gray::variants`]), or, when
/// that misses the whole board, in a later one that finds a quarter of the board more corners;
/// returns the variant's index too.
pub fn detect_variants(
    variants: &[Gray],
    max_grid: (u32, u32),
    opts: &DetectOptions,
) -> Option<(usize, Detection)> {
    let full = (max_grid.0 * max_grid.1) as usize;
    let mut best: Option<(usize, Detection)> = None;
    for (k, g) in variants.iter().enumerate() {
        // A later reading only with a quarter of the board more (its corners are less precise
        // where the first reading works at all: ironbow's hue is not monotonic).
        if let Some(d) = detect(g, max_grid, opts)
            && best
                .as_ref()
                .is_none_or(|b| d.corners.len() > b.1.corners.len() + full.div_ceil(4))
        {
            let whole = d.corners.len() >= full;
            best = Some((k, d));
            if whole {
                break;
            }
        }
    }
    best
}

/// Finds the board's inner corners, or `None` when fewer than `opts.min_corners` are found.
/// `max_grid` (cols, rows) bounds the labels: a detection spanning more columns or rows than the
/// board has (in either orientation) keeps the window of the board's size holding most corners.
pub fn detect(img: &Gray, max_grid: (u32, u32), opts: &DetectOptions) -> Option<Detection> {
    let full = (max_grid.0 * max_grid.1) as usize;
    let base = img.to_luma8_scaled(1);
    let mut params = ChessboardParams::default();
    params.min_corner_strength = 0.0;
    // The detector's ring is a few pixels wide: a small image is upsampled so that a square spans
    // enough pixels for it; a large image is tried at its size, a half and a third (on large
    // squares of crumpled foil the ring meets the foil's own texture first). When none of these
    // finds the whole board, the search goes on: a small image at smaller factors (on a blurred
    // or noisy one a coarser factor can see the board where the finest does not), a large one at
    // a quarter and a fifth, then all of them on a histogram-equalised copy (OpenCV's
    // `CALIB_CB_NORMALIZE_IMAGE`: a board in a dim corner of a glaring scene). A later try is
    // taken only when it finds clearly more corners; a whole board ends the search.
    let (preferred, more) = search_factors(img);
    let mut found: Vec<(calib_targets::chessboard::ChessboardDetection, f64)> = Vec::new();
    let mut found_at: Vec<usize> = Vec::new();
    let equalised = equalise(&base);
    let tries = preferred
        .iter()
        .map(|f| (&base, *f))
        .chain(more.iter().map(|f| (&base, *f)))
        .chain(preferred.iter().chain(&more).map(|f| (&equalised, *f)));
    for (k, (source, f)) in tries.enumerate() {
        if k >= preferred.len() && found.iter().any(|d| d.0.corners.len() >= full) {
            break;
        }
        let im = resized(source, img, f);
        let all = detect_chessboard_all(&im, &default_chess_config(), &params);
        if let Some(d) = all.into_iter().max_by_key(|d| d.corners.len()) {
            found.push((d, f));
            found_at.push(k);
        }
    }
    // Of the preferred tries, the most corners (on a tie the one tried first); a later try only
    // when it finds a quarter of the board more (its coarser or equalised corners are less
    // precise: one more corner at a coarser factor cost a simulated rig 3 mm).
    let mut pick = 0;
    for k in 1..found.len() {
        let (n, best) = (found[k].0.corners.len(), found[pick].0.corners.len());
        let margin = if found_at[k] < preferred.len() {
            0
        } else {
            full.div_ceil(4)
        };
        if n > best + margin {
            pick = k;
        }
    }
    if found.is_empty() {
        return None;
    }
    let (best, s) = found.swap_remove(pick);
    let mut corners: Vec<Corner> = best
        .corners
        .iter()
        .map(|c| Corner {
            i: c.grid.u,
            j: c.grid.v,
            x: (c.position.x as f64 + 0.5) / s - 0.5,
            y: (c.position.y as f64 + 0.5) / s - 0.5,
        })
        .collect();
    let cell_px = best
        .cell_size
        .map(|c| c as f64 / s)
        .unwrap_or_else(|| median_neighbour_distance(&corners));
    corners = clip_to_board(corners, max_grid);
    if opts.subpixel && s <= 1.0 {
        let half = (opts.window * cell_px).clamp(1.5, 6.0);
        for c in &mut corners {
            if let Some(p) = refine_corner(img, Point2::new(c.x, c.y), half) {
                c.x = p.x;
                c.y = p.y;
            }
        }
    }
    let before = corners.len();
    let corners = drop_inconsistent(corners, cell_px);
    let dropped = before - corners.len();
    if corners.len() < opts.min_corners.max(6) {
        return None;
    }
    let (mut ci, mut cj) = (i32::MAX, i32::MAX);
    for c in &corners {
        ci = ci.min(c.i);
        cj = cj.min(c.j);
    }
    let corners: Vec<Corner> = corners
        .into_iter()
        .map(|c| Corner {
            i: c.i - ci,
            j: c.j - cj,
            ..c
        })
        .collect();
    let d = Detection {
        width: img.width,
        height: img.height,
        cell_px,
        corners,
        dropped,
    };
    let (w, h) = d.extent();
    (w >= 2 && h >= 2).then_some(d)
}

fn median_neighbour_distance(c: &[Corner]) -> f64 {
    let mut d: Vec<f64> = c
        .iter()
        .filter_map(|a| {
            c.iter()
                .find(|b| b.i == a.i + 1 && b.j == a.j)
                .map(|b| (b.x - a.x).hypot(b.y - a.y))
        })
        .collect();
    if d.is_empty() {
        return 10.0;
    }
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

/// Keeps the board-sized window (either orientation) with the most corners.
fn clip_to_board(corners: Vec<Corner>, (cols, rows): (u32, u32)) -> Vec<Corner> {
    if corners.is_empty() {
        return corners;
    }
    let (i0, i1) = (
        corners.iter().map(|c| c.i).min().unwrap_or(0),
        corners.iter().map(|c| c.i).max().unwrap_or(0),
    );
    let (j0, j1) = (
        corners.iter().map(|c| c.j).min().unwrap_or(0),
        corners.iter().map(|c| c.j).max().unwrap_or(0),
    );
    let fits = |w: i32, h: i32| i1 - i0 < w && j1 - j0 < h;
    let (c, r) = (cols as i32, rows as i32);
    if fits(c, r) || fits(r, c) {
        return corners;
    }
    let mut best: Option<(usize, i32, i32, i32, i32)> = None;
    for (w, h) in [(c, r), (r, c)] {
        for a in i0..=(i1 - w + 1).max(i0) {
            for b in j0..=(j1 - h + 1).max(j0) {
                let n = corners
                    .iter()
                    .filter(|k| k.i >= a && k.i < a + w && k.j >= b && k.j < b + h)
                    .count();
                if best.is_none_or(|x| n > x.0) {
                    best = Some((n, a, b, w, h));
                }
            }
        }
    }
    let Some((_, a, b, w, h)) = best else {
        return corners;
    };
    corners
        .into_iter()
        .filter(|k| k.i >= a && k.i < a + w && k.j >= b && k.j < b + h)
        .collect()
}

/// Drops corners more than max(1.5 px, 0.2 square) from a homography fitted to the others
/// (twice, to let a refit settle after gross outliers go).
fn drop_inconsistent(mut corners: Vec<Corner>, cell_px: f64) -> Vec<Corner> {
    let tol = (0.2 * cell_px).max(1.5);
    for _ in 0..2 {
        if corners.len() < 8 {
            return corners;
        }
        let src: Vec<Point2<f64>> = corners
            .iter()
            .map(|c| Point2::new(c.i as f64, c.j as f64))
            .collect();
        let dst: Vec<Point2<f64>> = corners.iter().map(|c| Point2::new(c.x, c.y)).collect();
        let Some(h) = fit_homography(&src, &dst) else {
            return corners;
        };
        // Lens distortion bends straight rows: the limit grows with the median residual.
        let resid: Vec<f64> = src
            .iter()
            .zip(&dst)
            .map(|(s, d)| (apply_homography(&h, s) - d).norm())
            .collect();
        let mut sorted = resid.clone();
        sorted.sort_by(f64::total_cmp);
        let med = sorted[sorted.len() / 2];
        let limit = tol.max(4.0 * med);
        let keep: Vec<bool> = resid.iter().map(|r| *r <= limit).collect();
        if keep.iter().all(|k| *k) {
            return corners;
        }
        corners = corners
            .into_iter()
            .zip(keep)
            .filter_map(|(c, k)| k.then_some(c))
            .collect();
    }
    corners
}

/// Gradient-orthogonality refinement of a saddle point (Förstner; OpenCV's `cornerSubPix`):
/// the corner q satisfies Σ w·g·gᵀ·(p − q) = 0 over a Gaussian-weighted window. `None` when the
/// window is flat or the estimate runs away.
pub fn refine_corner(img: &Gray, start: Point2<f64>, half: f64) -> Option<Point2<f64>> {
    let r = half.ceil() as i32;
    let sigma2 = half * half;
    let mut q = start;
    for _ in 0..30 {
        let mut a = Matrix2::<f64>::zeros();
        let mut b = Vector2::<f64>::zeros();
        for dy in -r..=r {
            for dx in -r..=r {
                let (px, py) = (q.x + dx as f64, q.y + dy as f64);
                let gx = (img.sample(px + 1.0, py) - img.sample(px - 1.0, py)) as f64 * 0.5;
                let gy = (img.sample(px, py + 1.0) - img.sample(px, py - 1.0)) as f64 * 0.5;
                let w = (-((dx * dx + dy * dy) as f64) / sigma2).exp();
                let g = Vector2::new(gx, gy);
                let ggt = g * g.transpose() * w;
                a += ggt;
                b += ggt * Vector2::new(px, py);
            }
        }
        if a.determinant().abs() < 1e-12 {
            return None;
        }
        let next = a.try_inverse()? * b;
        let next = Point2::new(next.x, next.y);
        let moved = (next - q).norm();
        q = next;
        if (q - start).norm() > half {
            return None;
        }
        if moved < 0.001 {
            break;
        }
    }
    Some(q)
}
