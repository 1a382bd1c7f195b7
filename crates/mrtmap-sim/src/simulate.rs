//! The scan simulator: a walk through a room, sensors on their own clocks, a recording written in
//! the recording layout (docs/recording.md), and its truth.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use mrtmap_geometry::camera::{BrownConrady, PinholeCamera};
use mrtmap_geometry::nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};
use mrtmap_io::masks::{labels_path, mask_labels_json};
use mrtmap_io::{
    EncodeError, FileError, ImuSample, PartialDir, PoseFile, RecordingFile, RgbCamera, Rig,
    ThermalEncoding, Trajectory, encode_png_rgb8, encode_png16, imu_text, stream_list_text,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::SimError;
use crate::radiometric::{CameraErrors, RadiometricModel, ReferenceReading, reference_readings};
use crate::render::RoomRenderer;
use crate::room::Room;
use crate::room::grey::Surfaces;
use crate::sensors::{
    DepthNoise, ThermalNoise, camera_rays, render_depth, render_rgb_and_mask, render_thermal,
};
use crate::truth::compute_truth;
use crate::walk::{Walk, WalkParams};

/// How noisy the sensors are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum NoiseLevel {
    /// Exact depth (to the millimetre), exact thermal (to the centikelvin), exact labels.
    None,
    /// D435i-like depth noise and invalid pixels, Lepton-like NETD and blur, grazing emissivity,
    /// detector-like label mistakes.
    Realistic,
}

/// Pose drift of the SLAM estimate (trajectory.txt) against the truth (groundtruth.txt): random
/// walks in position and in heading about up.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Drift {
    /// Position random walk (m/√s).
    pub position_m_per_sqrt_s: f64,
    /// Heading random walk (degrees/√s).
    pub heading_deg_per_sqrt_s: f64,
}

impl Drift {
    /// No drift: trajectory.txt equals groundtruth.txt.
    pub const NONE: Drift = Drift {
        position_m_per_sqrt_s: 0.0,
        heading_deg_per_sqrt_s: 0.0,
    };
    /// Visual SLAM without loop closure (≈ 7 cm and 0.6° after 343 s, 1 σ).
    pub const SLAM: Drift = Drift {
        position_m_per_sqrt_s: 0.004,
        heading_deg_per_sqrt_s: 0.03,
    };
    /// Plain odometry (≈ 19 cm and 1.9° after 343 s).
    pub const ODOMETRY: Drift = Drift {
        position_m_per_sqrt_s: 0.01,
        heading_deg_per_sqrt_s: 0.1,
    };
}

