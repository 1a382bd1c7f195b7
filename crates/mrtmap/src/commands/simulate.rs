//! `mrtmap simulate`: a handheld scan of a room, with exact truth.

use std::time::Instant;

use mrtmap_pipeline::Progress;
use mrtmap_pipeline::simulation::{Drift, SimConfig, ThermalNoise, simulate};
use mrtmap_pipeline::simulation::{Surfaces, load_room, set_depth_size};

use crate::cli::{DriftArg, SimulateArgs};
use crate::output::Bar;

pub fn run(a: &SimulateArgs) -> anyhow::Result<()> {
    let room = load_room(&a.room)?;
    let mut cfg = SimConfig {
        seconds: a.seconds,
        seed: a.seed,
        ..SimConfig::default()
    };
    cfg.noise = a.noise;
    cfg.drift = match a.drift {
        DriftArg::None => Drift::NONE,
        DriftArg::Slam => Drift::SLAM,
        DriftArg::Odometry => Drift::ODOMETRY,
    };
    cfg.thermal_noise = ThermalNoise {
        bias_k: a.thermal_bias,
        blur_sigma_px: a.thermal_blur,
        time_constant_s: a.thermal_time_constant_ms / 1000.0,
        ..ThermalNoise::REALISTIC
    };
    cfg.glass = a.glass.choice();
    cfg.surfaces = a.surfaces;
    cfg.sun = a.sun.map(
        |[altitude_deg, azimuth_deg]| mrtmap_pipeline::simulation::SimSun {
            altitude_deg,
            azimuth_deg,
            dni_w_m2: a.dni.unwrap_or_default(),
            transmittance: a.transmittance.unwrap_or_default(),
        },
    );
    if let Some(ms) = a.thermal_lag_ms {
        cfg.thermal_lag_s = Some(ms / 1000.0);
    }
    set_depth_size(&mut cfg, a.depth_size)?;
    cfg.depth_hz = a.depth_hz;
    cfg.thermal_hz = a.thermal_hz;
    cfg.rgb_hz = a.rgb_hz;
    cfg.poses_in_recording = !a.no_poses;
    cfg.truth_rays = a.truth_rays;
    cfg.radiometric = a.camera.model(a.noise);
    cfg.references = a.camera.references(a.noise);
    let bar = Bar::new(" frames");
    bar.begin(&format!("simulating {}", room.file.name));
    let t0 = Instant::now();
    let summary = simulate(&room, &cfg, &a.out, &|done, total| bar.advance(done, total))?;
    bar.finish();
    outln!(
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
    outln!(
        "thermal frames stamped {:.1} ms after their exposure (truth.json: thermal_lag_s); glass {}; surfaces {}",
        cfg.lag_s() * 1000.0,
        if cfg.glass_on() {
            "gives no depth"
        } else {
            "returns depth like a wall"
        },
        match cfg.surfaces() {
            Surfaces::Grey =>
                "grey (the camera reads radiosities; truth.json's scene gives each surface's emissivity and true temperature)",
            Surfaces::Black => "black",
        }
    );
    outln!(
        "truth.json: MRT at the validation points and on the 20×20 grid at 1.1 m ({} view factors)",
        summary.truth_method
    );
    Ok(())
}
