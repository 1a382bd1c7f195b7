//! The thermal camera's radiometric errors, and a contact thermometer's reference readings.
//!
//! A Lepton-class camera does not read the true temperature: each unit has its own offset
//! (the datasheet allows ±5 K), a gain error of a few percent stretches contrasts about the
//! shutter's temperature, every flat-field correction (FFC, every 30 s to a few minutes) sets a
//! new offset that then drifts until the next one, the lens darkens the image edges
//! (vignetting, radial) and each pixel keeps a fixed-pattern offset. A reading is
//!
//! T_read = T_ref + (1 + g)(T − T_ref) + o_unit + o_ffc(k) + d_k (t − t_k) + v ρ + f(pixel)
//!
//! with ρ = r² / r_max² the squared distance from the image centre (1 at the corners) and period k
//! the one holding time t. The truth of every term goes to `radiometric_truth.json`, beside
//! `truth.json`; the recording the pipeline reads has only the readings (and, when asked for,
//! `references.csv`: contact-thermometer readings of surface points with their noise).

use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_geometry::polygon::{Containment, point_in_polygon};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use crate::room::{Room, SurfaceRef};

/// The camera's radiometric error terms (all zero: a perfect camera).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RadiometricModel {
    /// This unit's constant offset (K).
    pub unit_offset_k: f64,
    /// Relative gain error about `reference_c` (0.02 = contrasts read 2 % too large).
    pub gain: f64,
    /// The temperature the gain stretches about (°C; the shutter's).
    pub reference_c: f64,
    /// Time between FFCs, drawn uniformly in this range (s); 0, 0 = no FFC.
    pub ffc_interval_s: [f64; 2],
    /// σ of the offset each FFC sets (K).
    pub ffc_offset_sigma_k: f64,
    /// σ of the drift rate between FFCs (K per minute).
    pub drift_sigma_k_per_min: f64,
    /// Vignetting: the image corners read this much more than the centre (K; radial, ∝ r²).
    pub vignetting_k: f64,
    /// σ of the per-pixel fixed-pattern offset, constant over the scan (K).
    pub fixed_pattern_sigma_k: f64,
}

impl RadiometricModel {
    /// A perfect camera.
    pub const NONE: Self = Self {
        unit_offset_k: 0.0,
        gain: 0.0,
        reference_c: 20.0,
        ffc_interval_s: [0.0, 0.0],
        ffc_offset_sigma_k: 0.0,
        drift_sigma_k_per_min: 0.0,
        vignetting_k: 0.0,
        fixed_pattern_sigma_k: 0.0,
    };
    /// A Lepton 3.5-like unit: offset 1.5 K, gain 2 %, FFC every 30–120 s with σ 0.3 K offsets and
    /// σ 0.3 K/min drift, vignetting −0.6 K at the corners, fixed pattern σ 0.08 K.
    pub const REALISTIC: Self = Self {
        unit_offset_k: 1.5,
        gain: 0.02,
        reference_c: 20.0,
        ffc_interval_s: [30.0, 120.0],
        ffc_offset_sigma_k: 0.3,
        drift_sigma_k_per_min: 0.3,
        vignetting_k: -0.6,
        fixed_pattern_sigma_k: 0.08,
    };

    /// Whether every term is zero.
    pub fn is_perfect(&self) -> bool {
        self.unit_offset_k == 0.0
            && self.gain == 0.0
            && self.ffc_offset_sigma_k == 0.0
            && self.drift_sigma_k_per_min == 0.0
            && self.vignetting_k == 0.0
            && self.fixed_pattern_sigma_k == 0.0
    }
}

/// One FFC period: from `start_s`, offset `offset_k` drifting at `drift_k_per_s`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FfcPeriod {
    /// Start (s from the scan's start).
    pub start_s: f64,
    /// Offset set by the FFC (K).
    pub offset_k: f64,
    /// Drift until the next FFC (K/s).
    pub drift_k_per_s: f64,
}

/// The camera's errors over one scan: the model and what was drawn from it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraErrors {
    /// The model.
    pub model: RadiometricModel,
    /// The FFC periods, in time order (the first starts at 0).
    pub ffc: Vec<FfcPeriod>,
    /// The fixed pattern, row-major over the thermal image (K); not written to the truth file.
    #[serde(skip)]
    pub fixed_pattern: Vec<f64>,
    /// Its rms (K).
    pub fixed_pattern_rms_k: f64,
}

