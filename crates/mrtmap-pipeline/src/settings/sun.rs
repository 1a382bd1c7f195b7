//! `[sun]`: the sun outside and the glazing, by angle or by time and place (with an EnergyPlus
//! weather file), for SolarCal's ΔMRT on a person.

use std::path::Path;

use mrtmap_physics::{DEFAULT_ASW, DEFAULT_FLOOR_REFLECTANCE};
use mrtmap_radiation::SunDirection;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// `[sun]`: the sun outside and the glazing, for SolarCal's ΔMRT on a person (the `mrt_sun` map,
/// operative temperature and PMV/PPD with the sun, and `mrtmap validate`'s globes in the beam).
/// The sun is given either by `altitude_deg` and `azimuth_deg` in the room's frame, or by
/// `date_time` (UTC) with `latitude_deg`, `longitude_deg` and `north_deg`; a sun below the
/// horizon at that time is refused (no beam: leave `[sun]` out for a night-time map).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SunSection {
    /// Solar altitude (degrees above the horizon, 0…90).
    pub altitude_deg: Option<f64>,
    /// Solar azimuth in the room's frame (degrees from +x towards +y).
    pub azimuth_deg: Option<f64>,
    /// The moment, ISO 8601 in UTC ("2026-01-15T10:30:00Z").
    pub date_time: Option<String>,
    /// Latitude (degrees, north positive), with `date_time`.
    pub latitude_deg: Option<f64>,
    /// Longitude (degrees, east positive), with `date_time`.
    pub longitude_deg: Option<f64>,
    /// The compass bearing of the room's +y axis (degrees; 0: +y north, +x east), with
    /// `date_time`.
    pub north_deg: f64,
    /// An EnergyPlus weather file (EPW), with `date_time`: its LOCATION gives the latitude and
    /// longitude (unless given) and its hour holding `date_time` (local standard time, hour ending)
    /// the direct normal irradiance (unless `dni_w_m2` is given) and the diffuse horizontal
    /// irradiance (SolarCal's sky term, else 0.2 × direct). A relative path is from the folder of
    /// the project.toml that names it (from the folder mrtmap runs in for a flag or Python).
    pub epw: Option<String>,
    /// Direct normal irradiance outside (W/m²); needed with a sun.
    pub dni_w_m2: Option<f64>,
    /// The windows' total solar transmittance with their shades (0…1); needed with a sun.
    pub transmittance: Option<f64>,
    /// The floor's short-wave reflectance (0…1).
    pub floor_reflectance: f64,
    /// The person's short-wave absorptivity (0…1).
    pub asw: f64,
}

impl Default for SunSection {
    fn default() -> Self {
        Self {
            altitude_deg: None,
            azimuth_deg: None,
            date_time: None,
            latitude_deg: None,
            longitude_deg: None,
            north_deg: 0.0,
            epw: None,
            dni_w_m2: None,
            transmittance: None,
            floor_reflectance: DEFAULT_FLOOR_REFLECTANCE,
            asw: DEFAULT_ASW,
        }
    }
}

impl SunSection {
    /// Whether any key places a sun (so that `query` gives one or an error).
    pub fn is_given(&self) -> bool {
        self.altitude_deg.is_some()
            || self.azimuth_deg.is_some()
            || self.date_time.is_some()
            || self.latitude_deg.is_some()
            || self.longitude_deg.is_some()
            || self.epw.is_some()
            || self.dni_w_m2.is_some()
            || self.transmittance.is_some()
    }

