//! The one error type of the physics crate.

/// Why a physics computation could not give a number.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PhysicsError {
    /// An input is NaN or infinite.
    #[error("{name} is not a finite number ({value})")]
    NotFinite {
        /// The input's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// An input lies outside the range where the formula applies.
    #[error("{name} = {} is outside the valid range {min}…{max}", short(*value))]
    OutOfRange {
        /// The input's name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Nothing to average: no view factor (or emissivity-weighted view factor) is positive.
    #[error("the view factors sum to {sum}: nothing is seen, so there is no radiant temperature")]
    NothingSeen {
        /// Σ εF.
        sum: f64,
    },
    /// A globe reading no surroundings could give: the globe loses more heat to the air than
    /// surroundings above absolute zero could return (Tr⁴ ≤ 0).
    #[error(
        "the globe reading implies no radiant temperature: a globe at {} °C in air at {} °C moving at {} m/s would need surroundings below absolute zero; check the globe and air temperatures and the air speed",
        short(*globe_c), short(*air_c), short(*air_speed_m_s)
    )]
    NoRadiantTemperature {
        /// Globe temperature (°C).
        globe_c: f64,
        /// Air temperature (°C).
        air_c: f64,
        /// Air speed (m/s).
        air_speed_m_s: f64,
    },
    /// A numerical solution did not converge.
    #[error("{what} did not converge")]
    NoConvergence {
        /// What was being solved.
        what: &'static str,
    },
}

pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, PhysicsError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(PhysicsError::NotFinite { name, value })
    }
}

pub(crate) fn in_range(
    name: &'static str,
    value: f64,
    min: f64,
    max: f64,
) -> Result<f64, PhysicsError> {
    finite(name, value)?;
    if value < min || value > max {
        Err(PhysicsError::OutOfRange {
            name,
            value,
            min,
            max,
        })
    } else {
        Ok(value)
    }
}

/// A number as people write it: at most six significant digits, no trailing zeros
/// (14.799999999999999 → "14.8").
pub fn short(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return format!("{v}");
    }
    let digits = (5 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(short(14.799999999999999), "14.8");
        assert_eq!(short(50.0), "50");
        assert_eq!(short(-0.00012345678), "-0.000123457");
        assert_eq!(short(123456789.0), "123456789");
        let e = PhysicsError::OutOfRange {
            name: "relative air speed (m/s)",
            value: 0.1 + 0.3 * 49.0,
            min: 0.0,
            max: 10.0,
        };
        assert_eq!(
            e.to_string(),
            "relative air speed (m/s) = 14.8 is outside the valid range 0…10"
        );
    }
}