/// Simulation settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimConfig {
    /// Length of the scan (s); the seed paper's took 343 s.
    pub seconds: f64,
    /// Seed of everything random.
    pub seed: u64,
    /// Noise level.
    pub noise: NoiseLevel,
    /// Depth camera (the colour camera is the same: depth aligned to colour).
    pub depth_camera: PinholeCamera,
    /// Depth raw units per metre.
    pub depth_scale: f64,
    /// Depth and colour frame rates (Hz).
    pub depth_hz: f64,
    /// Thermal camera.
    pub thermal_camera: PinholeCamera,
    /// Thermal frame rate (Hz).
    pub thermal_hz: f64,
    /// Colour and mask frame rate (Hz).
    pub rgb_hz: f64,
    /// Pose rate (Hz).
    pub pose_hz: f64,
    /// p_in_depth = depth_from_thermal · p_in_thermal.
    pub depth_from_thermal: Isometry3<f64>,
    /// Thermal imperfections used with `NoiseLevel::Realistic` (bias also applies to `None`).
    pub thermal_noise: ThermalNoise,
    /// Depth imperfections used with `NoiseLevel::Realistic`.
    pub depth_noise: DepthNoise,
    /// SLAM drift of trajectory.txt.
    pub drift: Drift,
    /// The walk.
    pub walk: WalkParams,
    /// Monte Carlo rays per truth point (rooms with furniture or not convex).
    pub truth_rays: usize,
    /// The thermal camera's radiometric errors (offset, gain, FFC, drift, vignetting, fixed
    /// pattern); none by default.
    pub radiometric: RadiometricModel,
    /// Contact-thermometer readings written to references.csv (0: none).
    pub references: usize,
    /// Their standard uncertainty (K).
    pub reference_std_k: f64,
    /// Write trajectory.txt (the pose source's estimate); without it the recording has no poses
    /// and a tracker must find them (groundtruth.txt keeps the truth either way).
    pub poses_in_recording: bool,
    /// How late the thermal frames are stamped (s): a USB thermal board's frames are stamped by
    /// the host when they arrive, after readout and transfer, so thermal.txt's times are the
    /// exposure's plus this. `None`: the noise level's default (a lag drawn from the seed,
    /// uniform in 40–120 ms, with realistic noise; none without noise).
    pub thermal_lag_s: Option<f64>,
    /// Whether glass gives no depth (see [`DepthNoise::glass_see_through`]); `None`: the noise
    /// level's default (on with realistic noise, off without: panes then return depth like a
    /// wall, an idealised camera).
    pub glass: Option<bool>,
    /// Black or grey surfaces (see [`Surfaces`]); `None`: the noise level's default (grey with
    /// realistic noise: real rooms are grey, and window glass mirrors the operator; black without).
    #[serde(default)]
    pub surfaces: Option<Surfaces>,
    /// The sun through the windows: truth.json gets SolarCal's ΔMRT on its grid (the recording
    /// is unchanged: a long-wave camera cannot see the beam).
    #[serde(default)]
    pub sun: Option<crate::truth::SimSun>,
    /// How far the rig's true `depth_from_thermal` is from the one rig.toml is written with (a
    /// calibration a little off): the frames are rendered with the true one.
    #[serde(default)]
    pub extrinsic_error: Option<ExtrinsicError>,
}

/// A calibration error of the thermal camera's pose: a translation of `translation_mm` and a
/// rotation of `rotation_deg`, each along (about) a direction drawn from the seed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExtrinsicError {
    /// The translation's length (mm).
    pub translation_mm: f64,
    /// The rotation's angle (degrees).
    pub rotation_deg: f64,
}

/// Where a realistic thermal lag is drawn from (s).
pub const REALISTIC_LAG_S: std::ops::Range<f64> = 0.040..0.120;

impl SimConfig {
    /// The thermal camera's true pose in the depth camera's frame: rig.toml's
    /// (`depth_from_thermal`) moved by [`SimConfig::extrinsic_error`], its directions drawn from
    /// the seed.
    pub fn true_depth_from_thermal(&self) -> Isometry3<f64> {
        let Some(e) = self.extrinsic_error else {
            return self.depth_from_thermal;
        };
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed ^ 0x0e7a_1b5c);
        let mut unit = || {
            let v = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if v.norm() > 1e-6 {
                v.normalize()
            } else {
                Vector3::x()
            }
        };
        let (t, axis) = (unit(), unit());
        let error = Isometry3::from_parts(
            Translation3::from(t * e.translation_mm / 1000.0),
            UnitQuaternion::from_scaled_axis(axis * e.rotation_deg.to_radians()),
        );
        self.depth_from_thermal * error
    }

    /// Whether the depth camera sees through glass in this configuration.
    pub fn glass_on(&self) -> bool {
        self.glass.unwrap_or(self.noise == NoiseLevel::Realistic)
    }

    /// Whether the room's surfaces are black or grey in this configuration.
    pub fn surfaces(&self) -> Surfaces {
        self.surfaces.unwrap_or(match self.noise {
            NoiseLevel::Realistic => Surfaces::Grey,
            NoiseLevel::None => Surfaces::Black,
        })
    }

    /// The thermal stamps' lag this configuration gives (s).
    pub fn lag_s(&self) -> f64 {
        match (self.thermal_lag_s, self.noise) {
            (Some(l), _) => l,
            (None, NoiseLevel::None) => 0.0,
            (None, NoiseLevel::Realistic) => {
                let mut r = ChaCha8Rng::seed_from_u64(self.seed ^ 0x1a6_u64.rotate_left(52));
                r.random_range(REALISTIC_LAG_S)
            }
        }
    }
}

