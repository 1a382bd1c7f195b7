//! The absolute level of the temperatures: contact-thermometer reference readings fix the thermal
//! camera's offset (one reading) and gain (two or more on different temperatures); without any,
//! the level is the camera's and its stated absolute accuracy goes into every ±.
//!
//! A recording may hold `references.csv` (`label,x,y,z,temperature_c[,std_k][,frame]`; x, y, z
//! in the room frame, what a person with a tape measures from the origin corner, unless `frame`
//! says `scan`, the frame of trajectory.txt; `#` comments); project.toml may add
//! `[[references]]` (room frame by default). Room-frame readings are placed once segmentation has
//! found the room frame, as `[[points]]` are.
//! The camera's reading at a reference is the fused cloud's around it (within 5 cm, else 10 cm).
//! The fit is weighted least squares camera = α + β·true; with three or more readings, the one whose
//! leave-one-out residual is largest beyond max(3σ, 0.5 K) (judged against an offset alone, with
//! 3 % gain slack, when only two others remain) is named and left out. The scene's temperatures
//! become (T − α)/β, and the level's standard uncertainty at the scene's mean temperature is
//! written as the scene's `temperature_level_std_k`; with the offset alone it holds the gain
//! error left ([`GAIN_STD`] × the distance from the readings).
//!
//! Everything about the absolute level is here: the readings ([`Reference::read_csv`]), what a run
//! gathers ([`LevelInputs`]), the fit ([`find_level`]) and segmentation's scene and tables carried
//! to it ([`level_segmentation`]). The relative level (each frame's offset after a flat-field
//! correction, the vignetting) is removed during fusion, frame by frame, by
//! `mrtmap-scan/src/radiometric.rs`.

use std::path::Path;

use mrtmap_geometry::nalgebra::Vector3;
use mrtmap_geometry::nalgebra::{Isometry3, Point3};
use mrtmap_io::{Recording, ThermalCloud};
use mrtmap_physics::{Temperature, ZERO_CELSIUS_K};
use mrtmap_radiation::RadiantScene;
use mrtmap_radiation::grey;
use mrtmap_scan::segment::Segmentation;
use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::settings::Reference;
use crate::settings::{EmissivitySection, MrtSection, PointFrame, Project};

/// A thermal camera's absolute accuracy when the rig does not state one (K): the Lepton 3.5's
/// datasheet (high gain).
pub(crate) const DEFAULT_CAMERA_ACCURACY_K: f64 = 5.0;

fn one() -> f64 {
    1.0
}

/// How one reference was used.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceUse {
    /// Label.
    pub label: String,
    /// The reading (°C): the surface's true temperature.
    pub reference_c: f64,
    /// The emissivity taken for the surface read.
    #[serde(default = "one")]
    pub emissivity: f64,
    /// What the camera should read there (°C): the radiant temperature of a surface at the
    /// reading with that emissivity, in the irradiance the scene gives that spot (the reading
    /// itself where the emissivity is 1). The level is fitted to these.
    #[serde(default)]
    pub radiant_c: f64,
    /// The camera's (fused) temperature there (°C), when the scan saw the point.
    pub camera_c: Option<f64>,
    /// Corrected camera temperature − what the camera should read (K), when used or judged.
    pub residual_k: Option<f64>,
    /// Whether the fit used it; else why not.
    pub used: bool,
    /// Why it was left out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// What the temperatures' level rests on (in level.json by its phrase).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum LevelBasis {
    /// Readings at two or more temperatures: the camera's offset and gain.
    #[serde(rename = "references (offset and gain)")]
    OffsetAndGain,
    /// Readings that fix the offset alone.
    #[serde(rename = "references (offset)")]
    Offset,
    /// No readings: the camera as it is, its stated accuracy in every ±.
    #[serde(rename = "camera")]
    Camera,
}

impl std::fmt::Display for LevelBasis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::OffsetAndGain => "references (offset and gain)",
            Self::Offset => "references (offset)",
            Self::Camera => "camera",
        })
    }
}

/// The temperatures' level: what the fit found and what it rests on (`level.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Level {
    /// What it rests on.
    pub basis: LevelBasis,
    /// α: the camera's reading of a 0 °C surface… in the fit camera = α + β·true (°C).
    pub alpha_c: f64,
    /// β: the camera's gain relative to the truth.
    pub beta: f64,
    /// The offset removed at the scene's mean temperature (K): camera − true.
    pub offset_at_mean_k: f64,
    /// The standard uncertainty of the level left (K).
    pub std_k: f64,
    /// The readings and how each was used.
    pub references: Vec<ReferenceUse>,
    /// What changes what the numbers mean: readings left out, a gain not fitted.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// The largest gain error of a thermal camera that a fit may find (|β − 1|): radiometric cameras
/// are off mostly in offset, by a few per cent in gain. Two readings implying more disagree with
/// each other (a typo: a wall read 40 instead of 20.9 gave a gain of 0.34 and a map 17 K warm).
pub(crate) const MAX_GAIN_ERROR: f64 = 0.1;

/// The standard uncertainty of a thermal camera's gain when the readings do not fix it (one
/// reading, or several within 2 K of each other): radiometric cameras are off by a few per cent
/// in gain (a Lepton 3.5's datasheet: ±5 % of the reading), so an offset fixed at a reading
/// leaves 3 % of the distance from it, 0.25 K at a room 8 K warmer than the window read.
pub(crate) const GAIN_STD: f64 = 0.03;

