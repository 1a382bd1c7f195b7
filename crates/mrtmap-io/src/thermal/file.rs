//! Single thermal images in the formats cameras write, decoded to temperatures:
//!
//! | file | how |
//! |---|---|
//! | FLIR R-JPEG (`.jpg` with APP1 "FLIR") and FFF (`.fff`, `.seq` frame) | raw counts + the file's Planck constants and object parameters ([`super::flir`]) |
//! | 16-bit PNG / TIFF | `raw × scale` kelvin; scale 0.01 (Lepton TLinear centikelvin) unless given or the values only make sense at 0.04 (Tau / Boson / Duo TLinear low resolution) |
//! | float TIFF | °C, or K when the median is above 150 |
//! | raw `.y16` / `.bin` | little-endian 16-bit, size given or 160×120 / 80×60 from the file length |

use std::path::Path;

use super::flir::{FlirOverrides, RawKind, TiffPixels, decode_tiff, is_flir, parse_flir};
use crate::bytes::Corrupt;
use crate::error::{FileError, FileErrorKind};
use crate::image16::Image16;

/// Largest thermal image we read, pixels (4096 × 4096).
const MAX_PIXELS: usize = 1 << 24;

/// How to read a thermal file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ThermalOptions {
    /// Size of a raw `.y16` / `.bin` file.
    pub size: Option<(u32, u32)>,
    /// Kelvin per count of a 16-bit PNG / TIFF / raw file.
    pub scale_k: Option<f64>,
    /// Kelvin added after scaling.
    pub offset_k: f64,
    /// Overrides of a FLIR file's parameters.
    pub flir: FlirOverrides,
}

/// What kind of file it was.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ThermalFileKind {
    /// FLIR radiometric JPEG.
    FlirJpeg,
    /// FLIR FFF.
    FlirFff,
    /// 16-bit PNG.
    Png16,
    /// 16-bit TIFF.
    Tiff16,
    /// Float TIFF.
    TiffFloat,
    /// Raw 16-bit counts.
    Raw16,
}

impl ThermalFileKind {
    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Self::FlirJpeg => "FLIR radiometric JPEG",
            Self::FlirFff => "FLIR FFF",
            Self::Png16 => "16-bit PNG",
            Self::Tiff16 => "16-bit TIFF",
            Self::TiffFloat => "float TIFF",
            Self::Raw16 => "raw 16-bit",
        }
    }
}

/// A thermal image in °C with what was learnt reading it.
#[derive(Clone, Debug)]
pub struct ThermalImage {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// °C per pixel, row-major (NaN where a raw value has no temperature).
    pub celsius: Vec<f64>,
    /// The raw counts, for 16-bit sources.
    pub raw: Option<Image16>,
    /// What the file was.
    pub kind: ThermalFileKind,
    /// Metadata (name, value), in reading order.
    pub metadata: Vec<(String, String)>,
    /// How the values were interpreted, where it was a choice.
    pub notes: Vec<String>,
}

impl ThermalImage {
    /// The temperatures (°C, 3 decimals) as CSV, one image row per line; pixels without a
    /// temperature are empty cells.
    pub fn csv(&self) -> String {
        let mut s = String::with_capacity(self.celsius.len() * 7);
        for row in self.celsius.chunks(self.width as usize) {
            let cells: Vec<String> = row
                .iter()
                .map(|c| {
                    if c.is_finite() {
                        format!("{c:.3}")
                    } else {
                        String::new()
                    }
                })
                .collect();
            s.push_str(&cells.join(","));
            s.push('\n');
        }
        s
    }

    /// The image in the iron palette from `lo_c` (black) to `hi_c` (white) as PNG; pixels without
    /// a temperature are black.
    pub fn iron_png(&self, lo_c: f64, hi_c: f64) -> Result<Vec<u8>, crate::EncodeError> {
        let span = (hi_c - lo_c).max(1e-9);
        let rgb: Vec<u8> = self
            .celsius
            .iter()
            .flat_map(|&c| {
                if c.is_finite() {
                    crate::iron(((c - lo_c) / span) as f32)
                } else {
                    [0, 0, 0]
                }
            })
            .collect();
        crate::encode_png_rgb8(self.width, self.height, &rgb)
    }

    /// Temperatures as 16-bit centikelvin (the recording layout's thermal encoding).
    pub fn centikelvin(&self) -> Image16 {
        Image16 {
            width: self.width,
            height: self.height,
            data: self
                .celsius
                .iter()
                .map(|&c| {
                    if c.is_finite() {
                        ((c + 273.15) * 100.0).round().clamp(0.0, 65535.0) as u16
                    } else {
                        0
                    }
                })
                .collect(),
        }
    }