impl Default for SimConfig {
    fn default() -> Self {
        let mut thermal = PinholeCamera::from_hfov(160, 120, 57f64.to_radians());
        thermal.distortion = BrownConrady::from_array([-0.12, 0.06, 0.0005, -0.0008, 0.0]);
        // The Lepton sits 3.5 cm right of and 2.5 cm above the depth camera, tilted by about a degree.
        let rot = UnitQuaternion::from_euler_angles(
            0.4f64.to_radians(),
            -1.1f64.to_radians(),
            0.3f64.to_radians(),
        );
        Self {
            seconds: 343.0,
            seed: 1,
            noise: NoiseLevel::Realistic,
            depth_camera: PinholeCamera::new(640, 480, 385.0, 385.0, 319.5, 239.5),
            depth_scale: 1000.0,
            depth_hz: 30.0,
            thermal_camera: thermal,
            thermal_hz: 8.7,
            rgb_hz: 5.0,
            pose_hz: 200.0,
            depth_from_thermal: Isometry3::from_parts(Translation3::new(0.035, -0.025, 0.004), rot),
            thermal_noise: ThermalNoise::REALISTIC,
            depth_noise: DepthNoise::default(),
            drift: Drift::NONE,
            walk: WalkParams::default(),
            truth_rays: 100_000,
            radiometric: RadiometricModel::NONE,
            references: 0,
            reference_std_k: 0.1,
            poses_in_recording: true,
            thermal_lag_s: None,
            glass: None,
            surfaces: None,
            sun: None,
            extrinsic_error: None,
        }
    }
}

/// What a simulation wrote.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimSummary {
    /// The recording folder.
    pub out: PathBuf,
    /// Depth frames.
    pub depth_frames: usize,
    /// Thermal frames.
    pub thermal_frames: usize,
    /// Colour (and mask) frames.
    pub rgb_frames: usize,
    /// Poses.
    pub poses: usize,
    /// Bytes written.
    pub bytes: u64,
    /// The truth method ("exact" or "montecarlo").
    pub truth_method: String,
}

/// Progress: frames done out of the total.
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

fn stamps(seconds: f64, hz: f64, jitter_s: f64, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let phase = rng.random_range(0.0..1.0 / hz);
    let mut out = Vec::new();
    let mut k = 0;
    loop {
        let t = phase + k as f64 / hz + rng.random_range(-jitter_s..=jitter_s);
        if t > seconds - 1e-3 {
            break;
        }
        if t > 1e-3 {
            out.push(t);
        }
        k += 1;
    }
    out
}

/// Recording timestamps start here (a Unix time, like real recordings).
pub const TIME_ORIGIN_S: f64 = 1_700_000_000.0;

/// The folder being written, and how many bytes went into it.
struct Out {
    root: PathBuf,
    bytes: AtomicU64,
}

impl Out {
    fn write(&self, rel: &str, bytes: &[u8]) -> Result<(), SimError> {
        let path = self.root.join(rel);
        std::fs::write(&path, bytes).map_err(|e| SimError::Write { path, source: e })?;
        self.bytes.fetch_add(bytes.len() as u64, Ordering::Relaxed);
        Ok(())
    }

    fn write_png(&self, rel: &str, png: Result<Vec<u8>, EncodeError>) -> Result<(), SimError> {
        let png = png.map_err(|e| FileError::encode(&self.root.join(rel), e))?;
        self.write(rel, &png)
    }
}

/// Refuses settings out of range.
fn check(cfg: &SimConfig) -> Result<(), SimError> {
    if !(cfg.seconds > 0.5 && cfg.seconds <= 7200.0) {
        return Err(SimError::OutOfRange {
            what: "seconds".into(),
            value: cfg.seconds,
            range: "0.5…7200 s",
        });
    }
    for (name, hz) in [
        ("depth", cfg.depth_hz),
        ("thermal", cfg.thermal_hz),
        ("rgb", cfg.rgb_hz),
        ("pose", cfg.pose_hz),
    ] {
        if !(hz > 0.0 && hz <= 1000.0) {
            return Err(SimError::OutOfRange {
                what: format!("{name} rate (Hz)"),
                value: hz,
                range: "0…1000 Hz",
            });
        }
    }
    let lag = cfg.lag_s();
    if !(0.0..=1.0).contains(&lag) {
        return Err(SimError::OutOfRange {
            what: "thermal lag (s)".into(),
            value: lag,
            range: "0…1 s",
        });
    }
    if let Some(sun) = &cfg.sun {
        sun.check()?;
    }
    Ok(())
}