/// The camera's fused temperature around a point (°C): within 5 cm, else 10 cm; `None` unseen.
fn camera_at(cloud: &ThermalCloud, p: &Point3<f64>) -> Option<(f64, f64)> {
    for r in [0.05f64, 0.10] {
        let (mut sw, mut st, mut stt) = (0.0, 0.0, 0.0);
        let mut n = 0;
        for (k, q) in cloud.positions.iter().enumerate() {
            let d2 = (q[0] as f64 - p.x).powi(2)
                + (q[1] as f64 - p.y).powi(2)
                + (q[2] as f64 - p.z).powi(2);
            if d2 <= r * r {
                let w = cloud.observations[k].max(1) as f64;
                let t = cloud.temperature_k[k] as f64 - ZERO_CELSIUS_K;
                sw += w;
                st += w * t;
                stt += w * t * t;
                n += 1;
            }
        }
        if n >= 3 {
            let m = st / sw;
            let sd = (stt / sw - m * m).max(0.0).sqrt();
            return Some((m, sd / (n as f64).sqrt()));
        }
    }
    None
}

/// Weighted least squares camera = α + β·true over `pts` (true, camera, σ): (α, β, σ of the fit's
/// prediction of the true temperature at `at_c`).
fn fit(pts: &[(f64, f64, f64)], at_c: f64, gain: bool) -> (f64, f64, f64) {
    let w: Vec<f64> = pts.iter().map(|p| 1.0 / (p.2 * p.2)).collect();
    let sw: f64 = w.iter().sum();
    let mx = pts.iter().zip(&w).map(|(p, w)| w * p.0).sum::<f64>() / sw;
    let my = pts.iter().zip(&w).map(|(p, w)| w * p.1).sum::<f64>() / sw;
    if !gain {
        let alpha = my - mx;
        return (alpha, 1.0, (1.0 / sw).sqrt());
    }
    let sxx: f64 = pts
        .iter()
        .zip(&w)
        .map(|(p, w)| w * (p.0 - mx).powi(2))
        .sum();
    let sxy: f64 = pts
        .iter()
        .zip(&w)
        .map(|(p, w)| w * (p.0 - mx) * (p.1 - my))
        .sum();
    let beta = sxy / sxx;
    let alpha = my - beta * mx;
    let var = 1.0 / sw + (at_c - mx).powi(2) / sxx;
    (alpha, beta, var.sqrt() / beta.abs())
}

/// A reading seen by the camera (what the camera should read, camera, σ, index into the uses) for
/// the fit.
type Seen = (f64, f64, f64, usize);

/// What the camera should read at a reading: the radiant temperature of the surface read (°C) and
/// the emissivity taken for it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Expected {
    /// The radiant temperature (°C).
    pub radiant_c: f64,
    /// The emissivity.
    pub emissivity: f64,
    /// The standard uncertainty the emissivity's puts on the radiant temperature (K): on glass
    /// 8 K colder than the room, ±0.02 in ε is ±0.16 K.
    pub std_k: f64,
}

impl Expected {
    /// A black surface: the camera should read the reading itself.
    pub fn black(r: &Reference) -> Self {
        Self {
            radiant_c: r.temperature_c,
            emissivity: 1.0,
            std_k: 0.0,
        }
    }
}

/// Each reading placed and compared with what the camera saw around it: its use (unseen, or
/// farther from the camera than the camera can be off: its stated accuracy, at least 1 K since
/// the fused temperature at a point carries blur and placement too, plus the reading's own 3σ)
/// and, when usable, its point for the fit. `expected` gives what the camera should read at each
/// (a grey surface's radiant temperature).
fn judge_readings(
    refs: &[Reference],
    expected: &[Expected],
    cloud: &ThermalCloud,
    world_from_room: &Isometry3<f64>,
    camera_accuracy_k: f64,
) -> (Vec<ReferenceUse>, Vec<Seen>) {
    let allowed = camera_accuracy_k.max(1.0);
    let mut uses: Vec<ReferenceUse> = Vec::new();
    let mut pts: Vec<Seen> = Vec::new();
    for (i, r) in refs.iter().enumerate() {
        let ex = expected
            .get(i)
            .copied()
            .unwrap_or_else(|| Expected::black(r));
        let p = match r.frame {
            PointFrame::Scan => Point3::from(r.xyz),
            PointFrame::Room => world_from_room * Point3::from(r.xyz),
        };
        let seen = camera_at(cloud, &p);
        // A reading farther from what the camera saw there than the camera can be off (its
        // stated accuracy, and the reading's own 3σ) is not a reading of that surface.
        let implausible = seen.and_then(|(c, _)| {
            let off = (c - ex.radiant_c).abs();
            (off > allowed + 3.0 * r.std_k).then(|| {
                // Grey: what the camera should read is not the reading itself; say so.
                let grey = if ex.emissivity < 1.0 {
                    format!(
                        ", whose surface at emissivity {:.2} should look {:.1} °C to the camera",
                        ex.emissivity, ex.radiant_c
                    )
                } else {
                    String::new()
                };
                format!(
                    "disagrees with what the camera saw there ({c:.1} °C) by {off:.1} K{grey}, more than the camera can be off ({allowed} K): left out; check the reading (a typo?), its coordinates and the emissivity taken for it ([emissivity], or the reading's own)"
                )
            })
        });
        if let Some((c, se)) = seen
            && implausible.is_none()
        {
            pts.push((
                ex.radiant_c,
                c,
                r.std_k.hypot(se).hypot(ex.std_k),
                uses.len(),
            ));
        }
        uses.push(ReferenceUse {
            label: r.label.clone(),
            reference_c: r.temperature_c,
            emissivity: ex.emissivity,
            radiant_c: ex.radiant_c,
            camera_c: seen.map(|s| s.0),
            residual_k: None,
            used: seen.is_some() && implausible.is_none(),
            note: implausible.or_else(|| {
                seen.is_none()
                    .then(|| "the scan saw no surface within 10 cm of this point".into())
            }),
        });
    }
    (uses, pts)
}

