//! MRT benchmarks on the built-in example office: the exact 20×20 map, one Monte Carlo point,
//! and a Monte Carlo 20×20 map.
#![allow(clippy::unwrap_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use mrtmap_geometry::nalgebra::Point3;
use mrtmap_radiation::{
    GridSpec, MapFrame, Method, MonteCarlo, MrtEngine, MrtField, example_office,
};

fn bench(c: &mut Criterion) {
    let scene = example_office();
    let exact = MrtEngine::new(&scene, Method::Exact).unwrap();
    let frame = MapFrame::of_scene(&scene).unwrap();
    c.bench_function("exact_map_20x20_example_office", |b| {
        b.iter(|| MrtField::compute(&exact, frame.clone(), GridSpec::default()).unwrap());
    });
    c.bench_function("exact_point_example_office", |b| {
        b.iter(|| exact.at(&Point3::new(2.1, 1.8, 1.1), 0).unwrap());
    });
    let mut g = c.benchmark_group("montecarlo");
    g.sample_size(10);
    for rays in [4_000usize, 20_000] {
        let mc = MrtEngine::new(
            &scene,
            Method::MonteCarlo(MonteCarlo {
                rays,
                ..MonteCarlo::default()
            }),
        )
        .unwrap();
        g.bench_function(format!("point_{rays}_rays"), |b| {
            b.iter(|| mc.at(&Point3::new(2.1, 1.8, 1.1), 0).unwrap());
        });
        g.bench_function(format!("map_20x20_{rays}_rays"), |b| {
            b.iter(|| MrtField::compute(&mc, frame.clone(), GridSpec::default()).unwrap());
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
