//! Rooms and simulator settings shared by `simulate` and `demo`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use mrtmap_sim::preset;
pub(crate) use mrtmap_sim::{
    Drift, ExtrinsicError, NoiseLevel, RadiometricModel, SimConfig, SimSun, Surfaces, ThermalNoise,
    simulate,
};
/// The simulator's preset rooms (mrtmap-sim's).
pub use mrtmap_sim::{PRESETS, Room};

use crate::error::{Error, Result};
use crate::progress::Progress;

/// A preset room by name, or a room TOML file.
pub(crate) fn load_room(spec: &str) -> Result<Room> {
    if let Some(r) = preset(spec) {
        return Ok(r?);
    }
    let path = Path::new(spec);
    if !path.exists() {
        let names: Vec<&str> = PRESETS.iter().map(|p| p.0).collect();
        return Err(Error::setting(
            format!("room '{spec}'"),
            format!("is neither a preset room ({}) nor a file", names.join(", ")),
        ));
    }
    let text = std::fs::read_to_string(path).map_err(|e| mrtmap_io::FileError::io(path, e))?;
    Room::from_toml(&text).map_err(|e| Error::source(path, e.to_string()))
}

/// Sets the depth (and colour) image size of `cfg`, scaling the intrinsics; the size must keep
/// the default camera's aspect.
pub(crate) fn set_depth_size(cfg: &mut SimConfig, (w, h): (usize, usize)) -> Result<()> {
    let s = w as f64 / cfg.depth_camera.width as f64;
    if (h as f64 / cfg.depth_camera.height as f64 - s).abs() > 1e-9 {
        return Err(Error::setting(
            format!("--depth-size {w}x{h}"),
            format!(
                "must keep the aspect of {}x{}",
                cfg.depth_camera.width, cfg.depth_camera.height
            ),
        ));
    }
    cfg.depth_camera = cfg.depth_camera.scaled(s);
    Ok(())
}

/// A simulated effect: on, off, or the noise level's default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum AutoOnOff {
    /// On with --noise realistic, off with none.
    Auto,
    /// On.
    On,
    /// Off.
    Off,
}

impl AutoOnOff {
    /// `None` for auto.
    pub fn choice(self) -> Option<bool> {
        match self {
            Self::Auto => None,
            Self::On => Some(true),
            Self::Off => Some(false),
        }
    }
}

/// SLAM drift of a simulation's trajectory.txt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum DriftChoice {
    /// trajectory.txt equals groundtruth.txt.
    None,
    /// Visual SLAM without loop closure: 4 mm/√s in position, 0.03°/√s in heading.
    Slam,
    /// Plain odometry: 1 cm/√s, 0.1°/√s.
    Odometry,
}

