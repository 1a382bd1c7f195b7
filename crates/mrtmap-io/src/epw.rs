//! EnergyPlus weather files (EPW): the LOCATION line and the hourly rows' solar fields.
//!
//! An EPW file is CSV text: eight header lines, the first `LOCATION,city,state,country,source,
//! WMO,latitude,longitude,time zone,elevation` (exactly ten fields), then one row per hour whose
//! first fields are year, month, day, hour (1–24, local standard time, hour ending: hour h covers
//! h − 1 to h), minute and a data-source flag, with the direct normal irradiance in field 15 and
//! the diffuse horizontal irradiance in field 16 (W/m²). EnergyPlus marks a missing irradiance
//! with 9999 (its "missing" code for both fields), which is read as missing, not as a value.
//! Every field read is checked against its range, and an error names the file, the line and the
//! field.

use std::path::Path;

use crate::error::FileError;

/// EnergyPlus's missing-value code for the irradiance fields.
pub const EPW_MISSING_IRRADIANCE: f64 = 9999.0;
/// Fields in an hourly row, as EnergyPlus writes them.
pub const EPW_ROW_FIELDS: usize = 35;
/// The largest irradiance accepted (W/m²): above the solar constant (about 1361 W/m²), generously.
pub const EPW_MAX_IRRADIANCE_W_M2: f64 = 1500.0;

/// An EPW file's LOCATION line.
#[derive(Clone, Debug, PartialEq)]
pub struct EpwLocation {
    /// The city (field 2).
    pub city: String,
    /// Latitude (degrees, north positive; field 7).
    pub latitude_deg: f64,
    /// Longitude (degrees, east positive; field 8).
    pub longitude_deg: f64,
    /// The time zone: hours from UTC (−12…+14; field 9).
    pub time_zone_h: f64,
    /// Elevation (m; field 10).
    pub elevation_m: f64,
}

/// One hourly row's solar fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EpwRow {
    /// Its line in the file (1-based).
    pub line: usize,
    /// Month (1–12).
    pub month: u32,
    /// Day of the month (1–31).
    pub day: u32,
    /// Hour, local standard time, hour ending (1–24).
    pub hour: u32,
    /// Direct normal irradiance (W/m², field 15); `None` where the file says 9999 (missing).
    pub dni_w_m2: Option<f64>,
    /// Diffuse horizontal irradiance (W/m², field 16); `None` where the file says 9999.
    pub dhi_w_m2: Option<f64>,
}

/// A weather file read: its place and its hourly rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Epw {
    /// The LOCATION line.
    pub location: EpwLocation,
    /// The hourly rows, in file order.
    pub rows: Vec<EpwRow>,
}

impl Epw {
    /// Reads and checks the EPW file at `path`.
    pub fn read(path: &Path) -> Result<Self, FileError> {
        let bytes = std::fs::read(path).map_err(|e| FileError::io(path, e))?;
        let text = String::from_utf8_lossy(&bytes);
        Self::parse(path, &text)
    }