/// The level from `refs` (in the scan's frame, or the room's through `world_from_room`) seen in
/// `cloud`, for a scene whose mean temperature is `mean_c`; `camera_accuracy_k` when none is usable.
/// `expected` is what the camera should read at each reading (empty: the readings themselves, as
/// on black surfaces).
pub(crate) fn find_level(
    refs: &[Reference],
    expected: &[Expected],
    cloud: &ThermalCloud,
    world_from_room: &Isometry3<f64>,
    mean_c: f64,
    camera_accuracy_k: f64,
) -> Level {
    let (mut uses, mut pts) =
        judge_readings(refs, expected, cloud, world_from_room, camera_accuracy_k);
    let span = |p: &[(f64, f64, f64, usize)]| {
        p.iter().map(|x| x.0).fold(f64::NEG_INFINITY, f64::max)
            - p.iter().map(|x| x.0).fold(f64::INFINITY, f64::min)
    };
    let solve = |p: &[(f64, f64, f64, usize)]| {
        let gain = p.len() >= 2 && span(p) >= 2.0;
        let q: Vec<(f64, f64, f64)> = p.iter().map(|x| (x.0, x.1, x.2)).collect();
        (fit(&q, mean_c, gain), gain)
    };
    // Leave-one-out: a reading that disagrees with the others is named and left out.
    if pts.len() >= 3 {
        let mut worst: Option<(usize, f64)> = None;
        for k in 0..pts.len() {
            let others: Vec<_> = pts
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != k)
                .map(|x| *x.1)
                .collect();
            // Two others fit any gain exactly: judge against an offset alone then, allowing for a
            // gain error of up to 3 % over the distance from their mean.
            let ((a, b, s), slack) = if others.len() >= 3 {
                (solve(&others).0, 0.0)
            } else {
                let q: Vec<(f64, f64, f64)> = others.iter().map(|x| (x.0, x.1, x.2)).collect();
                let m = q.iter().map(|x| x.0).sum::<f64>() / q.len() as f64;
                (fit(&q, mean_c, false), 0.03 * (pts[k].0 - m).abs())
            };
            let resid = (pts[k].1 - a) / b - pts[k].0;
            let limit = (3.0 * pts[k].2.hypot(s)).max(0.5) + slack;
            if resid.abs() > limit && worst.is_none_or(|w| resid.abs() > w.1) {
                worst = Some((k, resid.abs()));
            }
        }
        if let Some((k, r)) = worst {
            let u = &mut uses[pts[k].3];
            u.used = false;
            u.note = Some(format!("disagrees with the others by {r:.2} K: left out"));
            pts.remove(k);
        }
    }
    let mut warnings: Vec<String> = uses
        .iter()
        .filter(|u| !u.used)
        .filter_map(|u| {
            u.note
                .as_ref()
                .map(|n| format!("reference '{}' ({} °C): {n}", u.label, u.reference_c))
        })
        .collect();
    if pts.is_empty() {
        return Level {
            basis: LevelBasis::Camera,
            alpha_c: 0.0,
            beta: 1.0,
            offset_at_mean_k: 0.0,
            std_k: camera_accuracy_k,
            references: uses,
            warnings,
        };
    }
    let ((mut alpha, mut beta, mut std_k), mut gain) = solve(&pts);
    if gain && (beta - 1.0).abs() > MAX_GAIN_ERROR {
        let q: Vec<(f64, f64, f64)> = pts.iter().map(|x| (x.0, x.1, x.2)).collect();
        warnings.push(format!(
            "the reference readings imply a camera gain of {beta:.2}, while a thermal camera's is within {:.0} % of 1: they disagree with each other, so only the offset is fitted (check the readings: a typo?)",
            100.0 * MAX_GAIN_ERROR
        ));
        (alpha, beta, std_k) = fit(&q, mean_c, false);
        // The readings disagree by more than their stated uncertainty: the offset's does too.
        let spread = q
            .iter()
            .map(|x| (x.1 - alpha) - x.0)
            .map(|r| r * r)
            .sum::<f64>()
            / q.len() as f64;
        std_k = std_k.hypot(spread.sqrt());
        gain = false;
    }
    if !gain {
        // The offset holds at the readings; away from them the unfitted gain error grows.
        let w: f64 = pts.iter().map(|p| 1.0 / (p.2 * p.2)).sum();
        let at = pts.iter().map(|p| p.0 / (p.2 * p.2)).sum::<f64>() / w;
        std_k = std_k.hypot(GAIN_STD * (mean_c - at).abs());
    }
    for u in &mut uses {
        if let Some(c) = u.camera_c {
            u.residual_k = Some((c - alpha) / beta - u.radiant_c);
        }
    }
    Level {
        basis: if gain {
            LevelBasis::OffsetAndGain
        } else {
            LevelBasis::Offset
        },
        alpha_c: alpha,
        beta,
        offset_at_mean_k: alpha + (beta - 1.0) * mean_c,
        std_k,
        references: uses,
        warnings,
    }
}

