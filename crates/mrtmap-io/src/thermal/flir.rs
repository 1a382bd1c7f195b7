//! FLIR radiometric files: R-JPEG (APP1 "FLIR" segments) and FFF (either byte order).
//!
//! The JPEG's APP1 segments that start with `FLIR\0` are numbered; their payloads concatenate into
//! an FFF file: a 64-byte header, then a directory of 32-byte records. We read the RawData record
//! (16-bit raw counts as PNG — FLIR writes those little-endian, so byte-swapped — TIFF, or packed)
//! and the CameraInfo record (Planck constants, emissivity, distances, temperatures, atmosphere),
//! and convert raw counts to temperature with the formula of exiftool-based tools (Thermimage's
//! `raw2temp`). Offsets follow exiftool's FLIR tables; every one is checked against exiftool's own
//! output for the real FLIR files of the shared data folder (`MRTMAP_DATA_DIR`).

use crate::bytes::{Bytes, Corrupt, Endian};
use crate::image16::Image16;

/// Largest raw thermal image side we accept (FLIR's largest sensors are 1280 × 1024).
const MAX_SIDE: u32 = 8192;

/// Radiometric parameters of a FLIR file (temperatures in °C, humidity as a fraction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlirParams {
    /// Emissivity of the object.
    pub emissivity: f64,
    /// Object distance, metres.
    pub object_distance_m: f64,
    /// Reflected apparent temperature, °C.
    pub reflected_c: f64,
    /// Atmospheric temperature, °C.
    pub atmospheric_c: f64,
    /// IR window temperature, °C.
    pub ir_window_c: f64,
    /// IR window transmission.
    pub ir_window_transmission: f64,
    /// Relative humidity, 0…1.
    pub relative_humidity: f64,
    /// Planck R1.
    pub planck_r1: f64,
    /// Planck R2.
    pub planck_r2: f64,
    /// Planck B.
    pub planck_b: f64,
    /// Planck F.
    pub planck_f: f64,
    /// Planck O.
    pub planck_o: f64,
    /// Atmospheric transmission α1.
    pub alpha1: f64,
    /// α2.
    pub alpha2: f64,
    /// β1.
    pub beta1: f64,
    /// β2.
    pub beta2: f64,
    /// X.
    pub atm_x: f64,
}

/// Values that replace the file's own (from the command line).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlirOverrides {
    /// Emissivity.
    pub emissivity: Option<f64>,
    /// Object distance, m.
    pub object_distance_m: Option<f64>,
    /// Reflected apparent temperature, °C.
    pub reflected_c: Option<f64>,
    /// Atmospheric temperature, °C.
    pub atmospheric_c: Option<f64>,
    /// Relative humidity, 0…1.
    pub relative_humidity: Option<f64>,
}

impl FlirParams {
    /// The parameters with overrides applied.
    pub fn with(mut self, o: &FlirOverrides) -> Self {
        if let Some(v) = o.emissivity {
            self.emissivity = v;
        }
        if let Some(v) = o.object_distance_m {
            self.object_distance_m = v;
        }
        if let Some(v) = o.reflected_c {
            self.reflected_c = v;
        }
        if let Some(v) = o.atmospheric_c {
            self.atmospheric_c = v;
        }
        if let Some(v) = o.relative_humidity {
            self.relative_humidity = v;
        }
        self
    }

    /// Raw counts of a blackbody at `t_c` °C.
    fn raw_of(&self, t_c: f64) -> f64 {
        self.planck_r1 / (self.planck_r2 * ((self.planck_b / (t_c + 273.15)).exp() - self.planck_f))
            - self.planck_o
    }

