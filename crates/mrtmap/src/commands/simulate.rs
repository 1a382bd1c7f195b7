//! `mrtmap simulate` and `mrtmap rooms`.

use std::time::Instant;

use anyhow::{Context, bail};
use mrtmap_sim::{Drift, NoiseLevel, PRESETS, Room, SimConfig, ThermalNoise, preset, simulate};

use crate::cli::{DriftArg, NoiseArg, RoomsArgs, SimulateArgs};

/// A preset name or a TOML file.
pub(crate) fn load_room(spec: &str) -> anyhow::Result<Room> {
    if let Some(r) = preset(spec) {
        return Ok(r?);
    }
    let path = std::path::Path::new(spec);
    if !path.exists() {
        let names: Vec<&str> = PRESETS.iter().map(|p| p.0).collect();
        bail!(
            "'{spec}' is neither a preset room ({}) nor a file",
            names.join(", ")
        );
    }
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {spec}"))?;
    Room::from_toml(&text).with_context(|| spec.to_string())
}

pub fn run(a: &SimulateArgs) -> anyhow::Result<()> {
    let room = load_room(&a.room)?;
    let mut cfg = SimConfig {
        seconds: a.seconds,
        seed: a.seed,
        ..SimConfig::default()
    };
    cfg.noise = match a.noise {
        NoiseArg::None => NoiseLevel::None,
        NoiseArg::Realistic => NoiseLevel::Realistic,
    };
    cfg.drift = match a.drift {
        DriftArg::None => Drift::NONE,
        DriftArg::Slam => Drift::SLAM,
        DriftArg::Odometry => Drift::ODOMETRY,
    };
    cfg.thermal_noise = ThermalNoise {
        bias_k: a.thermal_bias,
        blur_sigma_px: a.thermal_blur,
        ..ThermalNoise::REALISTIC
    };
    let s = a.depth_size.0 as f64 / cfg.depth_camera.width as f64;
    if (a.depth_size.1 as f64 / cfg.depth_camera.height as f64 - s).abs() > 1e-9 {
        bail!(
            "--depth-size {}x{} must keep the 4:3 aspect of 640x480",
            a.depth_size.0,
            a.depth_size.1
        );
    }
    cfg.depth_camera = cfg.depth_camera.scaled(s);
    cfg.depth_hz = a.depth_hz;
    cfg.thermal_hz = a.thermal_hz;
    cfg.rgb_hz = a.rgb_hz;
    cfg.truth_rays = a.truth_rays;
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} frames ({eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message(format!("simulating {}", room.file.name));
    let t0 = Instant::now();
    let summary = simulate(&room, &cfg, &a.out, &|done, total| {
        bar.set_length(total);
        bar.set_position(done);
    })?;
    bar.finish_and_clear();
    println!(
        "simulated {:.0} s of scanning the {} room in {:.1} s: {} depth, {} thermal, {} colour + mask frames, {} poses; {:.1} MB in {}",
        a.seconds,
        room.file.name,
        t0.elapsed().as_secs_f64(),
        summary.depth_frames,
        summary.thermal_frames,
        summary.rgb_frames,
        summary.poses,
        summary.bytes as f64 / 1e6,
        summary.out.display()
    );
    println!(
        "truth.json: MRT at the validation points and on the 20×20 grid at 1.1 m ({} view factors)",
        summary.truth_method
    );
    Ok(())
}

pub fn rooms(a: &RoomsArgs) -> anyhow::Result<()> {
    match &a.name {
        Some(n) => match PRESETS.iter().find(|p| p.0 == n) {
            Some((_, text)) => print!("{text}"),
            None => bail!("no preset room '{n}' (see `mrtmap rooms`)"),
        },
        None => {
            for (name, text) in PRESETS {
                let room = Room::from_toml(text)?;
                println!("{name:<16} {}", room.file.description);
            }
        }
    }
    Ok(())
}
