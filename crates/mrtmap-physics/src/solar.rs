//! The sun on a person: SolarCal (ASHRAE 55-2023 Appendix C; Arens et al. 2015), the sky-vault
//! view fraction of a window, and where the sun is.
//!
//! SolarCal turns the short-wave radiation that reaches a person indoors into an effective
//! radiant field ERF (W/m²) and the rise ΔMRT it causes in the mean radiant temperature:
//!
//! ```text
//!  E_diff  = f_eff · f_svv · ½ · T_sol · I_diff      (sky; I_diff = 0.2 I_dir, or a weather file's)
//!  E_dir   = f_eff · f_p(β, SHARP) · T_sol · f_bes · I_dir             (the beam)
//!  E_refl  = f_eff · f_svv · ½ · T_sol · (I_dir sin β + I_diff) · R_floor   (off the floor;
//!            the beam's part only where the beam enters the room: [`SkyAndRoom`])
//!  ERF     = (E_diff + E_dir + E_refl) · α_sw / α_lw                  (α_lw = 0.95)
//!  ΔMRT    = ERF / (f_eff · h_r)                                      (h_r = 6 W/m²K)
//! ```
//!
//! f_p is the projected-area factor of a seated or standing body ([`crate::projected_area_factor`],
//! the same SolarCal table, bilinear); a supine body reads the standing table at the angles seen
//! from the body's own axis. Constants, tables and the supine rotation are pythermalcomfort 4.8's
//! `models.solar_gain` (its `h_r` is 6, not the 6.012 sometimes quoted), whose unrounded output
//! [`solar_gain`] reproduces.
//!
//! [`sun_position`] gives the sun's altitude and compass azimuth from a UTC time and a place
//! (NOAA's solar calculator, after Meeus: about 0.01° from 1901 to 2099), [`room_azimuth_deg`]
//! turns a compass azimuth into a room's frame, and [`sharp_deg`] gives SHARP from the way a
//! person faces.

use serde::{Deserialize, Serialize};

use crate::error::{PhysicsError, in_range};
use crate::person::{Posture, projected_area_factor};

/// The body's long-wave absorptivity SolarCal divides by.
const LONG_WAVE_ABSORPTIVITY: f64 = 0.95;
/// The radiative heat transfer coefficient of SolarCal (W/m²K), as pythermalcomfort has it.
pub const SOLAR_HR_W_M2K: f64 = 6.0;
/// The diffuse sky irradiance as a fraction of the direct normal irradiance.
const DIFFUSE_FRACTION: f64 = 0.2;
/// The largest direct normal irradiance accepted (W/m²): above the solar constant (about
/// 1361 W/m², 1412 at perihelion), generously.
pub const MAX_DNI_W_M2: f64 = 1500.0;
/// pythermalcomfort's default short-wave absorptivity of a person.
pub const DEFAULT_ASW: f64 = 0.7;
/// pythermalcomfort's default floor reflectance.
pub const DEFAULT_FLOOR_REFLECTANCE: f64 = 0.6;

/// A person's posture for SolarCal: seated, standing or lying on the back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum SolarPosture {
    /// Seated (pythermalcomfort's "sitting"); f_eff 0.696.
    #[default]
    #[cfg_attr(feature = "clap", value(alias = "sitting"))]
    Seated,
    /// Standing; f_eff 0.725.
    Standing,
    /// Lying on the back; the standing table read from the body's axis, f_eff 0.725.
    Supine,
}

impl SolarPosture {
    /// The fraction of the body's surface that exchanges radiation with the surroundings, as
    /// SolarCal uses it (seated 0.696, standing and supine 0.725).
    pub fn f_eff(self) -> f64 {
        match self {
            Self::Seated => Posture::Seated.f_eff(),
            Self::Standing | Self::Supine => Posture::Standing.f_eff(),
        }
    }

    /// "seated", "standing" or "supine".
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Seated => "seated",
            Self::Standing => "standing",
            Self::Supine => "supine",
        }
    }

    /// From pythermalcomfort's names ("sitting", "standing", "supine"; "seated" too), any case.
    pub fn from_name(name: &str) -> Option<Self> {
        match name.trim().to_ascii_lowercase().as_str() {
            "sitting" | "seated" => Some(Self::Seated),
            "standing" => Some(Self::Standing),
            "supine" => Some(Self::Supine),
            _ => None,
        }
    }
}