    /// (min, max, mean, median) of the finite temperatures, °C.
    pub fn stats(&self) -> Option<(f64, f64, f64, f64)> {
        let mut v: Vec<f64> = self
            .celsius
            .iter()
            .copied()
            .filter(|c| c.is_finite())
            .collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let n = v.len();
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        };
        Some((v[0], v[n - 1], mean, median))
    }
}

fn err(path: &Path, msg: impl Into<String>) -> FileError {
    FileError::new(path, None, FileErrorKind::Image(msg.into()))
}

fn median16(v: &[u16]) -> f64 {
    let mut s = v.to_vec();
    s.sort_unstable();
    s.get(s.len() / 2).map_or(0.0, |&x| x as f64)
}

/// Kelvin per count for 16-bit data: the given one, else 0.01 unless only 0.04 gives a plausible
/// scene (median between −50 and 200 °C).
fn scale_of(raw: &Image16, opts: &ThermalOptions, notes: &mut Vec<String>) -> f64 {
    if let Some(s) = opts.scale_k {
        notes.push(format!("{s} K per count (given)"));
        return s;
    }
    let m = median16(&raw.data);
    let plausible = |s: f64| (223.15..=473.15).contains(&(m * s + opts.offset_k));
    if !plausible(0.01) && plausible(0.04) {
        notes.push(format!(
            "0.04 K per count (FLIR Tau/Boson/Duo TLinear low resolution): at 0.01 the median would be {:.1} °C; pass --scale to choose",
            m * 0.01 + opts.offset_k - 273.15
        ));
        0.04
    } else {
        notes.push("0.01 K per count (centikelvin, Lepton TLinear)".into());
        0.01
    }
}

fn scaled(raw: Image16, kind: ThermalFileKind, opts: &ThermalOptions) -> ThermalImage {
    let mut notes = Vec::new();
    let s = scale_of(&raw, opts, &mut notes);
    ThermalImage {
        width: raw.width,
        height: raw.height,
        celsius: raw
            .data
            .iter()
            .map(|&v| v as f64 * s + opts.offset_k - 273.15)
            .collect(),
        raw: Some(raw),
        kind,
        metadata: Vec::new(),
        notes,
    }
}

/// Reads raw 16-bit little-endian counts.
fn read_raw(path: &Path, bytes: &[u8], opts: &ThermalOptions) -> Result<ThermalImage, FileError> {
    let (w, h) = match opts.size {
        Some(s) => s,
        None => match bytes.len() {
            38_400 => (160, 120),
            9_600 => (80, 60),
            n => {
                return Err(err(
                    path,
                    format!(
                        "raw file of {n} bytes is not a Lepton frame (160×120 or 80×60): give its size (--size WxH)"
                    ),
                ));
            }
        },
    };
    let n = (w as usize) * (h as usize);
    if n == 0 || n > MAX_PIXELS {
        return Err(err(
            path,
            format!("raw size {w}×{h} is not a usable image size"),
        ));
    }
    if bytes.len() != 2 * n {
        return Err(Corrupt::new(
            bytes.len().min(2 * n) as u64,
            format!(
                "a {w}×{h} raw frame is {} bytes but the file has {}",
                2 * n,
                bytes.len()
            ),
        )
        .in_file(path));
    }
    let raw = Image16 {
        width: w,
        height: h,
        data: bytes
            .chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]))
            .collect(),
    };
    Ok(scaled(raw, ThermalFileKind::Raw16, opts))
}

/// Reads a thermal image file in any supported format (by content, then by extension).
pub fn read_thermal_file(path: &Path, opts: &ThermalOptions) -> Result<ThermalImage, FileError> {
    let bytes = std::fs::read(path).map_err(|e| FileError::io(path, e))?;
    decode_thermal(path, &bytes, opts)
}

/// How a FLIR file's raw image was stored, in words.
fn flir_notes(f: &super::flir::FlirFile) -> String {
    format!(
        "raw {}×{} stored as {}{}; {} byte order; {} records{}",
        f.raw.width,
        f.raw.height,
        match f.raw_kind {
            RawKind::Png => "PNG",
            RawKind::Tiff => "TIFF",
            RawKind::Packed => "packed counts",
        },
        if f.byte_swapped {
            " (byte-swapped)"
        } else {
            ""
        },
        match f.endian {
            crate::bytes::Endian::Little => "little-endian",
            crate::bytes::Endian::Big => "big-endian",
        },
        f.records,
        if f.segments > 0 {
            format!(
                " in {} APP1 segment{}",
                f.segments,
                if f.segments == 1 { "" } else { "s" }
            )
        } else {
            String::new()
        }
    )
}

