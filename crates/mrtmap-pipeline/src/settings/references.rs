//! `[[references]]`: contact-thermometer readings of surface points (also references.csv's
//! rows).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

use crate::settings::PointFrame;

/// A contact (or spot) thermometer's reading of a surface point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// Label.
    pub label: String,
    /// The point (m).
    pub xyz: [f64; 3],
    /// The reading (°C).
    pub temperature_c: f64,
    /// Its standard uncertainty (K).
    #[serde(default = "default_std")]
    pub std_k: f64,
    /// The frame of `xyz`: room (project.toml's default) or scan (references.csv's).
    #[serde(default)]
    pub frame: PointFrame,
    /// The emissivity of the surface read; unset: the emissivity of the scene's surface or
    /// feature under the point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emissivity: Option<f64>,
}

pub(crate) fn default_std() -> f64 {
    0.2
}

/// One value of a reading that is out of its range: the key (references.csv's column and
/// `[[references]]`'s key alike), the value and what is allowed.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct BadReading {
    pub key: &'static str,
    pub value: String,
    pub allowed: &'static str,
}

impl Reference {
    /// The readings of references.csv text (see docs/project.md); errors name `path` and the
    /// line.
    pub fn parse_csv(text: &str, path: &Path) -> Result<Vec<Self>> {
        parse_references(text, path)
    }

    /// Reads references.csv; errors name the file and the line.
    pub(crate) fn read_csv(path: &Path) -> Result<Vec<Self>> {
        read_references(path)
    }

    /// The one check of a reading, for references.csv's rows and `[[references]]` alike: a place
    /// (finite coordinates), a temperature within the scene's range, 0 < std_k < 50 K and
    /// 0 < emissivity ≤ 1.
    pub(crate) fn check(&self) -> Result<(), BadReading> {
        let bad = |key, value: String, allowed| {
            Err(BadReading {
                key,
                value,
                allowed,
            })
        };
        if self.xyz.iter().any(|v| !v.is_finite()) {
            return bad("xyz", format!("{:?}", self.xyz), "three numbers in metres");
        }
        let (lo, hi) = mrtmap_radiation::TEMPERATURE_RANGE_C;
        if !(self.temperature_c.is_finite() && (lo..=hi).contains(&self.temperature_c)) {
            return bad(
                "temperature_c",
                self.temperature_c.to_string(),
                "-60…200 °C",
            );
        }
        if !(self.std_k > 0.0 && self.std_k < 50.0) {
            return bad("std_k", self.std_k.to_string(), "0…50 K (above 0)");
        }
        if let Some(e) = self.emissivity
            && !(e > 0.0 && e <= 1.0)
        {
            return bad(
                "emissivity",
                e.to_string(),
                "0 < ε ≤ 1 (leave it out for the emissivity of the surface under the point)",
            );
        }
        Ok(())
    }
}

/// Reads `references.csv`; errors name the file and line.
pub(crate) fn read_references(path: &Path) -> Result<Vec<Reference>> {
    let text = std::fs::read_to_string(path).map_err(|e| mrtmap_io::FileError::io(path, e))?;
    parse_references(&text, path)
}

