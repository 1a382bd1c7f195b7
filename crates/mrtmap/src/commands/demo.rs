//! `mrtmap demo`: simulate the office scan, run the pipeline, compare with the exact truth.

use mrtmap_pipeline::RunLayout;
use mrtmap_pipeline::demo::{DemoSettings, demo};

use crate::cli::DemoArgs;
use crate::output::{Bar, print_lines};

pub fn run(a: &DemoArgs) -> anyhow::Result<()> {
    let t0 = std::time::Instant::now();
    let settings = DemoSettings {
        room: a.room.clone(),
        seconds: if a.full { 343.0 } else { a.seconds },
        seed: a.seed,
        noise: a.noise,
        air_speed_m_s: a.air_speed,
        depth_size: a.depth_size,
        depth_hz: a.depth_hz,
        radiometric: a.camera.model(a.noise),
        references: a.camera.references(a.noise),
        force: a.force,
    };
    // Measured (2026-12-03, with glass and late stamps): 15 s at 640×480 and 30 Hz wrote 154 MB
    // (depth 94 MB, colour 32, thermal 4, the run 20), 60 s 577 MB; at 15 Hz 30 s wrote 197 MB
    // and 60 s 373 MB: about 20 MB for the run, 2.7 MB per second of scan plus 6.6 MB per second
    // of 640×480 depth at 30 Hz.
    // Depth data per second against 640×480 at 30 Hz.
    let depth_share =
        (a.depth_size.0 * a.depth_size.1) as f64 / (640.0 * 480.0) * a.depth_hz / 30.0;
    let estimate_mb = 20.0 + settings.seconds * (2.7 + 6.6 * depth_share);
    eprintln!(
        "writing into {} (about {:.0} MB; remove it when done)",
        a.out.display(),
        estimate_mb
    );
    let bar = Bar::new("");
    let d = demo(&a.out, &settings, &bar)?;
    bar.finish();
    outln!(
        "simulated {:.0} s of scanning the {} room ({:?} noise), ran the pipeline:",
        settings.seconds,
        d.room,
        a.noise
    );
    outln!(
        "  {:<14} {:>7.1} s{}",
        "simulate",
        d.simulate.secs,
        if d.simulate.skipped { "  (reused)" } else { "" }
    );
    print_lines(d.run.lines(&d.run_dir, t0.elapsed().as_secs_f64()));
    outln!();
    outln!("MRT at the validation points (°C), as in the seed paper's table:");
    outln!(
        "  {:<6} {:>12} {:>18} {:>10} {:>16}",
        "point",
        "truth",
        "black globe (ISO)",
        "mrtmap",
        "mrtmap − truth"
    );
    for r in &d.rows {
        outln!(
            "  {:<6} {:>12.2} {:>18.2} {:>10.2} {:>14} K",
            r.name,
            r.truth_c,
            r.globe_c,
            r.ours_c,
            mrtmap_pipeline::report::numbers::signed(r.diff_k, 2)
        );
    }
    outln!(
        "over the 20×20 grid at 1.1 m ({} nodes): max |Δ| {:.3} K, RMSE {:.3} K",
        d.grid.nodes,
        d.grid.max_abs_error_k,
        d.grid.rmse_k
    );
    outln!(
        "report: {}",
        RunLayout::new(&d.run_dir).report_html().display()
    );
    outln!(
        "{} holds {:.0} MB (recording, fused cloud, maps, report)",
        a.out.display(),
        folder_bytes(&a.out) as f64 / 1e6
    );
    Ok(())
}

/// The bytes of the files under `dir` (what cannot be read counts as nothing).
fn folder_bytes(dir: &std::path::Path) -> u64 {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .map(|e| match e.file_type() {
            Ok(t) if t.is_dir() => folder_bytes(&e.path()),
            Ok(t) if t.is_file() => e.metadata().map_or(0, |m| m.len()),
            _ => 0,
        })
        .sum()
}