/// `mrtmap simulate`: a handheld scan of a room, with exact truth.
#[derive(Debug, Clone, clap::Args)]
pub struct SimulateArgs {
    /// A preset room (office, l-shaped, radiant-ceiling; see `mrtmap rooms`) or a room TOML file.
    #[arg(long, default_value = "office")]
    pub(crate) room: String,
    /// Output folder for the recording (written as DIR.partial, renamed when complete).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: PathBuf,
    /// Length of the scan (s); the seed paper's took 343 s.
    #[arg(long, default_value_t = 343.0)]
    pub(crate) seconds: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Sensor noise.
    #[arg(long, value_enum, default_value_t = NoiseLevel::Realistic)]
    pub(crate) noise: NoiseLevel,
    /// SLAM drift in trajectory.txt (groundtruth.txt always has the true poses).
    #[arg(long, value_enum, default_value_t = DriftChoice::None)]
    pub(crate) drift: DriftChoice,
    /// Constant thermal camera offset (K), added to every reading.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub(crate) thermal_bias: f64,
    /// Thermal optical blur, Gaussian σ in pixels (realistic noise only).
    #[arg(long, default_value_t = 0.5)]
    pub(crate) thermal_blur: f64,
    /// Depth (and colour) image size, WIDTHxHEIGHT; intrinsics scale with it.
    #[arg(long, default_value = "640x480", value_parser = crate::parse::parse_grid)]
    pub(crate) depth_size: (usize, usize),
    /// Depth frame rate (Hz).
    #[arg(long, default_value_t = 30.0)]
    pub(crate) depth_hz: f64,
    /// Thermal frame rate (Hz).
    #[arg(long, default_value_t = 8.7)]
    pub(crate) thermal_hz: f64,
    /// Colour and instance-mask frame rate (Hz).
    #[arg(long, default_value_t = 5.0)]
    pub(crate) rgb_hz: f64,
    /// Leave trajectory.txt out: a recording without a pose source (colour, depth and thermal
    /// only), for `mrtmap track`; groundtruth.txt still has the true poses.
    #[arg(long)]
    pub(crate) no_poses: bool,
    /// How late the thermal frames are stamped (ms): a USB thermal board's frames are stamped on
    /// arrival. Default: drawn from the seed, 40–120 ms, with --noise realistic; 0 with none.
    #[arg(long, value_name = "MS")]
    pub(crate) thermal_lag_ms: Option<f64>,
    /// The microbolometer's time constant (ms): fast turns smear the thermal image (realistic
    /// noise only).
    #[arg(long, value_name = "MS", default_value_t = 12.0)]
    pub(crate) thermal_time_constant_ms: f64,
    /// Windows as an active-stereo depth camera sees them: no depth on the glass (10 % of its
    /// pixels see 4 m beyond); off: panes return depth like a wall. Auto: on with --noise
    /// realistic, off with none.
    #[arg(long, value_enum, default_value_t = AutoOnOff::Auto)]
    pub(crate) glass: AutoOnOff,
    /// The room's surfaces: grey (window glass emissivity 0.84 mirroring the room and the
    /// operator holding the camera, every other surface 0.90–0.95 drawn from the seed, unless the
    /// room's TOML gives emissivities; the camera reads radiosities, the contact readings true
    /// temperatures) or black (ε = 1: the camera reads each surface's own temperature). Default:
    /// grey with --noise realistic, black with none.
    /// A calibration a little off: the thermal camera's true pose is this far (mm) from the one
    /// rig.toml is written with, along a direction drawn from the seed (the frames are rendered
    /// with the true one; truth.json says it).
    #[arg(long, value_name = "MM", default_value_t = 0.0)]
    pub(crate) extrinsic_error_mm: f64,
    /// The same, turned by this angle (degrees) about an axis drawn from the seed.
    #[arg(long, value_name = "DEG", default_value_t = 0.0)]
    pub(crate) extrinsic_error_deg: f64,
    #[arg(long, value_enum)]
    pub(crate) surfaces: Option<Surfaces>,
    /// The sun outside the room, for truth.json only (the recording is unchanged: a long-wave
    /// camera cannot see the beam): its altitude and azimuth in the room's frame (degrees, 0 = the
    /// sun beyond the +x side). truth.json gets SolarCal's ΔMRT of a seated person facing the sun
    /// at each grid node. Needs --dni and --transmittance.
    #[arg(long, value_name = "ALT,AZ", allow_hyphen_values = true, value_parser = crate::parse::parse_sun, requires_all = ["dni", "transmittance"])]
    pub(crate) sun: Option<[f64; 2]>,
    /// Direct normal irradiance outside (W/m²), with --sun.
    #[arg(
        long,
        value_name = "W_M2",
        allow_negative_numbers = true,
        requires = "sun"
    )]
    pub(crate) dni: Option<f64>,
    /// The windows' total solar transmittance with their shades (0…1), with --sun.
    #[arg(
        long,
        value_name = "T",
        allow_negative_numbers = true,
        requires = "sun"
    )]
    pub(crate) transmittance: Option<f64>,
    /// Monte Carlo rays per truth point (rooms with furniture or not convex).
    #[arg(long, default_value_t = 100_000)]
    pub(crate) truth_rays: usize,
    #[command(flatten)]
    pub(crate) camera: CameraErrorArgs,
}

impl SimulateArgs {
    /// The simulator's settings these flags describe (the room's depth size checked).
    fn config(&self) -> Result<SimConfig> {
        let mut cfg = SimConfig {
            seconds: self.seconds,
            seed: self.seed,
            noise: self.noise,
            drift: match self.drift {
                DriftChoice::None => Drift::NONE,
                DriftChoice::Slam => Drift::SLAM,
                DriftChoice::Odometry => Drift::ODOMETRY,
            },
            thermal_noise: ThermalNoise {
                bias_k: self.thermal_bias,
                blur_sigma_px: self.thermal_blur,
                time_constant_s: self.thermal_time_constant_ms / 1000.0,
                ..ThermalNoise::REALISTIC
            },
            glass: self.glass.choice(),
            surfaces: self.surfaces,
            sun: self.sun.map(|[altitude_deg, azimuth_deg]| SimSun {
                altitude_deg,
                azimuth_deg,
                dni_w_m2: self.dni.unwrap_or_default(),
                transmittance: self.transmittance.unwrap_or_default(),
            }),
            depth_hz: self.depth_hz,
            thermal_hz: self.thermal_hz,
            rgb_hz: self.rgb_hz,
            poses_in_recording: !self.no_poses,
            truth_rays: self.truth_rays,
            radiometric: self.camera.model(self.noise),
            references: self.camera.references(self.noise),
            extrinsic_error: (self.extrinsic_error_mm != 0.0 || self.extrinsic_error_deg != 0.0)
                .then_some(ExtrinsicError {
                    translation_mm: self.extrinsic_error_mm,
                    rotation_deg: self.extrinsic_error_deg,
                }),
            ..SimConfig::default()
        };
        if !(0.0..=50.0).contains(&self.extrinsic_error_mm)
            || !(0.0..=10.0).contains(&self.extrinsic_error_deg)
        {
            return Err(Error::setting(
                format!(
                    "--extrinsic-error-mm {} --extrinsic-error-deg {}",
                    self.extrinsic_error_mm, self.extrinsic_error_deg
                ),
                "is outside 0…50 mm and 0…10°: a calibration that far off is no calibration",
            ));
        }
        if let Some(ms) = self.thermal_lag_ms {
            cfg.thermal_lag_s = Some(ms / 1000.0);
        }
        set_depth_size(&mut cfg, self.depth_size)?;
        Ok(cfg)
    }
}