impl Level {
    /// The true temperature (°C) of a camera temperature.
    pub fn correct(&self, camera_c: f64) -> f64 {
        (camera_c - self.alpha_c) / self.beta
    }
}

/// What fixes the temperatures' absolute level: reference readings and the camera's accuracy;
/// and what turns the camera's radiant temperatures into surface temperatures: the emissivities
/// and the engine that gives each surface's irradiance.
#[derive(Clone, Debug, Default)]
pub(crate) struct LevelInputs {
    /// Contact-thermometer readings (references.csv and `[[references]]`).
    pub references: Vec<Reference>,
    /// The camera's stated absolute accuracy (K), used when no reading is usable.
    pub camera_accuracy_k: f64,
    /// The emissivities.
    pub emissivity: EmissivitySection,
    /// The view-factor settings the irradiances are computed with.
    pub mrt: MrtSection,
    /// What gathering the readings changed (duplicates merged).
    pub warnings: Vec<String>,
}

/// Readings closer than this to each other (m), in the same frame, are one spot read again.
pub(crate) const SAME_SPOT_M: f64 = 0.02;

/// Readings of one spot merged into one: their mean temperature, with the largest of their own
/// uncertainties and their spread (a repeated reading of one spot shares its contact's error, so
/// it is not an independent reading: two identical rows once took the level's ± from 0.12 to
/// 0.07 K). Returns the readings and a warning per merge.
pub(crate) fn merge_same_spot(refs: Vec<Reference>) -> (Vec<Reference>, Vec<String>) {
    let mut groups: Vec<Vec<Reference>> = Vec::new();
    for r in refs {
        let near = |g: &Vec<Reference>| {
            g[0].frame == r.frame
                && (Point3::from(g[0].xyz) - Point3::from(r.xyz)).norm() < SAME_SPOT_M
        };
        match groups.iter_mut().find(|g| near(g)) {
            Some(g) => g.push(r),
            None => groups.push(vec![r]),
        }
    }
    let mut warnings = Vec::new();
    let out = groups
        .into_iter()
        .map(|mut g| {
            if g.len() == 1 {
                return g.remove(0);
            }
            let n = g.len() as f64;
            let mean = g.iter().map(|r| r.temperature_c).sum::<f64>() / n;
            let spread = g
                .iter()
                .map(|r| (r.temperature_c - mean).abs())
                .fold(0.0, f64::max);
            let std = g.iter().map(|r| r.std_k).fold(spread, f64::max);
            let names: Vec<String> = g.iter().map(|r| format!("'{}'", r.label)).collect();
            warnings.push(format!(
                "references {} read the same spot (within {:.0} cm): taken as one reading, {mean:.2} °C ± {std:.2} K",
                names.join(", "),
                SAME_SPOT_M * 100.0
            ));
            Reference {
                temperature_c: mean,
                std_k: std,
                ..g[0].clone()
            }
        })
        .collect();
    (out, warnings)
}

impl LevelInputs {
    /// The recording's references.csv (when present) and the project's `[[references]]`.
    pub fn of(rec: &Recording, p: &Project) -> Result<Self> {
        Self::gathered(Some(rec), None, p)
    }

    /// What every path gives the level: the readings of `csv` (by default the recording's
    /// references.csv, when a recording is given and has one) and the project's
    /// `[[references]]`, same spots merged; the camera's accuracy from the recording's rig (the
    /// default without one); the project's emissivities and `[mrt]`.
    pub fn gathered(rec: Option<&Recording>, csv: Option<&Path>, p: &Project) -> Result<Self> {
        let mut references = Vec::new();
        let own = rec
            .map(|r| mrtmap_io::RecordingFile::References.path_in(&r.dir))
            .filter(|f| f.exists());
        if let Some(csv) = csv.or(own.as_deref()) {
            references.extend(Reference::read_csv(csv)?);
        }
        references.extend(p.references.iter().cloned());
        let (references, warnings) = merge_same_spot(references);
        Ok(Self {
            references,
            warnings,
            camera_accuracy_k: rec
                .and_then(|r| r.rig.thermal_accuracy_k)
                .unwrap_or(DEFAULT_CAMERA_ACCURACY_K),
            emissivity: p.emissivity.clone(),
            mrt: p.mrt,
        })
    }
}

/// The scene's temperatures carried to the level: (T − α)/β, uncertainties scaled by 1/β, and
/// the level's uncertainty recorded.
fn apply_level(scene: &mut RadiantScene, level: &Level) {
    let fix = |t: &mut Temperature| {
        *t = Temperature::from_celsius(level.correct(t.celsius()));
    };
    let scale = |s: &mut Option<f64>| {
        if let Some(v) = s {
            *v /= level.beta.abs();
        }
    };
    for s in &mut scene.surfaces {
        fix(&mut s.temperature);
        scale(&mut s.temperature_std_k);
        if let Some(r) = &mut s.raster {
            r.map_celsius(|c| level.correct(c));
        }
        for f in &mut s.features {
            fix(&mut f.temperature);
            scale(&mut f.temperature_std_k);
        }
    }
    for o in &mut scene.occluders {
        fix(&mut o.temperature);
    }
    scene.temperature_level_std_k = level.std_k;
}

