//! Calibration images as grey levels in [0, 1], from 8-bit grey or colour, or 16-bit radiometric
//! (stretched between its 0.5th and 99.5th percentiles).

use std::path::Path;

use image::{DynamicImage, GrayImage, ImageReader};

use crate::CalibError;

/// A grey image, row-major, values in [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct Gray {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Pixels.
    pub data: Vec<f32>,
}

impl Gray {
    /// A constant image.
    pub fn new(width: u32, height: u32, value: f32) -> Self {
        Self {
            width,
            height,
            data: vec![value; (width * height) as usize],
        }
    }

    /// The pixel at (x, y), clamped to the border.
    pub fn at(&self, x: i64, y: i64) -> f32 {
        let x = x.clamp(0, self.width as i64 - 1) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        self.data[y * self.width as usize + x]
    }

    /// Bilinear sample at (x, y), pixel centres at integers.
    pub fn sample(&self, x: f64, y: f64) -> f32 {
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let a = self.at(x0, y0) * (1.0 - fx) + self.at(x0 + 1, y0) * fx;
        let b = self.at(x0, y0 + 1) * (1.0 - fx) + self.at(x0 + 1, y0 + 1) * fx;
        a * (1.0 - fy) + b * fy
    }

    /// From 16-bit values, stretched between the 0.5th and 99.5th percentiles (radiometric thermal
    /// images span a few kelvin of a 65536-value range).
    pub fn from_u16(width: u32, height: u32, raw: &[u16]) -> Self {
        let mut sorted: Vec<u16> = raw.to_vec();
        sorted.sort_unstable();
        let n = sorted.len().max(1);
        let lo = sorted.get(n / 200).copied().unwrap_or(0) as f32;
        let hi = sorted.get(n - 1 - n / 200).copied().unwrap_or(1) as f32;
        let span = (hi - lo).max(1.0);
        Self {
            width,
            height,
            data: raw
                .iter()
                .map(|&v| ((v as f32 - lo) / span).clamp(0.0, 1.0))
                .collect(),
        }
    }

    /// From an 8-bit grey image.
    pub fn from_luma8(img: &GrayImage) -> Self {
        Self {
            width: img.width(),
            height: img.height(),
            data: img.as_raw().iter().map(|&v| v as f32 / 255.0).collect(),
        }
    }

    /// From any decoded image: 16-bit single channel is stretched, everything else goes through
    /// its luminance.
    pub fn from_dynamic(img: &DynamicImage) -> Self {
        match img {
            DynamicImage::ImageLuma16(g) => Self::from_u16(g.width(), g.height(), g.as_raw()),
            DynamicImage::ImageLumaA16(_)
            | DynamicImage::ImageRgb16(_)
            | DynamicImage::ImageRgba16(_) => {
                let g = img.to_luma16();
                Self::from_u16(g.width(), g.height(), g.as_raw())
            }
            _ => Self::from_luma8(&img.to_luma8()),
        }
    }

    /// Reads an image file (PNG, JPEG, TIFF; 8- or 16-bit, grey or colour).
    pub fn read(path: &Path) -> Result<Self, CalibError> {
        let img = ImageReader::open(path)
            .map_err(|e| CalibError::file(path, e.to_string()))?
            .with_guessed_format()
            .map_err(|e| CalibError::file(path, e.to_string()))?
            .decode()
            .map_err(|e| CalibError::file(path, format!("cannot decode the image: {e}")))?;
        if img.width() < 16 || img.height() < 16 {
            return Err(CalibError::file(
                path,
                format!(
                    "image is {}×{} pixels, too small for a checkerboard",
                    img.width(),
                    img.height()
                ),
            ));
        }
        Ok(Self::from_dynamic(&img))
    }

    /// 8-bit copy, upsampled by an integer factor (bicubic) for the corner detector.
    pub fn to_luma8_scaled(&self, scale: u32) -> GrayImage {
        let img = GrayImage::from_fn(self.width, self.height, |x, y| {
            image::Luma([(self.data[(y * self.width + x) as usize] * 255.0)
                .round()
                .clamp(0.0, 255.0) as u8])
        });
        if scale <= 1 {
            img
        } else {
            image::imageops::resize(
                &img,
                self.width * scale,
                self.height * scale,
                image::imageops::FilterType::CatmullRom,
            )
        }
    }
}
