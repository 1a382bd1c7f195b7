use mrtmap_physics::{
    AsymmetryKind, Iso7730Edition, OperativeMethod, PmvInputs, Temperature, operative_temperature,
    pmv_ppd, pmv_ppd_edition, pmv_ppd_many, ppd_from_pmv, radiant_asymmetry_ppd,
};

fn c(x: f64) -> Temperature {
    Temperature::from_celsius(x)
}

#[test]
fn operative_ashrae_vectors() {
    for (v, expect) in [(0.1, 25.0), (0.3, 24.0), (0.7, 23.0)] {
        let to = operative_temperature(c(20.0), c(30.0), v, OperativeMethod::Ashrae55).unwrap();
        assert!(
            (to.celsius() - expect).abs() < 1e-9,
            "v {v}: {}",
            to.celsius()
        );
    }
    assert!(operative_temperature(c(20.0), c(30.0), 1.2, OperativeMethod::Ashrae55).is_err());
}

#[test]
fn operative_iso_vectors() {
    for (ta, tr, v, expect) in [(25.0, 30.0, 0.3, 26.83), (20.0, 30.0, 0.3, 23.66)] {
        let to = operative_temperature(c(ta), c(tr), v, OperativeMethod::Iso).unwrap();
        assert!((to.celsius() - expect).abs() < 5e-3, "{}", to.celsius());
    }
}

fn pmv(ta: f64, tr: f64, rh: f64, vr: f64, met: f64, clo: f64) -> mrtmap_physics::Pmv {
    pmv_ppd(&PmvInputs {
        air: c(ta),
        mrt: c(tr),
        relative_air_speed_m_s: vr,
        relative_humidity_pct: rh,
        met,
        clo,
        external_work_met: 0.0,
    })
    .unwrap()
}

/// ISO 7730 table values: PMV ±0.1, PPD ±1.
#[test]
fn pmv_ppd_table_vectors() {
    let table = [
        (22.0, 22.0, 60.0, 0.1, 1.2, 0.5, -0.8, 16.9),
        (27.0, 27.0, 60.0, 0.1, 1.2, 0.5, 0.8, 17.3),
        (27.0, 27.0, 60.0, 0.3, 1.2, 0.5, 0.4, 8.9),
        (23.5, 25.5, 60.0, 0.1, 1.2, 0.5, -0.0, 5.0),
        (23.5, 25.5, 60.0, 0.3, 1.2, 0.5, -0.6, 11.4),
        (19.0, 19.0, 40.0, 0.1, 1.2, 1.0, -0.6, 12.5),
    ];
    for (ta, tr, rh, vr, met, clo, p, d) in table {
        let r = pmv(ta, tr, rh, vr, met, clo);
        assert!(
            (r.pmv - p).abs() <= 0.1,
            "{ta} {tr} {vr}: PMV {} vs {p}",
            r.pmv
        );
        assert!(
            (r.ppd_pct - d).abs() <= 1.0,
            "{ta} {tr} {vr}: PPD {} vs {d}",
            r.ppd_pct
        );
        assert!(r.within_iso_ranges);
    }
}

/// Unrounded: ta = tr = 25, vr 0.1, rh 50, met 1.1, clo 0.5 → −0.13201636 (ISO 7730:2005's
/// code); ISO 7730:2025's first guess gives −0.13214292, pythermalcomfort 4.8.1's
/// `pmv_ppd_iso(25, 25, 0.1, 50, 1.1, 0.5, round_output=False)`.
#[test]
fn pmv_unrounded_vector() {
    let inputs = |t: f64| PmvInputs {
        air: Temperature::from_celsius(t),
        mrt: Temperature::from_celsius(t),
        relative_air_speed_m_s: 0.1,
        relative_humidity_pct: 50.0,
        met: 1.1,
        clo: 0.5,
        external_work_met: 0.0,
    };
    let y2005 = pmv_ppd_edition(&inputs(25.0), Iso7730Edition::Y2005).unwrap();
    assert!((y2005.pmv - -0.13201636).abs() < 1e-6, "{}", y2005.pmv);
    let y2025 = pmv_ppd_edition(&inputs(25.0), Iso7730Edition::Y2025).unwrap();
    assert!((y2025.pmv - -0.13214292).abs() < 1e-6, "{}", y2025.pmv);
    assert_eq!(pmv_ppd(&inputs(25.0)).unwrap(), y2025);
}