    /// The converter from raw counts to °C (precomputes the atmosphere and reflection terms).
    pub fn converter(&self) -> RawToTemp {
        // Thermimage raw2temp (v4): h2o = (RH% / 100)·exp(…), half the distance each way.
        let t_atm = self.atmospheric_c;
        let h2o = self.relative_humidity
            * (1.5587 + 0.06939 * t_atm - 0.00027816 * t_atm * t_atm
                + 0.00000068455 * t_atm * t_atm * t_atm)
                .exp();
        let d = (self.object_distance_m / 2.0).sqrt();
        let tau = self.atm_x * (-d * (self.alpha1 + self.beta1 * h2o.sqrt())).exp()
            + (1.0 - self.atm_x) * (-d * (self.alpha2 + self.beta2 * h2o.sqrt())).exp();
        let e = self.emissivity;
        let irt = self.ir_window_transmission;
        let emiss_wind = 1.0 - irt;
        let refl_wind = 0.0;
        let raw_refl = self.raw_of(self.reflected_c);
        let raw_atm = self.raw_of(t_atm);
        let raw_wind = self.raw_of(self.ir_window_c);
        let refl1 = (1.0 - e) / e * raw_refl;
        let atm1 = (1.0 - tau) / e / tau * raw_atm;
        let wind = emiss_wind / e / tau / irt * raw_wind;
        let refl2 = refl_wind / e / tau / irt * raw_refl;
        let atm2 = (1.0 - tau) / e / tau / irt / tau * raw_atm;
        RawToTemp {
            gain: 1.0 / (e * tau * irt * tau),
            offset: atm1 + atm2 + wind + refl1 + refl2,
            r1: self.planck_r1,
            r2: self.planck_r2,
            b: self.planck_b,
            f: self.planck_f,
            o: self.planck_o,
        }
    }
}

/// Raw counts → °C for one set of parameters.
#[derive(Clone, Copy, Debug)]
pub struct RawToTemp {
    gain: f64,
    offset: f64,
    r1: f64,
    r2: f64,
    b: f64,
    f: f64,
    o: f64,
}

impl RawToTemp {
    /// °C of a raw count (NaN where the count is outside the Planck curve's range).
    pub fn celsius(&self, raw: f64) -> f64 {
        let raw_obj = raw * self.gain - self.offset;
        let arg = self.r1 / (self.r2 * (raw_obj + self.o)) + self.f;
        if arg > 0.0 && raw_obj + self.o > 0.0 {
            self.b / arg.ln() - 273.15
        } else {
            f64::NAN
        }
    }
}

/// How the raw image was stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RawKind {
    /// 16-bit PNG.
    Png,
    /// 16-bit TIFF.
    Tiff,
    /// Packed 16-bit counts.
    Packed,
}

/// A decoded FLIR file.
#[derive(Clone, Debug)]
pub struct FlirFile {
    /// Byte order of the FFF data.
    pub endian: Endian,
    /// Raw counts.
    pub raw: Image16,
    /// How they were stored.
    pub raw_kind: RawKind,
    /// True when the PNG's bytes were swapped (FLIR's usual little-endian PNG).
    pub byte_swapped: bool,
    /// Radiometric parameters.
    pub params: FlirParams,
    /// Camera metadata as exiftool names it (model, serial, lens, field of view, raw statistics).
    pub metadata: Vec<(String, String)>,
    /// The camera's median raw value, when recorded.
    pub raw_value_median: Option<u16>,
    /// Number of FFF records.
    pub records: usize,
    /// Number of APP1 segments (0 for an FFF file).
    pub segments: usize,
}

/// FFF bytes and where each piece came from in the file (for error offsets).
struct Fff<'a> {
    /// The FFF bytes: the file itself, or the JPEG's segments joined.
    data: std::borrow::Cow<'a, [u8]>,
    /// (offset in `data`, offset in the file) of each contiguous piece.
    pieces: Vec<(usize, u64)>,
    segments: usize,
}

impl Fff<'_> {
    fn file_offset(&self, at: u64) -> u64 {
        let mut best = (0usize, 0u64);
        for &(d, f) in &self.pieces {
            if (d as u64) <= at {
                best = (d, f);
            }
        }
        best.1 + (at - best.0 as u64)
    }

    fn remap(&self, e: Corrupt) -> Corrupt {
        Corrupt::new(self.file_offset(e.offset), e.what)
    }
}

