use mrtmap_geometry::nalgebra::Point3;
use mrtmap_geometry::sampling::DirectionSet;
use mrtmap_geometry::sphere_view_factor;
use mrtmap_radiation::{Method, MonteCarlo, MrtEngine, MrtError, PatchKind, SceneFile};
use proptest::prelude::*;

use crate::common::*;

fn mc(rays: usize, seed: u64, directions: DirectionSet, replicates: usize) -> Method {
    Method::MonteCarlo(MonteCarlo {
        rays,
        seed,
        directions,
        replicates,
    })
}

/// Adds a rectangular feature at fractions (s0..s1, t0..t1) of surface `si`'s two first edges.
fn add_feature(f: &mut SceneFile, si: usize, s: (f64, f64), t: (f64, f64), temp: f64) {
    let poly = f.surfaces[si].polygon.clone();
    let at = |a: f64, b: f64| {
        let mut p = [0.0; 3];
        for k in 0..3 {
            p[k] = poly[0][k] + a * (poly[1][k] - poly[0][k]) + b * (poly[3][k] - poly[0][k]);
        }
        p
    };
    let id = format!("feat-{si}-{}", f.surfaces[si].features.len());
    f.surfaces[si].features.push(feature(
        &id,
        vec![at(s.0, t.0), at(s.1, t.0), at(s.1, t.1), at(s.0, t.1)],
        temp,
    ));
}

#[test]
fn exact_closed_room_with_features_sums_to_one_and_subtracts_features() {
    let mut f = box_room(4.2, 3.6, 2.7, [20.0, 22.0, 21.0, 18.0, 21.0, 21.0]);
    add_feature(&mut f, 3, (0.2, 0.7), (0.3, 0.8), 11.0);
    add_feature(&mut f, 1, (0.1, 0.3), (0.1, 0.3), 30.0);
    let s = scene(&f);
    let e = MrtEngine::new(&s, Method::Exact).unwrap();
    let p = Point3::new(1.3, 2.2, 1.1);
    let r = e.at(&p, 0).unwrap();
    assert!((r.view_factor_sum - 1.0).abs() < 1e-9);
    let patches = e.patches();
    let east = patches.iter().position(|p| p.id == "wall-e").unwrap();
    let win = patches
        .iter()
        .position(|p| p.kind == PatchKind::Feature && p.host.as_deref() == Some("wall-e"))
        .unwrap();
    let host_whole = sphere_view_factor(&p, &s.surfaces[3].polygon);
    let win_alone = sphere_view_factor(&p, &s.surfaces[3].features[0].polygon);
    assert!((r.view_factors[win] - win_alone).abs() < 1e-15);
    assert!((r.view_factors[east] - (host_whole - win_alone)).abs() < 1e-15);
    // The cold window pulls the MRT below the area-free average of the walls.
    assert!(r.mrt.celsius() < 21.0);
}

#[test]
fn uniform_room_gives_its_temperature_with_zero_sampling_error() {
    let s = scene(&box_room(5.0, 4.0, 3.0, [23.0; 6]));
    for m in [
        Method::Exact,
        mc(4000, 3, DirectionSet::Fibonacci, 8),
        mc(4000, 3, DirectionSet::Random, 8),
    ] {
        let r = MrtEngine::new(&s, m)
            .unwrap()
            .at(&Point3::new(1.0, 3.0, 2.0), 0)
            .unwrap();
        assert!((r.mrt.celsius() - 23.0).abs() < 1e-9, "{}", m.name());
        assert!(r.sampling_std_error_k < 1e-9);
    }
}

#[test]
fn temperature_uncertainty_is_carried_into_the_mrt() {
    let mut f = box_room(4.0, 4.0, 4.0, [20.0; 6]);
    f.surfaces[3].temperature_std_k = Some(0.6);
    let s = scene(&f);
    let r = MrtEngine::new(&s, Method::Exact)
        .unwrap()
        .at(&Point3::new(2.0, 2.0, 2.0), 0)
        .unwrap();
    // Cube centre: F = 1/6 and ∂Tr/∂T = 1/6 at uniform temperature.
    assert!(
        (r.temperature_std_error_k - 0.1).abs() < 1e-9,
        "{}",
        r.temperature_std_error_k
    );
    assert!((r.std_error_k - 0.1).abs() < 1e-9);
}

