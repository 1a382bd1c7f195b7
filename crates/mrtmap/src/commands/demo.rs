//! `mrtmap demo`: simulate the office scan, run the pipeline, compare with the exact truth.

use mrtmap_pipeline::demo::{DemoSettings, demo};
use mrtmap_sim::NoiseLevel;

use crate::cli::{DemoArgs, NoiseArg};
use crate::output::{Bar, print_run};

pub fn run(a: &DemoArgs) -> anyhow::Result<()> {
    let t0 = std::time::Instant::now();
    let settings = DemoSettings {
        room: a.room.clone(),
        seconds: if a.full { 343.0 } else { a.seconds },
        seed: a.seed,
        noise: match a.noise {
            NoiseArg::None => NoiseLevel::None,
            NoiseArg::Realistic => NoiseLevel::Realistic,
        },
        air_speed_m_s: a.air_speed,
        depth_size: a.depth_size,
        force: a.force,
    };
    let bar = Bar::new("");
    let d = demo(&a.out, &settings, &bar)?;
    bar.finish();
    println!(
        "simulated {:.0} s of scanning the {} room ({:?} noise), ran the pipeline:",
        settings.seconds, d.room, a.noise
    );
    println!(
        "  {:<14} {:>7.1} s{}",
        "simulate",
        d.simulate.secs,
        if d.simulate.skipped { "  (reused)" } else { "" }
    );
    print_run(&d.run, &d.run_dir, t0.elapsed().as_secs_f64());
    println!();
    println!("MRT at the validation points (°C), as in the seed paper's table:");
    println!(
        "  {:<6} {:>12} {:>18} {:>10} {:>16}",
        "point", "truth", "black globe (ISO)", "mrtmap", "mrtmap − truth"
    );
    for r in &d.rows {
        println!(
            "  {:<6} {:>12.2} {:>18.2} {:>10.2} {:>+14.2} K",
            r.name, r.truth_c, r.globe_c, r.ours_c, r.diff_k
        );
    }
    println!(
        "over the 20×20 grid at 1.1 m ({} nodes): max |Δ| {:.3} K, RMSE {:.3} K",
        d.grid.nodes, d.grid.max_abs_error_k, d.grid.rmse_k
    );
    println!("report: {}", d.run_dir.join("report.html").display());
    Ok(())
}
