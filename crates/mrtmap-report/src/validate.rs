//! Validation against black-globe readings: each reading converted to MRT (ISO 7726 general
//! formula, and the mixed-convection correction of Teitelbaum et al.), beside the map's MRT at
//! the same point, with ISO 7726's accuracy classes (required ±2 K, desired ±0.2 K).
//!
//! `globe.csv` has a header and the columns `label,x,y,z,tg_c,ta_c,va_m_s,diameter_m,emissivity`;
//! x, y, z are in the scan's frame (the frame of scene.json); blank lines and lines starting with
//! `#` are skipped.

use mrtmap_physics::{Globe, GlobeMethod, GlobeReading, Temperature, mrt_from_globe};
use serde::{Deserialize, Serialize};

use crate::ReportError;

/// ISO 7726's required accuracy of MRT (K).
pub const ISO_REQUIRED_K: f64 = 2.0;
/// ISO 7726's desired accuracy of MRT (K).
pub const ISO_DESIRED_K: f64 = 0.2;

/// One globe reading.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GlobeRow {
    /// Location label.
    pub label: String,
    /// Position in the scan's frame (m).
    pub xyz: [f64; 3],
    /// Globe temperature (°C).
    pub tg_c: f64,
    /// Air temperature (°C).
    pub ta_c: f64,
    /// Air speed (m/s).
    pub va_m_s: f64,
    /// Globe diameter (m).
    pub diameter_m: f64,
    /// Globe emissivity.
    pub emissivity: f64,
}

/// Parses globe.csv text.
pub fn parse_globe_csv(text: &str, file: &str) -> Result<Vec<GlobeRow>, ReportError> {
    let mut rows = Vec::new();
    let mut header_seen = false;
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = l.split(',').map(|c| c.trim()).collect();
        if !header_seen {
            header_seen = true;
            if cols
                .first()
                .is_some_and(|c| c.eq_ignore_ascii_case("label"))
            {
                continue;
            }
        }
        let bad = |m: String| ReportError::Input(format!("{file}:{}: {m}", i + 1));
        if cols.len() != 9 {
            return Err(bad(format!(
                "expected 9 columns (label,x,y,z,tg_c,ta_c,va_m_s,diameter_m,emissivity), found {}",
                cols.len()
            )));
        }
        let num = |k: usize, name: &str| -> Result<f64, ReportError> {
            cols[k]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| bad(format!("{name} '{}' is not a number", cols[k])))
        };
        rows.push(GlobeRow {
            label: cols[0].to_string(),
            xyz: [num(1, "x")?, num(2, "y")?, num(3, "z")?],
            tg_c: num(4, "tg_c")?,
            ta_c: num(5, "ta_c")?,
            va_m_s: num(6, "va_m_s")?,
            diameter_m: num(7, "diameter_m")?,
            emissivity: num(8, "emissivity")?,
        });
    }
    if rows.is_empty() {
        return Err(ReportError::Input(format!("{file}: no readings")));
    }
    Ok(rows)
}

/// The map's MRT (°C) and its standard error (K) at a scan-frame point, or why not.
pub type MrtAt<'a> = dyn Fn(&[f64; 3]) -> Result<(f64, f64), String> + 'a;

/// A validation row. In JSON every value is a number or null, a missing one with a `…_note`
/// saying why (`mrt_mixed_note`: "globe diameter … outside …").
#[derive(Clone, Debug, PartialEq)]
pub struct ValidationRow {
    /// The reading.
    pub globe: GlobeRow,
    /// MRT from the globe by the ISO 7726 general formula (°C), or why not.
    pub mrt_iso_c: Result<f64, String>,
    /// The ISO branch used (natural or forced convection).
    pub iso_formula: String,
    /// MRT from the globe with the mixed-convection correction (°C), or why not (0.04–0.15 m globes).
    pub mrt_mixed_c: Result<f64, String>,
    /// The map's MRT at the point (°C) and its standard error (K), or why not.
    pub ours_c: Result<(f64, f64), String>,
    /// Ours − ISO (K).
    pub diff_iso_k: Option<f64>,
    /// Ours − mixed convection (K).
    pub diff_mixed_k: Option<f64>,
    /// Whether |ours − ISO| meets ISO 7726's required accuracy (±2 K).
    pub meets_required: Option<bool>,
    /// Whether it meets the desired accuracy (±0.2 K).
    pub meets_desired: Option<bool>,
}