#[test]
fn exact_refuses_occluders_with_a_clear_message() {
    let mut f = box_room(4.0, 4.0, 3.0, [20.0; 6]);
    f.occluders.push(box_occluder(
        "desk-1",
        [1.0, 1.0, 0.0],
        [2.2, 1.8, 0.75],
        21.0,
    ));
    let s = scene(&f);
    let e = MrtEngine::new(&s, Method::Exact).err().unwrap();
    assert_eq!(
        e.to_string(),
        "the scene has furniture (1 piece(s) as occluders; first: 'desk-1'), which exact solid angles cannot see: use the Monte Carlo method (--method montecarlo, or auto)"
    );
    let engine = MrtEngine::new(&s, mc(2000, 1, DirectionSet::Fibonacci, 8)).unwrap();
    assert!(matches!(
        engine.at(&Point3::new(1.5, 1.5, 0.5), 0),
        Err(MrtError::InsideOccluder { .. })
    ));
}

/// A box between the point and a wall reduces that wall's factor by the box's solid angle.
#[test]
fn occluding_box_takes_its_solid_angle_from_the_wall() {
    let base = box_room(5.0, 4.0, 3.0, [20.0, 20.0, 20.0, 15.0, 20.0, 20.0]);
    let p = Point3::new(1.0, 2.0, 1.2);
    let exact = MrtEngine::new(&scene(&base), Method::Exact)
        .unwrap()
        .at(&p, 0)
        .unwrap();
    let (lo, hi) = ([3.0, 1.5, 0.9], [3.5, 2.5, 1.5]);
    let mut f = base.clone();
    f.occluders.push(box_occluder("cabinet", lo, hi, 30.0));
    let s = scene(&f);
    // The box's solid angle: the faces whose outer side faces the point.
    let box_f: f64 = mrtmap_geometry::box_triangles(&Point3::from(lo), &Point3::from(hi))
        .chunks(2)
        .filter(|q| {
            let n = (q[0][1] - q[0][0]).cross(&(q[0][2] - q[0][0]));
            let c = Point3::from(
                (lo[0] + hi[0]) / 2.0 * mrtmap_geometry::nalgebra::Vector3::x()
                    + (lo[1] + hi[1]) / 2.0 * mrtmap_geometry::nalgebra::Vector3::y()
                    + (lo[2] + hi[2]) / 2.0 * mrtmap_geometry::nalgebra::Vector3::z(),
            );
            let outward = if n.dot(&(q[0][0] - c)) > 0.0 { n } else { -n };
            outward.dot(&(p - q[0][0])) > 0.0
        })
        .map(|q| sphere_view_factor(&p, &[q[0][0], q[0][1], q[0][2], q[1][2]]))
        .sum();
    assert!(box_f > 0.005, "the test must occlude something: {box_f}");
    let e = MrtEngine::new(&s, mc(200_000, 9, DirectionSet::Fibonacci, 16)).unwrap();
    let r = e.at(&p, 0).unwrap();
    let ip = |id: &str| e.patches().iter().position(|x| x.id == id).unwrap();
    let (east, cab) = (ip("wall-e"), ip("cabinet"));
    let expect_east = exact.view_factors[east] - box_f;
    assert!(
        (r.view_factors[east] - expect_east).abs() < 4.0 * r.view_factor_std_errors[east] + 1e-4,
        "{} vs {}",
        r.view_factors[east],
        expect_east
    );
    assert!(
        (r.view_factors[cab] - box_f).abs() < 4.0 * r.view_factor_std_errors[cab] + 1e-4,
        "{} vs {}",
        r.view_factors[cab],
        box_f
    );
    // The other walls do not change.
    let west = ip("wall-w");
    assert!(
        (r.view_factors[west] - exact.view_factors[west]).abs()
            < 4.0 * r.view_factor_std_errors[west] + 1e-4
    );
    assert!((r.view_factor_sum - 1.0).abs() < 1e-3);
}

#[test]
fn non_convex_room_exact_checks_visibility_and_monte_carlo_sums_to_one() {
    let s = scene(&l_room());
    let exact = MrtEngine::new(&s, Method::Exact).unwrap();
    // In the kernel (sees every wall whole): exact is exact.
    let r = exact.at(&Point3::new(1.5, 1.0, 1.2), 0).unwrap();
    assert!((r.view_factor_sum - 1.0).abs() < 1e-9);
    // In the far leg: walls hide walls and exact refuses.
    let e = exact.at(&Point3::new(5.0, 1.0, 1.2), 0).unwrap_err();
    assert!(
        matches!(e, MrtError::SurfacesHidden { sum, .. } if sum > 1.0 + 1e-3),
        "{e}"
    );
    assert!(e.to_string().contains("use the Monte Carlo method"));
    let mcm = MrtEngine::new(&s, mc(40_000, 2, DirectionSet::Fibonacci, 8)).unwrap();
    let r = mcm.at(&Point3::new(5.0, 1.0, 1.2), 0).unwrap();
    assert!(
        (r.view_factor_sum - 1.0).abs() < 1e-3,
        "{}",
        r.view_factor_sum
    );
    // The wall facing away at x = 3 (y 2..4) is wholly hidden from there.
    let hidden = mcm.patches().iter().position(|p| p.id == "wall-3").unwrap();
    assert_eq!(r.view_factors[hidden], 0.0);
}