    /// Parses EPW `text` (errors name `path`).
    pub fn parse(path: &Path, text: &str) -> Result<Self, FileError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines = text.lines().enumerate();
        let (loc_k, loc_line) = lines
            .by_ref()
            .find(|(_, l)| !l.trim().is_empty())
            .ok_or_else(|| FileError::syntax(path, 1, "is empty: is it an EPW weather file?"))?;
        let line = loc_k + 1;
        if !loc_line.starts_with("LOCATION") {
            return Err(FileError::syntax(
                path,
                line,
                "does not start with a LOCATION line: is it an EPW weather file?",
            ));
        }
        let cells: Vec<&str> = loc_line.split(',').map(str::trim).collect();
        if cells.len() != 10 {
            return Err(FileError::syntax(
                path,
                line,
                format!(
                    "LOCATION has {} fields where EnergyPlus writes 10 (LOCATION, city, state, country, source, WMO, latitude, longitude, time zone, elevation): a field is missing or split",
                    cells.len()
                ),
            ));
        }
        let field = |k: usize, what: &str, lo: f64, hi: f64, allowed: &str| {
            let raw = cells[k];
            let v: f64 = raw.parse().map_err(|_| {
                FileError::syntax(
                    path,
                    line,
                    format!(
                        "LOCATION's {what} (field {}) '{raw}' is not a number",
                        k + 1
                    ),
                )
            })?;
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(v)
            } else {
                Err(FileError::syntax(
                    path,
                    line,
                    format!(
                        "LOCATION's {what} (field {}) {raw} is outside {allowed}",
                        k + 1
                    ),
                ))
            }
        };
        let location = EpwLocation {
            city: cells[1].to_string(),
            latitude_deg: field(6, "latitude", -90.0, 90.0, "-90…90°")?,
            longitude_deg: field(7, "longitude", -180.0, 180.0, "-180…180° (east positive)")?,
            time_zone_h: field(8, "time zone", -12.0, 14.0, "-12…+14 h from UTC")?,
            elevation_m: field(9, "elevation", -1000.0, 9999.9, "-1000…9999.9 m")?,
        };
        let mut rows = Vec::new();
        let mut seen = std::collections::HashMap::new();
        for (k, l) in lines {
            let line = k + 1;
            let c: Vec<&str> = l.split(',').map(str::trim).collect();
            // Header lines (DESIGN CONDITIONS, …, DATA PERIODS) start with a word.
            if c[0].is_empty() || c[0].parse::<i64>().is_err() {
                if rows.is_empty() {
                    continue;
                }
                if l.trim().is_empty() {
                    continue;
                }
                return Err(FileError::syntax(
                    path,
                    line,
                    format!("'{}' among the hourly rows is not a row of numbers", c[0]),
                ));
            }
            let row = parse_row(path, line, &c)?;
            if let Some(first) = seen.insert((row.month, row.day, row.hour), line) {
                return Err(FileError::syntax(
                    path,
                    line,
                    format!(
                        "repeats the hour of line {first} (month {}, day {}, hour {}): which one holds that hour?",
                        row.month, row.day, row.hour
                    ),
                ));
            }
            rows.push(row);
        }
        if rows.is_empty() {
            return Err(FileError::syntax(
                path,
                line,
                "has a LOCATION line but no hourly rows",
            ));
        }
        Ok(Self { location, rows })
    }

    /// The row of `month`, `day` and `hour` (local standard time, hour ending), the first one when
    /// a file holds several years.
    pub fn row(&self, month: u32, day: u32, hour: u32) -> Option<&EpwRow> {
        self.rows
            .iter()
            .find(|r| r.month == month && r.day == day && r.hour == hour)
    }
}