/// The FFF data of a JPEG's APP1 "FLIR" segments, in segment order.
fn jpeg_fff(file: &[u8]) -> Result<Fff<'static>, Corrupt> {
    let b = Bytes::new(file, Endian::Big);
    let mut pos = 2usize;
    let mut segs: Vec<(u8, u8, usize, usize)> = Vec::new();
    loop {
        if pos >= file.len() {
            break;
        }
        let m0 = b.u8(pos, "a JPEG marker")?;
        if m0 != 0xFF {
            return Err(b.err(
                pos,
                format!("expected a JPEG marker (0xFF), found 0x{m0:02X}"),
            ));
        }
        let marker = b.u8(pos + 1, "a JPEG marker")?;
        match marker {
            0xFF => {
                pos += 1;
                continue;
            }
            0xD9 | 0xDA => break,
            0x01 | 0xD0..=0xD7 => {
                pos += 2;
                continue;
            }
            _ => {}
        }
        let len = b.u16(pos + 2, "a JPEG segment length")? as usize;
        if len < 2 {
            return Err(b.err(pos + 2, format!("JPEG segment length {len} is below 2")));
        }
        let seg = b.slice(pos + 4, len - 2, &format!("JPEG segment 0xFF{marker:02X}"))?;
        if marker == 0xE1 && seg.starts_with(b"FLIR\0") {
            if seg.len() < 8 {
                return Err(b.err(pos + 4, "FLIR APP1 segment shorter than its 8-byte header"));
            }
            segs.push((seg[6], seg[7], pos + 12, seg.len() - 8));
        }
        pos += 2 + len;
    }
    if segs.is_empty() {
        return Err(Corrupt::new(
            0,
            "a JPEG without FLIR APP1 segments (not a radiometric JPEG, or its metadata was stripped)",
        ));
    }
    segs.sort_by_key(|s| s.0);
    let last = segs[0].1;
    let mut data = Vec::new();
    let mut pieces = Vec::new();
    for (i, &(n, total, at, len)) in segs.iter().enumerate() {
        if n as usize != i || total != last {
            return Err(Corrupt::new(
                at as u64,
                format!(
                    "FLIR segment {n} of {} out of sequence (segment {i} expected): the JPEG is missing part of its thermal data",
                    last as usize + 1
                ),
            ));
        }
        pieces.push((data.len(), at as u64));
        data.extend_from_slice(&file[at..at + len]);
    }
    if segs.len() != last as usize + 1 {
        return Err(Corrupt::new(
            file.len() as u64,
            format!(
                "{} of {} FLIR segments present: the JPEG is missing part of its thermal data",
                segs.len(),
                last as usize + 1
            ),
        ));
    }
    Ok(Fff {
        data: data.into(),
        pieces,
        segments: segs.len(),
    })
}

/// Byte order of a record whose first u16 is 2 (exiftool's rule); `fallback` when neither is.
fn record_endian(rec: &Bytes<'_>, fallback: Endian) -> Endian {
    match rec.with_endian(Endian::Little).u16(0, "") {
        Ok(2) => Endian::Little,
        Ok(0x0200) => Endian::Big,
        _ => fallback,
    }
}

fn decode_png16(data: &[u8]) -> Result<Image16, String> {
    let mut dec = png::Decoder::new(std::io::Cursor::new(data));
    dec.set_transformations(png::Transformations::IDENTITY);
    let mut reader = dec.read_info().map_err(|e| format!("raw PNG: {e}"))?;
    let info = reader.info();
    if info.bit_depth != png::BitDepth::Sixteen || info.color_type != png::ColorType::Grayscale {
        return Err(format!(
            "raw PNG is {:?} {:?}, not 16-bit grey",
            info.bit_depth, info.color_type
        ));
    }
    let (w, h) = (info.width, info.height);
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(format!("raw PNG of {w}×{h} pixels"));
    }
    let mut buf = vec![0u8; reader.output_buffer_size().ok_or("raw PNG too large")?];
    reader
        .next_frame(&mut buf)
        .map_err(|e| format!("raw PNG: {e}"))?;
    let data = buf
        .chunks_exact(2)
        .take((w * h) as usize)
        .map(|c| u16::from_be_bytes([c[0], c[1]]))
        .collect();
    Ok(Image16 {
        width: w,
        height: h,
        data,
    })
}

/// Decodes a single-channel TIFF: 16-bit unsigned, or 32/64-bit float.
pub(crate) enum TiffPixels {
    U16(Image16),
    F32 {
        width: u32,
        height: u32,
        data: Vec<f32>,
    },
}

