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

    /// The grey readings of an image worth searching for a board: its luminance (or 16-bit
    /// values), and for a colourful false-colour image also its hue. A palette whose luminance
    /// is not monotonic in temperature (a rainbow: blue, green, yellow, red) can give two
    /// temperatures the same luminance; its hue still runs one way.
    pub fn variants(img: &DynamicImage) -> Vec<Self> {
        let mut out = vec![Self::from_dynamic(img)];
        if let Some(h) = Self::hue_of(img) {
            out.push(h);
        }
        out
    }

    /// The hue (0…1 over 360°) of an 8-bit colour image whose mean saturation shows a palette
    /// (above 0.25); `None` for grey or 16-bit images.
    pub fn hue_of(img: &DynamicImage) -> Option<Self> {
        if !matches!(
            img,
            DynamicImage::ImageRgb8(_) | DynamicImage::ImageRgba8(_)
        ) {
            return None;
        }
        let rgb = img.to_rgb8();
        let (mut hue, mut sat) = (Vec::with_capacity(rgb.len() / 3), 0.0f64);
        for p in rgb.pixels() {
            let [r, g, b] = p.0.map(|c| c as f32 / 255.0);
            let (max, min) = (r.max(g).max(b), r.min(g).min(b));
            let c = max - min;
            sat += if max > 0.0 { (c / max) as f64 } else { 0.0 };
            let h = if c <= 1e-6 {
                0.0
            } else if max == r {
                ((g - b) / c).rem_euclid(6.0)
            } else if max == g {
                (b - r) / c + 2.0
            } else {
                (r - g) / c + 4.0
            };
            hue.push(h / 6.0);
        }
        let n = (rgb.width() as f64 * rgb.height() as f64).max(1.0);
        (sat / n > 0.25).then(|| Self {
            width: rgb.width(),
            height: rgb.height(),
            data: hue,
        })
    }

    /// Reads an image file (PNG, JPEG, TIFF; 8- or 16-bit, grey or colour) as its grey
    /// [`variants`](Self::variants).
    pub fn read_variants(path: &Path) -> Result<Vec<Self>, CalibError> {
        Ok(Self::variants(&Self::decode(path)?))
    }

    /// Reads an image file (PNG, JPEG, TIFF; 8- or 16-bit, grey or colour).
    pub fn read(path: &Path) -> Result<Self, CalibError> {
        Ok(Self::from_dynamic(&Self::decode(path)?))
    }

    fn decode(path: &Path) -> Result<DynamicImage, CalibError> {
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
        Ok(img)
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
