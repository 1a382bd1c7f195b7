//! SolarCal (ASHRAE 55 App. C) against pythermalcomfort 4.8.1's `models.solar_gain`
//! (`round_output=False`), the published vectors of `grey-and-sun.md`; f_svv; the sun's position
//! against NREL's SPA (pvlib 0.16 `spa_python`).

use mrtmap_physics::{
    PhysicsError, Posture, SolarInputs, SolarPosture, UtcTime, f_svv, room_azimuth_deg, sharp_deg,
    solar_gain, solar_projected_area_factor, sun_position,
};

use SolarPosture::{Seated, Standing, Supine};

fn inputs(v: [f64; 8], posture: SolarPosture) -> SolarInputs {
    let [
        altitude_deg,
        sharp_deg,
        dni_w_m2,
        transmittance,
        f_svv,
        f_bes,
        asw,
        floor_reflectance,
    ] = v;
    SolarInputs {
        altitude_deg,
        sharp_deg,
        dni_w_m2,
        transmittance,
        f_svv,
        f_bes,
        asw,
        posture,
        floor_reflectance,
    }
}

#[test]
fn published_vectors() {
    // β, SHARP, I_dir, T_sol, f_svv, f_bes, α_sw, R_floor; posture; ERF, ΔMRT.
    let cases = [
        (
            [30.0, 0.0, 700.0, 0.6, 0.04233, 1.0, 0.7, 0.6],
            Seated,
            68.522,
            16.4084,
        ),
        (
            [60.0, 90.0, 800.0, 0.5, 0.2, 0.5, 0.7, 0.2],
            Standing,
            24.642,
            5.6649,
        ),
        (
            [15.0, 120.0, 400.0, 0.8, 0.1, 1.0, 0.5, 0.4],
            Seated,
            32.725,
            7.8365,
        ),
        (
            [45.0, 45.0, 900.0, 0.3, 0.3, 0.0, 0.7, 0.6],
            Supine,
            16.103,
            3.7017,
        ),
        (
            [75.0, 180.0, 1000.0, 0.7, 0.05, 0.7, 0.9, 0.8],
            Standing,
            56.694,
            13.0331,
        ),
    ];
    for (v, posture, erf, dmrt) in cases {
        let g = solar_gain(&inputs(v, posture)).unwrap();
        assert!((g.erf_w_m2 - erf).abs() < 0.01, "{v:?}: ERF {}", g.erf_w_m2);
        assert!(
            (g.delta_mrt_k - dmrt).abs() < 0.005,
            "{v:?}: ΔMRT {}",
            g.delta_mrt_k
        );
    }
}

#[test]
fn supine_in_the_beam_and_the_sun_on_the_horizon() {
    // Unrounded pythermalcomfort 4.8.1 output: the published supine vector has f_bes = 0, so
    // this one checks the rotation into the body's frame; the second is its docstring's example.
    let cases = [
        (
            [20.0, 150.0, 600.0, 0.5, 0.1, 0.8, 0.7, 0.6],
            Supine,
            27.863020506214525,
            6.405292070394144,
        ),
        (
            [0.0, 120.0, 800.0, 0.5, 0.5, 0.5, 0.7, 0.6],
            Seated,
            43.28387368421052,
            10.364912280701752,
        ),
    ];
    for (v, posture, erf, dmrt) in cases {
        let g = solar_gain(&inputs(v, posture)).unwrap();
        assert!((g.erf_w_m2 - erf).abs() < 1e-6, "{v:?}: ERF {}", g.erf_w_m2);
        assert!(
            (g.delta_mrt_k - dmrt).abs() < 1e-6,
            "{v:?}: ΔMRT {}",
            g.delta_mrt_k
        );
    }
}

#[test]
fn beside_the_beam_only_sky_and_floor() {
    // grey-and-sun.md: the first vector's person out of the beam gains 0.68 K.
    let mut i = inputs([30.0, 0.0, 700.0, 0.6, 0.04233, 0.0, 0.7, 0.6], Seated);
    let g = solar_gain(&i).unwrap();
    assert!((g.delta_mrt_k - 0.68).abs() < 0.005, "{}", g.delta_mrt_k);
    // Linear in f_bes and in the transmittance.
    i.f_bes = 0.5;
    let half = solar_gain(&i).unwrap().delta_mrt_k;
    i.f_bes = 1.0;
    let full = solar_gain(&i).unwrap().delta_mrt_k;
    assert!((half - (g.delta_mrt_k + full) / 2.0).abs() < 1e-12);
    i.transmittance = 0.0;
    assert_eq!(solar_gain(&i).unwrap().erf_w_m2, 0.0);
}