/// The flat JSON form of a [`ValidationRow`].
#[derive(Serialize)]
struct ValidationJson<'a> {
    globe: &'a GlobeRow,
    mrt_iso_c: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mrt_iso_note: Option<&'a str>,
    iso_formula: &'a str,
    mrt_mixed_c: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mrt_mixed_note: Option<&'a str>,
    ours_c: Option<f64>,
    ours_std_error_k: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    ours_note: Option<&'a str>,
    diff_iso_k: Option<f64>,
    diff_mixed_k: Option<f64>,
    meets_required: Option<bool>,
    meets_desired: Option<bool>,
}

impl Serialize for ValidationRow {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        ValidationJson {
            globe: &self.globe,
            mrt_iso_c: self.mrt_iso_c.as_ref().ok().copied(),
            mrt_iso_note: self.mrt_iso_c.as_ref().err().map(String::as_str),
            iso_formula: &self.iso_formula,
            mrt_mixed_c: self.mrt_mixed_c.as_ref().ok().copied(),
            mrt_mixed_note: self.mrt_mixed_c.as_ref().err().map(String::as_str),
            ours_c: self.ours_c.as_ref().ok().map(|x| x.0),
            ours_std_error_k: self.ours_c.as_ref().ok().map(|x| x.1),
            ours_note: self.ours_c.as_ref().err().map(String::as_str),
            diff_iso_k: self.diff_iso_k,
            diff_mixed_k: self.diff_mixed_k,
            meets_required: self.meets_required,
            meets_desired: self.meets_desired,
        }
        .serialize(s)
    }
}

/// Validates `rows` against `ours` (MRT in °C and its standard error at a scan-frame point).
pub fn validate(rows: &[GlobeRow], ours: &MrtAt<'_>) -> Vec<ValidationRow> {
    rows.iter()
        .map(|g| {
            let globe = Globe {
                diameter_m: g.diameter_m,
                emissivity: g.emissivity,
            };
            let reading = GlobeReading {
                globe: Temperature::from_celsius(g.tg_c),
                air: Temperature::from_celsius(g.ta_c),
                air_speed_m_s: g.va_m_s,
            };
            let iso = mrt_from_globe(&globe, &reading, GlobeMethod::ISO);
            let mixed = mrt_from_globe(&globe, &reading, GlobeMethod::MixedConvection);
            let ours = ours(&g.xyz);
            let iso_c = iso
                .as_ref()
                .map(|r| r.mrt.celsius())
                .map_err(|e| e.to_string());
            let mixed_c = mixed
                .as_ref()
                .map(|r| r.mrt.celsius())
                .map_err(|e| e.to_string());
            let diff = |r: &Result<f64, String>| match (&ours, r) {
                (Ok((o, _)), Ok(x)) => Some(o - x),
                _ => None,
            };
            let d_iso = diff(&iso_c);
            ValidationRow {
                globe: g.clone(),
                iso_formula: iso
                    .map(|r| r.formula.describe().to_string())
                    .unwrap_or_default(),
                diff_iso_k: d_iso,
                diff_mixed_k: diff(&mixed_c),
                meets_required: d_iso.map(|d| d.abs() <= ISO_REQUIRED_K),
                meets_desired: d_iso.map(|d| d.abs() <= ISO_DESIRED_K),
                mrt_iso_c: iso_c,
                mrt_mixed_c: mixed_c,
                ours_c: ours,
            }
        })
        .collect()
}

/// validation.csv.
pub fn validation_csv(rows: &[ValidationRow]) -> String {
    let mut s = String::from(
        "label,x,y,z,tg_c,ta_c,va_m_s,diameter_m,emissivity,mrt_iso_c,mrt_mixed_c,ours_c,ours_std_error_k,diff_iso_k,diff_mixed_k,meets_required_2k,meets_desired_0_2k\n",
    );
    for r in rows {
        let g = &r.globe;
        let f = |x: Option<f64>| x.map(|v| format!("{v:.3}")).unwrap_or_default();
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            g.label,
            g.xyz[0],
            g.xyz[1],
            g.xyz[2],
            g.tg_c,
            g.ta_c,
            g.va_m_s,
            g.diameter_m,
            g.emissivity,
            f(r.mrt_iso_c.as_ref().ok().copied()),
            f(r.mrt_mixed_c.as_ref().ok().copied()),
            f(r.ours_c.as_ref().ok().map(|x| x.0)),
            f(r.ours_c.as_ref().ok().map(|x| x.1)),
            f(r.diff_iso_k),
            f(r.diff_mixed_k),
            r.meets_required.map(|b| b.to_string()).unwrap_or_default(),
            r.meets_desired.map(|b| b.to_string()).unwrap_or_default(),
        ));
    }
    s
}