/// The SLAM estimate of `truth`: a random walk in position and heading about `up`.
fn drifting(
    truth: &[Isometry3<f64>],
    up: &Unit<Vector3<f64>>,
    cfg: &SimConfig,
    rng: &mut ChaCha8Rng,
) -> Vec<Isometry3<f64>> {
    let std = Normal::new(0.0, 1.0).unwrap_or_else(|_| unreachable!("unit normal"));
    let dt = 1.0 / cfg.pose_hz;
    let (mut p, mut th) = (Vector3::zeros(), 0.0f64);
    truth
        .iter()
        .enumerate()
        .map(|(k, tp)| {
            if k > 0 {
                p += Vector3::new(std.sample(rng), std.sample(rng), std.sample(rng))
                    * cfg.drift.position_m_per_sqrt_s
                    * dt.sqrt();
                th += std.sample(rng) * cfg.drift.heading_deg_per_sqrt_s.to_radians() * dt.sqrt();
            }
            Isometry3::from_parts(
                Translation3::from(p),
                UnitQuaternion::from_axis_angle(up, th),
            ) * tp
        })
        .collect()
}

/// Writes groundtruth.txt and, unless the recording is to have no poses, trajectory.txt (with the
/// configured drift); returns the pose count.
fn write_poses(
    out: &Out,
    walk: &Walk,
    world_from_room: &Isometry3<f64>,
    cfg: &SimConfig,
    header: &str,
    rng: &mut ChaCha8Rng,
) -> Result<usize, SimError> {
    let n_poses = (cfg.seconds * cfg.pose_hz).floor() as usize + 1;
    let pose_t: Vec<f64> = (0..n_poses).map(|k| k as f64 / cfg.pose_hz).collect();
    let truth_poses: Vec<Isometry3<f64>> = pose_t
        .iter()
        .map(|&t| world_from_room * walk.room_from_depth(t))
        .collect();
    let up = Unit::new_normalize(world_from_room * Vector3::z());
    let slam_poses = drifting(&truth_poses, &up, cfg, rng);
    let gt = Trajectory {
        stamps: pose_t.iter().map(|&t| TIME_ORIGIN_S + t).collect(),
        poses: truth_poses,
    };
    let slam = Trajectory {
        stamps: gt.stamps.clone(),
        poses: slam_poses,
    };
    out.write(
        RecordingFile::Groundtruth.name(),
        gt.to_tum(&format!(
            "{header}\ntrue poses: timestamp tx ty tz qx qy qz qw (world_from_depth)"
        ))
        .as_bytes(),
    )?;
    if !cfg.poses_in_recording {
        return Ok(n_poses);
    }
    out.write(
        RecordingFile::Trajectory.name(),
        slam.to_tum(&format!("{header}\nSLAM poses (drift {:?})", cfg.drift))
            .as_bytes(),
    )?;
    Ok(n_poses)
}

