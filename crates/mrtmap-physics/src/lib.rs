//! # mrtmap-physics
//!
//! The comfort physics of mrtmap, with no I/O: temperature units that keep absolute temperature
//! and temperature difference apart, the ISO 7726 mean radiant temperature (MRT) from view factors,
//! globe thermometer conversions both ways, operative temperature, PMV/PPD and radiant asymmetry,
//! a person's projected-area factors (seated, standing) with ISO 7726's angle-factor fit, and the
//! sun on a person (SolarCal, ASHRAE 55 Appendix C) with the sun's position (`solar`).
//!
//! ```text
//!  view factors + surface temperatures ──► mean_radiant_temperature ──► Tr
//!  globe Tg, air Ta, air speed v       ──► mrt_from_globe           ──► Tr
//!  Tr, Ta, v                           ──► globe_temperature        ──► Tg (what a globe would read)
//!  Ta, Tr, v, RH, met, clo             ──► pmv_ppd                  ──► PMV, PPD
//!  sun β, SHARP, I_dir, window, body   ──► solar_gain               ──► ERF, ΔMRT
//! ```
//!
//! ```
//! use mrtmap_physics::*;
//! let c = Temperature::from_celsius;
//! // A room seen as two halves: a cold window wall and the rest.
//! let mrt = mean_radiant_temperature(&[
//!     RadiantSource::black(0.2, c(12.0)),
//!     RadiantSource::black(0.8, c(21.0)),
//! ]).unwrap();
//! // What a standard globe would read there in still air at 21 °C, and back again.
//! let tg = globe_temperature(&Globe::STANDARD, mrt.temperature, c(21.0), 0.0, GlobeMethod::ISO).unwrap();
//! let back = mrt_from_globe(
//!     &Globe::STANDARD,
//!     &GlobeReading { globe: tg, air: c(21.0), air_speed_m_s: 0.0 },
//!     GlobeMethod::ISO,
//! ).unwrap();
//! assert!((back.mrt - mrt.temperature).kelvin().abs() < 1e-5);
//! ```

mod comfort;
mod error;
mod globe;
mod mrt;
mod person;
mod solar;
mod units;

pub use comfort::{
    AsymmetryKind, Iso7730Edition, OperativeMethod, Pmv, PmvInputs, operative_temperature, pmv_ppd,
    pmv_ppd_each, pmv_ppd_edition, pmv_ppd_many, ppd_from_pmv, radiant_asymmetry_ppd,
};
pub use error::PhysicsError;
pub use globe::{
    Convection, Globe, GlobeFormula, GlobeMethod, GlobeMrt, GlobeReading,
    MIXED_CONVECTION_DIAMETERS_M, STEFAN_BOLTZMANN, globe_convection, globe_temperature,
    mrt_from_globe,
};
pub use mrt::{MeanRadiant, RadiantAverage, RadiantSource, mean_radiant_temperature};
pub use person::{
    Category, Posture, RectangleOrientation, angle_factor_fit, angle_factor_fit_rect,
    asymmetry_limits_k, projected_area_factor, projected_area_factor_averaged,
};
pub use solar::{
    DEFAULT_ASW, DEFAULT_FLOOR_REFLECTANCE, MAX_DNI_W_M2, SOLAR_HR_W_M2K, SkyAndRoom, SolarGain,
    SolarInput, SolarInputError, SolarInputs, SolarPosture, SunPosition, UtcTime, f_svv,
    room_azimuth_deg, sharp_deg, solar_gain, solar_gain_checked, solar_gain_in,
    solar_projected_area_factor, sun_position,
};
pub use units::{Temperature, TemperatureDelta, ZERO_CELSIUS_K};
