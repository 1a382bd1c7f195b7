//! One thermal image file (`mrtmap thermal`): read with the file's own calibration or the given
//! one, summarised (metadata, temperature statistics) and exported (CSV, iron-palette PNG,
//! 16-bit centikelvin PNG).

use std::path::{Path, PathBuf};

use mrtmap_io::flir::FlirOverrides;
use mrtmap_io::{
    FileError, ThermalImage, ThermalOptions, encode_png16, read_thermal_file, write_atomic,
};
use serde::Serialize;

use crate::error::{Error, Result};

/// How to read a thermal image: for raw 16-bit values their size and scale, for FLIR files
/// replacements of the file's own object parameters (also the flags of `mrtmap thermal`).
#[derive(Clone, Debug, Default, PartialEq, clap::Args)]
pub struct ThermalReading {
    /// Size of a raw .y16/.bin file, WxH (default: 160x120 or 80x60 from the file length).
    #[arg(long, value_name = "WxH", value_parser = crate::parse::parse_image_size)]
    pub size: Option<(u32, u32)>,
    /// Kelvin per count of 16-bit PNG/TIFF/raw values.
    #[arg(long)]
    pub scale: Option<f64>,
    /// Kelvin added after scaling 16-bit values.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub offset_k: f64,
    /// FLIR: object emissivity (replaces the file's).
    #[arg(long)]
    pub emissivity: Option<f64>,
    /// FLIR: object distance, m.
    #[arg(long, allow_negative_numbers = true)]
    pub distance: Option<f64>,
    /// FLIR: reflected apparent temperature, °C.
    #[arg(long, allow_negative_numbers = true)]
    pub reflected: Option<f64>,
    /// FLIR: atmospheric temperature, °C.
    #[arg(long, allow_negative_numbers = true)]
    pub atmospheric: Option<f64>,
    /// FLIR: relative humidity, percent.
    #[arg(long)]
    pub humidity: Option<f64>,
}

impl ThermalReading {
    /// The reader's options, after checking the ranges.
    pub fn options(&self) -> Result<ThermalOptions> {
        let refuse = |flag: String, problem: &str| Err(Error::setting(flag, problem));
        if let Some(e) = self.emissivity
            && !(e > 0.0 && e <= 1.0)
        {
            return refuse(format!("--emissivity {e}"), "is outside (0, 1]");
        }
        if let Some(h) = self.humidity
            && !(0.0..=100.0).contains(&h)
        {
            return refuse(format!("--humidity {h}"), "is outside 0…100 %");
        }
        if let Some(d) = self.distance
            && !(d >= 0.0 && d.is_finite())
        {
            return refuse(
                format!("--distance {d}"),
                "must be a distance in metres, 0 or more",
            );
        }
        for (flag, t) in [
            ("--reflected", self.reflected),
            ("--atmospheric", self.atmospheric),
        ] {
            // FLIR's own range for these is −40…+150 °C or wider; below absolute zero is no
            // temperature, and beyond 1000 °C no room's.
            if let Some(t) = t
                && !(-273.15..=1000.0).contains(&t)
            {
                return refuse(
                    format!("{flag} {t}"),
                    "is outside −273.15…1000 °C: give the temperature in °C",
                );
            }
        }
        if let Some(s) = self.scale
            && !(s > 0.0 && s.is_finite())
        {
            return refuse(
                format!("--scale {s}"),
                "must be a positive number of kelvin per count",
            );
        }
        Ok(ThermalOptions {
            size: self.size,
            scale_k: self.scale,
            offset_k: self.offset_k,
            flir: FlirOverrides {
                emissivity: self.emissivity,
                object_distance_m: self.distance,
                reflected_c: self.reflected,
                atmospheric_c: self.atmospheric,
                relative_humidity: self.humidity.map(|h| h / 100.0),
            },
        })
    }
}

/// Where to export an image's temperatures.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ThermalExports {
    /// CSV of °C, one image row per line.
    pub csv: Option<PathBuf>,
    /// Iron-palette PNG, min to max.
    pub png: Option<PathBuf>,
    /// 16-bit centikelvin PNG (the recording layout's thermal encoding).
    pub centikelvin: Option<PathBuf>,
}

