//! `[track]`, `[fuse]` and `[segment]`: how the scan is tracked, fused and segmented.

use mrtmap_scan::FuseParams;
use mrtmap_scan::clock::ClockOffset;
use mrtmap_scan::segment::SegmentParams;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::settings::RoomSection;

/// When the built-in tracker runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TrackMode {
    /// When the recording has no trajectory.txt.
    #[default]
    Auto,
    /// Always, replacing the recording's poses.
    Always,
    /// Never (a recording without poses is refused).
    Never,
}

/// `[track]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackSection {
    /// When the tracker runs.
    pub mode: TrackMode,
    /// Look for loop closures.
    pub loop_closure: bool,
    /// Predict each frame's rotation from the recording's gyro (imu.txt) where it has one.
    pub use_imu: bool,
    /// FAST corner threshold (grey levels).
    pub fast_threshold: u8,
}

impl Default for TrackSection {
    fn default() -> Self {
        let t = mrtmap_track::TrackParams::default();
        Self {
            mode: TrackMode::Auto,
            loop_closure: t.loop_closure,
            use_imu: t.use_imu,
            fast_threshold: t.fast_threshold,
        }
    }
}

impl TrackSection {
    /// The tracker's parameters.
    pub fn params(&self) -> mrtmap_track::TrackParams {
        mrtmap_track::TrackParams {
            loop_closure: self.loop_closure,
            use_imu: self.use_imu,
            fast_threshold: self.fast_threshold,
            ..Default::default()
        }
    }
}

/// `[fuse]` (its flags: [`crate::FuseFlags`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FuseSection {
    /// Voxel size (m).
    pub voxel_m: f64,
    /// Refine poses by point-to-plane ICP against the map built so far (on or off).
    pub icp: bool,
    /// Largest time between a thermal frame and the depth frame it takes (ms); at least 0.55 of
    /// the depth frames' interval is used, so every thermal frame finds one at any depth rate.
    pub sync_tolerance_ms: f64,
    /// Use every N-th depth pixel in each direction; 0: about one depth point per thermal pixel
    /// (the cameras' focal lengths' ratio, rounded: 3 for a 640×480 D435 beside a Lepton).
    pub depth_stride: u32,
    /// Radiometric self-calibration (on or off): estimate and remove each frame's offset
    /// (flat-field corrections, drift) and the vignetting from the frames' overlaps.
    pub self_calibrate: bool,
    /// What to add to the thermal stamps to put them on the depth camera's clock: auto (rig.toml's
    /// `[thermal] time_offset_s`, else estimated from the scan), estimate, off, or milliseconds
    /// (-70: frames stamped 70 ms after their exposure).
    pub time_offset: String,
}

/// The thermal clock's setting from its text: auto, estimate, off, or milliseconds.
pub fn parse_time_offset(text: &str) -> Result<ClockOffset> {
    let refuse = || {
        Error::setting(
            format!("time offset '{text}' (--time-offset, [fuse] time_offset)"),
            "is not auto, estimate, off or a number of milliseconds between -1000 and 1000",
        )
    };
    match text.trim() {
        "auto" => Ok(ClockOffset::Auto),
        "estimate" => Ok(ClockOffset::Estimate),
        "off" => Ok(ClockOffset::Off),
        other => {
            let ms: f64 = other
                .trim_end_matches("ms")
                .trim()
                .parse()
                .map_err(|_| refuse())?;
            if ms.is_finite() && ms.abs() <= 1000.0 {
                Ok(ClockOffset::Fixed(ms / 1000.0))
            } else {
                Err(refuse())
            }
        }
    }
}

impl Default for FuseSection {
    fn default() -> Self {
        Self {
            voxel_m: 0.03,
            icp: true,
            sync_tolerance_ms: 20.0,
            depth_stride: 0,
            self_calibrate: true,
            time_offset: "auto".into(),
        }
    }
}

impl FuseSection {
    /// The fusion's parameters, after checking the ranges.
    pub fn params(&self) -> Result<FuseParams> {
        if !(self.voxel_m > 0.001 && self.voxel_m <= 1.0) {
            return Err(Error::setting(
                format!("voxel size {} m (--voxel-m, [fuse] voxel_m)", self.voxel_m),
                "is outside 0.001…1 m",
            ));
        }
        if !(self.sync_tolerance_ms > 0.0 && self.sync_tolerance_ms <= 1000.0) {
            return Err(Error::setting(
                format!(
                    "sync tolerance {} ms (--sync-tolerance-ms, [fuse] sync_tolerance_ms)",
                    self.sync_tolerance_ms
                ),
                "is outside 0…1000 ms",
            ));
        }
        let mut p = FuseParams {
            voxel_m: self.voxel_m,
            sync_tolerance_s: self.sync_tolerance_ms / 1000.0,
            ..FuseParams::default()
        };
        p.icp.enabled = self.icp;
        p.depth.stride = self.depth_stride;
        p.radiometric.enabled = self.self_calibrate;
        p.clock = parse_time_offset(&self.time_offset)?;
        Ok(p)
    }
}

/// `[segment]` (its flags: [`crate::SegmentFlags`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SegmentSection {
    /// A texel belongs to a feature when it differs from its surface's background by more (K).
    pub feature_threshold_k: f64,
    /// Smallest feature (m²).
    pub feature_min_area_m2: f64,
    /// Texel of each surface's temperature raster in scene.json (m), so that a stratified wall
    /// radiates as it is; 0 for one temperature per surface.
    pub raster_m: f64,
    /// Label features by the recording's instance masks when it has them.
    pub masks: bool,
    /// Cast the fused thermal frames onto the room model found, so that what the depth camera
    /// did not see (glass, dark or shiny surfaces, dropouts) takes the thermal camera's
    /// temperatures.
    pub texture: bool,
}

impl Default for SegmentSection {
    fn default() -> Self {
        Self {
            feature_threshold_k: 0.3,
            feature_min_area_m2: 0.04,
            raster_m: 0.15,
            masks: true,
            texture: true,
        }
    }
}

impl SegmentSection {
    /// Settings that need no cloud: the raster's texel.
    pub fn check(&self) -> Result<()> {
        let r = self.raster_m;
        if !(r == 0.0 || (r.is_finite() && (0.03..=2.0).contains(&r))) {
            return Err(Error::setting(
                format!("--raster-m {r} ([segment] raster_m)"),
                "must be 0 (no raster) or between 0.03 and 2 m",
            ));
        }
        Ok(())
    }

    /// The segmentation's parameters, with the room frame's origin corner.
    pub fn params(&self, room: &RoomSection) -> SegmentParams {
        SegmentParams {
            feature_threshold_k: self.feature_threshold_k,
            feature_min_area_m2: self.feature_min_area_m2,
            raster_m: self.raster_m,
            origin_corner: room.origin_corner,
            ..SegmentParams::default()
        }
    }
}
