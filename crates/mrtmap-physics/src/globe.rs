//! Globe thermometer ↔ mean radiant temperature (ISO 7726, Teitelbaum et al. 2022).
//!
//! A black globe settles where the radiation it exchanges balances its convection to the air:
//! εσ(Tr⁴ − Tg⁴) = h (Tg − Ta). Methods differ only in the convective coefficient h:
//!
//! | method | h |
//! |---|---|
//! | [`GlobeMethod::Iso`] | natural 1.4(|ΔT|/D)^¼, forced 6.3 v^0.6 / D^0.4, or the larger |
//! | [`GlobeMethod::IsoClosedForm`] | the standard globe's printed constants 0.4×10⁸ and 2.5×10⁸ |
//! | [`GlobeMethod::MixedConvection`] | Nusselt correlations blended with exponent n = 1.27D + 0.57 |
//!
//! [`globe_temperature`] inverts any of them numerically, so a simulated globe can be read back.

use serde::{Deserialize, Serialize};

use crate::error::{PhysicsError, finite, in_range};
use crate::units::Temperature;

/// σ as used by ISO 7726 and pythermalcomfort (W m⁻² K⁻⁴).
pub const STEFAN_BOLTZMANN: f64 = 5.67e-8;

/// The globe diameters (m) the mixed-convection correction was fitted for (Teitelbaum et al.
/// 2022): outside them it is not defined.
pub const MIXED_CONVECTION_DIAMETERS_M: std::ops::RangeInclusive<f64> = 0.04..=0.15;

/// A globe thermometer: diameter and emissivity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Globe {
    /// Diameter in metres.
    pub diameter_m: f64,
    /// Emissivity of its surface.
    pub emissivity: f64,
}

impl Globe {
    /// The standard globe of ISO 7726: 0.15 m, ε = 0.95.
    pub const STANDARD: Globe = Globe {
        diameter_m: 0.15,
        emissivity: 0.95,
    };

    fn is_standard(&self) -> bool {
        (self.diameter_m - 0.15).abs() < 1e-9 && (self.emissivity - 0.95).abs() < 1e-9
    }
}

impl Default for Globe {
    fn default() -> Self {
        Self::STANDARD
    }
}

/// Which convection regime a method uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Convection {
    /// Natural (free) convection.
    Natural,
    /// Forced convection.
    Forced,
    /// The larger of the two coefficients (what ISO 7726 prescribes).
    Larger,
}

/// How to convert a globe reading to MRT.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "method")]
pub enum GlobeMethod {
    /// ISO 7726 general formula, any diameter and emissivity.
    Iso {
        /// Regime.
        convection: Convection,
    },
    /// ISO 7726 closed forms printed for the standard globe (0.15 m, ε 0.95), as in the seed paper.
    IsoClosedForm {
        /// Regime.
        convection: Convection,
    },
    /// Teitelbaum et al. (2022) mixed-convection correction, 0.04 ≤ D ≤ 0.15 m.
    MixedConvection,
}

impl GlobeMethod {
    /// ISO 7726 general formula with the larger coefficient: the default.
    pub const ISO: GlobeMethod = GlobeMethod::Iso {
        convection: Convection::Larger,
    };
}

/// The formula that produced a result (for methods that choose, the branch that won).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GlobeFormula {
    /// ISO 7726 general formula, natural convection h = 1.4(|ΔT|/D)^¼.
    IsoNatural,
    /// ISO 7726 general formula, forced convection h = 6.3 v^0.6 / D^0.4.
    IsoForced,
    /// ISO 7726 standard-globe closed form, natural: Tr⁴ = Tg⁴ + 0.4×10⁸ |ΔT|^¼ ΔT.
    IsoClosedFormNatural,
    /// ISO 7726 standard-globe closed form, forced: Tr⁴ = Tg⁴ + 2.5×10⁸ v^0.6 ΔT.
    IsoClosedFormForced,
    /// Teitelbaum et al. (2022) mixed convection.
    MixedConvection,
}