impl CameraErrors {
    /// Draws the scan's FFC schedule and fixed pattern for a `w`×`h` image.
    pub fn draw(model: RadiometricModel, seconds: f64, w: usize, h: usize, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5ad1_0c0f_fee5);
        let std = Normal::new(0.0, 1.0).unwrap_or_else(|_| unreachable!("unit normal"));
        let mut ffc = Vec::new();
        let mut t = 0.0;
        loop {
            ffc.push(FfcPeriod {
                start_s: t,
                offset_k: model.ffc_offset_sigma_k * std.sample(&mut rng),
                drift_k_per_s: model.drift_sigma_k_per_min / 60.0 * std.sample(&mut rng),
            });
            let [a, b] = model.ffc_interval_s;
            if !(b > 0.0 && b >= a) {
                break;
            }
            t += a + (b - a) * rng.random::<f64>();
            if t >= seconds {
                break;
            }
        }
        let fixed_pattern: Vec<f64> = (0..w * h)
            .map(|_| model.fixed_pattern_sigma_k * std.sample(&mut rng))
            .collect();
        let rms = (fixed_pattern.iter().map(|x| x * x).sum::<f64>()
            / fixed_pattern.len().max(1) as f64)
            .sqrt();
        Self {
            model,
            ffc,
            fixed_pattern,
            fixed_pattern_rms_k: rms,
        }
    }

    /// The offset common to the whole image at time `t_s` (unit + FFC + drift), K.
    pub fn offset_at(&self, t_s: f64) -> f64 {
        let p = self
            .ffc
            .iter()
            .rev()
            .find(|p| p.start_s <= t_s)
            .or(self.ffc.first());
        self.model.unit_offset_k
            + p.map_or(0.0, |p| p.offset_k + p.drift_k_per_s * (t_s - p.start_s))
    }

    /// The reading of a pixel whose true temperature is `t_k` (K), at time `t_s`, at squared
    /// relative radius `rho` from the image centre, pixel index `pixel`.
    pub fn read(&self, t_k: f64, t_s: f64, rho: f64, pixel: usize) -> f64 {
        let m = &self.model;
        let r = m.reference_c + mrtmap_physics::ZERO_CELSIUS_K;
        r + (1.0 + m.gain) * (t_k - r)
            + self.offset_at(t_s)
            + m.vignetting_k * rho
            + self.fixed_pattern.get(pixel).copied().unwrap_or(0.0)
    }
}

/// A contact thermometer's reading of a surface point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceReading {
    /// Label.
    pub label: String,
    /// The point in the room frame (m).
    pub xyz_room: [f64; 3],
    /// The true surface temperature there (°C).
    pub true_c: f64,
    /// The reading (°C).
    pub temperature_c: f64,
    /// The thermometer's standard uncertainty (K).
    pub std_k: f64,
}

