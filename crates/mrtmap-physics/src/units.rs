//! Absolute temperature and temperature difference as distinct types.
//!
//! `Temperature` is a point on the thermodynamic scale, `TemperatureDelta` a difference between two
//! points. Subtracting two temperatures gives a delta; adding a delta to a temperature gives a
//! temperature; adding two temperatures does not compile. Kelvin inside, Celsius only at the edges.

use std::fmt;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

use serde::{Deserialize, Serialize};

/// 0 °C in kelvin.
pub const ZERO_CELSIUS_K: f64 = 273.15;

/// An absolute (thermodynamic) temperature, stored in kelvin.
///
/// ```
/// use mrtmap_physics::{Temperature, TemperatureDelta};
/// let t = Temperature::from_celsius(20.0) + TemperatureDelta::from_kelvin(1.5);
/// assert!((t.celsius() - 21.5).abs() < 1e-12);
/// let d = Temperature::from_celsius(25.0) - Temperature::from_celsius(22.0);
/// assert!((d.kelvin() - 3.0).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd, Default, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Temperature(f64);

impl Temperature {
    /// From kelvin.
    pub const fn from_kelvin(k: f64) -> Self {
        Self(k)
    }

    /// From degrees Celsius.
    pub fn from_celsius(c: f64) -> Self {
        Self(c + ZERO_CELSIUS_K)
    }

    /// In kelvin.
    pub const fn kelvin(self) -> f64 {
        self.0
    }

    /// In degrees Celsius.
    pub fn celsius(self) -> f64 {
        self.0 - ZERO_CELSIUS_K
    }

    /// T⁴ in K⁴ (radiant power up to σ).
    pub fn fourth_power(self) -> f64 {
        let k2 = self.0 * self.0;
        k2 * k2
    }

    /// The temperature whose fourth power is `t4` (K⁴).
    pub fn from_fourth_power(t4: f64) -> Self {
        Self(t4.sqrt().sqrt())
    }

    /// Whether the value is finite and above absolute zero.
    pub fn is_physical(self) -> bool {
        self.0.is_finite() && self.0 > 0.0
    }
}

impl fmt::Display for Temperature {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match f.precision() {
            Some(p) => write!(f, "{:.*} °C", p, self.celsius()),
            None => write!(f, "{} °C", self.celsius()),
        }
    }
}

/// A temperature difference, stored in kelvin (= degrees Celsius of difference).
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd, Default, Serialize, Deserialize)]
#[serde(transparent)]
pub struct TemperatureDelta(f64);

impl TemperatureDelta {
    /// From kelvin.
    pub const fn from_kelvin(k: f64) -> Self {
        Self(k)
    }

    /// In kelvin.
    pub const fn kelvin(self) -> f64 {
        self.0
    }

    /// Absolute value.
    pub fn abs(self) -> Self {
        Self(self.0.abs())
    }
}

impl fmt::Display for TemperatureDelta {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match f.precision() {
            Some(p) => write!(f, "{:+.*} K", p, self.0),
            None => write!(f, "{:+} K", self.0),
        }
    }
}

impl Sub for Temperature {
    type Output = TemperatureDelta;
    fn sub(self, rhs: Self) -> TemperatureDelta {
        TemperatureDelta(self.0 - rhs.0)
    }
}

impl Add<TemperatureDelta> for Temperature {
    type Output = Temperature;
    fn add(self, rhs: TemperatureDelta) -> Temperature {
        Temperature(self.0 + rhs.0)
    }
}

impl Sub<TemperatureDelta> for Temperature {
    type Output = Temperature;
    fn sub(self, rhs: TemperatureDelta) -> Temperature {
        Temperature(self.0 - rhs.0)
    }
}

impl AddAssign<TemperatureDelta> for Temperature {
    fn add_assign(&mut self, rhs: TemperatureDelta) {
        self.0 += rhs.0;
    }
}

impl SubAssign<TemperatureDelta> for Temperature {
    fn sub_assign(&mut self, rhs: TemperatureDelta) {
        self.0 -= rhs.0;
    }
}

impl Add for TemperatureDelta {
    type Output = TemperatureDelta;
    fn add(self, rhs: Self) -> Self {
        Self(self.0 + rhs.0)
    }
}

impl Sub for TemperatureDelta {
    type Output = TemperatureDelta;
    fn sub(self, rhs: Self) -> Self {
        Self(self.0 - rhs.0)
    }
}

impl Neg for TemperatureDelta {
    type Output = TemperatureDelta;
    fn neg(self) -> Self {
        Self(-self.0)
    }
}

impl Mul<f64> for TemperatureDelta {
    type Output = TemperatureDelta;
    fn mul(self, rhs: f64) -> Self {
        Self(self.0 * rhs)
    }
}

impl Div<f64> for TemperatureDelta {
    type Output = TemperatureDelta;
    fn div(self, rhs: f64) -> Self {
        Self(self.0 / rhs)
    }
}