/// A FLIR R-JPEG or FFF file, converted with its own Planck constants and object parameters
/// (those of `opts` replacing the file's).
fn decode_flir(
    path: &Path,
    bytes: &[u8],
    opts: &ThermalOptions,
) -> Result<ThermalImage, FileError> {
    let f = parse_flir(bytes).map_err(|e| e.in_file(path))?;
    let p = f.params.with(&opts.flir);
    let conv = p.converter();
    let kind = if bytes.starts_with(b"\xFF\xD8") {
        ThermalFileKind::FlirJpeg
    } else {
        ThermalFileKind::FlirFff
    };
    let mut notes = vec![flir_notes(&f)];
    let mut metadata = f.metadata.clone();
    if p != f.params {
        notes.push("object parameters overridden from the command line".into());
        for (name, v) in [
            ("Used Emissivity", p.emissivity),
            ("Used ObjectDistance", p.object_distance_m),
            ("Used ReflectedApparentTemperature", p.reflected_c),
            ("Used AtmosphericTemperature", p.atmospheric_c),
            ("Used RelativeHumidity", p.relative_humidity),
        ] {
            metadata.push((name.into(), format!("{v}")));
        }
    }
    Ok(ThermalImage {
        width: f.raw.width,
        height: f.raw.height,
        celsius: f.raw.data.iter().map(|&r| conv.celsius(r as f64)).collect(),
        raw: Some(f.raw),
        kind,
        metadata,
        notes,
    })
}

/// A 16-bit or float TIFF (float: °C, or kelvin when the median is above 150).
fn decode_tiff_file(
    path: &Path,
    bytes: &[u8],
    opts: &ThermalOptions,
) -> Result<ThermalImage, FileError> {
    match decode_tiff(bytes).map_err(|e| err(path, e))? {
        TiffPixels::U16(img) => Ok(scaled(img, ThermalFileKind::Tiff16, opts)),
        TiffPixels::F32 {
            width,
            height,
            data,
        } => {
            let mut v: Vec<f32> = data.iter().copied().filter(|x| x.is_finite()).collect();
            v.sort_by(f32::total_cmp);
            let m = v.get(v.len() / 2).copied().unwrap_or(0.0);
            let kelvin = m > 150.0;
            let off = if kelvin { -273.15 } else { 0.0 };
            Ok(ThermalImage {
                width,
                height,
                celsius: data.iter().map(|&x| x as f64 + off).collect(),
                raw: None,
                kind: ThermalFileKind::TiffFloat,
                metadata: Vec::new(),
                notes: vec![if kelvin {
                    format!("float values read as kelvin (median {m:.2})")
                } else {
                    format!("float values read as °C (median {m:.2})")
                }],
            })
        }
    }
}

/// A 16-bit grey PNG.
fn decode_png_file(
    path: &Path,
    bytes: &[u8],
    opts: &ThermalOptions,
) -> Result<ThermalImage, FileError> {
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
        .map_err(|e| err(path, format!("cannot decode the PNG: {e}")))?;
    match img {
        image::DynamicImage::ImageLuma16(b) => {
            let (w, h) = b.dimensions();
            Ok(scaled(
                Image16 {
                    width: w,
                    height: h,
                    data: b.into_raw(),
                },
                ThermalFileKind::Png16,
                opts,
            ))
        }
        other => Err(err(
            path,
            format!(
                "a {:?} PNG holds no temperatures (radiometric PNGs are 16-bit grey)",
                other.color()
            ),
        )),
    }
}

/// Decodes thermal image bytes (`path` names the file in errors and picks raw by extension).
pub fn decode_thermal(
    path: &Path,
    bytes: &[u8],
    opts: &ThermalOptions,
) -> Result<ThermalImage, FileError> {
    if is_flir(bytes) {
        return decode_flir(path, bytes, opts);
    }
    if bytes.starts_with(b"II*\0") || bytes.starts_with(b"MM\0*") {
        return decode_tiff_file(path, bytes, opts);
    }
    if bytes.starts_with(b"\x89PNG") {
        return decode_png_file(path, bytes, opts);
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if matches!(ext.as_str(), "y16" | "bin" | "raw") || opts.size.is_some() {
        return read_raw(path, bytes, opts);
    }
    if bytes.starts_with(b"\xFF\xD8") {
        return Err(err(
            path,
            "a JPEG without FLIR radiometric data holds no temperatures",
        ));
    }
    Err(err(
        path,
        "unknown thermal format (expected a FLIR JPEG or FFF, a 16-bit PNG or TIFF, a float TIFF, or raw .y16/.bin)",
    ))
}
