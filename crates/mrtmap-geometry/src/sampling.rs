//! Direction sets on the unit sphere for Monte Carlo view factors.
//!
//! - [`DirectionSet::Random`]: independent uniform directions (z = 1 − 2u, φ = 2πv).
//! - [`DirectionSet::Fibonacci`]: the spherical Fibonacci lattice (equal-area, low discrepancy)
//!   under a uniformly random rotation: still an unbiased estimator of every solid angle, with an
//!   error that falls faster than 1/√N for smooth targets.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rand::Rng;
use serde::{Deserialize, Serialize};

/// How ray directions are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum DirectionSet {
    /// Independent uniform random directions.
    Random,
    /// A randomly rotated spherical Fibonacci lattice.
    #[default]
    Fibonacci,
}

impl DirectionSet {
    /// The set in words ("Fibonacci-lattice", "random").
    pub fn describe(self) -> &'static str {
        match self {
            Self::Random => "random",
            Self::Fibonacci => "Fibonacci-lattice",
        }
    }
}

/// A uniform random direction.
pub fn uniform_direction<R: Rng + ?Sized>(rng: &mut R) -> Vector3<f64> {
    let z: f64 = 1.0 - 2.0 * rng.random::<f64>();
    let phi = std::f64::consts::TAU * rng.random::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vector3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A uniformly random rotation (Shoemake's method).
pub fn uniform_rotation<R: Rng + ?Sized>(rng: &mut R) -> UnitQuaternion<f64> {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (t2, t3) = (std::f64::consts::TAU * u2, std::f64::consts::TAU * u3);
    UnitQuaternion::from_quaternion(Quaternion::new(
        b * t3.cos(),
        a * t2.sin(),
        a * t2.cos(),
        b * t3.sin(),
    ))
}

/// The `n`-point spherical Fibonacci lattice: z = 1 − (2i + 1)/n, φ = 2πi/ϕ.
pub fn fibonacci_sphere(n: usize) -> Vec<Vector3<f64>> {
    let golden = (1.0 + 5f64.sqrt()) / 2.0;
    (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let phi = std::f64::consts::TAU * (i as f64 / golden).fract();
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// `n` directions of the given set, drawn with `rng`.
pub fn directions<R: Rng + ?Sized>(set: DirectionSet, n: usize, rng: &mut R) -> Vec<Vector3<f64>> {
    match set {
        DirectionSet::Random => (0..n).map(|_| uniform_direction(rng)).collect(),
        DirectionSet::Fibonacci => {
            let rot = uniform_rotation(rng);
            fibonacci_sphere(n).into_iter().map(|d| rot * d).collect()
        }
    }
}