/// A thermal image's metadata and temperature statistics (what `mrtmap thermal --json` prints).
#[derive(Clone, Debug, Serialize)]
pub struct ThermalSummary {
    /// The file.
    pub file: String,
    /// Its format.
    pub format: &'static str,
    /// Width (pixels).
    pub width: u32,
    /// Height (pixels).
    pub height: u32,
    /// Lowest temperature (°C).
    pub min_c: f64,
    /// Highest temperature (°C).
    pub max_c: f64,
    /// Mean temperature (°C).
    pub mean_c: f64,
    /// Median temperature (°C).
    pub median_c: f64,
    /// The centre pixel's temperature (°C).
    pub centre_c: f64,
    /// Pixels without a temperature (raw value outside the calibration).
    pub invalid_pixels: usize,
    /// The file's metadata (name, value).
    pub metadata: Vec<(String, String)>,
    /// How the file was read.
    pub notes: Vec<String>,
    /// The files written, with what each is.
    #[serde(skip)]
    pub written: Vec<(&'static str, PathBuf)>,
}

/// Reads `file`, writes the exports asked for, and summarises it.
pub fn thermal_image(
    file: &Path,
    reading: &ThermalReading,
    exports: &ThermalExports,
) -> Result<ThermalSummary> {
    let img: ThermalImage = read_thermal_file(file, &reading.options()?)?;
    let Some((lo, hi, mean, median)) = img.stats() else {
        return Err(Error::source(
            file,
            "no pixel has a temperature (raw values outside the calibration)",
        ));
    };
    let mut written = Vec::new();
    if let Some(p) = &exports.csv {
        write_atomic(p, img.csv().as_bytes())?;
        written.push(("csv", p.clone()));
    }
    if let Some(p) = &exports.png {
        let png = img.iron_png(lo, hi).map_err(|e| FileError::encode(p, e))?;
        write_atomic(p, &png)?;
        written.push(("png", p.clone()));
    }
    if let Some(p) = &exports.centikelvin {
        let png = encode_png16(&img.centikelvin()).map_err(|e| FileError::encode(p, e))?;
        write_atomic(p, &png)?;
        written.push(("centikelvin", p.clone()));
    }
    Ok(ThermalSummary {
        file: file.display().to_string(),
        format: img.kind.name(),
        width: img.width,
        height: img.height,
        min_c: lo,
        max_c: hi,
        mean_c: mean,
        median_c: median,
        centre_c: img.celsius[(img.height / 2 * img.width + img.width / 2) as usize],
        invalid_pixels: img.celsius.iter().filter(|c| !c.is_finite()).count(),
        metadata: img.metadata.clone(),
        notes: img.notes.clone(),
        written,
    })
}

impl ThermalSummary {
    /// What `mrtmap thermal` prints, in lines.
    pub fn lines(&self) -> Vec<String> {
        let mut lines = vec![format!(
            "{}: {}, {}×{} pixels",
            self.file, self.format, self.width, self.height
        )];
        lines.extend(self.notes.iter().map(|n| format!("  {n}")));
        if !self.metadata.is_empty() {
            lines.push("metadata:".to_string());
            let w = self
                .metadata
                .iter()
                .map(|(k, _)| k.len())
                .max()
                .unwrap_or(0);
            lines.extend(self.metadata.iter().map(|(k, v)| format!("  {k:<w$}  {v}")));
        }
        lines.push(format!(
            "temperature °C: min {:.2}  max {:.2}  mean {:.2}  median {:.2}  centre {:.2}",
            self.min_c, self.max_c, self.mean_c, self.median_c, self.centre_c
        ));
        if self.invalid_pixels > 0 {
            lines.push(format!(
                "{} pixels have no temperature (raw value outside the calibration)",
                self.invalid_pixels
            ));
        }
        lines.extend(
            self.written
                .iter()
                .map(|(flag, p)| format!("wrote {} ({flag})", p.display())),
        );
        lines
    }
}