#[test]
fn projected_area_factor_follows_the_posture() {
    // Seated and standing read the person tables as they are.
    for (alt, sharp) in [(0.0, 0.0), (37.0, 100.0), (90.0, 180.0)] {
        assert_eq!(
            solar_projected_area_factor(Seated, alt, sharp),
            mrtmap_physics::projected_area_factor(Posture::Seated, sharp, alt)
        );
    }
    // Supine with the sun straight overhead sees the whole front of the body: the standing
    // body's fp from ahead at the horizon.
    let overhead = solar_projected_area_factor(Supine, 90.0, 0.0);
    assert!((overhead - 0.35).abs() < 1e-9, "{overhead}");
    // And from the feet (SHARP 0, sun on the horizon) the standing body's fp from above.
    let feet = solar_projected_area_factor(Supine, 0.0, 0.0);
    assert!((feet - 0.082).abs() < 1e-9, "{feet}");
}

#[test]
fn bad_inputs_are_refused_by_name() {
    let good = [30.0, 0.0, 700.0, 0.6, 0.04233, 1.0, 0.7, 0.6];
    let names = [
        "solar altitude (°)",
        "SHARP (°)",
        "direct normal irradiance (W/m²)",
        "solar transmittance",
        "sky-vault view fraction f_svv",
        "fraction of the body in the beam f_bes",
        "short-wave absorptivity",
        "floor reflectance",
    ];
    let bad = [
        [-1.0, 91.0],
        [-0.1, 181.0],
        [-1.0, 2000.0],
        [-0.1, 1.1],
        [-0.1, 1.5],
        [-0.1, 1.01],
        [-0.1, 1.2],
        [-0.5, 1.5],
    ];
    for k in 0..8 {
        for x in bad[k].into_iter().chain([f64::NAN, f64::INFINITY]) {
            let mut v = good;
            v[k] = x;
            match solar_gain(&inputs(v, Seated)) {
                Err(PhysicsError::OutOfRange { name, .. })
                | Err(PhysicsError::NotFinite { name, .. }) => {
                    assert_eq!(name, names[k], "input {k} = {x}");
                }
                other => panic!("input {k} = {x}: {other:?}"),
            }
        }
    }
    let e = solar_gain(&inputs(
        [95.0, 0.0, 700.0, 0.6, 0.04, 1.0, 0.7, 0.6],
        Seated,
    ))
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "solar altitude (°) = 95 is outside the valid range 0…90"
    );
}

#[test]
fn f_svv_examples() {
    // pythermalcomfort 4.8.1 `environment.f_svv`.
    let cases = [
        ((1.8, 1.3, 1.55), 0.04232999689099428),
        ((2.0, 1.5, 1.0), 0.10241638234956672),
        ((1.0, 1.0, 3.0), 0.005526885282005851),
    ];
    for ((w, h, d), want) in cases {
        let got = f_svv(w, h, d).unwrap();
        assert!((got - want).abs() < 1e-6, "({w}, {h}, {d}): {got}");
    }
    // Unbounded window close up: the whole half of the sky ahead, a quarter of the vault.
    assert!((f_svv(1e4, 1e4, 1e-3).unwrap() - 0.5).abs() < 1e-6);
    assert!(matches!(
        f_svv(1.0, 1.0, 0.0),
        Err(PhysicsError::OutOfRange {
            name: "distance to the window (m)",
            ..
        })
    ));
    assert!(matches!(
        f_svv(f64::NAN, 1.0, 1.0),
        Err(PhysicsError::NotFinite {
            name: "window width (m)",
            ..
        })
    ));
}

#[test]
fn sharp_and_room_azimuth() {
    assert_eq!(sharp_deg(0.0, 0.0), 0.0);
    assert_eq!(sharp_deg(90.0, 0.0), 90.0);
    assert_eq!(sharp_deg(-170.0, 170.0), 20.0);
    assert_eq!(sharp_deg(10.0, 190.0), 180.0);
    assert_eq!(sharp_deg(350.0, 10.0), 20.0);
    // +y north, +x east: east is +x (0), north +y (90), south −y (270), west −x (180).
    assert_eq!(room_azimuth_deg(90.0, 0.0), 0.0);
    assert_eq!(room_azimuth_deg(0.0, 0.0), 90.0);
    assert_eq!(room_azimuth_deg(180.0, 0.0), 270.0);
    assert_eq!(room_azimuth_deg(270.0, 0.0), 180.0);
    // A room whose +y points east (bearing 90): the sun in the east is along +y, in the south
    // along +x.
    assert_eq!(room_azimuth_deg(90.0, 90.0), 90.0);
    assert_eq!(room_azimuth_deg(180.0, 90.0), 0.0);
}