impl From<Posture> for SolarPosture {
    fn from(p: Posture) -> Self {
        match p {
            Posture::Seated => Self::Seated,
            Posture::Standing => Self::Standing,
        }
    }
}

/// What SolarCal needs: the sun, the window and the person.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolarInputs {
    /// Solar altitude β above the horizon (degrees, 0…90).
    pub altitude_deg: f64,
    /// The sun's horizontal angle from the person's front, SHARP (degrees, 0…180: 0 sun ahead,
    /// 90 beside, 180 behind; see [`sharp_deg`]).
    pub sharp_deg: f64,
    /// Direct normal irradiance I_dir outside (W/m², 0…[`MAX_DNI_W_M2`]; ASHRAE 55 Table C-2
    /// gives 200…1000 for design).
    pub dni_w_m2: f64,
    /// Total solar transmittance of the glazing with its shades (0…1).
    pub transmittance: f64,
    /// Fraction of the sky vault the person sees through the windows, f_svv (0…1; [`f_svv`]).
    pub f_svv: f64,
    /// Fraction of the body's projected area in the beam, f_bes (0…1).
    pub f_bes: f64,
    /// The person's short-wave absorptivity α_sw (0…1; 0.57–0.84 by skin and clothing, 0.7
    /// typical).
    pub asw: f64,
    /// Posture.
    pub posture: SolarPosture,
    /// Short-wave reflectance of the floor (0…1).
    pub floor_reflectance: f64,
}

/// SolarCal's answer.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolarGain {
    /// The effective radiant field of the short-wave radiation on the body (W/m²).
    pub erf_w_m2: f64,
    /// The rise of the mean radiant temperature it equals (K), to add to the long-wave MRT.
    pub delta_mrt_k: f64,
}

/// SolarCal (ASHRAE 55 Appendix C): the effective radiant field and ΔMRT of the sun on a person
/// indoors, equal to pythermalcomfort's `solar_gain` with `round_output=False`. Every input is
/// checked against its range, and the first one outside is named.
///
/// ```
/// use mrtmap_physics::{SolarInputs, SolarPosture, f_svv, solar_gain};
/// // Seated, facing a 1.8 × 1.3 m window 1.55 m away, wholly in a 30° beam.
/// let g = solar_gain(&SolarInputs {
///     altitude_deg: 30.0,
///     sharp_deg: 0.0,
///     dni_w_m2: 700.0,
///     transmittance: 0.6,
///     f_svv: f_svv(1.8, 1.3, 1.55).unwrap(),
///     f_bes: 1.0,
///     asw: 0.7,
///     posture: SolarPosture::Seated,
///     floor_reflectance: 0.6,
/// })
/// .unwrap();
/// assert!((g.delta_mrt_k - 16.41).abs() < 0.01);
/// ```
pub fn solar_gain(i: &SolarInputs) -> Result<SolarGain, PhysicsError> {
    solar_gain_in(i, &SkyAndRoom::SOLARCAL)
}

/// What SolarCal's short form assumes about the sky and the room, made explicit: the diffuse sky
/// irradiance (0.2 × the direct normal irradiance unless a weather file gives it) and whether the
/// beam lands in the room at all (else the floor reflects no beam).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkyAndRoom {
    /// The diffuse horizontal irradiance outside (W/m²), when known (an EPW file's field 16);
    /// `None`: SolarCal's 0.2 × I_dir.
    pub diffuse_horizontal_w_m2: Option<f64>,
    /// Whether the beam enters the room through some glazing: without it, the floor-reflected
    /// beam term (I_dir sin β R_floor) is left out, as no floor patch is lit.
    pub beam_enters: bool,
}

impl SkyAndRoom {
    /// SolarCal's own assumptions (pythermalcomfort's `solar_gain`): I_diff = 0.2 I_dir, a beam
    /// on the floor.
    pub const SOLARCAL: Self = Self {
        diffuse_horizontal_w_m2: None,
        beam_enters: true,
    };
}

/// SolarCal's inputs, each by what it is: which one an input error is about (a front end names
/// its own flag or key for it by this, not by the error's words).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SolarInput {
    /// The solar altitude (°).
    Altitude,
    /// SHARP, the sun's angle from the person's front (°).
    Sharp,
    /// The direct normal irradiance (W/m²).
    Dni,
    /// The glazing's solar transmittance.
    Transmittance,
    /// The sky-vault view fraction f_svv.
    FSvv,
    /// The fraction of the body in the beam f_bes.
    FBes,
    /// The person's short-wave absorptivity.
    Asw,
    /// The floor's reflectance.
    FloorReflectance,
    /// The diffuse horizontal irradiance (W/m²).
    DiffuseHorizontal,
}