/// `mrtmap simulate`: the scan `a` describes, written to `a.out` (recording, truth.json); gives
/// what the CLI prints.
pub fn simulate_recording(a: &SimulateArgs, progress: &dyn Progress) -> Result<Vec<String>> {
    let room = load_room(&a.room)?;
    let cfg = a.config()?;
    progress.begin(&format!("simulating {}", room.file.name));
    let t0 = Instant::now();
    let summary = simulate(&room, &cfg, &a.out, &|done, total| {
        progress.advance(done, total);
    })?;
    Ok(vec![
        format!(
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
        ),
        format!(
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
        ),
        format!(
            "truth.json: MRT at the validation points and on the 20×20 grid at 1.1 m ({} view factors)",
            summary.truth_method
        ),
    ])
}

/// A simulated camera's radiometric errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum CameraErrorsArg {
    /// Realistic with --noise realistic, none with --noise none.
    Auto,
    /// A perfect camera (the NETD and blur of --noise remain).
    None,
    /// A Lepton 3.5-like unit: offset 1.5 K, gain 2 %, FFC every 30–120 s (σ 0.3 K new offsets,
    /// σ 0.3 K/min drift between them), vignetting −0.6 K at the corners, fixed pattern σ 0.08 K.
    Realistic,
}

/// The thermal camera's radiometric errors in a simulation; each term can be set on its own (the
/// flags of `mrtmap simulate` and `mrtmap demo`).
#[derive(Debug, clap::Args, Clone)]
pub(crate) struct CameraErrorArgs {
    /// The camera's radiometric errors (the truth goes to radiometric_truth.json).
    #[arg(long, value_enum, default_value_t = CameraErrorsArg::Auto)]
    pub(crate) camera_errors: CameraErrorsArg,
    /// This unit's constant offset (K).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) unit_offset_k: Option<f64>,
    /// Relative gain error about 20 °C (0.02: contrasts 2 % too large).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) gain: Option<f64>,
    /// Time between flat-field corrections, MIN,MAX seconds (0,0: none).
    #[arg(long, value_name = "MIN,MAX", value_parser = crate::parse::parse_interval)]
    pub(crate) ffc_interval_s: Option<[f64; 2]>,
    /// σ of the offset each flat-field correction sets (K).
    #[arg(long)]
    pub(crate) ffc_offset_k: Option<f64>,
    /// σ of the offset's drift between flat-field corrections (K per minute).
    #[arg(long)]
    pub(crate) drift_k_per_min: Option<f64>,
    /// Vignetting: what the image corners read more than the centre (K).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) vignetting_k: Option<f64>,
    /// σ of the per-pixel fixed pattern (K).
    #[arg(long)]
    pub(crate) fixed_pattern_k: Option<f64>,
    /// Contact-thermometer readings of surface points to write to references.csv (default: 2 with
    /// camera errors, 0 without).
    #[arg(long)]
    pub(crate) references: Option<usize>,
}

impl CameraErrorArgs {
    /// The model these flags describe, with sensor noise `noise`.
    pub fn model(&self, noise: NoiseLevel) -> RadiometricModel {
        use RadiometricModel as M;
        let mut m = match (self.camera_errors, noise) {
            (CameraErrorsArg::None, _) | (CameraErrorsArg::Auto, NoiseLevel::None) => M::NONE,
            (CameraErrorsArg::Realistic, _) | (CameraErrorsArg::Auto, NoiseLevel::Realistic) => {
                M::REALISTIC
            }
        };
        let set = |x: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *x = v;
            }
        };
        set(&mut m.unit_offset_k, self.unit_offset_k);
        set(&mut m.gain, self.gain);
        set(&mut m.ffc_offset_sigma_k, self.ffc_offset_k);
        set(&mut m.drift_sigma_k_per_min, self.drift_k_per_min);
        set(&mut m.vignetting_k, self.vignetting_k);
        set(&mut m.fixed_pattern_sigma_k, self.fixed_pattern_k);
        if let Some(i) = self.ffc_interval_s {
            m.ffc_interval_s = i;
        }
        m
    }

    /// How many reference readings to write.
    pub fn references(&self, noise: NoiseLevel) -> usize {
        self.references
            .unwrap_or(if self.model(noise).is_perfect() { 0 } else { 2 })
    }
}