#[test]
fn random_sampling_errors_match_the_binomial_formula() {
    let s = scene(&box_room(
        4.0,
        3.0,
        2.5,
        [20.0, 22.0, 21.0, 18.0, 21.0, 21.0],
    ));
    let n = 32_000;
    let e = MrtEngine::new(&s, mc(n, 5, DirectionSet::Random, 32)).unwrap();
    let mut ratio = 0.0;
    let mut count = 0.0;
    for k in 0..20 {
        let r = e
            .at(&Point3::new(1.0 + 0.1 * k as f64, 1.2, 1.1), k)
            .unwrap();
        for (f, se) in r.view_factors.iter().zip(&r.view_factor_std_errors) {
            ratio += se / (f * (1.0 - f) / n as f64).sqrt();
            count += 1.0;
        }
    }
    let mean = ratio / count;
    assert!(
        (mean - 1.0).abs() < 0.1,
        "replicate SE / binomial SE = {mean}"
    );
}

#[test]
fn seeded_results_are_reproducible_and_streams_differ() {
    let s = scene(&box_room(
        4.0,
        3.0,
        2.5,
        [20.0, 22.0, 21.0, 18.0, 21.0, 21.0],
    ));
    let e = MrtEngine::new(&s, mc(5000, 42, DirectionSet::Fibonacci, 8)).unwrap();
    let p = Point3::new(1.0, 1.0, 1.0);
    assert_eq!(e.at(&p, 3).unwrap(), e.at(&p, 3).unwrap());
    assert_ne!(
        e.at(&p, 3).unwrap().view_factors,
        e.at(&p, 4).unwrap().view_factors
    );
}

proptest! {
    #![proptest_config(config(48))]
    /// Monte Carlo agrees with exact within 4 standard errors (plus half a ray's resolution) on
    /// random rooms with random features, for every view factor and for the MRT.
    #[test]
    fn monte_carlo_agrees_with_exact(
        sx in 2.5f64..8.0, sy in 2.5f64..8.0, sz in 2.2f64..4.0,
        temps in prop::array::uniform6(5.0f64..40.0),
        feats in prop::collection::vec((0usize..6, 0.05f64..0.45, 0.05f64..0.45, 0.05f64..0.4, 0.05f64..0.4, 0.0f64..60.0), 0..5),
        px in 0.1f64..0.9, py in 0.1f64..0.9, pz in 0.1f64..0.9,
        seed in 0u64..1000, random_dirs in any::<bool>(),
    ) {
        let mut f = box_room(sx, sy, sz, temps);
        // One feature per surface at most (the first drawn), so features never overlap.
        let mut used = [false; 6];
        for (si, s0, t0, ds, dt, temp) in feats {
            if !used[si] {
                used[si] = true;
                add_feature(&mut f, si, (s0, s0 + ds), (t0, t0 + dt), temp);
            }
        }
        let s = scene(&f);
        let p = Point3::new(px * sx, py * sy, pz * sz);
        let exact = MrtEngine::new(&s, Method::Exact).unwrap().at(&p, 0).unwrap();
        let set = if random_dirs { DirectionSet::Random } else { DirectionSet::Fibonacci };
        let rays = 16_000;
        let m = MrtEngine::new(&s, mc(rays, seed, set, 16)).unwrap().at(&p, 0).unwrap();
        let half_ray = 0.5 / (rays / 16) as f64;
        for (k, (fe, (fm, se))) in exact.view_factors.iter().zip(m.view_factors.iter().zip(&m.view_factor_std_errors)).enumerate() {
            prop_assert!((fe - fm).abs() <= 4.0 * se + half_ray, "patch {}: exact {} mc {} ± {}", k, fe, fm, se);
        }
        let d = (m.mrt.kelvin() - exact.mrt.kelvin()).abs();
        prop_assert!(d <= 4.0 * m.sampling_std_error_k + 1e-3, "MRT exact {} mc {} ± {}", exact.mrt.celsius(), m.mrt.celsius(), m.sampling_std_error_k);
        prop_assert!((m.view_factor_sum - 1.0).abs() < 2e-3);
    }

    /// Closed rooms: Σ F = 1 within 1e-9 from random interior points, features included.
    #[test]
    fn closed_rooms_sum_to_one(sx in 2.0f64..9.0, sy in 2.0f64..9.0, sz in 2.0f64..5.0, px in 0.01f64..0.99, py in 0.01f64..0.99, pz in 0.01f64..0.99, fsurf in 0usize..6) {
        let mut f = box_room(sx, sy, sz, [20.0; 6]);
        add_feature(&mut f, fsurf, (0.2, 0.6), (0.3, 0.7), 10.0);
        let s = scene(&f);
        let r = MrtEngine::new(&s, Method::Exact).unwrap().at(&Point3::new(px * sx, py * sy, pz * sz), 0).unwrap();
        prop_assert!((r.view_factor_sum - 1.0).abs() < 1e-9);
    }
}