impl SolarInput {
    /// Its name in an error.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Altitude => "solar altitude (°)",
            Self::Sharp => "SHARP (°)",
            Self::Dni => "direct normal irradiance (W/m²)",
            Self::Transmittance => "solar transmittance",
            Self::FSvv => "sky-vault view fraction f_svv",
            Self::FBes => "fraction of the body in the beam f_bes",
            Self::Asw => "short-wave absorptivity",
            Self::FloorReflectance => "floor reflectance",
            Self::DiffuseHorizontal => "diffuse horizontal irradiance (W/m²)",
        }
    }
}

/// A SolarCal input refused: which one, and why.
#[derive(Debug, thiserror::Error)]
#[error("{error}")]
pub struct SolarInputError {
    /// The input.
    pub input: SolarInput,
    /// Why (out of its range, or not a number).
    pub error: PhysicsError,
}

impl From<SolarInputError> for PhysicsError {
    fn from(e: SolarInputError) -> Self {
        e.error
    }
}

/// SolarCal as [`solar_gain`], with the sky's diffuse irradiance and whether the beam enters the
/// room given by `sky` (see [`SkyAndRoom`]).
pub fn solar_gain_in(i: &SolarInputs, sky: &SkyAndRoom) -> Result<SolarGain, PhysicsError> {
    Ok(solar_gain_checked(i, sky)?)
}

/// [`solar_gain_in`], an input refused with which one it is.
pub fn solar_gain_checked(i: &SolarInputs, sky: &SkyAndRoom) -> Result<SolarGain, SolarInputError> {
    let within = |input: SolarInput, v: f64, min: f64, max: f64| {
        in_range(input.name(), v, min, max).map_err(|error| SolarInputError { input, error })
    };
    let beta = within(SolarInput::Altitude, i.altitude_deg, 0.0, 90.0)?;
    let sharp = within(SolarInput::Sharp, i.sharp_deg, 0.0, 180.0)?;
    let i_dir = within(SolarInput::Dni, i.dni_w_m2, 0.0, MAX_DNI_W_M2)?;
    let t_sol = within(SolarInput::Transmittance, i.transmittance, 0.0, 1.0)?;
    let f_svv = within(SolarInput::FSvv, i.f_svv, 0.0, 1.0)?;
    let f_bes = within(SolarInput::FBes, i.f_bes, 0.0, 1.0)?;
    let asw = within(SolarInput::Asw, i.asw, 0.0, 1.0)?;
    let r_floor = within(SolarInput::FloorReflectance, i.floor_reflectance, 0.0, 1.0)?;
    let i_diff = match sky.diffuse_horizontal_w_m2 {
        Some(d) => within(SolarInput::DiffuseHorizontal, d, 0.0, MAX_DNI_W_M2)?,
        None => DIFFUSE_FRACTION * i_dir,
    };

    let fp = solar_projected_area_factor(i.posture, beta, sharp);
    let f_eff = i.posture.f_eff();
    let beam_on_floor = if sky.beam_enters {
        i_dir * beta.to_radians().sin()
    } else {
        0.0
    };
    let e_diff = f_eff * f_svv * 0.5 * t_sol * i_diff;
    let e_direct = f_eff * fp * t_sol * f_bes * i_dir;
    let e_reflected = f_eff * f_svv * 0.5 * t_sol * (beam_on_floor + i_diff) * r_floor;
    let erf = (e_diff + e_direct + e_reflected) * (asw / LONG_WAVE_ABSORPTIVITY);
    Ok(SolarGain {
        erf_w_m2: erf,
        delta_mrt_k: erf / (SOLAR_HR_W_M2K * f_eff),
    })
}

/// The projected-area factor SolarCal uses at altitude β and SHARP (degrees, in range): the
/// seated or standing table; supine, the standing table at the angles from the body's axis
/// (pythermalcomfort's `transpose_sharp_altitude`).
pub fn solar_projected_area_factor(
    posture: SolarPosture,
    altitude_deg: f64,
    sharp_deg: f64,
) -> f64 {
    match posture {
        SolarPosture::Seated => projected_area_factor(Posture::Seated, sharp_deg, altitude_deg),
        SolarPosture::Standing => projected_area_factor(Posture::Standing, sharp_deg, altitude_deg),
        SolarPosture::Supine => {
            let (alt, sharp) = (altitude_deg.to_radians(), sharp_deg.to_radians());
            let altitude = ((sharp_deg - 90.0).abs().to_radians().sin() * alt.cos())
                .clamp(-1.0, 1.0)
                .asin()
                .to_degrees();
            let sharp = (sharp.sin() * (90.0 - altitude_deg).to_radians().tan())
                .atan()
                .to_degrees();
            projected_area_factor(Posture::Standing, sharp, altitude)
        }
    }
}

