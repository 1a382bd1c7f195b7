//! Rooms and simulator settings shared by `simulate` and `demo`.

use std::path::Path;

use mrtmap_sim::preset;
/// The simulator's rooms, settings and noise models (mrtmap-sim's types).
pub use mrtmap_sim::{
    Drift, NoiseLevel, PRESETS, RadiometricModel, Room, SimConfig, SimSun, Surfaces, ThermalNoise,
    simulate,
};

use crate::error::{Error, Result};

/// A preset room by name, or a room TOML file.
pub fn load_room(spec: &str) -> Result<Room> {
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
pub fn set_depth_size(cfg: &mut SimConfig, (w, h): (usize, usize)) -> Result<()> {
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

/// A simulated camera's radiometric errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CameraErrorsArg {
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
pub struct CameraErrorArgs {
    /// The camera's radiometric errors (the truth goes to radiometric_truth.json).
    #[arg(long, value_enum, default_value_t = CameraErrorsArg::Auto)]
    pub camera_errors: CameraErrorsArg,
    /// This unit's constant offset (K).
    #[arg(long, allow_negative_numbers = true)]
    pub unit_offset_k: Option<f64>,
    /// Relative gain error about 20 °C (0.02: contrasts 2 % too large).
    #[arg(long, allow_negative_numbers = true)]
    pub gain: Option<f64>,
    /// Time between flat-field corrections, MIN,MAX seconds (0,0: none).
    #[arg(long, value_name = "MIN,MAX", value_parser = crate::parse::parse_interval)]
    pub ffc_interval_s: Option<[f64; 2]>,
    /// σ of the offset each flat-field correction sets (K).
    #[arg(long)]
    pub ffc_offset_k: Option<f64>,
    /// σ of the offset's drift between flat-field corrections (K per minute).
    #[arg(long)]
    pub drift_k_per_min: Option<f64>,
    /// Vignetting: what the image corners read more than the centre (K).
    #[arg(long, allow_negative_numbers = true)]
    pub vignetting_k: Option<f64>,
    /// σ of the per-pixel fixed pattern (K).
    #[arg(long)]
    pub fixed_pattern_k: Option<f64>,
    /// Contact-thermometer readings of surface points to write to references.csv (default: 2 with
    /// camera errors, 0 without).
    #[arg(long)]
    pub references: Option<usize>,
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
