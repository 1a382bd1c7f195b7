//! `[comfort]` and `[air]`: the person and the air of the comfort maps and points.

use mrtmap_physics::Posture;
use mrtmap_radiation::Facing;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::settings::Quantity;

/// `[comfort]`: the person whose comfort the person's maps and points describe.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ComfortSection {
    /// Seated or standing.
    pub posture: Posture,
    /// Which way the person faces (degrees from +x towards +y); `None`: any way (averaged).
    pub facing_deg: Option<f64>,
    /// Air temperature (°C); default `[air] temperature_c`.
    pub air_temperature_c: Option<f64>,
    /// Air temperature by height, `[height m, °C]` pairs (linear between, constant beyond).
    pub air_temperature_profile: Vec<[f64; 2]>,
    /// Air speed (m/s); default `[air] speed_m_s`.
    pub air_speed_m_s: Option<f64>,
    /// Relative humidity (%).
    pub relative_humidity_pct: f64,
    /// Metabolic rate (met).
    pub met: f64,
    /// Clothing insulation (clo).
    pub clo: f64,
}

impl Default for ComfortSection {
    fn default() -> Self {
        Self {
            posture: Posture::Seated,
            facing_deg: None,
            air_temperature_c: None,
            air_temperature_profile: Vec::new(),
            air_speed_m_s: None,
            relative_humidity_pct: 50.0,
            met: 1.2,
            clo: 0.7,
        }
    }
}

impl ComfortSection {
    /// Which way the person faces.
    pub fn facing(&self) -> Facing {
        self.facing_deg.map_or(Facing::Any, Facing::Azimuth)
    }

    /// The air temperature (°C) at `height_m` above the floor: the profile, else the one value
    /// here, else `[air]`'s; `None` when none is given.
    pub fn air_at(&self, air: &AirSection, height_m: f64) -> Option<f64> {
        let p = &self.air_temperature_profile;
        if let (Some(first), Some(last)) = (p.first(), p.last()) {
            if height_m <= first[0] {
                return Some(first[1]);
            }
            if height_m >= last[0] {
                return Some(last[1]);
            }
            return p.windows(2).find_map(|w| {
                let ([h0, t0], [h1, t1]) = (w[0], w[1]);
                (height_m >= h0 && height_m <= h1)
                    .then(|| t0 + (t1 - t0) * (height_m - h0) / (h1 - h0).max(1e-12))
            });
        }
        self.air_temperature_c.or(air.temperature_c)
    }

    /// The air speed (m/s).
    pub fn air_speed(&self, air: &AirSection) -> f64 {
        self.air_speed_m_s.unwrap_or(air.speed_m_s)
    }

    /// Checks ranges, and that the air is given when `quantities` need it.
    pub fn check(&self, air: &AirSection, quantities: &[Quantity]) -> Result<()> {
        let bad = |key: &str, v: f64, allowed: &str| {
            Error::setting(
                format!("[comfort] {key} = {v}"),
                format!("is outside {allowed}"),
            )
        };
        if !(0.0..=100.0).contains(&self.relative_humidity_pct) {
            return Err(bad(
                "relative_humidity_pct",
                self.relative_humidity_pct,
                "0…100 %",
            ));
        }
        if !(0.5..=5.0).contains(&self.met) {
            return Err(bad("met", self.met, "0.5…5 met"));
        }
        if !(0.0..=3.0).contains(&self.clo) {
            return Err(bad("clo", self.clo, "0…3 clo"));
        }
        let v = self.air_speed(air);
        if !(0.0..=5.0).contains(&v) {
            // Named where it was given: [comfort]'s own speed, else [air]'s.
            return Err(match self.air_speed_m_s {
                Some(_) => bad("air_speed_m_s", v, "0…5 m/s"),
                None => Error::setting(format!("[air] speed_m_s = {v}"), "is outside 0…5 m/s"),
            });
        }
        if let Some(f) = self.facing_deg
            && !f.is_finite()
        {
            return Err(bad("facing_deg", f, "finite degrees"));
        }
        // Air a room's occupants breathe: a typo (500 for 50, °F for °C) is refused, not mapped.
        let airs = [
            ("[air] temperature_c", air.temperature_c),
            ("[comfort] air_temperature_c", self.air_temperature_c),
        ]
        .into_iter()
        .filter_map(|(k, v)| v.map(|v| (k, v)))
        .chain(
            self.air_temperature_profile
                .iter()
                .map(|h| ("[comfort] air_temperature_profile", h[1])),
        );
        for (key, t) in airs {
            if !(AIR_RANGE_C.0..=AIR_RANGE_C.1).contains(&t) {
                return Err(Error::setting(
                    format!("{key} = {t}"),
                    format!(
                        "is outside {}…{} °C, the air of a room people occupy (in °C, not °F)",
                        AIR_RANGE_C.0, AIR_RANGE_C.1
                    ),
                ));
            }
        }
        let p = &self.air_temperature_profile;
        if p.windows(2).any(|w| w[1][0] <= w[0][0]) || p.iter().flatten().any(|x| !x.is_finite()) {
            return Err(Error::setting(
                "[comfort] air_temperature_profile",
                "must list [height m, °C] pairs with heights increasing",
            ));
        }
        if quantities.iter().any(|q| q.needs_air()) && self.air_at(air, 1.0).is_none() {
            return Err(Error::setting(
                "[map] quantities",
                "include operative, pmv or ppd, which need the air temperature: set [comfort] air_temperature_c (or [air] temperature_c, --air-c)",
            ));
        }
        Ok(())
    }
}

/// The error for `mrt_sun` asked for without `[sun]`.
pub fn no_sun_error() -> Error {
    Error::setting(
        "mrt_sun",
        "needs the sun: give [sun] in project.toml (--config) with altitude_deg and azimuth_deg (or date_time, latitude_deg, longitude_deg), dni_w_m2 and transmittance",
    )
}

/// The air temperatures accepted (°C): a room people occupy.
pub const AIR_RANGE_C: (f64, f64) = (-30.0, 60.0);

/// `[air]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AirSection {
    /// Air temperature (°C).
    pub temperature_c: Option<f64>,
    /// Air speed (m/s).
    pub speed_m_s: f64,
}

impl Default for AirSection {
    fn default() -> Self {
        Self {
            temperature_c: None,
            speed_m_s: 0.1,
        }
    }
}
