//! Validation against black-globe readings: each reading converted to MRT (ISO 7726 general
//! formula, and the mixed-convection correction of Teitelbaum et al.), beside the map's MRT at
//! the same point, with ISO 7726's accuracy classes (required ±2 K, desired ±0.2 K).
//!
//! `globe.csv` has a header and the columns `label,x,y,z,tg_c,ta_c,va_m_s,diameter_m,emissivity`;
//! x, y, z are in the frame of scene.json (the room's own frame for a scanned room); blank lines and lines starting with
//! `#` are skipped.

use mrtmap_physics::{Globe, GlobeMethod, GlobeReading, PhysicsError, Temperature, mrt_from_globe};
use mrtmap_radiation::MrtError;
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
    /// Position (m), in the frame of the scene it is compared with.
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
    /// The 1-based line of globe.csv it was read from (0 when not read from a file).
    #[serde(default)]
    pub line: u64,
}

/// The columns of globe.csv, in the order of a file without a header.
pub const GLOBE_COLUMNS: [&str; 9] = [
    "label",
    "x",
    "y",
    "z",
    "tg_c",
    "ta_c",
    "va_m_s",
    "diameter_m",
    "emissivity",
];

/// Parses globe.csv text (RFC 4180: quoted fields may hold commas). With a header (a first row
/// naming any of the columns; `location` may stand for `label`), columns are found by name in any order and other
/// columns (time, notes…) are ignored; without one, the nine columns come in [`GLOBE_COLUMNS`]
/// order. Errors name `file` and the line.
pub fn parse_globe_csv(text: &str, file: &str) -> Result<Vec<GlobeRow>, ReportError> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut rows = Vec::new();
    let mut columns: Option<[usize; 9]> = None;
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            ReportError::Globe {
                file: file.to_string(),
                line,
                problem: e.to_string(),
            }
        })?;
        let line = record
            .position()
            .map_or(0, |p| line_of(text, p.byte() as usize));
        let bad = |problem: String| ReportError::Globe {
            file: file.to_string(),
            line,
            problem,
        };
        if record.iter().all(str::is_empty) {
            continue;
        }
        let Some(cols) = columns else {
            let named = |h: &str| {
                h.eq_ignore_ascii_case("location")
                    || GLOBE_COLUMNS.iter().any(|c| h.eq_ignore_ascii_case(c))
            };
            if record.iter().any(named) {
                let mut idx = [0usize; 9];
                for (k, name) in GLOBE_COLUMNS.iter().enumerate() {
                    idx[k] = record
                        .iter()
                        .position(|h| {
                            h.eq_ignore_ascii_case(name)
                                || (k == 0 && h.eq_ignore_ascii_case("location"))
                        })
                        .ok_or_else(|| {
                            bad(format!(
                                "the header has no column '{name}' (needs {})",
                                GLOBE_COLUMNS.join(",")
                            ))
                        })?;
                }
                columns = Some(idx);
                continue;
            }
            columns = Some([0, 1, 2, 3, 4, 5, 6, 7, 8]);
            if record.len() != 9 {
                return Err(bad(format!(
                    "expected 9 columns ({}) or a header naming them, found {}",
                    GLOBE_COLUMNS.join(","),
                    record.len()
                )));
            }
            rows.push(globe_row(
                &record,
                &[0, 1, 2, 3, 4, 5, 6, 7, 8],
                line,
                &bad,
            )?);
            continue;
        };
        rows.push(globe_row(&record, &cols, line, &bad)?);
    }
    if rows.is_empty() {
        return Err(ReportError::NoReadings {
            file: file.to_string(),
        });
    }
    Ok(rows)
}

/// The 1-based line of the first non-blank character at or after byte `at` of `text` (the csv
/// reader counts a record from the blank lines before it).
fn line_of(text: &str, at: usize) -> u64 {
    let at = at.min(text.len());
    let start = text[at..]
        .find(|c: char| !c.is_whitespace())
        .map_or(text.len(), |k| at + k);
    text[..start].matches('\n').count() as u64 + 1
}

/// One reading from a record whose column k holds [`GLOBE_COLUMNS`]`[k]` at `cols[k]`.
fn globe_row(
    record: &csv::StringRecord,
    cols: &[usize; 9],
    line: u64,
    bad: &dyn Fn(String) -> ReportError,
) -> Result<GlobeRow, ReportError> {
    let field = |k: usize| record.get(cols[k]).unwrap_or("");
    let num = |k: usize| -> Result<f64, ReportError> {
        let v = field(k);
        if v.is_empty() {
            return Err(bad(format!("{} is missing", GLOBE_COLUMNS[k])));
        }
        v.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(format!("{} '{v}' is not a number", GLOBE_COLUMNS[k])))
    };
    Ok(GlobeRow {
        label: field(0).to_string(),
        xyz: [num(1)?, num(2)?, num(3)?],
        tg_c: num(4)?,
        ta_c: num(5)?,
        va_m_s: num(6)?,
        diameter_m: num(7)?,
        emissivity: num(8)?,
        line,
    })
}

/// The map's MRT (°C) and its standard error (K) at a scan-frame point, or why not.
pub type MrtAt<'a> = dyn Fn(&[f64; 3]) -> Result<(f64, f64), MrtError> + 'a;