#[test]
fn ppd_is_five_at_neutral_and_symmetric() {
    assert!((ppd_from_pmv(0.0) - 5.0).abs() < 1e-12);
    assert!((ppd_from_pmv(1.3) - ppd_from_pmv(-1.3)).abs() < 1e-12);
}

#[test]
fn radiant_asymmetry_curves() {
    let at = |k, dt| radiant_asymmetry_ppd(k, dt).unwrap();
    // The formulas of physics.md, evaluated independently.
    let logistic = |a: f64, b: f64, dt: f64| 100.0 / (1.0 + (a - b * dt).exp());
    assert!(
        (at(AsymmetryKind::WarmCeiling, 8.0) - (logistic(2.84, 0.174, 8.0) - 5.5)).abs() < 1e-12
    );
    assert!((at(AsymmetryKind::CoolWall, 12.0) - logistic(6.61, 0.345, 12.0)).abs() < 1e-12);
    assert!((at(AsymmetryKind::CoolCeiling, 15.0) - logistic(9.93, 0.50, 15.0)).abs() < 1e-12);
    assert!(
        (at(AsymmetryKind::WarmWall, 30.0) - (logistic(3.72, 0.052, 30.0) - 3.5)).abs() < 1e-12
    );
    // ISO 7730 category B limits (PD < 5 %) are rounded readings of these curves:
    // 5 K warm ceiling, 10 K cool wall, 14 K cool ceiling, 23 K warm wall, all within 2 points of 5 %.
    for (k, dt) in [
        (AsymmetryKind::WarmCeiling, 5.0),
        (AsymmetryKind::CoolWall, 10.0),
        (AsymmetryKind::CoolCeiling, 14.0),
        (AsymmetryKind::WarmWall, 23.0),
    ] {
        assert!(
            (at(k, dt) - 5.0).abs() < 2.0,
            "{k:?} at {dt} K: {}",
            at(k, dt)
        );
    }
    // Clamped at zero for small asymmetries, increasing beyond.
    assert_eq!(at(AsymmetryKind::WarmWall, 0.0), 0.0);
    assert!(at(AsymmetryKind::CoolWall, 15.0) > at(AsymmetryKind::CoolWall, 10.0));
    assert!(radiant_asymmetry_ppd(AsymmetryKind::CoolWall, -1.0).is_err());
}

/// The vectorised batch gives each input's own answer, errors included, in order.
#[test]
fn pmv_many_equals_one_at_a_time() {
    let mut inputs = Vec::new();
    for k in 0..103 {
        let x = k as f64;
        inputs.push(PmvInputs {
            air: c(10.0 + (x * 7.3) % 20.0),
            mrt: c(10.0 + (x * 3.1) % 30.0),
            relative_air_speed_m_s: (x * 0.137) % 1.0,
            // Every 17th input is invalid: an error in its place, the others unaffected.
            relative_humidity_pct: if k % 17 == 5 {
                150.0
            } else {
                5.0 + (x * 11.0) % 90.0
            },
            met: 0.8 + (x * 0.29) % 3.2,
            clo: (x * 0.071) % 2.0,
            external_work_met: 0.0,
        });
    }
    for edition in [Iso7730Edition::Y2005, Iso7730Edition::Y2025] {
        let many = pmv_ppd_many(&inputs, edition);
        assert_eq!(many.len(), inputs.len());
        for (i, m) in inputs.iter().zip(&many) {
            match (m, &pmv_ppd_edition(i, edition)) {
                (Ok(m), Ok(one)) => {
                    // Polynomial exponentials and a reciprocal: the last bits may differ.
                    assert!((m.pmv - one.pmv).abs() <= 1e-12, "{m:?} vs {one:?}");
                    assert!((m.ppd_pct - one.ppd_pct).abs() <= 1e-10, "{m:?} vs {one:?}");
                    assert_eq!(m.within_iso_ranges, one.within_iso_ranges);
                }
                (m, one) => assert_eq!(m, one),
            }
        }
        assert_eq!(many.iter().filter(|r| r.is_err()).count(), 6);
    }
}

