use mrtmap_geometry::nalgebra::Vector3;
use mrtmap_geometry::sampling::{DirectionSet, directions, fibonacci_sphere, uniform_rotation};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

#[test]
fn directions_are_unit_and_balanced() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for set in [DirectionSet::Random, DirectionSet::Fibonacci] {
        let d = directions(set, 20_000, &mut rng);
        assert_eq!(d.len(), 20_000);
        assert!(d.iter().all(|v| (v.norm() - 1.0).abs() < 1e-12));
        let mean = d.iter().fold(Vector3::zeros(), |a, v| a + v) / d.len() as f64;
        // Random: |mean| ~ 1/√(3N) ≈ 0.004 per axis; the lattice is far tighter.
        let limit = if set == DirectionSet::Random {
            0.03
        } else {
            1e-3
        };
        assert!(mean.norm() < limit, "{set:?}: {}", mean.norm());
        // Fraction in the upper hemisphere of an arbitrary axis: 1/2.
        let up = d.iter().filter(|v| v.x + 0.3 * v.y > 0.0).count() as f64 / d.len() as f64;
        assert!((up - 0.5).abs() < 0.02, "{set:?}: {up}");
    }
}

#[test]
fn lattice_is_equal_area_and_rotation_is_seeded() {
    let f = fibonacci_sphere(1000);
    // Equal-area in z: each band of height 2/10 holds 100 points.
    for band in 0..10 {
        let lo = -1.0 + 0.2 * band as f64;
        let n = f.iter().filter(|v| v.z >= lo && v.z < lo + 0.2).count();
        assert!((99..=101).contains(&n), "band {band}: {n}");
    }
    let r1 = uniform_rotation(&mut ChaCha8Rng::seed_from_u64(3));
    let r2 = uniform_rotation(&mut ChaCha8Rng::seed_from_u64(3));
    assert_eq!(r1, r2);
    assert!((r1.norm() - 1.0).abs() < 1e-12);
}
