use std::path::Path;

use mrtmap_sim::{NoiseLevel, SimConfig, SimSummary, preset, simulate};

/// A short, small simulation: 160×120 depth, few truth rays, so tests stay quick.
pub fn quick(room: &str, noise: NoiseLevel, seconds: f64, out: &Path) -> (SimConfig, SimSummary) {
    let mut cfg = SimConfig {
        seconds,
        noise,
        truth_rays: 2_000,
        ..SimConfig::default()
    };
    cfg.depth_camera = cfg.depth_camera.scaled(0.25);
    let room = preset(room).unwrap().unwrap();
    let s = simulate(&room, &cfg, out, &|_, _| {}).unwrap();
    (cfg, s)
}