/// The sky-vault view fraction f_svv of a window `width_m` × `height_m` straight ahead of a
/// person at `distance_m` (the CBE Comfort Tool's form, pythermalcomfort's `f_svv`):
/// atan(h / 2d)° · atan(w / 2d)° / 16200, the angles in degrees.
pub fn f_svv(width_m: f64, height_m: f64, distance_m: f64) -> Result<f64, PhysicsError> {
    let w = in_range("window width (m)", width_m, 0.0, 1e4)?;
    let h = in_range("window height (m)", height_m, 0.0, 1e4)?;
    let d = in_range("distance to the window (m)", distance_m, 1e-6, 1e4)?;
    let half_angle = |x: f64| (x / (2.0 * d)).atan().to_degrees();
    Ok(half_angle(h) * half_angle(w) / 16200.0)
}

/// SHARP (degrees, 0…180) of a sun at `sun_azimuth_deg` for a person facing `facing_deg`, both
/// measured the same way in one horizontal frame (a room's: from +x towards +y).
pub fn sharp_deg(facing_deg: f64, sun_azimuth_deg: f64) -> f64 {
    // + 0.0: a whole turn's −0 reads as 0.
    let d = (sun_azimuth_deg - facing_deg).rem_euclid(360.0) + 0.0;
    if d > 180.0 { 360.0 - d } else { d }
}

/// A compass azimuth (degrees clockwise from true north) in a room's frame: degrees from the
/// room's +x towards its +y (z up, right-handed), for a room whose +y axis points to compass
/// bearing `north_deg` (0 when +y is north and +x east). The result lies in 0…360.
pub fn room_azimuth_deg(compass_azimuth_deg: f64, north_deg: f64) -> f64 {
    (90.0 + north_deg - compass_azimuth_deg).rem_euclid(360.0)
}

/// A moment in Coordinated Universal Time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct UtcTime {
    /// Year (1901…2099, where the algorithm holds).
    pub year: i32,
    /// Month, 1…12.
    pub month: u32,
    /// Day of the month, 1…31.
    pub day: u32,
    /// Hour, 0…23.
    pub hour: u32,
    /// Minute, 0…59.
    pub minute: u32,
    /// Second, 0 up to (not including) 61.
    pub second: f64,
}

impl UtcTime {
    /// The Julian day (days since noon UTC, 1 January 4713 BC, Julian calendar), checked.
    pub fn julian_day(&self) -> Result<f64, PhysicsError> {
        let days = days_in_month(self.year, self.month);
        let year = in_range("year", f64::from(self.year), 1901.0, 2099.0)?;
        in_range("month", f64::from(self.month), 1.0, 12.0)?;
        in_range("day", f64::from(self.day), 1.0, f64::from(days))?;
        in_range("hour", f64::from(self.hour), 0.0, 23.0)?;
        in_range("minute", f64::from(self.minute), 0.0, 59.0)?;
        let second = in_range("second", self.second, 0.0, 60.999_999)?;
        // Meeus, Astronomical Algorithms, ch. 7 (Gregorian calendar).
        let (y, m) = if self.month <= 2 {
            (year - 1.0, f64::from(self.month) + 12.0)
        } else {
            (year, f64::from(self.month))
        };
        let a = (y / 100.0).floor();
        let b = 2.0 - a + (a / 4.0).floor();
        let day_fraction =
            (f64::from(self.hour) * 3600.0 + f64::from(self.minute) * 60.0 + second) / 86400.0;
        Ok((365.25 * (y + 4716.0)).floor()
            + (30.6001 * (m + 1.0)).floor()
            + f64::from(self.day)
            + day_fraction
            + b
            - 1524.5)
    }
}