pub(crate) fn decode_tiff(data: &[u8]) -> Result<TiffPixels, String> {
    use tiff::decoder::{Decoder, DecodingResult, Limits};
    let mut limits = Limits::default();
    limits.decoding_buffer_size = 512 << 20;
    let mut dec = Decoder::new(std::io::Cursor::new(data))
        .map_err(|e| format!("TIFF: {e}"))?
        .with_limits(limits);
    let (w, h) = dec.dimensions().map_err(|e| format!("TIFF: {e}"))?;
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(format!("TIFF of {w}×{h} pixels"));
    }
    let n = (w as usize) * (h as usize);
    let img = dec.read_image().map_err(|e| format!("TIFF: {e}"))?;
    let check = |len: usize| {
        if len == n {
            Ok(())
        } else {
            Err(format!(
                "TIFF has {len} samples for {w}×{h} pixels (one channel expected)"
            ))
        }
    };
    match img {
        DecodingResult::U16(v) => {
            check(v.len())?;
            Ok(TiffPixels::U16(Image16 {
                width: w,
                height: h,
                data: v,
            }))
        }
        DecodingResult::F32(v) => {
            check(v.len())?;
            Ok(TiffPixels::F32 {
                width: w,
                height: h,
                data: v,
            })
        }
        DecodingResult::F64(v) => {
            check(v.len())?;
            Ok(TiffPixels::F32 {
                width: w,
                height: h,
                data: v.into_iter().map(|x| x as f32).collect(),
            })
        }
        _ => Err("TIFF samples are neither 16-bit unsigned nor float".into()),
    }
}

/// Sum of absolute differences between horizontal neighbours.
fn roughness(img: &Image16) -> u64 {
    img.data
        .chunks(img.width as usize)
        .flat_map(|row| row.windows(2))
        .map(|w| w[0].abs_diff(w[1]) as u64)
        .sum()
}

/// Reads the RawData record.
fn raw_data(rec: Bytes<'_>) -> Result<(Image16, RawKind, bool), Corrupt> {
    let rec = rec.with_endian(record_endian(&rec, rec.endian));
    let w = rec.u16(2, "the raw image width")? as u32;
    let h = rec.u16(4, "the raw image height")? as u32;
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(rec.err(2, format!("raw thermal image of {w}×{h} pixels")));
    }
    let body = rec.sub(32, rec.len().saturating_sub(32), "the raw image")?;
    let check_dims = |img: &Image16| {
        if (img.width, img.height) != (w, h) {
            Err(body.err(
                0,
                format!(
                    "raw image is {}×{} but the record says {w}×{h}",
                    img.width, img.height
                ),
            ))
        } else {
            Ok(())
        }
    };
    if body.data.starts_with(b"\x89PNG") {
        let img = decode_png16(body.data).map_err(|e| body.err(0, e))?;
        check_dims(&img)?;
        let swapped = Image16 {
            data: img.data.iter().map(|v| v.swap_bytes()).collect(),
            ..img.clone()
        };
        // FLIR writes the PNG's samples little-endian (exiftool and Thermimage swap them), but not
        // every writer does: keep the order that gives the smoother image (in the wrong order the
        // low byte of each count becomes the high one and neighbours jump by hundreds).
        let use_swapped = roughness(&swapped) <= roughness(&img);
        return Ok(if use_swapped {
            (swapped, RawKind::Png, true)
        } else {
            (img, RawKind::Png, false)
        });
    }
    if body.data.starts_with(b"II*\0") || body.data.starts_with(b"MM\0*") {
        return match decode_tiff(body.data).map_err(|e| body.err(0, e))? {
            TiffPixels::U16(img) => {
                check_dims(&img)?;
                Ok((img, RawKind::Tiff, false))
            }
            TiffPixels::F32 { .. } => Err(body.err(0, "raw TIFF holds floats, not raw counts")),
        };
    }
    let n = (w * h) as usize;
    let bytes = body.slice(0, 2 * n, "the packed raw image")?;
    let data = bytes
        .chunks_exact(2)
        .map(|c| match rec.endian {
            Endian::Little => u16::from_le_bytes([c[0], c[1]]),
            Endian::Big => u16::from_be_bytes([c[0], c[1]]),
        })
        .collect();
    Ok((
        Image16 {
            width: w,
            height: h,
            data,
        },
        RawKind::Packed,
        false,
    ))
}

/// (name, value) pairs.
type Metadata = Vec<(String, String)>;

