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
    #[error("{name} = {value} is outside the valid range {min}…{max}")]
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
