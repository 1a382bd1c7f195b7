//! Ray casting throughput against a 100k-triangle closed mesh, single thread.
//!
//! `cargo bench -p mrtmap-geometry --bench raycast` measures the default BVH; with
//! `--features embree` the same rays also go through Embree in the same run.
//! `bench/raycast` runs both and prints the ratio.
#![allow(clippy::unwrap_used)]

use std::f64::consts::PI;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use mrtmap_geometry::nalgebra::{Point3, Vector3};
use mrtmap_geometry::ray::{BvhRayCaster, RayCaster, Tri};
use mrtmap_geometry::sampling::uniform_direction;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A closed bumpy sphere of 2·n² triangles (n = 224 → 100,352).
fn bumpy_sphere(n: usize) -> Vec<Tri> {
    let vert = |i: usize, j: usize| {
        let th = PI * i as f64 / n as f64;
        let ph = 2.0 * PI * (j % n) as f64 / n as f64;
        let r = 3.0 + 0.05 * (7.0 * th).sin() * (5.0 * ph).cos();
        Point3::new(
            r * th.sin() * ph.cos(),
            r * th.sin() * ph.sin(),
            r * th.cos(),
        )
    };
    let mut t = Vec::with_capacity(2 * n * n);
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (
                vert(i, j),
                vert(i, j + 1),
                vert(i + 1, j),
                vert(i + 1, j + 1),
            );
            t.push([a, b, c]);
            t.push([b, d, c]);
        }
    }
    t
}

fn rays(n: usize, one_origin: bool) -> Vec<(Point3<f64>, Vector3<f64>)> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let fixed = Point3::new(0.3, -0.2, 0.1);
    (0..n)
        .map(|_| {
            let o = if one_origin {
                fixed
            } else {
                Point3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                )
            };
            (o, uniform_direction(&mut rng))
        })
        .collect()
}

fn cast_all(c: &dyn RayCaster, rays: &[(Point3<f64>, Vector3<f64>)]) -> usize {
    rays.iter()
        .filter(|(o, d)| c.cast(o, d, f64::INFINITY).is_some())
        .count()
}

fn bench(c: &mut Criterion) {
    let tris = bumpy_sphere(224);
    let casters: Vec<Box<dyn RayCaster>> = vec![
        Box::new(BvhRayCaster::new(&tris)),
        #[cfg(feature = "embree")]
        Box::new(mrtmap_geometry::EmbreeRayCaster::new(&tris)),
    ];
    for (name, one) in [
        ("raycast_100k_incoherent", false),
        ("raycast_100k_from_one_point", true),
    ] {
        let rs = rays(100_000, one);
        let mut g = c.benchmark_group(name);
        g.throughput(Throughput::Elements(rs.len() as u64));
        g.sample_size(20);
        for caster in &casters {
            assert_eq!(
                cast_all(caster.as_ref(), &rs),
                rs.len(),
                "every ray from inside hits"
            );
            g.bench_with_input(
                BenchmarkId::from_parameter(caster.engine()),
                &rs,
                |b, rs| b.iter(|| cast_all(caster.as_ref(), rs)),
            );
        }
        g.finish();
    }
    let mut g = c.benchmark_group("bvh_build_100k");
    g.sample_size(10);
    g.bench_function("obvhs-cwbvh", |b| b.iter(|| BvhRayCaster::new(&tris)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
