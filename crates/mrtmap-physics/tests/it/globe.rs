use mrtmap_physics::{
    Convection, Globe, GlobeFormula, GlobeMethod, GlobeReading, Temperature, globe_temperature,
    mrt_from_globe,
};
use proptest::prelude::*;

fn reading(tg: f64, ta: f64, v: f64) -> GlobeReading {
    GlobeReading {
        globe: Temperature::from_celsius(tg),
        air: Temperature::from_celsius(ta),
        air_speed_m_s: v,
    }
}

fn mrt(globe: Globe, tg: f64, ta: f64, v: f64, method: GlobeMethod) -> f64 {
    mrt_from_globe(&globe, &reading(tg, ta, v), method)
        .unwrap()
        .mrt
        .celsius()
}

const CLOSED_NATURAL: GlobeMethod = GlobeMethod::IsoClosedForm {
    convection: Convection::Natural,
};
const CLOSED_FORCED: GlobeMethod = GlobeMethod::IsoClosedForm {
    convection: Convection::Forced,
};

/// ISO 7726 / seed paper closed forms (natural): 26.479, 20.452, 32.649 °C.
#[test]
fn closed_form_natural_vectors() {
    for (tg, ta, expect) in [
        (25.0, 22.0, 26.479),
        (22.0, 25.0, 20.452),
        (30.0, 25.0, 32.649),
    ] {
        let got = mrt(Globe::STANDARD, tg, ta, 0.0, CLOSED_NATURAL);
        assert!(
            (got - expect).abs() < 1e-3,
            "Tg {tg} Ta {ta}: {got} vs {expect}"
        );
    }
}

/// Closed form (forced): Tg 25, Ta 22, v 0.1 → 26.761 °C.
#[test]
fn closed_form_forced_vector() {
    let got = mrt(Globe::STANDARD, 25.0, 22.0, 0.1, CLOSED_FORCED);
    assert!((got - 26.761).abs() < 1e-3, "{got}");
    // "Larger" picks forced here (2.5e8·0.1^0.6 > 0.4e8·3^¼).
    let r = mrt_from_globe(
        &Globe::STANDARD,
        &reading(25.0, 22.0, 0.1),
        GlobeMethod::IsoClosedForm {
            convection: Convection::Larger,
        },
    )
    .unwrap();
    assert_eq!(r.formula, GlobeFormula::IsoClosedFormForced);
}

/// pythermalcomfort `mean_radiant_tmp(..., standard="ISO")` vectors (±0.1).
#[test]
fn pythermalcomfort_iso_vectors() {
    let g = |d| Globe {
        diameter_m: d,
        emissivity: 0.95,
    };
    for (tg, ta, v, d, expect) in [
        (53.2, 30.0, 0.3, 0.1, 74.8),
        (55.0, 30.0, 0.3, 0.1, 77.8),
        (55.0, 30.0, 0.1, 0.1, 71.9),
    ] {
        let got = mrt(g(d), tg, ta, v, GlobeMethod::ISO);
        assert!(
            (got - expect).abs() < 0.1,
            "tg {tg} v {v}: {got} vs {expect}"
        );
    }
    // v = 0, standard globe: 26.543 and 20.383 (to the printed three decimals).
    assert!((mrt(Globe::STANDARD, 25.0, 22.0, 0.0, GlobeMethod::ISO) - 26.543).abs() < 1.5e-3);
    assert!((mrt(Globe::STANDARD, 22.0, 25.0, 0.0, GlobeMethod::ISO) - 20.383).abs() < 1.5e-3);
}

/// The closed form's 0.4×10⁸ and the general 1.4/(εσD^¼) = 0.418×10⁸ differ by under 0.1 K.
#[test]
fn closed_form_and_general_formula_differ_slightly() {
    let a = mrt(Globe::STANDARD, 25.0, 22.0, 0.0, CLOSED_NATURAL);
    let b = mrt(
        Globe::STANDARD,
        25.0,
        22.0,
        0.0,
        GlobeMethod::Iso {
            convection: Convection::Natural,
        },
    );
    assert!((a - b).abs() > 0.03 && (a - b).abs() < 0.1, "{a} {b}");
}

#[test]
fn closed_form_refuses_a_non_standard_globe() {
    let r = mrt_from_globe(
        &Globe {
            diameter_m: 0.1,
            emissivity: 0.95,
        },
        &reading(25.0, 22.0, 0.0),
        CLOSED_NATURAL,
    );
    assert!(r.is_err());
}