/// A D435i's inertial unit (Bosch BMI055) as `imu.txt` at the pose rate, in the depth camera's
/// frame: angular velocity and specific force from the walk's motion (central differences of
/// its poses, 2.5 ms apart for the rate, 20 ms for the acceleration), with realistic noise: white noise (gyro 0.014 °/s/√Hz and accelerometer
/// 150 µg/√Hz over a 100 Hz bandwidth, the datasheet's densities) and a constant bias per axis
/// (gyro σ 0.3 °/s, accelerometer σ 0.05 m/s²); exact without noise. Its own random stream, so the
/// frames of a seed are the same with or without it.
fn write_imu(
    out: &Out,
    walk: &Walk,
    world_from_room: &Isometry3<f64>,
    cfg: &SimConfig,
    header: &str,
) -> Result<(), SimError> {
    const G: f64 = 9.80665;
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed ^ 0x1_3u64.rotate_left(40));
    let realistic = cfg.noise == NoiseLevel::Realistic;
    let std = Normal::new(0.0, 1.0).unwrap_or_else(|_| unreachable!("unit normal"));
    let (gyro_white, gyro_bias) = (0.014f64.to_radians() * 10.0, 0.3f64.to_radians());
    let (acc_white, acc_bias) = (150e-6 * G * 10.0, 0.05);
    let draw3 = |sd: f64, rng: &mut ChaCha8Rng| {
        if realistic {
            Vector3::new(std.sample(rng), std.sample(rng), std.sample(rng)) * sd
        } else {
            Vector3::zeros()
        }
    };
    let bg = draw3(gyro_bias, &mut rng);
    let ba = draw3(acc_bias, &mut rng);
    let up_world = world_from_room * Vector3::z();
    let h = 0.5 / cfg.pose_hz;
    let n = (cfg.seconds * cfg.pose_hz).floor() as usize + 1;
    let pose = |t: f64| world_from_room * walk.room_from_depth(t);
    // The acceleration over ±20 ms (an accelerometer's bandwidth; the walk's path has millimetre
    // steps that a 2.5 ms difference turns into spikes); both windows kept inside the walk.
    let wide = 0.02;
    let samples: Vec<ImuSample> = (0..n)
        .map(|k| {
            let t = k as f64 / cfg.pose_hz;
            let tw = t.clamp(h, cfg.seconds - h);
            let (a, b, c) = (pose(tw - h), pose(tw), pose(tw + h));
            // Body rates: the rotation from t - h to t + h (in the frame at t - h), turned into
            // the frame at t.
            let turn = (a.rotation.inverse() * c.rotation).scaled_axis() / (2.0 * h);
            let w = (b.rotation.inverse() * a.rotation) * turn;
            let ta = t.clamp(wide, cfg.seconds - wide);
            let acc = (pose(ta + wide).translation.vector - 2.0 * pose(ta).translation.vector
                + pose(ta - wide).translation.vector)
                / (wide * wide);
            // An accelerometer at rest reads +g upwards.
            let f = b.rotation.inverse() * (acc + up_world * G);
            ImuSample {
                t: TIME_ORIGIN_S + t,
                gyro: w + bg + draw3(gyro_white, &mut rng),
                accel: f + ba + draw3(acc_white, &mut rng),
            }
        })
        .collect();
    out.write(
        RecordingFile::Imu.name(),
        imu_text(&samples, &format!("{header}\ninertial unit (BMI055 model)")).as_bytes(),
    )
}

/// The rig the simulated cameras form.
fn rig(cfg: &SimConfig) -> Rig {
    Rig {
        depth: cfg.depth_camera,
        depth_scale: cfg.depth_scale,
        thermal: cfg.thermal_camera,
        thermal_encoding: ThermalEncoding::Centikelvin,
        // What the simulated camera can be off by: a Lepton's datasheet ±5 K with radiometric
        // errors, else only the constant bias asked for.
        thermal_accuracy_k: Some(if cfg.radiometric.is_perfect() {
            cfg.thermal_noise.bias_k.abs()
        } else {
            5.0
        }),
        // The simulated rig, like a real one, does not know its thermal stamps' lag.
        thermal_time_offset_s: None,
        depth_from_thermal: cfg.depth_from_thermal,
        rgb: Some(RgbCamera {
            camera: cfg.depth_camera,
            depth_from_rgb: Isometry3::identity(),
        }),
    }
}

/// What every frame renderer needs.
struct Frames<'a> {
    room: &'a Room,
    renderer: RoomRenderer,
    walk: Walk,
    cfg: &'a SimConfig,
    realistic: bool,
    camera: Option<CameraErrors>,
    out: &'a Out,
    tick: &'a (dyn Fn() + Sync),
}

