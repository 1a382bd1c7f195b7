//! `mrtmap demo`: simulate the office scan, run the pipeline, compare with the exact truth.

use std::time::Instant;

use anyhow::Context;
use mrtmap_geometry::nalgebra::Point3;
use mrtmap_io::write_atomic;
use mrtmap_physics::{
    Globe, GlobeMethod, GlobeReading, Temperature, globe_temperature, mrt_from_globe,
};
use mrtmap_radiation::{Method, MonteCarlo, MrtEngine};
use mrtmap_report::ComparisonRow;
use mrtmap_sim::{NoiseLevel, SimConfig, Truth, simulate};
use serde_json::json;

use super::simulate::load_room;
use crate::cli::{DemoArgs, NoiseArg};
use crate::output::json;
use crate::pipeline::{report_data, run_pipeline};
use crate::project::{PointEntry, Project};

pub fn run(a: &DemoArgs) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let seconds = if a.full { 343.0 } else { a.seconds };
    let room = load_room(&a.room)?;
    let rec_dir = a.out.join("recording");
    let sim_key = json!({ "room": room.file, "seconds": seconds, "seed": a.seed, "noise": format!("{:?}", a.noise), "depth_size": [a.depth_size.0, a.depth_size.1] });
    let sim_file = a.out.join("simulate.json");
    let reuse = !a.force
        && rec_dir.join("truth.json").exists()
        && std::fs::read_to_string(&sim_file)
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .is_some_and(|v| v == sim_key);
    let bar = crate::commands::fuse::progress_bar("");
    let t_sim = Instant::now();
    if !reuse {
        let cfg = SimConfig {
            seconds,
            seed: a.seed,
            noise: match a.noise {
                NoiseArg::None => NoiseLevel::None,
                NoiseArg::Realistic => NoiseLevel::Realistic,
            },
            ..SimConfig::default()
        };
        let mut cfg = cfg;
        cfg.depth_camera = cfg
            .depth_camera
            .scaled(a.depth_size.0 as f64 / cfg.depth_camera.width as f64);
        bar.set_message(format!(
            "simulating {seconds:.0} s of scanning the {} room",
            room.file.name
        ));
        simulate(&room, &cfg, &rec_dir, &|d, t| {
            bar.set_length(t);
            bar.set_position(d);
        })?;
        write_atomic(&sim_file, json(&sim_key)?.as_bytes())?;
    }
    let sim_secs = t_sim.elapsed().as_secs_f64();
    let truth: Truth = serde_json::from_str(&std::fs::read_to_string(rec_dir.join("truth.json"))?)
        .context("truth.json")?;
    let mut project = Project {
        points: truth
            .points
            .iter()
            .map(|p| PointEntry {
                name: p.name.clone(),
                xyz: p.xyz_world,
            })
            .collect(),
        ..Project::default()
    };
    project.air.temperature_c = Some(truth.air_temperature_c);
    project.air.speed_m_s = a.air_speed;
    if a.depth_size.0 < 640 {
        project.fuse.depth_stride = 1; // small frames: every pixel
    }
    let run_dir = a.out.join("run");
    let outcome = run_pipeline(
        &rec_dir,
        &run_dir,
        &project,
        a.force,
        &|stage, done, total| {
            bar.set_message(stage.to_string());
            bar.set_length(total);
            bar.set_position(done);
        },
    )?;
    bar.set_message("comparing with the truth");
    // Ours at the truth's points and grid nodes (world frame), from the segmented scene.
    let engine = MrtEngine::new(
        &outcome.scene,
        Method::Auto(MonteCarlo {
            rays: 100_000,
            ..MonteCarlo::default()
        }),
    )?;
    let air = Temperature::from_celsius(truth.air_temperature_c);
    let mut rows = Vec::new();
    for (k, p) in truth.points.iter().enumerate() {
        let ours = engine
            .at(&Point3::from(p.xyz_world), k as u64)?
            .mrt
            .celsius();
        // A standard black globe in the room: its equilibrium by the mixed-convection model, read
        // back through the ISO 7726 formula, as the seed paper's reference globes were read.
        let tg = globe_temperature(
            &Globe::STANDARD,
            Temperature::from_celsius(p.mrt_c),
            air,
            a.air_speed,
            GlobeMethod::MixedConvection,
        )?;
        let globe_c = mrt_from_globe(
            &Globe::STANDARD,
            &GlobeReading {
                globe: tg,
                air,
                air_speed_m_s: a.air_speed,
            },
            GlobeMethod::ISO,
        )?
        .mrt
        .celsius();
        rows.push(ComparisonRow {
            name: p.name.clone(),
            truth_c: p.mrt_c,
            globe_c,
            ours_c: ours,
            diff_k: ours - p.mrt_c,
        });
    }
    let grid_engine = MrtEngine::new(
        &outcome.scene,
        Method::Auto(MonteCarlo {
            rays: 20_000,
            ..MonteCarlo::default()
        }),
    )?;
    let diffs: Vec<f64> = truth
        .grid
        .nodes
        .iter()
        .enumerate()
        .filter_map(|(k, n)| {
            let t = n.mrt_c?;
            let o = grid_engine
                .at(&Point3::from(n.xyz_world), 10_000 + k as u64)
                .ok()?;
            Some(o.mrt.celsius() - t)
        })
        .collect();
    let max_abs = diffs.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let rmse = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len().max(1) as f64).sqrt();
    bar.finish_and_clear();
    let mut data = report_data(
        &outcome,
        &format!(
            "mrtmap demo: simulated {:.0} s scan of the {} room",
            seconds, room.file.name
        ),
        &rec_dir.display().to_string(),
        &project,
    );
    data.comparison = rows.clone();
    data.grid_error = Some((max_abs, rmse, diffs.len()));
    data.timing.insert(
        0,
        (
            "simulate".into(),
            format!("{sim_secs:.1}{}", if reuse { " (reused)" } else { "" }),
        ),
    );
    write_atomic(
        &run_dir.join("report.html"),
        mrtmap_report::render_html(&data).as_bytes(),
    )?;
    let secs = t0.elapsed().as_secs_f64();
    write_atomic(
        &a.out.join("demo.json"),
        json(&json!({ "points": rows, "grid": { "nodes": diffs.len(), "max_abs_error_k": max_abs, "rmse_k": rmse }, "stages": outcome.stages, "seconds": secs, "simulate_seconds": sim_secs, "scan_seconds": seconds }))?.as_bytes(),
    )?;
    println!(
        "simulated {seconds:.0} s of scanning the {} room ({:?} noise), ran the pipeline:",
        room.file.name, a.noise
    );
    println!(
        "  {:<14} {:>7.1} s{}",
        "simulate",
        sim_secs,
        if reuse { "  (reused)" } else { "" }
    );
    crate::commands::run::print_summary(&outcome, &run_dir, secs);
    println!();
    println!("MRT at the validation points (°C), as in the seed paper's table:");
    println!(
        "  {:<6} {:>12} {:>18} {:>10} {:>16}",
        "point", "truth", "black globe (ISO)", "mrtmap", "mrtmap − truth"
    );
    for r in &rows {
        println!(
            "  {:<6} {:>12.2} {:>18.2} {:>10.2} {:>+14.2} K",
            r.name, r.truth_c, r.globe_c, r.ours_c, r.diff_k
        );
    }
    println!(
        "over the 20×20 grid at 1.1 m ({} nodes): max |Δ| {max_abs:.3} K, RMSE {rmse:.3} K",
        diffs.len()
    );
    println!("report: {}", run_dir.join("report.html").display());
    Ok(())
}
