//! The calibration report: detected corners drawn on every image, the thermal image laid over the
//! colour image through the result (on the board's plane), and an HTML page tying them together.

use image::{Rgb, RgbImage};
use mrtmap_geometry::camera::PinholeCamera;
use mrtmap_geometry::nalgebra::{Isometry3, Point2};

use crate::board::Board;
use crate::calibrate::board_plane_point;
use crate::detect::Detection;
use crate::gray::Gray;

fn grey_rgb(g: &Gray, scale: u32) -> RgbImage {
    RgbImage::from_fn(g.width * scale, g.height * scale, |x, y| {
        let v = (g.data[((y / scale) * g.width + x / scale) as usize] * 255.0).round() as u8;
        Rgb([v, v, v])
    })
}

fn put(img: &mut RgbImage, x: i64, y: i64, c: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, c);
    }
}

fn ring(img: &mut RgbImage, cx: f64, cy: f64, r: f64, c: Rgb<u8>) {
    let steps = (r * 8.0).max(16.0) as usize;
    for k in 0..steps {
        let a = k as f64 / steps as f64 * std::f64::consts::TAU;
        put(
            img,
            (cx + r * a.cos()).round() as i64,
            (cy + r * a.sin()).round() as i64,
            c,
        );
    }
}

fn line(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), c: Rgb<u8>) {
    let n = ((b.0 - a.0).hypot(b.1 - a.1).ceil() as usize).max(1);
    for k in 0..=n {
        let t = k as f64 / n as f64;
        put(
            img,
            (a.0 + t * (b.0 - a.0)).round() as i64,
            (a.1 + t * (b.1 - a.1)).round() as i64,
            c,
        );
    }
}

/// Hue along the grid's rows, as OpenCV's drawChessboardCorners colours them.
fn row_colour(j: i32) -> Rgb<u8> {
    const C: [[u8; 3]; 6] = [
        [230, 40, 40],
        [240, 150, 20],
        [220, 220, 30],
        [40, 200, 60],
        [40, 150, 240],
        [170, 60, 230],
    ];
    let c = C[j.rem_euclid(6) as usize];
    Rgb(c)
}

/// The image (upscaled by `scale`) with the detected corners: a ring per corner coloured by row,
/// rows joined, the (0, 0) corner circled twice.
pub fn draw_corners(g: &Gray, det: Option<&Detection>, scale: u32) -> RgbImage {
    let mut img = grey_rgb(g, scale);
    let Some(det) = det else {
        return img;
    };
    let s = scale as f64;
    let at = |x: f64, y: f64| ((x + 0.5) * s - 0.5, (y + 0.5) * s - 0.5);
    let r = (0.2 * det.cell_px * s).clamp(3.0, 12.0);
    for c in &det.corners {
        if let Some(n) = det.corners.iter().find(|o| o.i == c.i + 1 && o.j == c.j) {
            line(&mut img, at(c.x, c.y), at(n.x, n.y), row_colour(c.j));
        }
    }
    for c in &det.corners {
        let (x, y) = at(c.x, c.y);
        ring(&mut img, x, y, r, row_colour(c.j));
        put(
            &mut img,
            x.round() as i64,
            y.round() as i64,
            Rgb([255, 255, 255]),
        );
        if (c.i, c.j) == (0, 0) {
            ring(&mut img, x, y, r * 1.8, Rgb([255, 255, 255]));
        }
    }
    img
}

/// The colour image with the thermal image (iron palette) laid over the board and one square
/// around it, through the board's plane: where the calibration is right, the thermal squares sit
/// on the colour squares.
#[allow(clippy::too_many_arguments)]
pub fn overlay(
    colour: &Gray,
    thermal: &Gray,
    rgb: &PinholeCamera,
    th: &PinholeCamera,
    rgb_from_board: &Isometry3<f64>,
    rgb_from_thermal: &Isometry3<f64>,
    board: &Board,
) -> RgbImage {
    let thermal_from_rgb = rgb_from_thermal.inverse();
    let board_from_rgb = rgb_from_board.inverse();
    let s = board.square_m;
    let (x1, y1) = (board.cols as f64 * s, board.rows as f64 * s);
    RgbImage::from_fn(colour.width, colour.height, |x, y| {
        let v = colour.data[(y * colour.width + x) as usize];
        let grey = [v * 255.0; 3];
        let px = Point2::new(x as f64, y as f64);
        let mixed = board_plane_point(rgb, rgb_from_board, &px).and_then(|p| {
            let b = board_from_rgb * p;
            if b.x < -s || b.y < -s || b.x > x1 || b.y > y1 {
                return None;
            }
            let q = th.project(&(thermal_from_rgb * p))?;
            th.contains(&q).then(|| {
                let t = thermal.sample(q.x, q.y);
                let c = mrtmap_io::iron(t);
                [
                    0.35 * grey[0] + 0.65 * c[0] as f32,
                    0.35 * grey[1] + 0.65 * c[1] as f32,
                    0.35 * grey[2] + 0.65 * c[2] as f32,
                ]
            })
        });
        let c = mixed.unwrap_or(grey);
        Rgb([c[0] as u8, c[1] as u8, c[2] as u8])
    })
}

/// PNG bytes of an RGB image.
pub fn png(img: &RgbImage) -> Result<Vec<u8>, mrtmap_io::EncodeError> {
    mrtmap_io::encode_png_rgb8(img.width(), img.height(), img.as_raw())
}
