//! Monte Carlo convergence study on the built-in example office.
//!
//! For both direction sets and a range of ray counts: the RMS error of the Monte Carlo MRT against
//! the exact MRT over 16 points × 24 seeds, and the mean standard error the engine reports. Then the
//! smallest ray count whose RMS error and reported error are both ≤ 0.05 K, and the time of a 20×20
//! map at that count (median of 5). Run with `cargo run --release -p mrtmap-radiation --example
//! mc_convergence`.
#![allow(clippy::unwrap_used, clippy::print_stdout)]

use std::time::Instant;

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_geometry::sampling::DirectionSet;
use mrtmap_radiation::{
    GridSpec, MapFrame, Method, MonteCarlo, MrtEngine, MrtField, example_office,
};

fn main() {
    let scene = example_office();
    let exact = MrtEngine::new(&scene, Method::Exact).unwrap();
    let points: Vec<Point3<f64>> = (0..16)
        .map(|k| {
            Point3::new(
                0.5 + 1.05 * (k % 4) as f64,
                0.45 + 0.9 * (k / 4) as f64,
                1.1,
            )
        })
        .collect();
    let truth: Vec<f64> = points
        .iter()
        .map(|p| exact.at(p, 0).unwrap().mrt.kelvin())
        .collect();
    let seeds = 24u64;
    let counts = [500usize, 1_000, 2_000, 4_000, 8_000, 16_000, 32_000, 64_000];
    println!(
        "{:>8} {:>10} {:>14} {:>14} {:>10}",
        "rays", "directions", "RMS error (K)", "mean SE (K)", "SE/RMS"
    );
    let mut needed = Vec::new();
    for set in [DirectionSet::Random, DirectionSet::Fibonacci] {
        let mut found = None;
        for &rays in &counts {
            let (mut sq, mut se, mut n) = (0.0, 0.0, 0.0);
            for seed in 0..seeds {
                let mc = MrtEngine::new(
                    &scene,
                    Method::MonteCarlo(MonteCarlo {
                        rays,
                        seed,
                        directions: set,
                        replicates: 8,
                    }),
                )
                .unwrap();
                for (k, p) in points.iter().enumerate() {
                    let r = mc.at(p, k as u64).unwrap();
                    sq += (r.mrt.kelvin() - truth[k]).powi(2);
                    se += r.sampling_std_error_k;
                    n += 1.0;
                }
            }
            let (rms, mse) = ((sq / n).sqrt(), se / n);
            println!(
                "{rays:>8} {:>10} {rms:>14.4} {mse:>14.4} {:>10.2}",
                format!("{set:?}"),
                mse / rms
            );
            if found.is_none() && rms <= 0.05 && mse <= 0.05 {
                found = Some(rays);
            }
        }
        needed.push((set, found));
    }
    let frame = MapFrame::of_scene(&scene).unwrap();
    println!();
    for (set, rays) in needed {
        let Some(rays) = rays else {
            println!(
                "{set:?}: no ray count up to {} reached 0.05 K",
                counts[counts.len() - 1]
            );
            continue;
        };
        let mc = MrtEngine::new(
            &scene,
            Method::MonteCarlo(MonteCarlo {
                rays,
                seed: 1,
                directions: set,
                replicates: 8,
            }),
        )
        .unwrap();
        let mut times: Vec<f64> = (0..5)
            .map(|_| {
                let t = Instant::now();
                let f = MrtField::compute(&mc, frame.clone(), GridSpec::default()).unwrap();
                assert_eq!(f.nodes.len(), 400);
                t.elapsed().as_secs_f64()
            })
            .collect();
        times.sort_by(f64::total_cmp);
        println!(
            "{set:?}: {rays} rays per point reach a 0.05 K standard error; a 20×20 map takes {:.3} s (median of 5, {} threads)",
            times[2],
            rayon::current_num_threads()
        );
    }
}