/// Where a reading lies: on which element (its emissivity), the foot of the point on its plane
/// and the plane's normal.
struct Spot {
    emissivity: f64,
    foot: Point3<f64>,
    normal: Vector3<f64>,
}

/// How far from a surface's plane a reading may lie and still be of it (m).
const READING_PLANE_M: f64 = 0.10;

/// The element under `p` (room frame): the nearest surface plane within 10 cm whose polygon holds
/// the point's foot (within 5 cm), and the feature on it that holds the foot, if any.
fn spot_at(scene: &RadiantScene, p: &Point3<f64>) -> Option<Spot> {
    use mrtmap_geometry::polygon::{Containment, point_in_polygon};
    let mut best: Option<(f64, Spot)> = None;
    for s in &scene.surfaces {
        let n = s.frame.normal.into_inner();
        let d = (p - s.frame.origin).dot(&n);
        if d.abs() > READING_PLANE_M || best.as_ref().is_some_and(|b| b.0 <= d.abs()) {
            continue;
        }
        let foot = p - n * d;
        let q = s.frame.to_2d(&foot);
        if point_in_polygon(&q, &s.polygon_2d, 0.05) == Containment::Outside {
            continue;
        }
        let emissivity = s
            .features
            .iter()
            .find(|f| point_in_polygon(&q, &f.polygon_2d, 0.0) != Containment::Outside)
            .map_or(s.emissivity, |f| f.emissivity);
        best = Some((
            d.abs(),
            Spot {
                emissivity,
                foot,
                normal: n,
            },
        ));
    }
    best.map(|b| b.1)
}

/// The area-weighted mean temperature of a scene's surfaces (°C).
fn mean_temperature_c(scene: &RadiantScene) -> f64 {
    let (mut a, mut t) = (0.0, 0.0);
    for s in &scene.surfaces {
        let area = mrtmap_geometry::polygon::area_3d(&s.polygon);
        a += area;
        t += area * s.temperature.celsius();
    }
    if a > 0.0 { t / a } else { 20.0 }
}

/// Segmentation's scene and tables carried to the level the readings of `level` fix: the
/// readings are compared with what the cameras saw (the cloud `cloud` and texturing's samples:
/// a contact reading on a window, where glass gives no depth, meets what texturing found), the
/// level fitted, the scene's temperatures corrected, segment.json's tables with them, and the
/// level's warnings added to segmentation's.
pub(crate) fn level_segmentation(
    seg: &mut Segmentation,
    cloud: &ThermalCloud,
    level: &LevelInputs,
) -> Level {
    let world_from_room = seg
        .report
        .world_from_room
        .to_isometry()
        .unwrap_or_else(Isometry3::identity);
    // What the cameras saw, texturing's samples included: a contact reading on a window (glass
    // gives no depth, so the cloud has nothing there) is compared with what texturing found.
    let mut seen = cloud.clone();
    seen.positions.extend_from_slice(&seg.textured.positions);
    seen.normals.extend_from_slice(&seg.textured.normals);
    seen.temperature_k
        .extend_from_slice(&seg.textured.temperature_k);
    seen.temperature_std_k
        .extend_from_slice(&seg.textured.temperature_std_k);
    seen.observations
        .extend_from_slice(&seg.textured.observations);
    let unmatched = level.emissivity.apply(&mut seg.scene);
    if !unmatched.is_empty() {
        seg.report.warnings.push(format!(
            "[emissivity] {} matched no surface, feature or furniture of the room found, so {} not used: check the ids and labels in segment/scene.json",
            unmatched.join(", "),
            if unmatched.len() == 1 { "it was" } else { "they were" }
        ));
    }
    let found = fit_grey_level(&seg.scene, &seen, &world_from_room, level);
    apply_level(&mut seg.scene, &found);
    // The surfaces' true temperatures, from the irradiance at the level found.
    match grey::derive_surface_temperatures(
        &mut seg.scene,
        |s| level.mrt.engine(s),
        level.emissivity.std,
    ) {
        Ok(unexplained) if !unexplained.is_empty() => seg.report.warnings.push(format!(
            "level: no surface temperature explains the radiant temperature of {} with the emissivity taken (colder than what it reflects): check its emissivity in [emissivity]",
            unexplained.join(", ")
        )),
        Ok(_) => {}
        Err(e) => seg.report.warnings.push(format!(
            "level: surface temperatures not derived: {e}"
        )),
    }
    carry_to_tables(seg, &found);
    seg.report.warnings.extend(
        level
            .warnings
            .iter()
            .chain(&found.warnings)
            .map(|w| format!("level: {w}")),
    );
    found
}

