//! On site, before leaving the room: is a scan good enough for a map within the target (±0.2 K by
//! default), and if not, where to point the camera (`mrtmap coverage`).
//!
//! A coarse run of the whole pipeline: 5 cm voxels, no ICP (the pose source's poses as they are),
//! every fourth depth pixel, a 10 × 10 grid at 1.1 m with a quarter of the rays and no placement
//! term (where a globe stands is not the scan's doing). What it reads from the result is what the
//! scan controls: the walls it never saw (placed at the floor's edge), each surface's coverage, and
//! the unseen-areas part of the map's ± with the patches behind it. The level of the temperatures
//! (contact readings) is named too, since without readings no scan is within 0.2 K.

use std::path::Path;

use mrtmap_geometry::nalgebra::Isometry3;
use mrtmap_radiation::UnseenImpact;

use crate::advice::{Advice, Namer, Target, advise};
use serde::Serialize;

use crate::error::{Error, Result};
use crate::level::LevelBasis;
use crate::progress::Progress;
use crate::run::{RunOutcome, run};
use crate::settings::Project;

/// One surface's coverage.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceCoverage {
    /// Surface id.
    pub id: String,
    /// Its area (m²).
    pub area_m2: f64,
    /// Share seen with depth (the fused cloud).
    pub seen_with_depth: f64,
    /// Share seen by thermal texturing only (no depth there: glass, dark surfaces, dropouts).
    pub textured_only: f64,
    /// Share never seen.
    pub unseen: f64,
    /// Never seen at all: placed at the floor's edge.
    pub inferred: bool,
}

/// The verdict on a scan.
#[derive(Clone, Debug, Serialize)]
pub struct Coverage {
    /// The target (K, 2σ).
    pub target_k: f64,
    /// Whether the scan is good enough for a map within the target.
    pub good_enough: bool,
    /// Why not (empty when good enough), most important first.
    pub reasons: Vec<String>,
    /// Where to point the camera, most important first (the advice's sentences).
    pub look_at: Vec<String>,
    /// The same, each with the point it is about (room frame).
    pub advice: Vec<Advice>,
    /// What the verdict does not rest on but the map does (the readings' level).
    pub notes: Vec<String>,
    /// Each surface's coverage.
    pub surfaces: Vec<SurfaceCoverage>,
    /// The unseen patches by what they do to the map, largest first.
    pub unseen_patches: Vec<UnseenImpact>,
    /// The largest unseen-areas part of a node's ± (K, 1σ; NaN, written null, when the room
    /// could not be put together).
    pub max_unseen_k: f64,
    /// What the temperatures' level rests on ("references (offset and gain)", …, "camera").
    pub level_basis: String,
    /// Its standard uncertainty (K).
    pub level_std_k: f64,
    /// Thermal frames fused, of those recorded.
    pub frames: [usize; 2],
}

/// The coarse settings of a coverage check, from the project's.
pub fn coarse(base: &Project) -> Project {
    let mut p = base.clone();
    p.fuse.voxel_m = p.fuse.voxel_m.max(0.05);
    p.fuse.icp = false;
    p.fuse.depth_stride = 4;
    p.map.grid = [10, 10];
    p.map.heights_m = vec![1.1];
    p.map.quantities.clear();
    p.mrt.rays = (p.mrt.rays / 4).max(1000);
    p.mrt.placement_std_m = 0.0;
    p.points.clear();
    p
}

/// Runs the coarse pipeline on `recording` into `out` and judges the scan against `target_k`.
pub fn coverage(
    recording: &Path,
    out: &Path,
    base: &Project,
    target_k: f64,
    progress: &dyn Progress,
) -> Result<Coverage> {
    match run(recording, out, &coarse(base), false, progress) {
        Ok(o) => {
            let poses =
                mrtmap_io::Trajectory::read(&crate::RunLayout::new(out).fuse().poses_txt()).ok();
            let start = poses.and_then(|t| t.poses.first().copied());
            Ok(judge(&o, target_k, start.as_ref(), None))
        }
        // A room segmentation cannot close is the clearest "not good enough": say why and where.
        Err(Error::Segment { source, .. }) => Ok(Coverage {
            target_k,
            good_enough: false,
            reasons: vec![format!("the room could not be put together: {source}")],
            look_at: Vec::new(),
            advice: Vec::new(),
            notes: Vec::new(),
            surfaces: Vec::new(),
            unseen_patches: Vec::new(),
            max_unseen_k: f64::NAN,
            level_basis: String::new(),
            level_std_k: f64::NAN,
            frames: [0, 0],
        }),
        Err(e) => Err(e),
    }
}

