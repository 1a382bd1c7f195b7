use std::path::Path;

use mrtmap_geometry::nalgebra::{Isometry3, Translation3};
use mrtmap_io::Recording;
use mrtmap_scan::{FuseParams, Fused, fuse};
use mrtmap_sim::{
    CloudScore, Drift, NoiseLevel, Room, SimConfig, Truth, preset, score_cloud, simulate,
};

/// Simulates a short scan at 320×240 depth.
pub fn scan(room: &str, noise: NoiseLevel, drift: Drift, seconds: f64, out: &Path) -> Room {
    scan_scaled(room, noise, drift, seconds, 0.5, out)
}

/// Simulates a scan with the depth camera scaled by `depth_scale` (1 = 640×480).
pub fn scan_scaled(
    room: &str,
    noise: NoiseLevel,
    drift: Drift,
    seconds: f64,
    depth_scale: f64,
    out: &Path,
) -> Room {
    scan_glass(room, noise, drift, seconds, depth_scale, 1, true, out)
}

/// [`scan_scaled`] with the walk of `seed` and the field effects of real rigs (glass that gives no depth, late thermal
/// stamps, the bolometer's time constant) as the noise level has them (`true`), or without them
/// (`false`: the idealised rig of the simulator before issue 36).
#[allow(clippy::too_many_arguments)]
pub fn scan_glass(
    room: &str,
    noise: NoiseLevel,
    drift: Drift,
    seconds: f64,
    depth_scale: f64,
    seed: u64,
    field_effects: bool,
    out: &Path,
) -> Room {
    let mut cfg = SimConfig {
        seconds,
        noise,
        drift,
        seed,
        truth_rays: 1_000,
        ..SimConfig::default()
    };
    if !field_effects {
        cfg.glass = Some(false);
        cfg.thermal_lag_s = Some(0.0);
        cfg.thermal_noise.time_constant_s = 0.0;
    }
    cfg.depth_camera = cfg.depth_camera.scaled(depth_scale);
    // A preset, or a room of bench/rooms by its file name.
    let room = match preset(room) {
        Some(r) => r.unwrap(),
        None => {
            let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../bench/rooms")
                .join(room);
            Room::from_toml(&std::fs::read_to_string(&path).unwrap()).unwrap()
        }
    };
    // The room as simulated (grey with realistic noise), so that scores compare with what the
    // camera saw.
    let room = mrtmap_sim::room_as_simulated(&room, &cfg).unwrap();
    simulate(&room, &cfg, out, &|_, _| {}).unwrap();
    room
}

/// Default fusion at depth stride 1 (the small test frames).
pub fn params(icp: bool) -> FuseParams {
    let mut p = FuseParams::default();
    p.depth.stride = 1;
    p.icp.enabled = icp;
    p
}

pub fn fuse_dir(dir: &Path, p: &FuseParams) -> Fused {
    fuse(&Recording::open(dir).unwrap(), p, &|_, _| {})
}

/// The simulated room's frame in the scan's world frame (from truth.json).
pub fn truth_world_from_room(dir: &Path) -> Isometry3<f64> {
    let truth: Truth =
        serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).unwrap()).unwrap();
    let t = truth.world_from_room;
    Isometry3::from_parts(
        Translation3::new(t.translation[0], t.translation[1], t.translation[2]),
        mrtmap_io::unit_quaternion(t.rotation_xyzw).unwrap(),
    )
}

pub fn score(room: &Room, dir: &Path, fused: &Fused) -> CloudScore {
    score_cloud(room, &truth_world_from_room(dir), &fused.cloud, 0.03)
}