impl Frames<'_> {
    /// Per-frame noise comes from a fast generator seeded from (seed, stream, frame), so frames
    /// can be rendered in any order and on any number of threads with the same result.
    fn rng(&self, stream: u64, k: usize) -> rand_xoshiro::Xoshiro256PlusPlus {
        let mut r = ChaCha8Rng::seed_from_u64(self.cfg.seed);
        r.set_stream((stream << 40) | k as u64);
        rand_xoshiro::Xoshiro256PlusPlus::from_rng(&mut r)
    }

    fn depth(&self, times: &[f64]) -> Result<(), SimError> {
        let cfg = self.cfg;
        let rays = camera_rays(&cfg.depth_camera, 1);
        let noise = self.realistic.then_some(&cfg.depth_noise);
        times.par_iter().enumerate().try_for_each(|(k, &t)| {
            let img = render_depth(
                &self.renderer,
                &cfg.depth_camera,
                &rays,
                &self.walk.room_from_depth(t),
                cfg.depth_scale,
                noise,
                cfg.glass_on().then_some(&cfg.depth_noise),
                &mut self.rng(1, k),
            );
            self.out
                .write_png(&format!("depth/{k:06}.png"), encode_png16(&img))?;
            (self.tick)();
            Ok(())
        })
    }

    fn thermal(&self, times: &[f64]) -> Result<(), SimError> {
        let cfg = self.cfg;
        let noise = if self.realistic {
            cfg.thermal_noise
        } else {
            ThermalNoise {
                bias_k: cfg.thermal_noise.bias_k,
                ..ThermalNoise::NONE
            }
        };
        let rays = camera_rays(&cfg.thermal_camera, noise.supersample);
        // The frames are taken with the true extrinsic; rig.toml says the nominal one.
        let depth_from_thermal = cfg.true_depth_from_thermal();
        let ss = noise.supersample.max(1) as usize;
        let ages = noise.sample_ages_s(ss * ss);
        times.par_iter().enumerate().try_for_each(|(k, &t)| {
            // The walk starts at 0: a frame exposed at its very start sees no earlier scene.
            let poses: Vec<Isometry3<f64>> = if noise.time_constant_s > 0.0 {
                ages.iter()
                    .map(|a| self.walk.room_from_depth((t - a).max(0.0)) * depth_from_thermal)
                    .collect()
            } else {
                vec![self.walk.room_from_depth(t) * depth_from_thermal]
            };
            let img = render_thermal(
                self.room,
                &self.renderer,
                &cfg.thermal_camera,
                &rays,
                &poses,
                ThermalEncoding::Centikelvin,
                &noise,
                self.camera.as_ref().map(|c| (c, t)),
                &mut self.rng(2, k),
            );
            self.out
                .write_png(&format!("thermal/{k:06}.png"), encode_png16(&img))?;
            (self.tick)();
            Ok(())
        })
    }

    fn colour_and_masks(&self, times: &[f64]) -> Result<(), SimError> {
        let cfg = self.cfg;
        let rays = camera_rays(&cfg.depth_camera, 1);
        let (w, h) = (cfg.depth_camera.width, cfg.depth_camera.height);
        times.par_iter().enumerate().try_for_each(|(k, &t)| {
            let (rgb, mask, labels) = render_rgb_and_mask(
                self.room,
                &self.renderer,
                &cfg.depth_camera,
                &rays,
                &self.walk.room_from_depth(t),
                self.realistic,
                &mut self.rng(3, k),
            );
            self.out
                .write_png(&format!("rgb/{k:06}.png"), encode_png_rgb8(w, h, &rgb))?;
            let mask_rel = format!("masks/{k:06}.png");
            self.out.write_png(&mask_rel, encode_png16(&mask))?;
            let labels_rel = labels_path(Path::new(&mask_rel));
            self.out.write(
                &labels_rel.to_string_lossy(),
                mask_labels_json(&labels).as_bytes(),
            )?;
            (self.tick)();
            Ok(())
        })
    }
}