/// Reads the CameraInfo record (byte offsets of exiftool's FLIR CameraInfo table).
fn camera_info(rec: Bytes<'_>) -> Result<(FlirParams, Metadata, Option<u16>), Corrupt> {
    let r = rec.with_endian(record_endian(&rec, rec.endian));
    let f = |at: usize, what: &str| r.f32(at, what).map(f64::from);
    let k = |at: usize, what: &str| f(at, what).map(|v| v - 273.15);
    let rh = f(0x3c, "RelativeHumidity")?;
    let params = FlirParams {
        emissivity: f(0x20, "Emissivity")?,
        object_distance_m: f(0x24, "ObjectDistance")?,
        reflected_c: k(0x28, "ReflectedApparentTemperature")?,
        atmospheric_c: k(0x2c, "AtmosphericTemperature")?,
        ir_window_c: k(0x30, "IRWindowTemperature")?,
        ir_window_transmission: f(0x34, "IRWindowTransmission")?,
        relative_humidity: if rh > 2.0 { rh / 100.0 } else { rh },
        planck_r1: f(0x58, "PlanckR1")?,
        planck_b: f(0x5c, "PlanckB")?,
        planck_f: f(0x60, "PlanckF")?,
        alpha1: f(0x70, "AtmosphericTransAlpha1")?,
        alpha2: f(0x74, "AtmosphericTransAlpha2")?,
        beta1: f(0x78, "AtmosphericTransBeta1")?,
        beta2: f(0x7c, "AtmosphericTransBeta2")?,
        atm_x: f(0x80, "AtmosphericTransX")?,
        planck_o: r.i32(0x308, "PlanckO")? as f64,
        planck_r2: f(0x30c, "PlanckR2")?,
    };
    let mut meta = Vec::new();
    for (at, len, name) in [
        (0xd4, 32, "CameraModel"),
        (0xf4, 16, "CameraPartNumber"),
        (0x104, 16, "CameraSerialNumber"),
        (0x114, 16, "CameraSoftware"),
        (0x170, 32, "LensModel"),
    ] {
        let s = r.fixed_str(at, len, name)?;
        if !s.is_empty() {
            meta.push((name.to_string(), s));
        }
    }
    meta.push((
        "FieldOfView".into(),
        format!("{}", f(0x1b4, "FieldOfView")?),
    ));
    for (at, name) in [
        (0x310, "RawValueRangeMin"),
        (0x312, "RawValueRangeMax"),
        (0x338, "RawValueMedian"),
        (0x33c, "RawValueRange"),
    ] {
        meta.push((name.to_string(), r.u16(at, name)?.to_string()));
    }
    let median = r.u16(0x338, "RawValueMedian")?;
    for (name, v) in [
        ("Emissivity", params.emissivity),
        ("ObjectDistance", params.object_distance_m),
        ("ReflectedApparentTemperature", params.reflected_c),
        ("AtmosphericTemperature", params.atmospheric_c),
        ("IRWindowTemperature", params.ir_window_c),
        ("IRWindowTransmission", params.ir_window_transmission),
        ("RelativeHumidity", params.relative_humidity),
        ("PlanckR1", params.planck_r1),
        ("PlanckR2", params.planck_r2),
        ("PlanckB", params.planck_b),
        ("PlanckF", params.planck_f),
        ("PlanckO", params.planck_o),
    ] {
        meta.push((name.to_string(), format!("{v}")));
    }
    let all_finite = [
        params.emissivity,
        params.object_distance_m,
        params.planck_r1,
        params.planck_r2,
        params.planck_b,
        params.planck_f,
    ]
    .iter()
    .all(|v| v.is_finite());
    if !all_finite || params.emissivity <= 0.0 || params.emissivity > 1.0 {
        return Err(r.err(
            0x20,
            format!(
                "CameraInfo holds an emissivity of {} or non-finite Planck constants",
                params.emissivity
            ),
        ));
    }
    Ok((params, meta, (median > 0).then_some(median)))
}