/// The level of the readings of `level` seen in `seen`, on grey surfaces: the camera reads radiant
/// temperatures and a contact reading is a surface temperature, so each reading is compared with
/// what the camera should read there (its emissivity, and the irradiance the scene gives the spot,
/// at the level being fitted: three rounds settle it, since a level error moves that prediction
/// by only 1 − ε of itself).
fn fit_grey_level(
    scene: &RadiantScene,
    seen: &ThermalCloud,
    world_from_room: &Isometry3<f64>,
    level: &LevelInputs,
) -> Level {
    let spots: Vec<Option<Spot>> = level
        .references
        .iter()
        .map(|r| {
            let p = match r.frame {
                PointFrame::Room => Point3::from(r.xyz),
                PointFrame::Scan => world_from_room.inverse() * Point3::from(r.xyz),
            };
            spot_at(scene, &p)
        })
        .collect();
    let irradiance_cam: Vec<Option<Temperature>> = match level.mrt.engine(scene) {
        Ok(engine) if !spots.is_empty() => spots
            .iter()
            .enumerate()
            .map(|(k, s)| {
                s.as_ref().and_then(|s| {
                    grey::irradiance(&engine, &[s.foot], &s.normal, 7_000 + k as u64).map(|x| x.0)
                })
            })
            .collect(),
        _ => vec![None; spots.len()],
    };
    let mean_c = mean_temperature_c(scene);
    let fit = |expected: &[Expected]| {
        find_level(
            &level.references,
            expected,
            seen,
            world_from_room,
            mean_c,
            level.camera_accuracy_k,
        )
    };
    let mut found = fit(&[]);
    for _ in 0..3 {
        let expected: Vec<Expected> = level
            .references
            .iter()
            .zip(&spots)
            .zip(&irradiance_cam)
            .map(|((r, spot), irr)| {
                let e = r
                    .emissivity
                    .or(spot.as_ref().map(|s| s.emissivity))
                    .unwrap_or(1.0);
                match irr {
                    Some(t) if e < 1.0 => expected_grey(r, e, *t, &found, level.emissivity.std),
                    _ => Expected::black(r),
                }
            })
            .collect();
        found = fit(&expected);
    }
    found
}

/// What the camera should read at reading `r` of a surface of emissivity `e` whose irradiance the
/// camera put at `irradiance_cam` (carried to the level `found`), with the uncertainty an
/// emissivity taken from the table (±`emissivity_std`) puts on it.
fn expected_grey(
    r: &Reference,
    e: f64,
    irradiance_cam: Temperature,
    found: &Level,
    emissivity_std: f64,
) -> Expected {
    let ts = Temperature::from_celsius(r.temperature_c);
    let ti = Temperature::from_celsius(found.correct(irradiance_cam.celsius()));
    let tr = grey::radiant_temperature(ts, ti, e);
    // ∂T_r/∂ε = (T⁴ − T_irr⁴) / 4T_r³; an emissivity the reading's column gives is taken as known.
    let d_e = (ts.kelvin().powi(4) - ti.kelvin().powi(4)) / (4.0 * tr.kelvin().powi(3));
    let sd_e = if r.emissivity.is_some() {
        0.0
    } else {
        emissivity_std
    };
    Expected {
        radiant_c: tr.celsius(),
        emissivity: e,
        std_k: (d_e * sd_e).abs(),
    }
}

