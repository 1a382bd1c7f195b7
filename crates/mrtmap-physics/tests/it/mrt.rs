use mrtmap_physics::{
    PhysicsError, RadiantAverage, RadiantSource, Temperature, mean_radiant_temperature,
};
use proptest::prelude::*;

fn c(x: f64) -> Temperature {
    Temperature::from_celsius(x)
}

/// EnergyPlus `ThermalComfort_CalcAngleFactorMRT`: 16.9 °C (formula 16.902).
#[test]
fn energyplus_angle_factor_vector() {
    let src = |f, t, e| RadiantSource {
        view_factor: f,
        temperature: c(t),
        emissivity: e,
        temperature_std_k: 0.0,
    };
    let mrt = mean_radiant_temperature(&[
        src(0.5, 20.0, 1.0),
        src(0.3, 15.0, 0.9),
        src(0.2, 10.0, 0.8),
    ])
    .unwrap();
    assert!(
        (mrt.temperature.celsius() - 16.902).abs() < 5e-4,
        "{}",
        mrt.temperature.celsius()
    );
    assert!((mrt.weight - (0.5 + 0.27 + 0.16)).abs() < 1e-12);
}

#[test]
fn black_form_is_fourth_power_average_not_linear() {
    let mrt = mean_radiant_temperature(&[
        RadiantSource::black(0.5, c(0.0)),
        RadiantSource::black(0.5, c(40.0)),
    ])
    .unwrap();
    let expect = ((273.15f64.powi(4) + 313.15f64.powi(4)) / 2.0).powf(0.25);
    assert!((mrt.temperature.kelvin() - expect).abs() < 1e-9);
    // The fourth-power mean is above the linear mean (20 °C) by about 0.34 K.
    assert!(mrt.temperature.celsius() - 20.0 > 0.3);
}

#[test]
fn bad_inputs_are_errors() {
    assert!(matches!(
        mean_radiant_temperature(&[]),
        Err(PhysicsError::NothingSeen { .. })
    ));
    assert!(mean_radiant_temperature(&[RadiantSource::black(f64::NAN, c(20.0))]).is_err());
    assert!(mean_radiant_temperature(&[RadiantSource::black(1.5, c(20.0))]).is_err());
    let mut s = RadiantSource::black(1.0, c(20.0));
    s.emissivity = 1.2;
    assert!(mean_radiant_temperature(&[s]).is_err());
}

#[test]
fn temperature_uncertainty_propagates() {
    // One surface seen whole: Tr = T, so σ(Tr) = σ(T).
    let mut s = RadiantSource::black(1.0, c(20.0));
    s.temperature_std_k = 0.3;
    let m = mean_radiant_temperature(&[s]).unwrap();
    assert!((m.std_from_temperatures_k - 0.3).abs() < 1e-12);
    // Two equal halves with independent errors: σ/√2.
    let m = mean_radiant_temperature(&[
        RadiantSource {
            view_factor: 0.5,
            ..s
        },
        RadiantSource {
            view_factor: 0.5,
            ..s
        },
    ])
    .unwrap();
    assert!((m.std_from_temperatures_k - 0.3 / 2f64.sqrt()).abs() < 1e-9);
}

#[test]
fn radiant_average_matches_formula_and_spread() {
    let mut a = RadiantAverage::new();
    a.add(c(10.0), 1.0);
    a.add(c(30.0), 3.0);
    let expect = ((283.15f64.powi(4) + 3.0 * 303.15f64.powi(4)) / 4.0).powf(0.25);
    assert!((a.mean().unwrap().kelvin() - expect).abs() < 1e-9);
    assert_eq!(a.count(), 2);
    let mut b = RadiantAverage::new();
    b.add(c(20.0), 0.0); // ignored
    assert!(b.mean().is_none());
    b.merge(&a);
    assert!((b.mean().unwrap().kelvin() - expect).abs() < 1e-9);
    // Equal weights: unbiased sample standard deviation.
    let mut e = RadiantAverage::new();
    for t in [19.0, 20.0, 21.0] {
        e.add(c(t), 2.0);
    }
    assert!((e.std_dev_k().unwrap() - 1.0).abs() < 1e-9);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha, rng_seed: proptest::test_runner::RngSeed::Fixed(0x6d7274), failure_persistence: None, ..ProptestConfig::default() })]
    /// The MRT lies between the coldest and warmest source, and a uniform enclosure gives its temperature.
    #[test]
    fn mrt_is_bounded(fs in prop::collection::vec((0.01f64..1.0, -20.0f64..80.0, 0.5f64..1.0), 1..8)) {
        let srcs: Vec<_> = fs.iter().map(|&(f, t, e)| RadiantSource { view_factor: f / fs.len() as f64, temperature: c(t), emissivity: e, temperature_std_k: 0.0 }).collect();
        let m = mean_radiant_temperature(&srcs).unwrap().temperature.celsius();
        let lo = fs.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
        let hi = fs.iter().map(|x| x.1).fold(f64::NEG_INFINITY, f64::max);
        prop_assert!(m >= lo - 1e-9 && m <= hi + 1e-9);
        let uniform: Vec<_> = srcs.iter().map(|s| RadiantSource { temperature: c(lo), ..*s }).collect();
        prop_assert!((mean_radiant_temperature(&uniform).unwrap().temperature.celsius() - lo).abs() < 1e-9);
    }
}