/// Parses FFF data.
fn parse_fff(fff: &Fff<'_>) -> Result<FlirFile, Corrupt> {
    let all = Bytes::new(&fff.data, Endian::Big);
    let magic = all.slice(0, 4, "the FFF header")?;
    if magic != b"FFF\0" && magic != b"AFF\0" {
        return Err(all.err(0, "not FLIR FFF data (no \"FFF\" magic)"));
    }
    let v_be = all.u32(20, "the FFF version")?;
    let endian = if (100..200).contains(&v_be) {
        Endian::Big
    } else if (100..200).contains(&all.with_endian(Endian::Little).u32(20, "")?) {
        Endian::Little
    } else {
        return Err(all.err(20, format!("unknown FFF version {v_be}")));
    };
    let all = all.with_endian(endian);
    let dir = all.u32(24, "the record directory offset")? as usize;
    let n = all.u32(28, "the record count")? as usize;
    if n > (all.len().saturating_sub(dir)) / 32 {
        return Err(all.err(
            28,
            format!(
                "the record directory ({n} records at byte {dir}) runs past the end of the FFF data ({} bytes)",
                all.len()
            ),
        ));
    }
    let mut raw_rec = None;
    let mut info_rec = None;
    for i in 0..n {
        let e = dir + 32 * i;
        let ty = all.u16(e, "a record type")?;
        let off = all.u32(e + 12, "a record offset")? as usize;
        let len = all.u32(e + 16, "a record length")? as usize;
        if ty == 0 {
            continue;
        }
        let what = format!("record {i} (type {ty})");
        let rec = all.sub(off, len, &what).map_err(|_| {
            all.err(
                e + 12,
                format!(
                    "{what} at byte {off} of {len} bytes runs past the end of the FFF data ({} bytes)",
                    all.len()
                ),
            )
        })?;
        match ty {
            1 if raw_rec.is_none() => raw_rec = Some(rec),
            0x20 if info_rec.is_none() => info_rec = Some(rec),
            _ => {}
        }
    }
    let info = info_rec.ok_or_else(|| all.err(dir, "no CameraInfo record (Planck constants)"))?;
    let raw = raw_rec.ok_or_else(|| all.err(dir, "no RawData record (raw thermal image)"))?;
    let (params, metadata, median) = camera_info(info)?;
    let (raw, raw_kind, byte_swapped) = raw_data(raw)?;
    Ok(FlirFile {
        endian,
        raw,
        raw_kind,
        byte_swapped,
        params,
        metadata,
        raw_value_median: median,
        records: n,
        segments: fff.segments,
    })
}

/// True when the bytes look like a FLIR R-JPEG or FFF file.
pub fn is_flir(bytes: &[u8]) -> bool {
    bytes.starts_with(b"FFF\0")
        || bytes.starts_with(b"AFF\0")
        || (bytes.starts_with(&[0xFF, 0xD8]) && bytes.windows(5).any(|w| w == b"FLIR\0"))
}

/// Parses a FLIR radiometric JPEG or FFF file; errors carry the file offset.
pub fn parse_flir(bytes: &[u8]) -> Result<FlirFile, Corrupt> {
    let fff = if bytes.starts_with(&[0xFF, 0xD8]) {
        jpeg_fff(bytes)?
    } else {
        Fff {
            data: bytes.into(),
            pieces: vec![(0, 0)],
            segments: 0,
        }
    };
    parse_fff(&fff).map_err(|e| fff.remap(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> FlirParams {
        FlirParams {
            emissivity: 0.95,
            object_distance_m: 1.0,
            reflected_c: 20.0,
            atmospheric_c: 20.0,
            ir_window_c: 20.0,
            ir_window_transmission: 1.0,
            relative_humidity: 0.5,
            planck_r1: 16951.796875,
            planck_r2: 0.0142948674038053,
            planck_b: 1435.1,
            planck_f: 1.0,
            planck_o: -7142.0,
            alpha1: 0.006569,
            alpha2: 0.01262,
            beta1: -0.002276,
            beta2: -0.00667,
            atm_x: 1.9,
        }
    }

    #[test]
    fn blackbody_at_unit_emissivity_round_trips() {
        let p = FlirParams {
            emissivity: 1.0,
            object_distance_m: 0.0,
            ..params()
        };
        let c = p.converter();
        for t in [-10.0, 0.0, 25.0, 80.0] {
            let raw = p.raw_of(t);
            assert!((c.celsius(raw) - t).abs() < 1e-9, "{t}");
        }
    }

    #[test]
    fn lower_emissivity_reads_warmer_above_the_reflected_temperature() {
        let p = params();
        let raw = p.raw_of(40.0);
        let e95 = p.converter().celsius(raw);
        let e70 = FlirParams {
            emissivity: 0.7,
            ..p
        }
        .converter()
        .celsius(raw);
        assert!(e70 > e95 && e95 > 39.0, "{e95} {e70}");
        assert!(p.converter().celsius(-1e9).is_nan());
    }

    #[test]
    fn non_flir_and_cut_files_are_errors_not_panics() {
        assert!(parse_flir(b"").is_err());
        assert!(parse_flir(&[0xFF, 0xD8, 0xFF, 0xE1, 0x00]).is_err());
        assert!(parse_flir(b"FFF\0short").is_err());
        let mut j = vec![0xFF, 0xD8, 0xFF, 0xE1, 0x00, 0x40];
        j.extend_from_slice(b"FLIR\0\x01\x00\x00");
        let e = parse_flir(&j).unwrap_err();
        assert_eq!(e.offset, 6, "{e}");
    }
}