/// A validation row. In JSON every value is a number or null, a missing one with a `…_note`
/// saying why (`mrt_mixed_note`: "globe diameter … outside …").
#[derive(Clone, Debug, PartialEq)]
pub struct ValidationRow {
    /// The reading.
    pub globe: GlobeRow,
    /// MRT from the globe by the ISO 7726 general formula (°C), or why not.
    pub mrt_iso_c: Result<f64, PhysicsError>,
    /// The ISO branch used (natural or forced convection).
    pub iso_formula: String,
    /// MRT from the globe with the mixed-convection correction (°C), or why not (0.04–0.15 m globes).
    pub mrt_mixed_c: Result<f64, PhysicsError>,
    /// The map's MRT at the point (°C) and its standard error (K), or why not.
    pub ours_c: Result<(f64, f64), MrtError>,
    /// Ours − ISO (K).
    pub diff_iso_k: Option<f64>,
    /// Ours − mixed convection (K).
    pub diff_mixed_k: Option<f64>,
    /// Whether |ours − ISO| meets ISO 7726's required accuracy (±2 K).
    pub meets_required: Option<bool>,
    /// Whether it meets the desired accuracy (±0.2 K).
    pub meets_desired: Option<bool>,
    /// Whether this reading fixed the map's temperature level (it is then not judged).
    pub calibrates: bool,
    /// The window through which the sun (`[sun]`) reaches the globe's centre: its reading
    /// includes short-wave radiation the long-wave map does not, so it is not judged.
    pub in_sun: Option<String>,
}

/// Why a globe in the sun is not judged.
pub const IN_SUN_NOTE: &str = "in sun: its reading includes short-wave the long-wave map does not";

/// The flat JSON form of a [`ValidationRow`].
#[derive(Serialize)]
struct ValidationJson<'a> {
    globe: &'a GlobeRow,
    mrt_iso_c: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mrt_iso_note: Option<String>,
    iso_formula: &'a str,
    mrt_mixed_c: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mrt_mixed_note: Option<String>,
    ours_c: Option<f64>,
    ours_std_error_k: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    ours_note: Option<String>,
    diff_iso_k: Option<f64>,
    diff_mixed_k: Option<f64>,
    meets_required: Option<bool>,
    meets_desired: Option<bool>,
    calibrates: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    in_sun: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    in_sun_note: Option<&'static str>,
}

impl Serialize for ValidationRow {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        ValidationJson {
            globe: &self.globe,
            mrt_iso_c: self.mrt_iso_c.as_ref().ok().copied(),
            mrt_iso_note: self.mrt_iso_c.as_ref().err().map(ToString::to_string),
            iso_formula: &self.iso_formula,
            mrt_mixed_c: self.mrt_mixed_c.as_ref().ok().copied(),
            mrt_mixed_note: self.mrt_mixed_c.as_ref().err().map(ToString::to_string),
            ours_c: self.ours_c.as_ref().ok().map(|x| x.0),
            ours_std_error_k: self.ours_c.as_ref().ok().map(|x| x.1),
            ours_note: self.ours_c.as_ref().err().map(ToString::to_string),
            diff_iso_k: self.diff_iso_k,
            diff_mixed_k: self.diff_mixed_k,
            meets_required: self.meets_required,
            meets_desired: self.meets_desired,
            calibrates: self.calibrates,
            in_sun: self.in_sun.as_deref(),
            in_sun_note: self.in_sun.as_ref().map(|_| IN_SUN_NOTE),
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
            let iso_c = iso.as_ref().map(|r| r.mrt.celsius()).map_err(Clone::clone);
            let mixed_c = mixed
                .as_ref()
                .map(|r| r.mrt.celsius())
                .map_err(Clone::clone);
            let diff = |r: &Result<f64, PhysicsError>| match (&ours, r) {
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
                calibrates: false,
                in_sun: None,
            }
        })
        .collect()
}

/// validation.csv (labels quoted where they need it).
pub fn validation_csv(rows: &[ValidationRow]) -> Result<String, ReportError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let header = [
        "label",
        "x",
        "y",
        "z",
        "tg_c",
        "ta_c",
        "va_m_s",
        "diameter_m",
        "emissivity",
        "mrt_iso_c",
        "mrt_mixed_c",
        "ours_c",
        "ours_std_error_k",
        "diff_iso_k",
        "diff_mixed_k",
        "meets_required_2k",
        "meets_desired_0_2k",
        "calibrates",
        "in_sun",
    ];
    let f = |x: Option<f64>| x.map(|v| format!("{v:.3}")).unwrap_or_default();
    let b = |x: Option<bool>| x.map(|v| v.to_string()).unwrap_or_default();
    let mut records = vec![header.map(String::from).to_vec()];
    for r in rows {
        let g = &r.globe;
        records.push(vec![
            g.label.clone(),
            g.xyz[0].to_string(),
            g.xyz[1].to_string(),
            g.xyz[2].to_string(),
            g.tg_c.to_string(),
            g.ta_c.to_string(),
            g.va_m_s.to_string(),
            g.diameter_m.to_string(),
            g.emissivity.to_string(),
            f(r.mrt_iso_c.as_ref().ok().copied()),
            f(r.mrt_mixed_c.as_ref().ok().copied()),
            f(r.ours_c.as_ref().ok().map(|x| x.0)),
            f(r.ours_c.as_ref().ok().map(|x| x.1)),
            f(r.diff_iso_k),
            f(r.diff_mixed_k),
            b(r.meets_required),
            b(r.meets_desired),
            r.calibrates.to_string(),
            r.in_sun.clone().unwrap_or_default(),
        ]);
    }
    for rec in &records {
        w.write_record(rec)
            .map_err(|e| ReportError::Csv(e.to_string()))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| ReportError::Csv(e.error().to_string()))?;
    // Every cell was a String: the bytes are UTF-8.
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}