    /// The sun's altitude and room azimuth at `when` (`date_time`), at the place the keys (or the
    /// EPW file) give, and the EPW file's hour when one is given.
    fn sun_at_time(&self, when: &str) -> Result<(f64, f64, Option<EpwHour>)> {
        let time = parse_utc(when).ok_or_else(|| {
            Error::setting(
                format!("[sun] date_time = \"{when}\""),
                "is not an ISO 8601 UTC time like \"2026-01-15T10:30:00Z\"",
            )
        })?;
        let epw = match &self.epw {
            Some(path) => Some(epw_at(Path::new(path), &time)?),
            None => None,
        };
        let lat_given = self.latitude_deg.or(epw.as_ref().map(|w| w.latitude_deg));
        let lon_given = self.longitude_deg.or(epw.as_ref().map(|w| w.longitude_deg));
        let need = |key: &str, v: Option<f64>| {
            v.ok_or_else(|| {
                Error::setting(
                    "[sun] date_time",
                    format!("needs [sun] {key} to place the sun"),
                )
            })
        };
        let lat = sun_within(
            "latitude_deg",
            need("latitude_deg", lat_given)?,
            -90.0,
            90.0,
            "-90…90°",
        )?;
        let lon = sun_within(
            "longitude_deg",
            need("longitude_deg", lon_given)?,
            -180.0,
            180.0,
            "-180…180° (east positive)",
        )?;
        let north = sun_within("north_deg", self.north_deg, -360.0, 360.0, "-360…360°")?;
        let pos = mrtmap_physics::sun_position(&time, lat, lon)
            .map_err(|e| Error::setting(format!("[sun] date_time = \"{when}\""), e.to_string()))?;
        if pos.altitude_deg <= 0.0 {
            return Err(Error::setting(
                format!("[sun] date_time = \"{when}\""),
                format!(
                    "puts the sun {:.1}° below the horizon at {lat}°, {lon}°: no beam (leave [sun] out for a map without the sun)",
                    -pos.altitude_deg
                ),
            ));
        }
        Ok((
            pos.altitude_deg,
            mrtmap_physics::room_azimuth_deg(pos.azimuth_deg, north),
            epw,
        ))
    }

    /// Checks every key (the same as [`SunSection::query`] without its answer).
    pub fn check(&self) -> Result<()> {
        self.query().map(|_| ())
    }

    /// The sun in the room's frame with the glazing and the person's absorptivity; `None` when
    /// `[sun]` places no sun. Errors name the key.
    pub fn query(&self) -> Result<Option<SunQuery>> {
        if !self.is_given() {
            return Ok(None);
        }
        let bad = |key: &str, v: f64, allowed: &str| {
            Error::setting(
                format!("[sun] {key} = {v}"),
                format!("is outside {allowed}"),
            )
        };
        let within = |key: &str, v: f64, lo: f64, hi: f64, allowed: &str| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(v)
            } else {
                Err(bad(key, v, allowed))
            }
        };
        if self.epw.is_some() && self.date_time.is_none() {
            return Err(Error::setting(
                "[sun] epw",
                "needs [sun] date_time (UTC) to pick its hour",
            ));
        }
        let mut epw: Option<EpwHour> = None;
        let (altitude, azimuth) = match (
            self.altitude_deg,
            self.azimuth_deg,
            self.date_time.as_deref(),
        ) {
            (Some(_), Some(_), None)
                if self.north_deg != 0.0
                    || self.latitude_deg.is_some()
                    || self.longitude_deg.is_some() =>
            {
                return Err(Error::setting(
                    "[sun] north_deg, latitude_deg and longitude_deg",
                    "place a sun given by date_time; with altitude_deg and azimuth_deg (already in the room's frame) they would be ignored: leave them out, or give date_time instead",
                ));
            }
            (Some(alt), Some(az), None) => {
                let alt = within(
                    "altitude_deg",
                    alt,
                    0.0,
                    90.0,
                    "0…90° (a sun above the horizon)",
                )?;
                let az = within("azimuth_deg", az, -360.0, 360.0, "-360…360°")?;
                (alt, az.rem_euclid(360.0))
            }
            (None, None, Some(when)) => {
                let (alt, az, w) = self.sun_at_time(when)?;
                epw = w;
                (alt, az)
            }
            (_, _, Some(_)) => {
                return Err(Error::setting(
                    "[sun] date_time",
                    "is given with altitude_deg or azimuth_deg: place the sun one way, not both",
                ));
            }
            (None, None, None) => {
                return Err(Error::setting(
                    "[sun]",
                    "places no sun: give altitude_deg and azimuth_deg, or date_time with latitude_deg and longitude_deg",
                ));
            }
            (Some(_), None, None) | (None, Some(_), None) => {
                return Err(Error::setting(
                    "[sun] altitude_deg and azimuth_deg",
                    "go together: give both",
                ));
            }
        };
        let dni = match (self.dni_w_m2, &epw) {
            (Some(v), _) => v,
            (None, Some(w)) => w.dni_w_m2.ok_or_else(|| Error::Config {
                path: w.path.clone(),
                line: w.line,
                message: "the direct normal irradiance (field 15) of this hour is missing (9999): give [sun] dni_w_m2".into(),
            })?,
            (None, None) => {
                return Err(Error::setting(
                    "[sun] dni_w_m2",
                    "is needed with a sun: the direct normal irradiance outside (W/m²)",
                ));
            }
        };
        let dni = within(
            "dni_w_m2",
            dni,
            0.0,
            mrtmap_physics::MAX_DNI_W_M2,
            "0…1500 W/m²",
        )?;
        let tau = self.transmittance.ok_or_else(|| {
            Error::setting(
                "[sun] transmittance",
                "is needed with a sun: the windows' total solar transmittance (0…1)",
            )
        })?;
        let tau = within("transmittance", tau, 0.0, 1.0, "0…1")?;
        let floor = within("floor_reflectance", self.floor_reflectance, 0.0, 1.0, "0…1")?;
        let asw = within("asw", self.asw, 0.0, 1.0, "0…1")?;
        let mut q = SunQuery::new(altitude, azimuth, dni, tau);
        q.floor_reflectance = floor;
        q.asw = asw;
        q.diffuse_horizontal_w_m2 = epw.and_then(|w| w.dhi_w_m2);
        Ok(Some(q))
    }
}