/// Parses references.csv text; errors name `path` and the line.
pub(crate) fn parse_references(text: &str, path: &Path) -> Result<Vec<Reference>> {
    // Excel's "CSV UTF-8" starts with a byte-order mark: read past it.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let bad = |line: usize, msg: String| Error::Config {
        path: path.to_path_buf(),
        line,
        message: msg,
    };
    let mut out = Vec::new();
    let mut header: Option<Vec<String>> = None;
    for (k, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let Some(h) = &header else {
            let names: Vec<String> = cells.iter().map(|c| c.to_lowercase()).collect();
            for need in ["label", "x", "y", "z", "temperature_c"] {
                if !names.iter().any(|n| n == need) {
                    return Err(bad(
                        k + 1,
                        format!(
                            "the header has no column '{need}' (needs label,x,y,z,temperature_c and optionally std_k, frame and emissivity)"
                        ),
                    ));
                }
            }
            header = Some(names);
            continue;
        };
        let col = |name: &str| h.iter().position(|n| n == name).and_then(|i| cells.get(i));
        let num = |name: &str| -> Result<f64> {
            let v = col(name).copied().unwrap_or("");
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(k + 1, format!("{name} '{v}' is not a number")))
        };
        let std_k = match col("std_k") {
            Some(s) if !s.is_empty() => num("std_k")?,
            _ => default_std(),
        };
        let frame = match col("frame").map(|f| f.to_lowercase()).as_deref() {
            None | Some("") | Some("room") => PointFrame::Room,
            Some("scan") => PointFrame::Scan,
            Some(other) => {
                return Err(bad(
                    k + 1,
                    format!(
                        "frame '{other}' is neither room (x, y along the floor from the room frame's origin corner, z above the floor) nor scan (the frame of trajectory.txt)"
                    ),
                ));
            }
        };
        let emissivity = match col("emissivity") {
            Some(s) if !s.is_empty() => Some(num("emissivity")?),
            _ => None,
        };
        let reading = Reference {
            label: col("label").map_or(String::new(), |s| s.to_string()),
            xyz: [num("x")?, num("y")?, num("z")?],
            temperature_c: num("temperature_c")?,
            std_k,
            frame,
            emissivity,
        };
        reading.check().map_err(|b| {
            bad(
                k + 1,
                format!("{} {} is outside {}", b.key, b.value, b.allowed),
            )
        })?;
        out.push(reading);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::path::Path;

    use super::parse_references;
    use crate::settings::Project;

    /// Issue 63: `[[references]]` in project.toml is checked as strictly as references.csv's rows,
    /// by the one checker: an emissivity above 1, NaN, 0 or negative, a negative std_k and a NaN
    /// temperature are refused naming the reading and the key (they were clamped or accepted).
    #[test]
    fn project_readings_are_checked_as_strictly_as_the_csv_s() {
        let reading = |extra: &str| {
            format!(
                "[[references]]\nlabel = \"window\"\nxyz = [4.2, 1.8, 1.5]\ntemperature_c = 11.5\n{extra}"
            )
        };
        for (extra, key) in [
            ("emissivity = 1.5\n", "emissivity = 1.5"),
            ("emissivity = nan\n", "emissivity = NaN"),
            ("emissivity = 0.0\n", "emissivity = 0"),
            ("emissivity = -0.3\n", "emissivity = -0.3"),
            ("std_k = -1.0\n", "std_k = -1"),
            ("std_k = 0.0\n", "std_k = 0"),
        ] {
            let p = Project::parse(&reading(extra)).unwrap();
            let e = p.check().unwrap_err().to_string();
            assert!(
                e.contains(&format!("[[references]] \"window\" {key}")) && e.contains("outside"),
                "{extra}: {e}"
            );
            // The same value in references.csv is refused by the same rule.
            let csv = format!(
                "label,x,y,z,temperature_c,std_k,emissivity\nwindow,4.2,1.8,1.5,11.5,{},{}\n",
                if extra.starts_with("std_k") {
                    extra.trim_start_matches("std_k = ").trim()
                } else {
                    "0.2"
                },
                if extra.starts_with("emissivity") {
                    extra.trim_start_matches("emissivity = ").trim()
                } else {
                    ""
                }
            );
            let csv_err = parse_references(&csv, Path::new("references.csv"));
            assert!(csv_err.is_err(), "{csv}");
        }
        let nan = Project::parse(
            "[[references]]\nlabel = \"wall\"\nxyz = [1.0, 0.0, 1.5]\ntemperature_c = nan\n",
        )
        .unwrap();
        let e = nan.check().unwrap_err().to_string();
        assert!(
            e.contains("[[references]] \"wall\" temperature_c = NaN"),
            "{e}"
        );
        // A good reading passes.
        Project::parse(&reading("emissivity = 0.84\nstd_k = 0.3\n"))
            .unwrap()
            .check()
            .unwrap();
    }
}