/// segment.json's tables at the same level as scene.json (the report's Surfaces and Features tables
/// showed the camera's uncorrected temperatures beside corrected maps), with each element's
/// emissivity and true temperature.
fn carry_to_tables(seg: &mut Segmentation, found: &Level) {
    for x in &mut seg.report.surfaces {
        x.temperature_c = x.temperature_c.map(|c| found.correct(c));
        x.temperature_std_k /= found.beta.abs();
    }
    for f in &mut seg.report.features {
        f.temperature_c = found.correct(f.temperature_c);
        f.contrast_k /= found.beta;
    }
    for f in &mut seg.report.furniture {
        f.temperature_c = found.correct(f.temperature_c);
    }
    let grey_of = |id: &str| {
        seg.scene.surfaces.iter().find_map(|s| {
            if s.id == id {
                return Some((s.emissivity, s.surface_temperature));
            }
            s.features
                .iter()
                .find(|f| f.id == id)
                .map(|f| (f.emissivity, f.surface_temperature))
        })
    };
    for x in &mut seg.report.surfaces {
        if let Some((e, st)) = grey_of(&x.id) {
            x.emissivity = Some(e);
            x.surface_temperature_c = st.map(|t| t.0.celsius());
            x.surface_temperature_std_k = st.map(|t| t.1);
        }
    }
    for x in &mut seg.report.features {
        if let Some((e, st)) = grey_of(&x.id) {
            x.emissivity = Some(e);
            x.surface_temperature_c = st.map(|t| t.0.celsius());
            x.surface_temperature_std_k = st.map(|t| t.1);
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// A cloud of three patches at x = 0, 5, 10 m read by a camera with offset and gain.
    fn cloud(true_c: [f64; 3], alpha: f64, beta: f64) -> ThermalCloud {
        let mut c = ThermalCloud::default();
        for (k, t) in true_c.iter().enumerate() {
            for i in 0..10 {
                let cam = alpha + beta * t;
                c.push(
                    [5.0 * k as f32 + 0.002 * i as f32, 0.0, 0.0],
                    [0.0, 0.0, 1.0],
                    (cam + ZERO_CELSIUS_K) as f32,
                    0.0,
                    5,
                );
            }
        }
        c
    }

    fn reading(label: &str, x: f64, t: f64) -> Reference {
        Reference {
            label: label.into(),
            xyz: [x, 0.0, 0.0],
            temperature_c: t,
            std_k: 0.1,
            frame: PointFrame::Scan,
            emissivity: None,
        }
    }

    #[test]
    fn one_reading_fixes_the_offset_two_the_gain() {
        let c = cloud([10.0, 20.0, 30.0], 1.5, 1.02);
        let id = Isometry3::identity();
        let one = find_level(&[reading("a", 5.0, 20.0)], &[], &c, &id, 20.0, 5.0);
        assert_eq!(one.basis, LevelBasis::Offset);
        assert!((one.correct(1.5 + 1.02 * 20.0) - 20.0).abs() < 1e-3);
        assert!((one.std_k - 0.1).abs() < 0.01, "{}", one.std_k);
        // One reading of the window (10 °C) for a room at 20 °C: the camera's 2 % gain error is
        // 0.2 K there, which the ± must hold (a 20 s walk whose wall reading the scan missed
        // stated 0.10 K and was 0.28-0.34 K off).
        let window = find_level(&[reading("w", 0.0, 10.0)], &[], &c, &id, 20.0, 5.0);
        assert_eq!(window.basis, LevelBasis::Offset);
        let err = window.correct(1.5 + 1.02 * 20.0) - 20.0;
        assert!((err - 0.2).abs() < 0.01, "{err}");
        assert!(2.0 * window.std_k > err.abs(), "{}", window.std_k);
        assert!(
            (window.std_k - 0.1f64.hypot(0.3)).abs() < 0.01,
            "{}",
            window.std_k
        );
        let two = find_level(
            &[reading("a", 0.0, 10.0), reading("b", 10.0, 30.0)],
            &[],
            &c,
            &id,
            20.0,
            5.0,
        );
        assert_eq!(two.basis, LevelBasis::OffsetAndGain);
        assert!((two.beta - 1.02).abs() < 1e-3 && (two.alpha_c - 1.5).abs() < 1e-2);
        assert!((two.correct(1.5 + 1.02 * 20.0) - 20.0).abs() < 1e-3);
    }

    #[test]
    fn a_disagreeing_reading_is_named_and_an_unseen_one_noted() {
        let c = cloud([10.0, 20.0, 30.0], 0.0, 1.0);
        let id = Isometry3::identity();
        let l = find_level(
            &[
                reading("a", 0.0, 10.0),
                reading("b", 5.0, 22.0),
                reading("c", 10.0, 30.0),
                reading("far", 50.0, 20.0),
            ],
            &[],
            &c,
            &id,
            20.0,
            5.0,
        );
        let b = l.references.iter().find(|r| r.label == "b").unwrap();
        assert!(
            !b.used && b.note.as_deref().unwrap().contains("disagrees"),
            "{b:?}"
        );
        let far = l.references.iter().find(|r| r.label == "far").unwrap();
        assert!(!far.used && far.camera_c.is_none());
        // The cloud stores kelvin as f32 (about 3e-5 K apart near 293 K).
        assert!(
            (l.beta - 1.0).abs() < 1e-5 && l.alpha_c.abs() < 1e-3,
            "{l:?}"
        );
        let none = find_level(&[], &[], &c, &id, 20.0, 5.0);
        assert_eq!((none.basis, none.std_k), (LevelBasis::Camera, 5.0));
    }

    /// Issue 41: a wall read 40 instead of 20.9 gave a gain of 0.34 and a map 17 K warm, without a
    /// word. A reading farther from the camera than its accuracy is left out with a warning; two
    /// readings implying an implausible gain fit the offset alone, with a warning.
    #[test]
    fn a_typo_in_a_reading_is_left_out_and_an_implausible_gain_is_not_fitted() {
        let c = cloud([10.0, 20.0, 30.0], 1.0, 1.0);
        let id = Isometry3::identity();
        let l = find_level(
            &[reading("window", 0.0, 10.0), reading("wall", 5.0, 40.0)],
            &[],
            &c,
            &id,
            20.0,
            5.0,
        );
        let wall = l.references.iter().find(|r| r.label == "wall").unwrap();
        assert!(!wall.used, "{wall:?}");
        assert_eq!(l.basis, LevelBasis::Offset);
        assert!((l.correct(21.0) - 20.0).abs() < 1e-3, "{l:?}");
        assert!(
            l.warnings
                .iter()
                .any(|w| w.contains("'wall'") && w.contains("typo")),
            "{:?}",
            l.warnings
        );
        // Both within the camera's accuracy, but 5 K apart where the camera saw 10 K apart.
        let l = find_level(
            &[reading("window", 0.0, 12.0), reading("wall", 5.0, 17.0)],
            &[],
            &c,
            &id,
            20.0,
            5.0,
        );
        assert_eq!(l.basis, LevelBasis::Offset, "{l:?}");
        assert!((l.beta - 1.0).abs() < 1e-12);
        assert!(
            l.warnings.iter().any(|w| w.contains("gain of 2.00")),
            "{:?}",
            l.warnings
        );
        assert!(l.std_k > 1.5, "{}", l.std_k);
    }

    /// Issue 52: a window (true 10 °C, ε 0.84) in a 20 °C room looks 11.6 °C to a perfect camera.
    /// Taken as black, its reading and a wall's imply a gain of 0.84, which is refused, and the
    /// offset fitted to both is off; compared with what the camera should read, they fit exactly.
    #[test]
    fn a_reading_on_glass_is_compared_with_what_the_camera_should_read() {
        let window_seen = grey::radiant_temperature(
            Temperature::from_celsius(10.0),
            Temperature::from_celsius(20.0),
            0.84,
        )
        .celsius();
        let c = cloud([window_seen, 20.0, 30.0], 0.0, 1.0);
        let id = Isometry3::identity();
        let refs = [reading("window", 0.0, 10.0), reading("wall", 5.0, 20.0)];
        let black = find_level(&refs, &[], &c, &id, 20.0, 5.0);
        assert_eq!(black.basis, LevelBasis::Offset, "{black:?}");
        assert!((black.correct(20.0) - 20.0).abs() > 0.5, "{black:?}");
        let expected = [
            Expected {
                radiant_c: window_seen,
                emissivity: 0.84,
                std_k: 0.0,
            },
            Expected::black(&refs[1]),
        ];
        let grey = find_level(&refs, &expected, &c, &id, 20.0, 5.0);
        assert_eq!(grey.basis, LevelBasis::OffsetAndGain, "{grey:?}");
        assert!(
            (grey.beta - 1.0).abs() < 1e-3 && grey.alpha_c.abs() < 1e-2,
            "{grey:?}"
        );
        assert!(grey.references.iter().all(|r| r.used));
    }

    /// Issue 54: duplicate rows are one reading, not two independent ones.
    #[test]
    fn readings_of_one_spot_are_merged_and_named() {
        let mut a = reading("a", 1.0, 20.0);
        a.std_k = 0.2;
        let b = Reference {
            label: "b".into(),
            ..a.clone()
        };
        let c = reading("c", 1.005, 20.4);
        let far = reading("far", 3.0, 18.0);
        let (merged, warnings) = merge_same_spot(vec![a, b, c, far]);
        assert_eq!(merged.len(), 2, "{merged:?}");
        assert!((merged[0].temperature_c - 20.4 / 3.0 - 40.0 / 3.0).abs() < 1e-9);
        assert!(
            (merged[0].std_k - 0.2667).abs() < 1e-3,
            "{}",
            merged[0].std_k
        );
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("'a', 'b', 'c'"), "{warnings:?}");
        // The level's ± from two identical rows is that of one.
        let cl = cloud([10.0, 20.0, 30.0], 0.0, 1.0);
        let id = Isometry3::identity();
        let one = find_level(&[reading("w", 5.0, 20.0)], &[], &cl, &id, 20.0, 5.0);
        let (twice, _) = merge_same_spot(vec![reading("w", 5.0, 20.0), reading("w", 5.0, 20.0)]);
        let two = find_level(&twice, &[], &cl, &id, 20.0, 5.0);
        assert!(
            (one.std_k - two.std_k).abs() < 1e-12,
            "{} vs {}",
            one.std_k,
            two.std_k
        );
    }

    #[test]
    fn references_csv_errors_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("references.csv");
        std::fs::write(
            &p,
            "# ok\nlabel,x,y,z,temperature_c\nw,1,2,3,20.5\nv,1,2,x,20\n",
        )
        .unwrap();
        let e = Reference::read_csv(&p).unwrap_err().to_string();
        assert!(
            e.ends_with("references.csv:4: z 'x' is not a number"),
            "{e}"
        );
        std::fs::write(&p, "label,x,y,temperature_c\n").unwrap();
        let e = Reference::read_csv(&p).unwrap_err().to_string();
        assert!(e.contains(":1: the header has no column 'z'"), "{e}");
        // A byte-order mark before the header (Excel's "CSV UTF-8") is read past.
        let bom = "\u{feff}label,x,y,z,temperature_c\nwall,1,2,1,20.5\n";
        assert_eq!(
            Reference::parse_csv(bom, Path::new("r.csv")).unwrap().len(),
            1
        );
        std::fs::write(&p, "temperature_c,label,z,y,x,std_k\n20.5,w,3,2,1,0.05\n").unwrap();
        let r = Reference::read_csv(&p).unwrap();
        assert_eq!(
            (r[0].xyz, r[0].std_k, r[0].frame),
            ([1.0, 2.0, 3.0], 0.05, PointFrame::Room)
        );
        // The recording format's example: the room frame by default, or as the column says.
        std::fs::write(
            &p,
            "label,x,y,z,temperature_c,frame\nfloor,1.83,0.42,0.00,20.6,room\nwall x0,-1.30,0.95,0.41,21.0,scan\nw,1,2,3,20,\n",
        )
        .unwrap();
        let r = Reference::read_csv(&p).unwrap();
        let frames: Vec<PointFrame> = r.iter().map(|x| x.frame).collect();
        assert_eq!(
            frames,
            [PointFrame::Room, PointFrame::Scan, PointFrame::Room]
        );
        std::fs::write(&p, "label,x,y,z,temperature_c,frame\nw,1,2,3,20,world\n").unwrap();
        let e = Reference::read_csv(&p).unwrap_err().to_string();
        assert!(e.contains(":2: frame 'world' is neither room"), "{e}");
        // An emissivity column: a number in (0, 1], or empty for the surface's.
        std::fs::write(
            &p,
            "label,x,y,z,temperature_c,emissivity\nw,1,2,3,11.5,0.84\nv,1,2,3,20,\n",
        )
        .unwrap();
        let r = Reference::read_csv(&p).unwrap();
        assert_eq!((r[0].emissivity, r[1].emissivity), (Some(0.84), None));
        std::fs::write(
            &p,
            "label,x,y,z,temperature_c,emissivity\nw,1,2,3,11.5,84\n",
        )
        .unwrap();
        let e = Reference::read_csv(&p).unwrap_err().to_string();
        assert!(e.contains(":2: emissivity 84 is outside"), "{e}");
    }
}