fn days_in_month(year: i32, month: u32) -> u32 {
    let leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    match month {
        2 if leap => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Where the sun is, seen from a place on the Earth.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunPosition {
    /// Altitude above the horizon as seen (degrees; with atmospheric refraction, NOAA's
    /// correction), negative below the horizon.
    pub altitude_deg: f64,
    /// The same without refraction (degrees): 90° less the geometric zenith angle.
    pub geometric_altitude_deg: f64,
    /// Compass azimuth (degrees clockwise from true north, 0…360).
    pub azimuth_deg: f64,
    /// The sun's declination (degrees).
    pub declination_deg: f64,
    /// The equation of time (minutes: apparent less mean solar time).
    pub equation_of_time_min: f64,
}

/// The sun's position at a UTC time from a latitude (degrees, north positive) and longitude
/// (degrees, east positive): NOAA's solar calculator (after Meeus), within about 0.01° of
/// NREL's SPA between 1901 and 2099 for altitudes above a few degrees.
pub fn sun_position(
    time: &UtcTime,
    latitude_deg: f64,
    longitude_deg: f64,
) -> Result<SunPosition, PhysicsError> {
    let lat = in_range("latitude (°)", latitude_deg, -90.0, 90.0)?;
    let lon = in_range("longitude (°)", longitude_deg, -180.0, 180.0)?;
    let jd = time.julian_day()?;
    let t = (jd - 2451545.0) / 36525.0;
    let (sin, cos) = (|d: f64| d.to_radians().sin(), |d: f64| d.to_radians().cos());

    let mean_long = (280.46646 + t * (36000.76983 + t * 0.0003032)).rem_euclid(360.0);
    let mean_anom = 357.52911 + t * (35999.05029 - 0.0001537 * t);
    let ecc = 0.016708634 - t * (0.000042037 + 0.0000001267 * t);
    let centre = sin(mean_anom) * (1.914602 - t * (0.004817 + 0.000014 * t))
        + sin(2.0 * mean_anom) * (0.019993 - 0.000101 * t)
        + sin(3.0 * mean_anom) * 0.000289;
    let omega = 125.04 - 1934.136 * t;
    let apparent_long = mean_long + centre - 0.00569 - 0.00478 * sin(omega);
    let mean_obliquity =
        23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0;
    let obliquity = mean_obliquity + 0.00256 * cos(omega);
    let declination = (sin(obliquity) * sin(apparent_long)).asin().to_degrees();
    let y = (obliquity / 2.0).to_radians().tan().powi(2);
    let eot_min = 4.0
        * (y * sin(2.0 * mean_long) - 2.0 * ecc * sin(mean_anom)
            + 4.0 * ecc * y * sin(mean_anom) * cos(2.0 * mean_long)
            - 0.5 * y * y * sin(4.0 * mean_long)
            - 1.25 * ecc * ecc * sin(2.0 * mean_anom))
        .to_degrees();

    let minutes_utc = (jd + 0.5).fract() * 1440.0;
    let true_solar_min = (minutes_utc + eot_min + 4.0 * lon).rem_euclid(1440.0);
    let hour_angle = true_solar_min / 4.0 - 180.0;
    let cos_zenith = (sin(lat) * sin(declination) + cos(lat) * cos(declination) * cos(hour_angle))
        .clamp(-1.0, 1.0);
    let zenith = cos_zenith.acos().to_degrees();
    let geometric = 90.0 - zenith;
    // Clockwise from north: 180° + atan2(sin H, cos H sin φ − tan δ cos φ).
    let azimuth = (180.0
        + sin(hour_angle)
            .atan2(cos(hour_angle) * sin(lat) - declination.to_radians().tan() * cos(lat))
            .to_degrees())
    .rem_euclid(360.0);
    Ok(SunPosition {
        altitude_deg: geometric + refraction_deg(geometric),
        geometric_altitude_deg: geometric,
        azimuth_deg: azimuth,
        declination_deg: declination,
        equation_of_time_min: eot_min,
    })
}

/// NOAA's atmospheric refraction correction (degrees) at a geometric altitude (degrees).
fn refraction_deg(altitude_deg: f64) -> f64 {
    let e = altitude_deg;
    let tan_e = e.to_radians().tan();
    let arcsec = if e > 85.0 {
        0.0
    } else if e > 5.0 {
        58.1 / tan_e - 0.07 / tan_e.powi(3) + 0.000086 / tan_e.powi(5)
    } else if e > -0.575 {
        1735.0 + e * (-518.2 + e * (103.4 + e * (-12.79 + e * 0.711)))
    } else {
        -20.772 / tan_e
    };
    arcsec / 3600.0
}