fn utc(s: &str) -> UtcTime {
    let n: Vec<f64> = s
        .split(|c: char| !c.is_ascii_digit())
        .map(|x| x.parse().unwrap())
        .collect();
    UtcTime {
        year: n[0] as i32,
        month: n[1] as u32,
        day: n[2] as u32,
        hour: n[3] as u32,
        minute: n[4] as u32,
        second: n[5],
    }
}

#[test]
fn sun_position_against_spa() {
    // pvlib 0.16 `solarposition.spa_python` (NREL SPA): time, latitude, longitude, geometric
    // elevation, apparent elevation (refraction at 101325 Pa, 12 °C), azimuth.
    let cases = [
        ("2024-03-20 12:00:00", 0.0, 0.0, 88.1669, 88.1674, 85.4147),
        (
            "2023-06-21 10:30:00",
            51.5,
            -0.13,
            56.7986,
            56.8096,
            138.9592,
        ),
        (
            "2023-12-21 16:00:00",
            40.71,
            -74.0,
            24.6322,
            24.6686,
            166.3669,
        ),
        (
            "2025-09-01 03:15:00",
            -33.87,
            151.21,
            43.8601,
            43.8776,
            332.0786,
        ),
        (
            "2022-01-15 20:45:30",
            37.77,
            -122.42,
            30.8969,
            30.9249,
            187.1580,
        ),
        (
            "2030-07-04 14:00:00",
            64.15,
            -21.94,
            48.4260,
            48.4409,
            189.6542,
        ),
        (
            "1950-05-10 08:00:00",
            28.61,
            77.21,
            70.0050,
            70.0111,
            240.1865,
        ),
    ];
    for (t, lat, lon, elevation, apparent, azimuth) in cases {
        let s = sun_position(&utc(t), lat, lon).unwrap();
        let tol_az = if elevation > 85.0 { 0.2 } else { 0.02 };
        assert!(
            (s.geometric_altitude_deg - elevation).abs() < 0.02,
            "{t}: {s:?}"
        );
        assert!((s.altitude_deg - apparent).abs() < 0.02, "{t}: {s:?}");
        assert!((s.azimuth_deg - azimuth).abs() < tol_az, "{t}: {s:?}");
    }
}

#[test]
fn sun_position_known_cases() {
    // J2000.0 is Julian day 2451545.0.
    assert_eq!(
        utc("2000-01-01 12:00:00").julian_day().unwrap(),
        2_451_545.0
    );
    // Noon on the equinox (03:06 UTC that day) on the equator at Greenwich: nearly overhead,
    // with the sun a little late (equation of time about −7.3 min: it crosses the meridian at
    // 12:07), so east of the meridian.
    let s = sun_position(&utc("2024-03-20 12:00:00"), 0.0, 0.0).unwrap();
    assert!(s.declination_deg.abs() < 0.2, "{s:?}");
    assert!((s.equation_of_time_min + 7.3).abs() < 0.2, "{s:?}");
    assert!(s.altitude_deg > 88.0 && s.azimuth_deg < 180.0, "{s:?}");
    // Solstice at local solar noon: altitude 90 − |φ − δ|.
    let s = sun_position(&utc("2023-06-21 12:00:00"), 45.0, 0.0).unwrap();
    assert!((s.geometric_altitude_deg - (90.0 - (45.0 - s.declination_deg))).abs() < 0.1);
    assert!((s.declination_deg - 23.44).abs() < 0.01, "{s:?}");
    // Midnight: below the horizon.
    assert!(
        sun_position(&utc("2023-06-21 00:00:00"), 45.0, 0.0)
            .unwrap()
            .altitude_deg
            < 0.0
    );
    // Bad dates and places are named.
    for (t, name) in [
        ("2023-02-29 12:00:00", "day"),
        ("2023-13-01 12:00:00", "month"),
        ("2023-01-01 24:00:00", "hour"),
        ("1800-01-01 12:00:00", "year"),
    ] {
        match sun_position(&utc(t), 45.0, 0.0) {
            Err(PhysicsError::OutOfRange { name: n, .. }) => assert_eq!(n, name, "{t}"),
            other => panic!("{t}: {other:?}"),
        }
    }
    assert!(matches!(
        sun_position(&utc("2024-02-29 12:00:00"), 91.0, 0.0),
        Err(PhysicsError::OutOfRange {
            name: "latitude (°)",
            ..
        })
    ));
}