/// Writes the stream lists of the frames' times.
/// (thermal frames are stamped `lag_s` after their exposure).
fn write_lists(
    out: &Out,
    header: &str,
    depth_t: &[f64],
    thermal_t: &[f64],
    rgb_t: &[f64],
    lag_s: f64,
) -> Result<(), SimError> {
    let list = |ts: &[f64], dir: &str, lag: f64| -> Vec<(f64, String)> {
        ts.iter()
            .enumerate()
            .map(|(k, &t)| (TIME_ORIGIN_S + t + lag, format!("{dir}/{k:06}.png")))
            .collect()
    };
    let thermal_what = format!(
        "thermal frames (stamped {:.1} ms after exposure)",
        lag_s * 1e3
    );
    for (file, what, ts, dir, lag) in [
        (
            RecordingFile::Depth.name(),
            "depth frames",
            depth_t,
            "depth",
            0.0,
        ),
        (
            RecordingFile::Thermal.name(),
            thermal_what.as_str(),
            thermal_t,
            "thermal",
            lag_s,
        ),
        (
            RecordingFile::Rgb.name(),
            "colour frames",
            rgb_t,
            "rgb",
            0.0,
        ),
        (
            RecordingFile::Masks.name(),
            "instance masks (16-bit ids, labels in the .json beside each)",
            rgb_t,
            "masks",
            0.0,
        ),
    ] {
        let text = stream_list_text(
            &format!("{header}\n{what}: timestamp path"),
            &list(ts, dir, lag),
        );
        out.write(file, text.as_bytes())?;
    }
    Ok(())
}

/// radiometric_truth.json: the camera's errors and each thermal frame's offset; and
/// references.csv (in the recording's world frame) when contact readings are asked for.
fn write_camera_truth(
    files: &Out,
    room: &Room,
    cfg: &SimConfig,
    camera: Option<&CameraErrors>,
    thermal_t: &[f64],
    world_from_room: &Isometry3<f64>,
) -> Result<(), SimError> {
    let refs = reference_readings(room, cfg.references, cfg.reference_std_k, cfg.seed);
    if !refs.is_empty() {
        // A black room's readings say so (emissivity 1: the camera reads them as they are); a grey
        // room's leave it to the surface under the point, as a user with a contact probe would.
        let mut csv = String::from(
            "# contact-thermometer readings of surface points (x, y, z in the frame of trajectory.txt: frame scan)\nlabel,x,y,z,temperature_c,std_k,frame,emissivity\n",
        );
        let black = if room.is_grey() { "" } else { "1" };
        for r in &refs {
            let p = world_from_room * Point3::from(r.xyz_room);
            csv.push_str(&format!(
                "{},{:.4},{:.4},{:.4},{:.3},{},scan,{black}\n",
                r.label, p.x, p.y, p.z, r.temperature_c, r.std_k
            ));
        }
        files.write(RecordingFile::References.name(), csv.as_bytes())?;
    }
    #[derive(Serialize)]
    struct CameraTruth<'a> {
        camera: Option<&'a CameraErrors>,
        /// (time since the scan's start, offset common to the image) per thermal frame.
        frame_offsets_k: Vec<(f64, f64)>,
        references: &'a [ReferenceReading],
    }
    let truth = CameraTruth {
        camera,
        frame_offsets_k: thermal_t
            .iter()
            .map(|&t| (t, camera.map_or(0.0, |c| c.offset_at(t))))
            .collect(),
        references: &refs,
    };
    let json = serde_json::to_string_pretty(&truth)?;
    files.write("radiometric_truth.json", (json + "\n").as_bytes())
}