#[test]
fn placement_uncertainty_is_the_mrts_gradient_times_the_placement() {
    // A 8 °C window on the east wall (x = 4 m, y 1–3 m, z 0.78–2.08 m); 10 cm in front of its
    // left end the MRT changes by about a tenth of a kelvin per centimetre.
    let mut f = box_room(4.0, 4.0, 2.6, [20.0; 6]);
    add_feature(&mut f, 3, (0.25, 0.75), (0.3, 0.8), 8.0);
    let s = scene(&f);
    let plain = MrtEngine::new(&s, Method::Exact).unwrap();
    let placed = MrtEngine::new(&s, Method::Exact)
        .unwrap()
        .with_placement_std(0.01);
    let p = Point3::new(3.9, 1.2, 1.1);
    let (a, b) = (plain.at(&p, 0).unwrap(), placed.at(&p, 0).unwrap());
    assert_eq!(a.placement_std_error_k, 0.0);
    assert_eq!(a.mrt, b.mrt);
    // The gradient from 1 mm differences of the plain engine (the engine's own steps are 2 cm;
    // measured: both 0.126 K).
    let t = |q: Point3<f64>| plain.at(&q, 0).unwrap().mrt.kelvin();
    let d = 1e-3;
    let g: f64 = (0..3)
        .map(|k| {
            let mut e = mrtmap_geometry::nalgebra::Vector3::zeros();
            e[k] = d;
            ((t(p + e) - t(p - e)) / (2.0 * d)).powi(2)
        })
        .sum::<f64>()
        .sqrt();
    let expect = 0.01 * g;
    assert!(expect > 0.05, "gradient {g} K/m");
    assert!(
        (b.placement_std_error_k - expect).abs() < 0.02 * expect,
        "placement term {} K, gradient × 1 cm {expect} K",
        b.placement_std_error_k
    );
    assert!((b.std_error_k - a.std_error_k.hypot(b.placement_std_error_k)).abs() < 1e-12);
    // 1 cm from the wall the outer side is outside the room: a one-sided difference, larger still.
    let edge = placed.at(&Point3::new(3.99, 1.2, 1.1), 0).unwrap();
    assert!(edge.placement_std_error_k.is_finite() && edge.placement_std_error_k > expect);
    // On the wall itself there is no MRT (a point on a window gave 16.4 °C by view factors and
    // 11.5 °C by rays): refused by both methods, naming the surface.
    for engine in [&plain, &placed] {
        let e = engine
            .at(&Point3::new(4.0, 1.2, 1.1), 0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("from a wall, on it"), "{e}");
        let e = engine
            .at(&Point3::new(2.0, 1.2, 0.0), 0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("from floor, on it"), "{e}");
    }
    // At the centre of a uniform room nothing changes with the place.
    let uniform = scene(&box_room(4.0, 4.0, 2.6, [20.0; 6]));
    let c = MrtEngine::new(&uniform, Method::Exact)
        .unwrap()
        .with_placement_std(0.01)
        .at(&Point3::new(2.0, 2.0, 1.3), 0)
        .unwrap();
    assert!(c.placement_std_error_k < 1e-9);
    // Monte Carlo (a quarter of the rays, the same directions on both sides) agrees (measured:
    // 0.121 against 0.126 K).
    let m = MrtEngine::new(&s, mc(20_000, 1, DirectionSet::Fibonacci, 8))
        .unwrap()
        .with_placement_std(0.01)
        .at(&p, 0)
        .unwrap();
    assert!(
        (m.placement_std_error_k - b.placement_std_error_k).abs() < 0.08 * b.placement_std_error_k,
        "Monte Carlo {} K, exact {} K",
        m.placement_std_error_k,
        b.placement_std_error_k
    );
}
