use mrtmap_physics::{Temperature, TemperatureDelta};

#[test]
fn celsius_round_trip_and_delta_arithmetic() {
    let t = Temperature::from_celsius(21.3);
    assert!((t.kelvin() - 294.45).abs() < 1e-12);
    assert!((t.celsius() - 21.3).abs() < 1e-12);
    let d = Temperature::from_celsius(25.0) - Temperature::from_celsius(20.0);
    assert!((d.kelvin() - 5.0).abs() < 1e-12);
    let t2 = t + d * 2.0;
    assert!((t2.celsius() - 31.3).abs() < 1e-12);
    assert!(
        ((t2 - TemperatureDelta::from_kelvin(10.0)) - t)
            .kelvin()
            .abs()
            < 1e-12
    );
}

#[test]
fn fourth_power_round_trip() {
    let t = Temperature::from_kelvin(300.0);
    assert!((Temperature::from_fourth_power(t.fourth_power()).kelvin() - 300.0).abs() < 1e-9);
}

#[test]
fn display_uses_celsius_at_the_edge() {
    assert_eq!(format!("{:.1}", Temperature::from_kelvin(300.0)), "26.9 °C");
    assert_eq!(
        format!("{:.2}", TemperatureDelta::from_kelvin(-0.25)),
        "-0.25 K"
    );
}
