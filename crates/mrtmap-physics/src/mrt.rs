//! Mean radiant temperature from view factors and surface temperatures (ISO 7726).
//!
//! Tr⁴ = Σ εᵢFᵢTᵢ⁴ / Σ εᵢFᵢ, in kelvin; with every ε = 1 this is the plain Σ FᵢTᵢ⁴ / Σ Fᵢ.
//! Averaging is in T⁴ (radiant power), never linear in T.

use crate::error::{PhysicsError, finite, in_range};
use crate::units::Temperature;

/// One surface (or part of one) as seen from the point: its view factor, radiant temperature,
/// emissivity and the standard uncertainty of its temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiantSource {
    /// View factor from the point (a small sphere) to the surface, 0…1.
    pub view_factor: f64,
    /// The surface's temperature.
    pub temperature: Temperature,
    /// Emissivity, 0 < ε ≤ 1 (1 for a radiant temperature read by an IR camera at ε = 1).
    pub emissivity: f64,
    /// Standard uncertainty of the temperature in kelvin (0 when unknown or exact).
    pub temperature_std_k: f64,
}

impl RadiantSource {
    /// A black (ε = 1) source with an exact temperature.
    pub fn black(view_factor: f64, temperature: Temperature) -> Self {
        Self {
            view_factor,
            temperature,
            emissivity: 1.0,
            temperature_std_k: 0.0,
        }
    }
}

/// The mean radiant temperature and how uncertain it is given the sources' temperature
/// uncertainties (assumed independent).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeanRadiant {
    /// Tr.
    pub temperature: Temperature,
    /// Σ εᵢFᵢ: the weight behind the average (1 for a closed black enclosure).
    pub weight: f64,
    /// Standard uncertainty of Tr in kelvin propagated from the sources' `temperature_std_k`.
    pub std_from_temperatures_k: f64,
}

/// ISO 7726 mean radiant temperature from view factors, temperatures and emissivities.
///
/// ```
/// use mrtmap_physics::{RadiantSource, Temperature, mean_radiant_temperature};
/// let c = Temperature::from_celsius;
/// let mrt = mean_radiant_temperature(&[
///     RadiantSource { view_factor: 0.5, temperature: c(20.0), emissivity: 1.0, temperature_std_k: 0.0 },
///     RadiantSource { view_factor: 0.3, temperature: c(15.0), emissivity: 0.9, temperature_std_k: 0.0 },
///     RadiantSource { view_factor: 0.2, temperature: c(10.0), emissivity: 0.8, temperature_std_k: 0.0 },
/// ]).unwrap();
/// assert!((mrt.temperature.celsius() - 16.902).abs() < 1e-3);
/// ```
pub fn mean_radiant_temperature(sources: &[RadiantSource]) -> Result<MeanRadiant, PhysicsError> {
    let mut weight = 0.0;
    let mut sum_t4 = 0.0;
    for s in sources {
        in_range("view factor", s.view_factor, 0.0, 1.0 + 1e-9)?;
        in_range("emissivity", s.emissivity, 0.0, 1.0)?;
        finite("temperature", s.temperature.kelvin())?;
        if s.temperature.kelvin() <= 0.0 {
            return Err(PhysicsError::OutOfRange {
                name: "temperature (K)",
                value: s.temperature.kelvin(),
                min: 0.0,
                max: f64::INFINITY,
            });
        }
        let w = s.emissivity * s.view_factor;
        weight += w;
        sum_t4 += w * s.temperature.fourth_power();
    }
    if weight <= 0.0 {
        return Err(PhysicsError::NothingSeen { sum: weight });
    }
    let tr = Temperature::from_fourth_power(sum_t4 / weight);
    // ∂Tr/∂Tᵢ = wᵢ Tᵢ³ / (W Tr³)
    let tr3 = tr.kelvin().powi(3);
    let var: f64 = sources
        .iter()
        .map(|s| {
            let d = s.emissivity * s.view_factor * s.temperature.kelvin().powi(3) / (weight * tr3);
            (d * s.temperature_std_k).powi(2)
        })
        .sum();
    Ok(MeanRadiant {
        temperature: tr,
        weight,
        std_from_temperatures_k: var.sqrt(),
    })
}

/// Running radiant average of weighted temperature samples: (Σ wₖTₖ⁴ / Σ wₖ)^¼.
///
/// Used wherever many samples (pixels, voxels, observations) make one radiant temperature; it also
/// keeps the weighted spread so a standard deviation can be reported.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RadiantAverage {
    sum_w: f64,
    sum_w2: f64,
    sum_wt4: f64,
    sum_wt: f64,
    sum_wtt: f64,
    count: u64,
}

impl RadiantAverage {
    /// An empty average.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one sample with weight `w` (ignored unless w > 0 and T is physical).
    pub fn add(&mut self, temperature: Temperature, w: f64) {
        if !(w > 0.0 && w.is_finite() && temperature.is_physical()) {
            return;
        }
        let t = temperature.kelvin();
        self.sum_w += w;
        self.sum_w2 += w * w;
        self.sum_wt4 += w * temperature.fourth_power();
        self.sum_wt += w * t;
        self.sum_wtt += w * t * t;
        self.count += 1;
    }

    /// Merges another average into this one.
    pub fn merge(&mut self, other: &Self) {
        self.sum_w += other.sum_w;
        self.sum_w2 += other.sum_w2;
        self.sum_wt4 += other.sum_wt4;
        self.sum_wt += other.sum_wt;
        self.sum_wtt += other.sum_wtt;
        self.count += other.count;
    }

    /// Number of samples taken.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Σ w.
    pub fn total_weight(&self) -> f64 {
        self.sum_w
    }

    /// The radiant average, or `None` without samples.
    pub fn mean(&self) -> Option<Temperature> {
        (self.sum_w > 0.0).then(|| Temperature::from_fourth_power(self.sum_wt4 / self.sum_w))
    }

    /// Weighted standard deviation of the samples (K), or `None` with fewer than two samples.
    pub fn std_dev_k(&self) -> Option<f64> {
        if self.count < 2 || self.sum_w <= 0.0 {
            return None;
        }
        let mean = self.sum_wt / self.sum_w;
        let var = (self.sum_wtt / self.sum_w - mean * mean).max(0.0);
        // Reliability-weights correction: V1² / (V1² − V2).
        let denom = self.sum_w * self.sum_w - self.sum_w2;
        let corr = if denom > 0.0 {
            self.sum_w * self.sum_w / denom
        } else {
            1.0
        };
        Some((var * corr).sqrt())
    }

    /// Effective number of samples (Kish): (Σw)² / Σw².
    pub fn effective_count(&self) -> f64 {
        if self.sum_w2 > 0.0 {
            self.sum_w * self.sum_w / self.sum_w2
        } else {
            0.0
        }
    }

    /// Standard error of the mean (K): standard deviation / √(effective count).
    pub fn std_error_k(&self) -> Option<f64> {
        self.std_dev_k().map(|s| s / self.effective_count().sqrt())
    }
}
