use mrtmap_geometry::nalgebra::{Point3, Vector3};
use mrtmap_geometry::ray::{BvhRayCaster, RayCaster, Tri, box_triangles};
use mrtmap_geometry::sampling::uniform_direction;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn brute(tris: &[Tri], o: &Point3<f64>, d: &Vector3<f64>) -> Option<(f64, u32)> {
    let mut best: Option<(f64, u32)> = None;
    for (i, t) in tris.iter().enumerate() {
        let e1 = t[1] - t[0];
        let e2 = t[2] - t[0];
        let pv = d.cross(&e2);
        let det = e1.dot(&pv);
        if det.abs() < 1e-14 {
            continue;
        }
        let tv = o - t[0];
        let u = tv.dot(&pv) / det;
        let qv = tv.cross(&e1);
        let v = d.dot(&qv) / det;
        let s = e2.dot(&qv) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && s > 0.0 && best.is_none_or(|b| s < b.0) {
            best = Some((s, i as u32));
        }
    }
    best
}

fn random_soup(n: usize, rng: &mut ChaCha8Rng) -> Vec<Tri> {
    (0..n)
        .map(|_| {
            let c = Point3::new(
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
            );
            let mut v = || {
                c + Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                )
            };
            [v(), v(), v()]
        })
        .collect()
}

/// The BVH finds the same nearest triangle as a brute-force Möller–Trumbore on 2000 random rays.
#[test]
fn bvh_agrees_with_brute_force() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let tris = random_soup(500, &mut rng);
    let bvh = BvhRayCaster::new(&tris);
    assert_eq!(bvh.len(), 500);
    let mut hits = 0;
    for _ in 0..2000 {
        let o = Point3::new(
            rng.random_range(-6.0..6.0),
            rng.random_range(-6.0..6.0),
            rng.random_range(-6.0..6.0),
        );
        let d = uniform_direction(&mut rng);
        let a = bvh.cast(&o, &d, f64::INFINITY);
        let b = brute(&tris, &o, &d);
        match (a, b) {
            (Some(a), Some(b)) => {
                hits += 1;
                assert!(
                    (a.t - b.0).abs() < 1e-4 * b.0.max(1.0),
                    "t {} vs {}",
                    a.t,
                    b.0
                );
                // Ties between triangles at the same distance may pick either.
                if a.triangle != b.1 {
                    let other =
                        brute(&tris[a.triangle as usize..=a.triangle as usize], &o, &d).unwrap();
                    assert!((other.0 - b.0).abs() < 1e-4);
                }
            }
            (None, None) => {}
            (a, b) => {
                // Only grazing rays at f32 precision may disagree.
                let t = a.map(|h| h.t).or(b.map(|h| h.0)).unwrap_or(0.0);
                panic!("disagreement at t {t}: bvh {a:?} brute {b:?}");
            }
        }
    }
    assert!(hits > 200, "test must exercise hits: {hits}");
}

#[test]
fn box_from_inside_always_hits_and_t_max_limits() {
    let tris = box_triangles(&Point3::new(0.0, 0.0, 0.0), &Point3::new(2.0, 3.0, 4.0));
    assert_eq!(tris.len(), 12);
    let bvh = BvhRayCaster::new(&tris);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let o = Point3::new(1.0, 1.0, 1.0);
    for _ in 0..1000 {
        let d = uniform_direction(&mut rng);
        assert!(bvh.cast(&o, &d, f64::INFINITY).is_some());
    }
    let up = bvh.cast(&o, &Vector3::z(), f64::INFINITY).unwrap();
    assert!((up.t - 3.0).abs() < 1e-5);
    assert!(bvh.cast(&o, &Vector3::z(), 2.5).is_none());
    assert!(
        BvhRayCaster::new(&[])
            .cast(&o, &Vector3::z(), 10.0)
            .is_none()
    );
}

#[cfg(feature = "embree")]
#[test]
fn embree_agrees_with_bvh() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let tris = random_soup(500, &mut rng);
    let bvh = BvhRayCaster::new(&tris);
    let emb = mrtmap_geometry::EmbreeRayCaster::new(&tris);
    for _ in 0..2000 {
        let o = Point3::new(
            rng.random_range(-6.0..6.0),
            rng.random_range(-6.0..6.0),
            rng.random_range(-6.0..6.0),
        );
        let d = uniform_direction(&mut rng);
        let (a, b) = (
            bvh.cast(&o, &d, f64::INFINITY),
            emb.cast(&o, &d, f64::INFINITY),
        );
        assert_eq!(a.is_some(), b.is_some());
        if let (Some(a), Some(b)) = (a, b) {
            assert!((a.t - b.t).abs() < 1e-4 * a.t.max(1.0));
        }
    }
}