impl GlobeFormula {
    /// A human description with the formula.
    pub fn describe(self) -> &'static str {
        match self {
            Self::IsoNatural => {
                "ISO 7726 general formula, natural convection: h = 1.4·(|Tg−Ta|/D)^¼"
            }
            Self::IsoForced => "ISO 7726 general formula, forced convection: h = 6.3·v^0.6/D^0.4",
            Self::IsoClosedFormNatural => {
                "ISO 7726 standard-globe closed form, natural convection: Tr⁴ = Tg⁴ + 0.4×10⁸·|Tg−Ta|^¼·(Tg−Ta)"
            }
            Self::IsoClosedFormForced => {
                "ISO 7726 standard-globe closed form, forced convection: Tr⁴ = Tg⁴ + 2.5×10⁸·v^0.6·(Tg−Ta)"
            }
            Self::MixedConvection => "mixed-convection correction (Teitelbaum et al. 2022)",
        }
    }
}

/// A globe reading: globe and air temperature, air speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlobeReading {
    /// Globe temperature Tg.
    pub globe: Temperature,
    /// Air temperature Ta.
    pub air: Temperature,
    /// Air speed in m/s.
    pub air_speed_m_s: f64,
}

/// Mean radiant temperature from a globe, with the formula used and the convective coefficient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlobeMrt {
    /// Tr.
    pub mrt: Temperature,
    /// The formula that gave it.
    pub formula: GlobeFormula,
    /// The convective heat-transfer coefficient h (W m⁻² K⁻¹); for the closed forms the
    /// coefficient implied by their constants.
    pub h_w_m2k: f64,
}

fn check(globe: &Globe, reading: &GlobeReading) -> Result<(), PhysicsError> {
    in_range("globe diameter (m)", globe.diameter_m, 1e-3, 1.0)?;
    in_range("globe emissivity", globe.emissivity, 0.01, 1.0)?;
    in_range("air speed (m/s)", reading.air_speed_m_s, 0.0, 100.0)?;
    in_range(
        "globe temperature (°C)",
        reading.globe.celsius(),
        -100.0,
        300.0,
    )?;
    in_range("air temperature (°C)", reading.air.celsius(), -100.0, 300.0)?;
    Ok(())
}

/// The convective coefficient h (W m⁻² K⁻¹) and formula of a method at a reading.
pub fn globe_convection(
    globe: &Globe,
    reading: &GlobeReading,
    method: GlobeMethod,
) -> Result<(f64, GlobeFormula), PhysicsError> {
    check(globe, reading)?;
    let dt = reading.globe.kelvin() - reading.air.kelvin();
    let d = globe.diameter_m;
    let v = reading.air_speed_m_s;
    let eps_sigma = globe.emissivity * STEFAN_BOLTZMANN;
    let pick = |conv: Convection, hn: f64, hf: f64, n: GlobeFormula, f: GlobeFormula| match conv {
        Convection::Natural => (hn, n),
        Convection::Forced => (hf, f),
        Convection::Larger => {
            if hf > hn {
                (hf, f)
            } else {
                (hn, n)
            }
        }
    };
    Ok(match method {
        GlobeMethod::Iso { convection } => {
            let hn = 1.4 * (dt.abs() / d).powf(0.25);
            let hf = 6.3 * v.powf(0.6) / d.powf(0.4);
            pick(
                convection,
                hn,
                hf,
                GlobeFormula::IsoNatural,
                GlobeFormula::IsoForced,
            )
        }
        GlobeMethod::IsoClosedForm { convection } => {
            if !globe.is_standard() {
                return Err(PhysicsError::OutOfRange {
                    name: "globe (the closed forms hold only for the standard 0.15 m, ε 0.95 globe) diameter (m)",
                    value: d,
                    min: 0.15,
                    max: 0.15,
                });
            }
            let hn = 0.4e8 * dt.abs().powf(0.25) * eps_sigma;
            let hf = 2.5e8 * v.powf(0.6) * eps_sigma;
            pick(
                convection,
                hn,
                hf,
                GlobeFormula::IsoClosedFormNatural,
                GlobeFormula::IsoClosedFormForced,
            )
        }
        GlobeMethod::MixedConvection => {
            in_range(
                "globe diameter for mixed convection (m)",
                d,
                *MIXED_CONVECTION_DIAMETERS_M.start(),
                *MIXED_CONVECTION_DIAMETERS_M.end(),
            )?;
            const MU: f64 = 1.81e-5;
            const K: f64 = 0.02662;
            const BETA: f64 = 0.0034;
            const NU: f64 = 1.48e-5;
            const ALPHA: f64 = 2.591e-5;
            const CP: f64 = 1004.0;
            const G: f64 = 9.81;
            let pr = CP * MU / K;
            let n = 1.27 * d + 0.57;
            let ra = G * BETA * dt.abs() * d.powi(3) / (NU * ALPHA);
            let re = v * d / NU;
            let nu_nat =
                2.0 + 0.589 * ra.powf(0.25) / (1.0 + (0.469 / pr).powf(9.0 / 16.0)).powf(4.0 / 9.0);
            let nu_forced = 2.0 + (0.4 * re.sqrt() + 0.06 * re.powf(2.0 / 3.0)) * pr.powf(0.4);
            let h = (nu_forced.powf(n) + nu_nat.powf(n)).powf(1.0 / n) * K / d;
            (h, GlobeFormula::MixedConvection)
        }
    })
}