/// Teitelbaum et al. mixed convection: tg 25.42, tdb 26.10, v 0.1931, d 0.1 → 24.2 (±0.1).
#[test]
fn mixed_convection_vector_and_validity() {
    let g = Globe {
        diameter_m: 0.1,
        emissivity: 0.95,
    };
    let got = mrt(g, 25.42, 26.10, 0.1931, GlobeMethod::MixedConvection);
    assert!((got - 24.2).abs() < 0.1, "{got}");
    let too_big = Globe {
        diameter_m: 0.2,
        emissivity: 0.95,
    };
    assert!(
        mrt_from_globe(
            &too_big,
            &reading(25.0, 22.0, 0.1),
            GlobeMethod::MixedConvection
        )
        .is_err()
    );
    let too_small = Globe {
        diameter_m: 0.03,
        emissivity: 0.95,
    };
    assert!(
        mrt_from_globe(
            &too_small,
            &reading(25.0, 22.0, 0.1),
            GlobeMethod::MixedConvection
        )
        .is_err()
    );
}

#[test]
fn invalid_readings_are_errors() {
    assert!(
        mrt_from_globe(
            &Globe::STANDARD,
            &reading(f64::NAN, 22.0, 0.0),
            GlobeMethod::ISO
        )
        .is_err()
    );
    assert!(
        mrt_from_globe(
            &Globe::STANDARD,
            &reading(25.0, 22.0, -1.0),
            GlobeMethod::ISO
        )
        .is_err()
    );
}

/// Regression: a cold radiant field in warm, fast air made the bisection evaluate globe
/// temperatures whose Tr⁴ is negative, and the inverse failed instead of solving.
#[test]
fn inverse_solves_cold_radiant_field_in_warm_fast_air() {
    for (tr, ta, v) in [(5.0, 35.0, 1.5), (6.0, 34.0, 1.2), (-10.0, 30.0, 3.0)] {
        let tr_t = Temperature::from_celsius(tr);
        let tg = globe_temperature(
            &Globe::STANDARD,
            tr_t,
            Temperature::from_celsius(ta),
            v,
            GlobeMethod::ISO,
        )
        .unwrap();
        let back = mrt_from_globe(
            &Globe::STANDARD,
            &reading(tg.celsius(), ta, v),
            GlobeMethod::ISO,
        )
        .unwrap();
        assert!(
            (back.mrt.celsius() - tr).abs() < 1e-4,
            "{tr} {ta} {v}: {}",
            back.mrt.celsius()
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha, rng_seed: proptest::test_runner::RngSeed::Fixed(0x676c6f6265), failure_persistence: None, ..ProptestConfig::default() })]
    /// Reading a simulated globe back gives the MRT it was simulated at, for every method.
    #[test]
    fn globe_inverse_round_trips(tr in 5.0f64..45.0, ta in 10.0f64..35.0, v in 0.0f64..1.5, d in 0.04f64..0.15, which in 0usize..4) {
        let (globe, method) = match which {
            0 => (Globe { diameter_m: d, emissivity: 0.95 }, GlobeMethod::ISO),
            1 => (Globe::STANDARD, GlobeMethod::IsoClosedForm { convection: Convection::Larger }),
            2 => (Globe { diameter_m: d, emissivity: 0.95 }, GlobeMethod::MixedConvection),
            _ => (Globe { diameter_m: d, emissivity: 0.9 }, GlobeMethod::Iso { convection: Convection::Natural }),
        };
        let tr_t = Temperature::from_celsius(tr);
        let tg = globe_temperature(&globe, tr_t, Temperature::from_celsius(ta), v, method).unwrap();
        // The globe reads between air and mean radiant temperature.
        prop_assert!(tg.celsius() >= tr.min(ta) - 1e-6 && tg.celsius() <= tr.max(ta) + 1e-6);
        let back = mrt_from_globe(&globe, &GlobeReading { globe: tg, air: Temperature::from_celsius(ta), air_speed_m_s: v }, method).unwrap();
        prop_assert!((back.mrt.celsius() - tr).abs() < 1e-4, "{} vs {}", back.mrt.celsius(), tr);
    }
}

/// A reading no surroundings could give (a cold globe in hot, fast air) says so in words, not as
/// "Tr⁴ = -35259969917 is outside the valid range".
#[test]
fn a_reading_no_room_could_give_is_named_in_words() {
    let e = mrt_from_globe(&Globe::STANDARD, &reading(-20.0, 40.0, 5.0), CLOSED_FORCED)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("a globe at -20 °C in air at 40 °C moving at 5 m/s")
            && e.contains("below absolute zero"),
        "{e}"
    );
}