/// `v` when finite and within `lo…hi`, else an error naming `[sun] key` and `allowed`.
fn sun_within(key: &str, v: f64, lo: f64, hi: f64, allowed: &str) -> Result<f64> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(Error::setting(
            format!("[sun] {key} = {v}"),
            format!("is outside {allowed}"),
        ))
    }
}

/// What an EPW weather file gives for one hour: its place and the hour's irradiances.
#[derive(Clone, Debug, PartialEq)]
pub struct EpwHour {
    /// The file.
    pub path: std::path::PathBuf,
    /// The row's line in it.
    pub line: usize,
    /// Latitude (degrees, north positive).
    pub latitude_deg: f64,
    /// Longitude (degrees, east positive).
    pub longitude_deg: f64,
    /// Direct normal irradiance (W/m², the file's field 15); `None` where the file marks it
    /// missing (9999).
    pub dni_w_m2: Option<f64>,
    /// Diffuse horizontal irradiance (W/m², field 16); `None` where missing.
    pub dhi_w_m2: Option<f64>,
}

/// The hour of the EnergyPlus weather file `path` that holds the instant `time` (UTC): the file's
/// LOCATION line (latitude, longitude, time zone in hours from UTC) and the data row whose month,
/// day and hour (local standard time, hour ending: hour h covers h − 1 to h) hold it, any year
/// (typical-year files mix them). The file is read and checked by [`mrtmap_io::epw::Epw`]; errors
/// name the file and, for a row or a field, the line.
pub fn epw_at(path: &Path, time: &mrtmap_physics::UtcTime) -> Result<EpwHour> {
    let epw = mrtmap_io::epw::Epw::read(path)?;
    let tz = epw.location.time_zone_h;
    // The local standard time: the time zone is within −12…+14 h, so the day moves by one at most.
    let days_in = |y: i32, m: u32| match m {
        2 if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    };
    let minutes = f64::from(time.hour * 60 + time.minute) + time.second / 60.0 + tz * 60.0;
    let day_shift = (minutes / 1440.0).floor() as i64;
    let local_min = minutes - 1440.0 * day_shift as f64;
    // Typical-year files mix years: the row is found by month, day and hour alone.
    let (mut y, mut m, mut d) = (time.year, time.month, i64::from(time.day));
    match day_shift {
        1.. => {
            d += 1;
            if d > i64::from(days_in(y, m)) {
                d = 1;
                m = m % 12 + 1;
            }
        }
        ..0 => {
            d -= 1;
            if d < 1 {
                m = if m == 1 { 12 } else { m - 1 };
                if m == 12 {
                    y -= 1;
                }
                d = i64::from(days_in(y, m));
            }
        }
        0 => {}
    }
    let hour = ((local_min / 60.0).floor() as i64 + 1).clamp(1, 24) as u32;
    let row = epw.row(m, d as u32, hour).ok_or_else(|| {
        Error::source(
            path,
            format!(
                "has no row for {m:02}-{d:02}, hour {hour} (local standard time, UTC{tz:+}): the file holds no such hour"
            ),
        )
    })?;
    Ok(EpwHour {
        path: path.to_path_buf(),
        line: row.line,
        latitude_deg: epw.location.latitude_deg,
        longitude_deg: epw.location.longitude_deg,
        dni_w_m2: row.dni_w_m2,
        dhi_w_m2: row.dhi_w_m2,
    })
}