/// Refuses a target that is not a positive number of kelvin, at most 10.
pub(crate) fn check_target(target_k: f64) -> Result<()> {
    if !(target_k.is_finite() && target_k > 0.0 && target_k <= 10.0) {
        return Err(Error::setting(
            format!("--target-k {target_k}"),
            "give the map's target as a positive number of kelvin (2σ), at most 10",
        ));
    }
    Ok(())
}

/// The verdict on a run's outcome; the advice names walls from where the scan started (`start`,
/// world_from_camera), and starts with the turn to make from `camera` when given.
pub(crate) fn judge(
    o: &RunOutcome,
    target_k: f64,
    start: Option<&Isometry3<f64>>,
    camera: Option<&Isometry3<f64>>,
) -> Coverage {
    let s = &o.segment;
    let surfaces: Vec<SurfaceCoverage> = s
        .surfaces
        .iter()
        .map(|x| {
            let area_m2 = o
                .scene
                .surfaces
                .iter()
                .find(|y| y.id == x.id)
                .map_or(0.0, |y| mrtmap_geometry::polygon::area_3d(&y.polygon));
            let seen = x.observed_fraction.clamp(0.0, 1.0);
            let textured = x.textured_fraction.clamp(0.0, seen);
            SurfaceCoverage {
                id: x.id.clone(),
                area_m2,
                seen_with_depth: seen - textured,
                textured_only: textured,
                unseen: 1.0 - seen,
                inferred: s.inferred_walls.contains(&x.id),
            }
        })
        .collect();
    let field = o.maps.first().and_then(|m| m.summary.map.field.as_ref());
    let unseen_patches = field.map_or(Vec::new(), |f| f.unseen_patches.clone());
    let max_unseen_k = field.map_or(0.0, |f| f.max_std_error_parts.unseen_k);
    let (basis, level_std_k) = o
        .level
        .as_ref()
        .map_or((LevelBasis::Camera, o.scene.temperature_level_std_k), |l| {
            (l.basis, l.std_k)
        });
    let level_basis = basis.to_string();
    let namer = Namer::new(&o.scene, start.copied());
    let mut reasons = Vec::new();
    let mut targets = Vec::new();
    for w in surfaces.iter().filter(|x| x.inferred) {
        reasons.push(format!(
            "{} was never seen: it is placed at the floor's edge",
            namer.wall(&w.id)
        ));
        targets.push(Target::Wall(&w.id));
    }
    if 2.0 * max_unseen_k > target_k {
        reasons.push(format!(
            "what the scan did not see makes the map uncertain by up to ±{:.2} K (2σ) on its own",
            2.0 * max_unseen_k
        ));
    }
    for u in unseen_patches
        .iter()
        .filter(|u| 2.0 * u.max_std_error_k > 0.25 * target_k)
        .take(5)
    {
        targets.push(Target::Patch(u));
    }
    let advice = advise(&namer, &targets, camera);
    let look_at = advice.iter().map(|a| a.text.clone()).collect();
    // The level is the readings', not the scan's: two readings at σ 0.1 K leave about ±0.2 K
    // (2σ) however well the room was scanned. It is a reason only when no reading was usable or
    // the readings leave over twice the target (one reading, far from the room's temperature).
    let mut notes = Vec::new();
    if basis == LevelBasis::Camera {
        reasons.push(format!(
            "no contact reading was usable: the temperatures' level is the camera's (±{level_std_k:.1} K); read a wall and the coldest surface (references.csv)"
        ));
    } else if 2.0 * level_std_k > 2.0 * target_k {
        reasons.push(format!(
            "the contact readings fix the temperatures' level to ±{:.2} K (2σ) only: add a reading on a surface at another temperature (a wall and the window)",
            2.0 * level_std_k
        ));
    } else if 2.0 * level_std_k > target_k {
        notes.push(format!(
            "the contact readings fix the temperatures' level to ±{:.2} K (2σ): the map is no better than that, however well the room is scanned",
            2.0 * level_std_k
        ));
    }
    let fused = o.fusion.used_frames;
    let recorded = o.fusion.thermal_frames;
    if recorded > 0 && fused * 2 < recorded {
        reasons.push(format!(
            "only {fused} of {recorded} thermal frames could be fused (see the run's warnings)"
        ));
    }
    Coverage {
        target_k,
        good_enough: reasons.is_empty(),
        reasons,
        look_at,
        advice,
        notes,
        surfaces,
        unseen_patches,
        max_unseen_k,
        level_basis,
        level_std_k,
        frames: [fused, recorded],
    }
}

