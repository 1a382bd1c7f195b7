//! `[[references]]`: contact-thermometer readings of surface points (also references.csv's
//! rows).

use serde::{Deserialize, Serialize};

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
    pub fn parse_csv(text: &str, path: &std::path::Path) -> crate::Result<Vec<Self>> {
        crate::level::parse_references(text, path)
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::path::Path;

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
            let csv_err = crate::level::parse_references(&csv, Path::new("references.csv"));
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