/// Up to `n` contact readings on surfaces of different temperatures: the coldest feature's
/// centre, then the longest wall at 1.2 m away from features, then the floor's centre; each with
/// σ `std_k` noise.
pub fn reference_readings(room: &Room, n: usize, std_k: f64, seed: u64) -> Vec<ReferenceReading> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7e_f0_ce);
    let std = Normal::new(0.0, 1.0).unwrap_or_else(|_| unreachable!("unit normal"));
    let mut spots: Vec<(String, Point3<f64>, f64)> = Vec::new();
    if let Some(f) = room
        .features
        .iter()
        .min_by(|a, b| a.temperature_c.total_cmp(&b.temperature_c))
    {
        let c = f.polygon_2d.iter().fold(Point2::origin(), |acc, p| {
            acc + p.coords / f.polygon_2d.len() as f64
        });
        spots.push((f.label.clone(), room.on_surface(f.on, &c), f.temperature_c));
    }
    let free = |s: SurfaceRef, q: &Point2<f64>| {
        room.features
            .iter()
            .filter(|f| f.on == s)
            .all(|f| point_in_polygon(q, &f.polygon_2d, 0.05) == Containment::Outside)
    };
    let mut walls: Vec<usize> = (0..room.wall_count()).collect();
    walls.sort_by(|a, b| {
        let len = |i: usize| (room.plan[(i + 1) % room.plan.len()] - room.plan[i]).norm();
        len(*b).total_cmp(&len(*a))
    });
    if let Some(q) = walls.iter().find_map(|&i| {
        let len = (room.plan[(i + 1) % room.plan.len()] - room.plan[i]).norm();
        [0.5, 0.3, 0.7]
            .iter()
            .map(|f| Point2::new(len * f, 1.2))
            .find(|q| free(SurfaceRef::Wall(i), q))
            .map(|q| (i, q))
    }) {
        let s = SurfaceRef::Wall(q.0);
        // Labelled by what it is, not by the simulator's wall number: segmentation numbers the
        // walls its own way (from the room frame's origin corner, from 1), and a report listing
        // "wall-0" beside walls 1-4 reads as a mistake.
        spots.push((
            "wall".to_string(),
            room.on_surface(s, &q.1),
            room.background_temperature_c(s, 1.2),
        ));
    }
    let c = room.plan.iter().fold(Point2::origin(), |acc, p| {
        acc + p.coords / room.plan.len() as f64
    });
    if free(SurfaceRef::Floor, &c) {
        spots.push((
            "floor".into(),
            room.on_surface(SurfaceRef::Floor, &c),
            room.background_temperature_c(SurfaceRef::Floor, 0.0),
        ));
    }
    spots
        .into_iter()
        .take(n)
        .map(|(label, p, t)| ReferenceReading {
            label,
            xyz_room: [p.x, p.y, p.z],
            true_c: t,
            temperature_c: t + std_k * std.sample(&mut rng),
            std_k,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The office's three readings: the window (its coldest feature), a wall and the floor, each
    /// labelled by what it is (a "wall-0" beside segmentation's walls 1-4 read as a mistake),
    /// their noise drawn with the stated σ.
    #[test]
    fn reference_readings_are_labelled_by_what_they_are() {
        let room = crate::preset("office").unwrap().unwrap();
        let r = reference_readings(&room, 3, 0.1, 4);
        let labels: Vec<&str> = r.iter().map(|x| x.label.as_str()).collect();
        assert_eq!(labels, ["window", "wall", "floor"]);
        for x in &r {
            assert!((x.temperature_c - x.true_c).abs() < 0.5, "{x:?}");
        }
    }

    #[test]
    fn flat_field_corrections_come_at_the_drawn_intervals_and_offsets_drift_between() {
        let e = CameraErrors::draw(RadiometricModel::REALISTIC, 600.0, 160, 120, 3);
        assert!(e.ffc.len() >= 5, "{}", e.ffc.len());
        for w in e.ffc.windows(2) {
            let dt = w[1].start_s - w[0].start_s;
            assert!((30.0..=120.0).contains(&dt), "{dt}");
        }
        let p = e.ffc[1];
        let at = |t: f64| e.offset_at(t);
        assert!((at(p.start_s + 10.0) - at(p.start_s) - 10.0 * p.drift_k_per_s).abs() < 1e-12);
        assert!((at(p.start_s) - 1.5 - p.offset_k).abs() < 1e-12);
        assert!(
            (e.fixed_pattern_rms_k - 0.08).abs() < 0.005,
            "{}",
            e.fixed_pattern_rms_k
        );
    }

    #[test]
    fn a_reading_adds_gain_offset_and_vignetting() {
        let m = RadiometricModel {
            unit_offset_k: 1.0,
            gain: 0.02,
            vignetting_k: -0.5,
            ..RadiometricModel::NONE
        };
        let e = CameraErrors::draw(m, 10.0, 4, 4, 1);
        let k = mrtmap_physics::ZERO_CELSIUS_K;
        // 30 °C at a corner: 20 + 1.02·10 + 1 − 0.5.
        assert!((e.read(30.0 + k, 1.0, 1.0, 0) - (30.7 + k)).abs() < 1e-9);
        // At the reference temperature, in the centre: only the offset.
        assert!((e.read(20.0 + k, 1.0, 0.0, 0) - (21.0 + k)).abs() < 1e-9);
        assert!(RadiometricModel::NONE.is_perfect() && !m.is_perfect());
    }
}