impl Coverage {
    /// The verdict in lines, as `mrtmap coverage` prints it (`secs`: how long the check took).
    pub fn lines(&self, secs: f64) -> Vec<String> {
        let mut lines = Vec::new();
        if self.surfaces.is_empty() {
            lines.push(format!(
                "not good enough for a ±{} K map (checked in {secs:.1} s):",
                self.target_k
            ));
            for r in &self.reasons {
                lines.push(format!("  - {r}"));
            }
            return lines;
        }
        lines.push(format!(
            "{:<10} {:>8} {:>16} {:>14} {:>8}",
            "surface", "area m²", "seen with depth", "textured only", "unseen"
        ));
        for s in &self.surfaces {
            lines.push(format!(
                "{:<10} {:>8.1} {:>15.0} % {:>12.0} % {:>6.0} %{}",
                s.id,
                s.area_m2,
                100.0 * s.seen_with_depth,
                100.0 * s.textured_only,
                100.0 * s.unseen,
                if s.inferred { "  (never seen)" } else { "" }
            ));
        }
        lines.push(format!(
            "{} of {} thermal frames fused; the temperatures' level rests on {} (±{:.2} K)",
            self.frames[0], self.frames[1], self.level_basis, self.level_std_k
        ));
        lines.push(format!(
            "what the scan did not see: up to ±{:.2} K (2σ) on the map at 1.1 m",
            2.0 * self.max_unseen_k
        ));
        if self.good_enough {
            lines.push(format!(
                "good enough for a ±{} K map (checked in {secs:.1} s)",
                self.target_k
            ));
        } else {
            lines.push(format!(
                "not good enough for a ±{} K map (checked in {secs:.1} s):",
                self.target_k
            ));
            for r in &self.reasons {
                lines.push(format!("  - {r}"));
            }
        }
        for n in &self.notes {
            lines.push(format!("note: {n}"));
        }
        if !self.look_at.is_empty() {
            lines.push("where to point the camera, most important first:".to_string());
            for l in &self.look_at {
                lines.push(format!("  - {l}"));
            }
        }
        lines
    }
}

/// `mrtmap coverage` in one call, with the settings `p`: checks the target (K, 2σ), prepares the
/// recording (any source `run` takes) and runs the coarse check into `out`, or into a temporary
/// folder that is removed.
pub(crate) fn coverage_with(
    recording: &Path,
    out: Option<&Path>,
    p: &Project,
    source: &crate::source::SourceOptions,
    target_k: f64,
    progress: &dyn Progress,
) -> Result<Coverage> {
    p.check_heights_above_floor()?;
    check_target(target_k)?;
    let temp = match out {
        Some(_) => None,
        None => Some(
            tempfile::tempdir()
                .map_err(|e| mrtmap_io::FileError::io(Path::new("a temporary folder"), e))?,
        ),
    };
    let out = match (out, &temp) {
        (Some(o), _) => o.to_path_buf(),
        (None, Some(t)) => t.path().join("coverage"),
        (None, None) => unreachable!("one of the two is set"),
    };
    crate::run::check_out_dir(&out)?;
    let prepared = crate::source::prepare(recording, &out, source)?;
    coverage(&prepared.dir, &out, p, target_k, progress)
}