/// Simulates a scan of `room` into the folder `out` (written as `out.partial` and renamed when
/// complete).
pub fn simulate(
    room: &Room,
    cfg: &SimConfig,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SimSummary, SimError> {
    check(cfg)?;
    // The room's surfaces as the configuration asks (a room already made grey stays as it is).
    let greyed;
    let room = if room.grey.is_none() && cfg.surfaces() == Surfaces::Grey {
        greyed = room
            .clone()
            .with_surfaces(cfg.surfaces(), cfg.seed, 20_000)?;
        &greyed
    } else {
        room
    };
    let dir = PartialDir::create(out)?;
    let root = dir.path().to_path_buf();
    for sub in ["depth", "thermal", "rgb", "masks"] {
        std::fs::create_dir_all(root.join(sub)).map_err(|e| SimError::Write {
            path: root.join(sub),
            source: e,
        })?;
    }
    let files = Out {
        root,
        bytes: AtomicU64::new(0),
    };
    let walk = Walk::new(room, cfg.walk, cfg.seed);
    let world_from_room = walk.room_from_depth(0.0).inverse();
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let header = format!(
        "mrtmap simulate: room {}, seed {}, noise {:?}",
        room.file.name, cfg.seed, cfg.noise
    );
    let poses = write_poses(&files, &walk, &world_from_room, cfg, &header, &mut rng)?;
    write_imu(&files, &walk, &world_from_room, cfg, &header)?;
    let depth_t = stamps(cfg.seconds, cfg.depth_hz, 0.0003, &mut rng);
    let thermal_t = stamps(cfg.seconds, cfg.thermal_hz, 0.002, &mut rng);
    let rgb_t = stamps(cfg.seconds, cfg.rgb_hz, 0.0003, &mut rng);
    let total = (depth_t.len() + thermal_t.len() + rgb_t.len()) as u64;
    let done = AtomicU64::new(0);
    let tick = || progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
    files.write(RecordingFile::Rig.name(), rig(cfg).to_toml().as_bytes())?;
    let camera = (!cfg.radiometric.is_perfect()).then(|| {
        CameraErrors::draw(
            cfg.radiometric,
            cfg.seconds,
            cfg.thermal_camera.width as usize,
            cfg.thermal_camera.height as usize,
            cfg.seed,
        )
    });
    let frames = Frames {
        room,
        renderer: RoomRenderer::new(room),
        walk,
        cfg,
        realistic: cfg.noise == NoiseLevel::Realistic,
        camera,
        out: &files,
        tick: &tick,
    };
    frames.depth(&depth_t)?;
    frames.thermal(&thermal_t)?;
    frames.colour_and_masks(&rgb_t)?;
    let lag_s = cfg.lag_s();
    write_lists(&files, &header, &depth_t, &thermal_t, &rgb_t, lag_s)?;
    let room_toml = toml::to_string(&room.file_as_simulated())?;
    files.write("room.toml", room_toml.as_bytes())?;
    let mut truth = compute_truth(room, &world_from_room, cfg.truth_rays, cfg.seed)?;
    truth.thermal_lag_s = lag_s;
    truth.true_depth_from_thermal = cfg
        .extrinsic_error
        .map(|_| PoseFile::from_isometry(&cfg.true_depth_from_thermal()));
    truth.sun = cfg
        .sun
        .as_ref()
        .map(|s| crate::truth::sun_truth(room, &truth.grid, s))
        .transpose()?;
    if cfg.noise == NoiseLevel::Realistic {
        truth.thermal_time_constant_s = cfg.thermal_noise.time_constant_s;
    }
    let truth_json = serde_json::to_string_pretty(&truth)?;
    files.write("truth.json", (truth_json + "\n").as_bytes())?;
    write_camera_truth(
        &files,
        room,
        cfg,
        frames.camera.as_ref(),
        &thermal_t,
        &world_from_room,
    )?;
    let out = dir.finish()?;
    Ok(SimSummary {
        out,
        depth_frames: depth_t.len(),
        thermal_frames: thermal_t.len(),
        rgb_frames: rgb_t.len(),
        poses,
        bytes: files.bytes.load(Ordering::Relaxed),
        truth_method: truth.method,
    })
}
/// `room` with its surfaces as `cfg` asks (see [`crate::SimConfig::surfaces`]): what
/// [`crate::simulate`] renders and computes the truth of. A room already grey, or one whose file
/// gives the emissivities simulated (a recording's room.toml), keeps them.
pub fn room_as_simulated(room: &Room, cfg: &SimConfig) -> Result<Room, SimError> {
    if room.grey.is_some() {
        return Ok(room.clone());
    }
    room.clone()
        .with_surfaces(cfg.surfaces(), cfg.seed, crate::room::grey::IRRADIANCE_RAYS)
}