/// An ISO 8601 time in UTC: `YYYY-MM-DDTHH:MM[:SS[.fff]]` with `Z` or `+00:00` (a space for the
/// `T` too); ranges are checked by `sun_position`.
fn parse_utc(s: &str) -> Option<mrtmap_physics::UtcTime> {
    let s = s.trim();
    let body = s
        .strip_suffix('Z')
        .or_else(|| s.strip_suffix('z'))
        .or_else(|| s.strip_suffix("+00:00"))?;
    let (date, time) = body.split_once(['T', 't', ' '])?;
    let mut d = date.split('-');
    let (year, month, day) = (d.next()?, d.next()?, d.next()?);
    if d.next().is_some() || year.len() != 4 || month.len() != 2 || day.len() != 2 {
        return None;
    }
    let mut t = time.split(':');
    let (hour, minute, second) = (t.next()?, t.next()?, t.next().unwrap_or("0"));
    if t.next().is_some() || hour.len() != 2 || minute.len() != 2 {
        return None;
    }
    let second: f64 = second.parse().ok()?;
    second.is_finite().then_some(())?;
    Some(mrtmap_physics::UtcTime {
        year: year.parse().ok()?,
        month: month.parse().ok()?,
        day: day.parse().ok()?,
        hour: hour.parse().ok()?,
        minute: minute.parse().ok()?,
        second,
    })
}

/// The sun outside and the glazing, for SolarCal at each person.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SunQuery {
    /// Where the sun is in the room's frame (altitude, and azimuth from +x towards +y).
    pub direction: SunDirection,
    /// Direct normal irradiance outside (W/m²).
    pub dni_w_m2: f64,
    /// The windows' total solar transmittance (0…1).
    pub transmittance: f64,
    /// The person's short-wave absorptivity.
    pub asw: f64,
    /// The floor's short-wave reflectance.
    pub floor_reflectance: f64,
    /// The diffuse horizontal irradiance outside (W/m²), when a weather file gives it; `None`:
    /// SolarCal's 0.2 × the direct normal irradiance.
    pub diffuse_horizontal_w_m2: Option<f64>,
}