/// Over the whole range the formulas accept (not only ISO 7730's), in blocks that mix natural
/// and forced convection, converged and not: the batch equals one at a time to the last bits.
#[test]
fn pmv_many_equals_one_at_a_time_over_all_accepted_inputs() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7730);
    let inputs: Vec<PmvInputs> = (0..20_000)
        .map(|k| PmvInputs {
            air: c(rng.random_range(-50.0..=100.0)),
            mrt: c(rng.random_range(-50.0..=150.0)),
            // Still air in a quarter of them: natural convection throughout.
            relative_air_speed_m_s: if k % 4 == 0 {
                0.0
            } else {
                rng.random_range(0.0..=10.0)
            },
            relative_humidity_pct: rng.random_range(0.0..=100.0),
            met: rng.random_range(0.1..=10.0),
            clo: rng.random_range(0.0..=5.0),
            external_work_met: rng.random_range(0.0..=2.0),
        })
        .collect();
    let many = pmv_ppd_many(&inputs, Iso7730Edition::Y2025);
    let mut answered = 0;
    for (i, m) in inputs.iter().zip(&many) {
        match (m, &pmv_ppd_edition(i, Iso7730Edition::Y2025)) {
            (Ok(m), Ok(one)) => {
                let scale = one.pmv.abs().max(1.0);
                assert!(
                    (m.pmv - one.pmv).abs() <= 1e-12 * scale,
                    "{i:?}: {m:?} vs {one:?}"
                );
                assert!(
                    (m.ppd_pct - one.ppd_pct).abs() <= 1e-10,
                    "{i:?}: {m:?} vs {one:?}"
                );
                assert_eq!(m.within_iso_ranges, one.within_iso_ranges, "{i:?}");
                answered += 1;
            }
            (m, one) => assert_eq!(m, one, "{i:?}"),
        }
    }
    assert!(answered > 15_000, "only {answered} of 20000 answered");
}

/// An input outside what the formulas accept is refused by name, the metabolic rate before the
/// air speed derived from it, NaN as not a number, and the batch says the same as one at a time.
#[test]
fn pmv_refusals_name_the_input() {
    let ok = PmvInputs {
        air: c(22.0),
        mrt: c(22.0),
        relative_air_speed_m_s: 0.1,
        relative_humidity_pct: 50.0,
        met: 1.2,
        clo: 0.5,
        external_work_met: 0.0,
    };
    let cases = [
        (
            PmvInputs {
                met: 50.0,
                relative_air_speed_m_s: 14.8,
                ..ok
            },
            "metabolic rate (met) = 50 is outside",
        ),
        (
            PmvInputs {
                relative_humidity_pct: f64::NAN,
                ..ok
            },
            "relative humidity (%) is not a finite number",
        ),
        (
            PmvInputs { clo: 6.0, ..ok },
            "clothing (clo) = 6 is outside",
        ),
    ];
    let inputs: Vec<PmvInputs> = cases.iter().map(|(i, _)| *i).collect();
    let many = pmv_ppd_many(&inputs, Iso7730Edition::Y2025);
    for ((inp, want), batch) in cases.iter().zip(many) {
        let one = pmv_ppd(inp).unwrap_err().to_string();
        assert!(one.starts_with(want), "{one}");
        assert_eq!(batch.unwrap_err().to_string(), one);
    }
    assert!(pmv_ppd(&ok).is_ok());
}