/// Mean radiant temperature from a globe reading.
///
/// ```
/// use mrtmap_physics::{Globe, GlobeMethod, GlobeReading, Temperature, mrt_from_globe};
/// let reading = GlobeReading {
///     globe: Temperature::from_celsius(25.0),
///     air: Temperature::from_celsius(22.0),
///     air_speed_m_s: 0.0,
/// };
/// let r = mrt_from_globe(&Globe::STANDARD, &reading, GlobeMethod::ISO).unwrap();
/// assert!((r.mrt.celsius() - 26.543).abs() < 2e-3);
/// ```
pub fn mrt_from_globe(
    globe: &Globe,
    reading: &GlobeReading,
    method: GlobeMethod,
) -> Result<GlobeMrt, PhysicsError> {
    let (t4, h, formula) = mrt4_from_globe(globe, reading, method)?;
    if t4 <= 0.0 {
        return Err(PhysicsError::NoRadiantTemperature {
            globe_c: reading.globe.celsius(),
            air_c: reading.air.celsius(),
            air_speed_m_s: reading.air_speed_m_s,
        });
    }
    Ok(GlobeMrt {
        mrt: Temperature::from_fourth_power(t4),
        formula,
        h_w_m2k: h,
    })
}

/// Tr⁴ = Tg⁴ + h(Tg − Ta)/(εσ), which may be negative for readings no radiant field can produce.
fn mrt4_from_globe(
    globe: &Globe,
    reading: &GlobeReading,
    method: GlobeMethod,
) -> Result<(f64, f64, GlobeFormula), PhysicsError> {
    let (h, formula) = globe_convection(globe, reading, method)?;
    let dt = reading.globe.kelvin() - reading.air.kelvin();
    Ok((
        reading.globe.fourth_power() + h * dt / (globe.emissivity * STEFAN_BOLTZMANN),
        h,
        formula,
    ))
}

/// The temperature a globe would read at mean radiant temperature `mrt`, air temperature `air` and
/// air speed `air_speed_m_s`: the inverse of [`mrt_from_globe`], solved by bisection to 1 µK.
pub fn globe_temperature(
    globe: &Globe,
    mrt: Temperature,
    air: Temperature,
    air_speed_m_s: f64,
    method: GlobeMethod,
) -> Result<Temperature, PhysicsError> {
    finite("mean radiant temperature", mrt.kelvin())?;
    let reading = |tg: f64| GlobeReading {
        globe: Temperature::from_kelvin(tg),
        air,
        air_speed_m_s,
    };
    // Validate inputs once (at the air temperature, where Tr = Ta).
    globe_convection(globe, &reading(air.kelvin()), method)?;
    let target = mrt.kelvin();
    let target4 = mrt.fourth_power();
    let (mut lo, mut hi) = if target >= air.kelvin() {
        (air.kelvin(), target)
    } else {
        (target, air.kelvin())
    };
    // Tr⁴(Tg) increases with Tg and Tg lies between Ta and Tr. Tr⁴ is compared directly: near a
    // cold Tr with warm, fast air it is negative (no radiant field gives such a reading), which
    // only means the root lies higher.
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let (tr4, _, _) = mrt4_from_globe(globe, &reading(mid), method)?;
        if tr4 < target4 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-6 {
            return Ok(Temperature::from_kelvin(0.5 * (lo + hi)));
        }
    }
    Err(PhysicsError::NoConvergence {
        what: "globe temperature from MRT",
    })
}
