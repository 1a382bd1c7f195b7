//! 16-bit single-channel images (depth, radiometric thermal, instance masks) and colour images.

use std::path::Path;

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder, ImageReader};

use crate::error::{EncodeError, FileError, FileErrorKind};

/// A 16-bit single-channel image, row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image16 {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Pixels, row-major.
    pub data: Vec<u16>,
}

impl Image16 {
    /// A zero image.
    pub fn zeros(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            data: vec![0; (width * height) as usize],
        }
    }

    /// The pixel at (u, v).
    pub fn get(&self, u: u32, v: u32) -> u16 {
        self.data[(v * self.width + u) as usize]
    }

    /// Checks the size against the rig's.
    pub fn check_size(&self, path: &Path, width: u32, height: u32) -> Result<(), FileError> {
        if (self.width, self.height) != (width, height) {
            return Err(FileError::new(
                path,
                None,
                FileErrorKind::ImageSize {
                    width: self.width,
                    height: self.height,
                    expected_width: width,
                    expected_height: height,
                },
            ));
        }
        Ok(())
    }
}

/// Reads a 16-bit single-channel PNG or TIFF. 8-bit or colour images are an error.
pub fn read_image16(path: &Path) -> Result<Image16, FileError> {
    let img = ImageReader::open(path)
        .map_err(|e| FileError::io(path, e))?
        .with_guessed_format()
        .map_err(|e| FileError::io(path, e))?
        .decode()
        .map_err(|e| {
            FileError::new(
                path,
                None,
                FileErrorKind::Image(format!("cannot decode the image: {e}")),
            )
        })?;
    match img {
        image::DynamicImage::ImageLuma16(b) => {
            let (w, h) = b.dimensions();
            Ok(Image16 {
                width: w,
                height: h,
                data: b.into_raw(),
            })
        }
        other => Err(FileError::new(
            path,
            None,
            FileErrorKind::Image(format!(
                "expected a 16-bit single-channel image, found {:?}",
                other.color()
            )),
        )),
    }
}

fn encode_png(
    data: &[u8],
    width: u32,
    height: u32,
    colour: ExtendedColorType,
) -> Result<Vec<u8>, EncodeError> {
    let mut out = Vec::new();
    let enc = PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive);
    enc.write_image(data, width, height, colour)
        .map_err(|source| EncodeError {
            width,
            height,
            source,
        })?;
    Ok(out)
}

/// Encodes a 16-bit single-channel PNG (fast compression).
pub fn encode_png16(img: &Image16) -> Result<Vec<u8>, EncodeError> {
    // image 0.25 takes 16-bit samples in native byte order and writes PNG's big-endian itself.
    let mut bytes = Vec::with_capacity(2 * img.data.len());
    for v in &img.data {
        bytes.extend_from_slice(&v.to_ne_bytes());
    }
    encode_png(&bytes, img.width, img.height, ExtendedColorType::L16)
}

/// Encodes an 8-bit RGB PNG (fast compression).
pub fn encode_png_rgb8(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, EncodeError> {
    encode_png(rgb, width, height, ExtendedColorType::Rgb8)
}

/// Separable Gaussian blur of a row-major image with edge clamping (σ in pixels; σ ≤ 0 copies).
pub fn gaussian_blur(src: &[f64], w: usize, h: usize, sigma: f64) -> Vec<f64> {
    if sigma <= 0.0 || !sigma.is_finite() {
        return src.to_vec();
    }
    let r = (3.0 * sigma).ceil() as isize;
    let kernel: Vec<f64> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f64 = kernel.iter().sum();
    let kernel: Vec<f64> = kernel.iter().map(|k| k / sum).collect();
    let pass = |src: &[f64], horizontal: bool| -> Vec<f64> {
        let mut out = vec![0.0; src.len()];
        for y in 0..h {
            for x in 0..w {
                let mut acc = 0.0;
                for (ki, kv) in kernel.iter().enumerate() {
                    let o = ki as isize - r;
                    let (xx, yy) = if horizontal {
                        ((x as isize + o).clamp(0, w as isize - 1) as usize, y)
                    } else {
                        (x, (y as isize + o).clamp(0, h as isize - 1) as usize)
                    };
                    acc += kv * src[yy * w + xx];
                }
                out[y * w + x] = acc;
            }
        }
        out
    };
    pass(&pass(src, true), false)
}
