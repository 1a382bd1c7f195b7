//! `mrtmap thermal`: one thermal image → metadata, statistics, CSV / PNG.

use anyhow::bail;
use mrtmap_pipeline::files::FlirOverrides;
use mrtmap_pipeline::files::{FileError, ThermalOptions, encode_png16};
use serde::Serialize;

use crate::cli::ThermalArgs;
use mrtmap_pipeline::files::write_atomic;

use crate::output::json;

pub(crate) fn options(a: &ThermalArgs) -> anyhow::Result<ThermalOptions> {
    if let Some(e) = a.emissivity
        && !(e > 0.0 && e <= 1.0)
    {
        bail!("--emissivity {e} is outside (0, 1]");
    }
    if let Some(h) = a.humidity
        && !(0.0..=100.0).contains(&h)
    {
        bail!("--humidity {h} is outside 0…100 %");
    }
    if let Some(d) = a.distance
        && !(d >= 0.0 && d.is_finite())
    {
        bail!("--distance {d} must be a distance in metres, 0 or more");
    }
    if let Some(s) = a.scale
        && !(s > 0.0 && s.is_finite())
    {
        bail!("--scale {s} must be a positive number of kelvin per count");
    }
    Ok(ThermalOptions {
        size: a.size,
        scale_k: a.scale,
        offset_k: a.offset_k,
        flir: FlirOverrides {
            emissivity: a.emissivity,
            object_distance_m: a.distance,
            reflected_c: a.reflected,
            atmospheric_c: a.atmospheric,
            relative_humidity: a.humidity.map(|h| h / 100.0),
        },
    })
}

#[derive(Serialize)]
struct Out<'a> {
    file: String,
    format: &'static str,
    width: u32,
    height: u32,
    min_c: f64,
    max_c: f64,
    mean_c: f64,
    median_c: f64,
    centre_c: f64,
    invalid_pixels: usize,
    metadata: &'a [(String, String)],
    notes: &'a [String],
}

pub fn run(a: &ThermalArgs) -> anyhow::Result<()> {
    let opts = options(a)?;
    let img = mrtmap_pipeline::files::read_thermal_file(&a.file, &opts)?;
    let Some((lo, hi, mean, median)) = img.stats() else {
        bail!(
            "{}: no pixel has a temperature (raw values outside the calibration)",
            a.file.display()
        );
    };
    let centre = img.celsius[(img.height / 2 * img.width + img.width / 2) as usize];
    let out = Out {
        file: a.file.display().to_string(),
        format: img.kind.name(),
        width: img.width,
        height: img.height,
        min_c: lo,
        max_c: hi,
        mean_c: mean,
        median_c: median,
        centre_c: centre,
        invalid_pixels: img.celsius.iter().filter(|c| !c.is_finite()).count(),
        metadata: &img.metadata,
        notes: &img.notes,
    };
    if let Some(p) = &a.csv {
        write_atomic(p, img.csv().as_bytes())?;
    }
    if let Some(p) = &a.png {
        let png = img.iron_png(lo, hi).map_err(|e| FileError::encode(p, e))?;
        write_atomic(p, &png)?;
    }
    if let Some(p) = &a.centikelvin {
        let png = encode_png16(&img.centikelvin()).map_err(|e| FileError::encode(p, e))?;
        write_atomic(p, &png)?;
    }
    if a.json {
        out!("{}", json(&out)?);
        return Ok(());
    }
    outln!(
        "{}: {}, {}×{} pixels",
        out.file,
        out.format,
        out.width,
        out.height
    );
    for n in &img.notes {
        outln!("  {n}");
    }
    if !img.metadata.is_empty() {
        outln!("metadata:");
        let w = img.metadata.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
        for (k, v) in &img.metadata {
            outln!("  {k:<w$}  {v}");
        }
    }
    outln!(
        "temperature °C: min {lo:.2}  max {hi:.2}  mean {mean:.2}  median {median:.2}  centre {centre:.2}"
    );
    if out.invalid_pixels > 0 {
        outln!(
            "{} pixels have no temperature (raw value outside the calibration)",
            out.invalid_pixels
        );
    }
    for (flag, p) in [
        ("csv", &a.csv),
        ("png", &a.png),
        ("centikelvin", &a.centikelvin),
    ] {
        if let Some(p) = p {
            outln!("wrote {} ({flag})", p.display());
        }
    }
    Ok(())
}