impl SunQuery {
    /// The sun at `altitude_deg` and `azimuth_deg` (room frame) with SolarCal's default
    /// absorptivity (0.7) and floor reflectance (0.6).
    pub fn new(altitude_deg: f64, azimuth_deg: f64, dni_w_m2: f64, transmittance: f64) -> Self {
        Self {
            direction: SunDirection {
                altitude_deg,
                azimuth_deg,
            },
            dni_w_m2,
            transmittance,
            asw: DEFAULT_ASW,
            floor_reflectance: DEFAULT_FLOOR_REFLECTANCE,
            diffuse_horizontal_w_m2: None,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::settings::Project;

    /// An EPW file gives the place and the hour's direct normal irradiance: 11:00 UTC in Berlin
    /// (UTC+1) is in the local hour ending at 13:00.
    #[test]
    fn an_epw_file_gives_the_place_and_the_hour_s_irradiance() {
        let dir = tempfile::tempdir().unwrap();
        let epw = dir.path().join("berlin.epw");
        let row = |h: u32, dni: f64| {
            format!(
                "1989,1,15,{h},60,?9?9?9?9E0,1.0,-2.0,80,101000,0,0,250,150,{dni},60,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n"
            )
        };
        let text = format!(
            "LOCATION,Berlin,,DEU,IWEC Data,103840,52.47,13.40,1.0,49.0\nDESIGN CONDITIONS,0\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n{}{}",
            row(12, 100.0),
            row(13, 345.0)
        );
        std::fs::write(&epw, text).unwrap();
        let t = parse_utc("2026-01-15T11:00:00Z").unwrap();
        let h = epw_at(&epw, &t).unwrap();
        assert_eq!(
            (h.latitude_deg, h.longitude_deg, h.dni_w_m2, h.dhi_w_m2),
            (52.47, 13.40, Some(345.0), Some(60.0))
        );
        let sun = SunSection {
            date_time: Some("2026-01-15T11:00:00Z".into()),
            epw: Some(epw.display().to_string()),
            transmittance: Some(0.6),
            ..SunSection::default()
        };
        let q = sun.query().unwrap().unwrap();
        assert_eq!(q.dni_w_m2, 345.0);
        assert_eq!(q.diffuse_horizontal_w_m2, Some(60.0));
        let direct = SunSection {
            epw: None,
            latitude_deg: Some(52.47),
            longitude_deg: Some(13.40),
            dni_w_m2: Some(345.0),
            ..sun.clone()
        };
        let d = direct.query().unwrap().unwrap();
        assert!((d.direction.altitude_deg - q.direction.altitude_deg).abs() < 1e-9);
        // An hour the file does not hold, and an epw without a time, are refused by name.
        let e = epw_at(&epw, &parse_utc("2026-01-16T11:00:00Z").unwrap())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("berlin.epw") && e.contains("01-16, hour 13"),
            "{e}"
        );
        let e = SunSection {
            date_time: None,
            ..sun
        }
        .query()
        .unwrap_err()
        .to_string();
        assert!(e.contains("[sun] epw"), "{e}");
    }

    /// Issue 63: a relative `epw` is found beside the project.toml that names it (not in the
    /// folder mrtmap runs in); the hour's missing DNI (9999) is named by file, line and field, not
    /// read as 9999 W/m² and blamed on a key the user never wrote; a time zone of 1e13 is refused
    /// at once (it made `map` spin).
    #[test]
    fn a_weather_file_is_found_beside_its_project_and_read_strictly() {
        let dir = tempfile::tempdir().unwrap();
        let row = |h: u32, dni: &str| {
            format!(
                "1989,1,15,{h},60,?9?9?9?9E0,1.0,-2.0,80,101000,0,0,250,150,{dni},60,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n"
            )
        };
        let loc = "LOCATION,Berlin,,DEU,IWEC Data,103840,52.47,13.40,1.0,49.0\n";
        std::fs::write(
            dir.path().join("site.epw"),
            format!("{loc}{}{}", row(12, "100"), row(13, "9999")),
        )
        .unwrap();
        let toml = |when: &str| {
            format!("[sun]\ndate_time = \"{when}\"\nepw = \"site.epw\"\ntransmittance = 0.6\n")
        };
        std::fs::write(dir.path().join("p.toml"), toml("2026-01-15T10:30:00Z")).unwrap();
        let p = Project::load(&dir.path().join("p.toml")).unwrap();
        assert_eq!(
            Path::new(p.sun.epw.as_deref().unwrap()),
            dir.path().join("site.epw")
        );
        let q = p.sun.query().unwrap().unwrap();
        assert_eq!((q.dni_w_m2, q.diffuse_horizontal_w_m2), (100.0, Some(60.0)));
        assert_eq!(p.named_files(), vec![dir.path().join("site.epw")]);
        // 11:30 UTC is in the local hour ending at 13:00, whose DNI is missing.
        std::fs::write(dir.path().join("p.toml"), toml("2026-01-15T11:30:00Z")).unwrap();
        let e = Project::load(&dir.path().join("p.toml"))
            .unwrap()
            .sun
            .query()
            .unwrap_err()
            .to_string();
        assert!(e.contains("site.epw:3:") && e.contains("field 15"), "{e}");
        assert!(!e.contains("dni_w_m2 = 9999"), "{e}");
        std::fs::write(
            dir.path().join("site.epw"),
            format!("{}{}", loc.replace(",1.0,", ",1e13,"), row(12, "100")),
        )
        .unwrap();
        let e = Project::load(&dir.path().join("p.toml"))
            .unwrap()
            .sun
            .check()
            .unwrap_err()
            .to_string();
        assert!(e.contains("time zone (field 9) 1e13"), "{e}");
    }

    #[test]
    fn the_sun_parses_from_an_angle_or_a_time_and_place() {
        let p = Project::parse(
            "[sun]\naltitude_deg = 30.0\nazimuth_deg = -90.0\ndni_w_m2 = 700\ntransmittance = 0.6\nasw = 0.5\n",
        )
        .unwrap();
        p.check().unwrap();
        let q = p.sun.query().unwrap().unwrap();
        assert_eq!(q.direction.altitude_deg, 30.0);
        assert_eq!(q.direction.azimuth_deg, 270.0);
        assert_eq!((q.dni_w_m2, q.transmittance, q.asw), (700.0, 0.6, 0.5));
        assert_eq!(q.floor_reflectance, DEFAULT_FLOOR_REFLECTANCE);
        assert!(Project::default().sun.query().unwrap().is_none());

        // Berlin, 15 January 2026, 11:00 UTC (about solar noon): the sun due south, about 15°
        // high. With +y pointing north the room's azimuth of south is 270° (−y); with +y pointing
        // east (north_deg 90) +x points south, so the sun is near 0°.
        let text = |north: f64| {
            format!(
                "[sun]\ndate_time = \"2026-01-15T11:00:00Z\"\nlatitude_deg = 52.52\nlongitude_deg = 13.40\nnorth_deg = {north}\ndni_w_m2 = 600\ntransmittance = 0.5\n"
            )
        };
        let q = Project::parse(&text(0.0))
            .unwrap()
            .sun
            .query()
            .unwrap()
            .unwrap();
        let expect = mrtmap_physics::sun_position(
            &mrtmap_physics::UtcTime {
                year: 2026,
                month: 1,
                day: 15,
                hour: 11,
                minute: 0,
                second: 0.0,
            },
            52.52,
            13.40,
        )
        .unwrap();
        assert!((q.direction.altitude_deg - expect.altitude_deg).abs() < 1e-12);
        assert!((10.0..20.0).contains(&q.direction.altitude_deg), "{q:?}");
        assert!((q.direction.azimuth_deg - 270.0).abs() < 5.0, "{q:?}");
        let east = Project::parse(&text(90.0))
            .unwrap()
            .sun
            .query()
            .unwrap()
            .unwrap();
        let e = east.direction.azimuth_deg;
        assert!(!(5.0..=355.0).contains(&e), "{east:?}");
        assert!(
            ((e - q.direction.azimuth_deg).rem_euclid(360.0) - 90.0).abs() < 1e-9,
            "turning the room turns the sun"
        );
    }

    #[test]
    fn a_bad_sun_is_refused_naming_the_key() {
        let base = "altitude_deg = 30.0\nazimuth_deg = 0.0\ndni_w_m2 = 700\ntransmittance = 0.6\n";
        let err = |extra: &str, body: &str| {
            Project::parse(&format!("[sun]\n{body}{extra}"))
                .map_err(|(_, m)| m)
                .and_then(|p| p.check().map_err(|e| e.to_string()))
                .unwrap_err()
        };
        let e = err("", &base.replace("700", "-5"));
        assert!(e.contains("[sun] dni_w_m2 = -5"), "{e}");
        let e = err("", &base.replace("0.6", "1.6"));
        assert!(e.contains("[sun] transmittance = 1.6"), "{e}");
        let e = err("", &base.replace("30.0", "-3.0"));
        assert!(e.contains("[sun] altitude_deg = -3"), "{e}");
        let e = err("asw = 2.0\n", base);
        assert!(e.contains("[sun] asw = 2"), "{e}");
        let e = err("floor_reflectance = -0.1\n", base);
        assert!(e.contains("[sun] floor_reflectance = -0.1"), "{e}");
        let e = err(
            "",
            "altitude_deg = 30.0\nazimuth_deg = 0.0\ntransmittance = 0.6\n",
        );
        assert!(e.contains("[sun] dni_w_m2") && e.contains("needed"), "{e}");
        let e = err(
            "",
            "altitude_deg = 30.0\ndni_w_m2 = 700\ntransmittance = 0.6\n",
        );
        assert!(e.contains("azimuth_deg") && e.contains("both"), "{e}");
        let when =
            "dni_w_m2 = 700\ntransmittance = 0.6\nlatitude_deg = 52.5\nlongitude_deg = 13.4\n";
        let e = err("date_time = \"2026-13-15T10:30:00Z\"\n", when);
        assert!(
            e.contains("[sun] date_time = \"2026-13-15T10:30:00Z\""),
            "{e}"
        );
        let e = err("date_time = \"15.01.2026 10:30\"\n", when);
        assert!(e.contains("ISO 8601"), "{e}");
        // Midnight in Berlin: below the horizon, refused.
        let e = err("date_time = \"2026-01-15T23:00:00Z\"\n", when);
        assert!(e.contains("below the horizon"), "{e}");
        let e = err(
            "date_time = \"2026-01-15T11:00:00Z\"\n",
            "dni_w_m2 = 700\ntransmittance = 0.6\n",
        );
        assert!(e.contains("latitude_deg"), "{e}");
        let e = err("date_time = \"2026-01-15T11:00:00Z\"\n", base);
        assert!(e.contains("not both"), "{e}");
        assert!(Project::parse("[sun]\nsun_altitude = 3\n").is_err());
        // mrt_sun without a sun is refused before anything runs.
        let p = Project::parse("[map]\nquantities = [\"mrt_sun\"]\n").unwrap();
        let e = p.check().unwrap_err().to_string();
        assert!(e.contains("mrt_sun") && e.contains("[sun]"), "{e}");
    }
}