/// One hourly row (`c`, its fields, at `line`): exactly 35 fields, the month, day and hour in
/// range, the irradiances in range or missing (9999).
fn parse_row(path: &Path, line: usize, c: &[&str]) -> Result<EpwRow, FileError> {
    if c.len() != EPW_ROW_FIELDS {
        return Err(FileError::syntax(
            path,
            line,
            format!(
                "the hourly row has {} fields where EnergyPlus writes {EPW_ROW_FIELDS}: a field missing or added would shift the irradiances (fields 15 and 16)",
                c.len()
            ),
        ));
    }
    let int = |i: usize, what: &str, lo: u32, hi: u32| {
        c[i].parse::<u32>()
            .ok()
            .filter(|v| (lo..=hi).contains(v))
            .ok_or_else(|| {
                FileError::syntax(
                    path,
                    line,
                    format!(
                        "the {what} (field {}) '{}' is not a whole number within {lo}…{hi}",
                        i + 1,
                        c[i]
                    ),
                )
            })
    };
    let irradiance = |i: usize, what: &str| -> Result<Option<f64>, FileError> {
        let v: f64 = c[i].parse().map_err(|_| {
            FileError::syntax(
                path,
                line,
                format!("the {what} (field {}) '{}' is not a number", i + 1, c[i]),
            )
        })?;
        if v >= EPW_MISSING_IRRADIANCE {
            return Ok(None);
        }
        if v.is_finite() && (0.0..=EPW_MAX_IRRADIANCE_W_M2).contains(&v) {
            Ok(Some(v))
        } else {
            Err(FileError::syntax(
                path,
                line,
                format!(
                    "the {what} (field {}) {} is outside 0…1500 W/m² (9999 marks a missing value)",
                    i + 1,
                    c[i]
                ),
            ))
        }
    };
    let (month, day, hour) = (
        int(1, "month", 1, 12)?,
        int(2, "day", 1, 31)?,
        int(3, "hour", 1, 24)?,
    );
    Ok(EpwRow {
        line,
        month,
        day,
        hour,
        dni_w_m2: irradiance(14, "direct normal irradiance")?,
        dhi_w_m2: irradiance(15, "diffuse horizontal irradiance")?,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    const LOC: &str = "LOCATION,Berlin,,DEU,IWEC Data,103840,52.47,13.40,1.0,49.0";

    fn row(h: u32, dni: &str, dhi: &str) -> String {
        format!(
            "1989,1,15,{h},60,?9?9?9?9E0,1.0,-2.0,80,101000,0,0,250,150,{dni},{dhi},0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n"
        )
    }

    fn parse(text: &str) -> Result<Epw, String> {
        Epw::parse(Path::new("site.epw"), text).map_err(|e| e.to_string())
    }

    #[test]
    fn a_weather_file_gives_its_place_and_hours() {
        let text = format!(
            "{LOC}\nDESIGN CONDITIONS,0\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n{}{}",
            row(12, "100", "40"),
            row(13, "9999", "9999")
        );
        let w = parse(&text).unwrap();
        assert_eq!(w.location.latitude_deg, 52.47);
        assert_eq!(w.location.time_zone_h, 1.0);
        let r = w.row(1, 15, 12).unwrap();
        assert_eq!(
            (r.dni_w_m2, r.dhi_w_m2, r.line),
            (Some(100.0), Some(40.0), 4)
        );
        // 9999 is EnergyPlus's missing value, not 9999 W/m².
        let r = w.row(1, 15, 13).unwrap();
        assert_eq!((r.dni_w_m2, r.dhi_w_m2), (None, None));
        assert!(w.row(1, 16, 13).is_none());
    }

    /// A LOCATION line short of a field would be read shifted (the longitude as the latitude, the
    /// elevation as the time zone): refused by its count. Each field out of range names the file,
    /// the line and the field.
    #[test]
    fn a_malformed_weather_file_is_refused_naming_line_and_field() {
        let body = row(12, "100", "40");
        let e = parse(&format!(
            "LOCATION,Berlin,DEU,IWEC Data,103840,52.47,13.40,1.0,49.0\n{body}"
        ))
        .unwrap_err();
        assert!(e.contains("site.epw:1:") && e.contains("9 fields"), "{e}");
        for (bad, field) in [
            (LOC.replace("52.47", "95"), "latitude (field 7) 95"),
            (LOC.replace("13.40", "-200"), "longitude (field 8) -200"),
            (LOC.replace(",1.0,", ",25,"), "time zone (field 9) 25"),
            (LOC.replace(",1.0,", ",1e13,"), "time zone (field 9) 1e13"),
            (LOC.replace(",1.0,", ",nan,"), "time zone (field 9) nan"),
            (LOC.replace("52.47", "north"), "latitude (field 7) 'north'"),
        ] {
            let e = parse(&format!("{bad}\n{body}")).unwrap_err();
            assert!(
                e.contains("site.epw:1:") && e.contains(field),
                "{field}: {e}"
            );
        }
        let e = parse(&format!("{LOC}\n{}", row(12, "2000", "40"))).unwrap_err();
        assert!(
            e.contains("site.epw:2:") && e.contains("direct normal irradiance (field 15) 2000"),
            "{e}"
        );
        let e = parse(&format!("{LOC}\n{}", row(12, "100", "-4"))).unwrap_err();
        assert!(
            e.contains("diffuse horizontal irradiance (field 16) -4"),
            "{e}"
        );
        let e = parse(&format!("{LOC}\n{}", row(25, "100", "40"))).unwrap_err();
        assert!(e.contains("hour (field 4) '25'"), "{e}");
        let e = parse(&format!("{LOC}\n1989,1,15,12,60,x,1.0\n")).unwrap_err();
        assert!(e.contains("site.epw:2:") && e.contains("7 fields"), "{e}");
        // One field short anywhere would read the diffuse column as the direct one.
        let short = row(12, "100", "40").replacen(",1.0,", ",", 1);
        let e = parse(&format!("{LOC}\n{short}")).unwrap_err();
        assert!(e.contains("34 fields"), "{e}");
        let e = parse(&format!(
            "{LOC}\n{}{}",
            row(12, "100", "40"),
            row(12, "90", "40")
        ))
        .unwrap_err();
        assert!(
            e.contains("site.epw:3:") && e.contains("repeats the hour of line 2"),
            "{e}"
        );
        let e = parse("not a weather file\n").unwrap_err();
        assert!(e.contains("LOCATION"), "{e}");
        let e = parse(&format!("{LOC}\n")).unwrap_err();
        assert!(e.contains("no hourly rows"), "{e}");
    }
}
