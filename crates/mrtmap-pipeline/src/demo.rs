//! The demo: simulate a scan of a preset room, run the pipeline on it, and compare with the exact
//! truth (the seed paper's table at points A–D, and the error over the truth's grid).

use std::path::{Path, PathBuf};

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_physics::{
    Globe, GlobeMethod, GlobeReading, Temperature, globe_temperature, mrt_from_globe,
};
use mrtmap_radiation::{Method, MonteCarlo, MrtEngine, RadiantScene};
use mrtmap_report::ComparisonRow;
use mrtmap_sim::{NoiseLevel, RadiometricModel, SimConfig, Truth, simulate};
use serde::Serialize;

use crate::cache::{Fingerprint, Stage, StageOutcome, read_json, run_or_reuse, write_json};
use crate::error::{Error, Result};
use crate::layout::{DemoLayout, RunLayout};
use crate::progress::Progress;
use crate::report::report_data;
use crate::run::{RunOutcome, run};
use crate::settings::{PointEntry, PointFrame, Project};
use crate::simulation::{load_room, set_depth_size};

/// Rays per grid node when comparing with the truth.
const GRID_RAYS: usize = 20_000;
/// First random stream of the grid nodes (the points use 0…).
const GRID_STREAM0: u64 = 10_000;

/// What the demo simulates.
#[derive(Clone, Debug)]
pub(crate) struct DemoSettings {
    /// A preset room.
    pub room: String,
    /// Length of the scan (s).
    pub seconds: f64,
    /// Seed of the simulation.
    pub seed: u64,
    /// Sensor noise.
    pub noise: NoiseLevel,
    /// Air speed at the simulated globes (m/s).
    pub air_speed_m_s: f64,
    /// Depth image size.
    pub depth_size: (usize, usize),
    /// Depth frame rate (Hz).
    pub depth_hz: f64,
    /// The thermal camera's radiometric errors.
    pub radiometric: RadiometricModel,
    /// Contact-thermometer readings written to references.csv.
    pub references: usize,
    /// Rerun every stage.
    pub force: bool,
}

/// The error over the truth's grid.
#[derive(Clone, Copy, Debug, Serialize)]
pub(crate) struct GridError {
    /// Nodes compared.
    pub nodes: usize,
    /// Largest |ours − truth| (K).
    pub max_abs_error_k: f64,
    /// RMS of ours − truth (K).
    pub rmse_k: f64,
}

/// What the demo did and found.
#[derive(Clone, Debug)]
pub(crate) struct DemoOutcome {
    /// The room's name.
    pub room: String,
    /// The simulation stage.
    pub simulate: StageOutcome,
    /// The recording.
    pub recording: PathBuf,
    /// The run folder (report.html).
    pub run_dir: PathBuf,
    /// The run.
    pub run: RunOutcome,
    /// The seed paper's table: truth, globe, ours at the validation points.
    pub rows: Vec<ComparisonRow>,
    /// The error over the grid.
    pub grid: GridError,
}

impl DemoOutcome {
    /// What `mrtmap demo` prints: the stages, the seed paper's table, the grid's error, the report,
    /// and how much `out` holds; `secs` is the whole demo's time.
    pub fn lines(&self, s: &DemoSettings, out: &Path, secs: f64) -> Vec<String> {
        let mut lines = vec![
            format!(
                "simulated {:.0} s of scanning the {} room ({:?} noise), ran the pipeline:",
                s.seconds, self.room, s.noise
            ),
            format!(
                "  {:<14} {:>7.1} s{}",
                "simulate",
                self.simulate.secs,
                if self.simulate.skipped {
                    "  (reused)"
                } else {
                    ""
                }
            ),
        ];
        lines.extend(self.run.lines(&self.run_dir, secs));
        lines.push(String::new());
        lines.push("MRT at the validation points (°C), as in the seed paper's table:".into());
        lines.push(format!(
            "  {:<6} {:>12} {:>18} {:>10} {:>16}",
            "point", "truth", "black globe (ISO)", "mrtmap", "mrtmap − truth"
        ));
        for r in &self.rows {
            lines.push(format!(
                "  {:<6} {:>12.2} {:>18.2} {:>10.2} {:>14} K",
                r.name,
                r.truth_c,
                r.globe_c,
                r.ours_c,
                mrtmap_report::numbers::signed(r.diff_k, 2)
            ));
        }
        lines.push(format!(
            "over the 20×20 grid at 1.1 m ({} nodes): max |Δ| {:.3} K, RMSE {:.3} K",
            self.grid.nodes, self.grid.max_abs_error_k, self.grid.rmse_k
        ));
        lines.push(format!(
            "report: {}",
            RunLayout::new(&self.run_dir).report_html().display()
        ));
        lines.push(format!(
            "{} holds {:.0} MB (recording, fused cloud, maps, report)",
            out.display(),
            folder_bytes(out) as f64 / 1e6
        ));
        lines
    }
}

/// The bytes of the files under `dir` (what cannot be read counts as nothing).
fn folder_bytes(dir: &Path) -> u64 {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .map(|e| match e.file_type() {
            Ok(t) if t.is_dir() => folder_bytes(&e.path()),
            Ok(t) if t.is_file() => e.metadata().map_or(0, |m| m.len()),
            _ => 0,
        })
        .sum()
}

/// Walking speeds the demo may choose, slowest first (m/s): a careful scan walks at 0.5 m/s; a
/// shorter one walks faster, up to a brisk 1 m/s, so that it still sees every wall.
pub(crate) const DEMO_SPEEDS_M_S: [f64; 6] = [0.5, 0.6, 0.7, 0.8, 0.9, 1.0];

/// The shortest demo walk of `room` at `speed_m_s` (s): one and a half times the time the walk
/// takes until every wall has been in view (the simulator's own coverage test on the floor plan),
/// at least 15 s, in whole 5 s (3600 s when it never does). Measured on 2026-12-03 at 0.5 m/s: the
/// office maps within 0.09 K from 15 s; the L-shaped room's 15 s walk missed two walls and its
/// 25 s walk placed a wall 0.7 m short (0.44 K).
pub(crate) fn shortest_walk_s(room: &mrtmap_sim::Room, seed: u64, speed_m_s: f64) -> f64 {
    let params = mrtmap_sim::WalkParams {
        speed_m_s,
        ..mrtmap_sim::WalkParams::default()
    };
    let walk = mrtmap_sim::Walk::new(room, params, seed);
    let t = walk.seconds_to_see_every_wall(3600.0).unwrap_or(3600.0);
    // Half as long again: in view on the plan is not yet seen up to the ceiling, often enough
    // for a wall to be placed from its own points.
    (1.5 * t / 5.0).ceil().clamp(3.0, 720.0) * 5.0
}

/// The slowest of [`DEMO_SPEEDS_M_S`] at which a walk of `seconds` sees every wall of `room`, or
/// the shortest walk at the fastest speed.
pub(crate) fn walk_speed_for(
    room: &mrtmap_sim::Room,
    seed: u64,
    seconds: f64,
) -> std::result::Result<f64, f64> {
    let mut shortest = f64::INFINITY;
    for v in DEMO_SPEEDS_M_S {
        shortest = shortest_walk_s(room, seed, v);
        if shortest <= seconds {
            return Ok(v);
        }
    }
    Err(shortest)
}

/// Simulates the scan into `out/recording` unless it holds this simulation already.
fn simulate_stage(
    out: &Path,
    s: &DemoSettings,
    progress: &dyn Progress,
) -> Result<(StageOutcome, String)> {
    let room = load_room(&s.room)?;
    let fastest = DEMO_SPEEDS_M_S[DEMO_SPEEDS_M_S.len() - 1];
    let speed = match walk_speed_for(&room, s.seed, s.seconds) {
        Ok(v) if s.seconds <= 3600.0 => v,
        found => {
            let shortest = match found {
                Err(t) => t,
                Ok(_) => shortest_walk_s(&room, s.seed, fastest),
            };
            return Err(Error::setting(
                format!("--seconds {}", s.seconds),
                format!(
                    "is outside {shortest:.0}…3600 s: the simulated walk loops the {} room, at 0.5 m/s or up to {fastest} m/s when short, and needs {shortest:.0} s to see every wall (a shorter walk leaves part of the room unseen, and points there are outside the room found); give --seconds {shortest:.0} or more",
                    room.file.name
                ),
            ));
        }
    };
    let layout = DemoLayout::new(out);
    let rec_dir = layout.recording_dir();
    let mut cfg = SimConfig {
        seconds: s.seconds,
        seed: s.seed,
        noise: s.noise,
        radiometric: s.radiometric,
        references: s.references,
        depth_hz: s.depth_hz,
        walk: mrtmap_sim::WalkParams {
            speed_m_s: speed,
            ..mrtmap_sim::WalkParams::default()
        },
        ..SimConfig::default()
    };
    set_depth_size(&mut cfg, s.depth_size)?;
    let fingerprint = Fingerprint::new()
        .setting("room", &room.file)
        .setting("seconds", &s.seconds)
        .setting("seed", &s.seed)
        .setting("noise", &s.noise)
        .setting("depth_size", &s.depth_size)
        .setting("depth_hz", &s.depth_hz)
        .setting("radiometric", &s.radiometric)
        .setting("references", &s.references);
    let stage = Stage {
        name: "simulate".into(),
        stamp: layout.simulate_json(),
        outputs: vec![layout.truth_json()],
    };
    let outcome = run_or_reuse(&stage, fingerprint, s.force, || {
        progress.begin(&format!(
            "simulating {:.0} s of scanning the {} room (walking at {speed:.1} m/s)",
            s.seconds, room.file.name
        ));
        simulate(&room, &cfg, &rec_dir, &|d, t| progress.advance(d, t))?;
        Ok(())
    })?;
    Ok((outcome, room.file.name))
}

/// The project of a simulated scan: its validation points, its air.
fn demo_project(truth: &Truth, s: &DemoSettings) -> Project {
    let mut project = Project {
        points: truth
            .points
            .iter()
            .map(|p| PointEntry {
                name: p.name.clone(),
                xyz: p.xyz_world,
                frame: PointFrame::Scan,
            })
            .collect(),
        ..Project::default()
    };
    project.air.temperature_c = Some(truth.air_temperature_c);
    project.air.speed_m_s = s.air_speed_m_s;
    project
}

/// An engine with Monte Carlo of `rays` where needed.
fn engine(scene: &RadiantScene, rays: usize) -> Result<MrtEngine<'_>> {
    Ok(mrtmap_radiation::enclosure::engine(
        scene,
        Method::Auto(MonteCarlo {
            rays,
            ..MonteCarlo::default()
        }),
    )?)
}

/// Ours against the truth at the validation points (ours: the run's own values at its marks, one
/// computation per number), with what a standard black globe would read: its equilibrium by the
/// mixed-convection model, read back through the ISO 7726 formula, as the seed paper's reference
/// globes were read.
fn compare_points(run: &RunOutcome, truth: &Truth, air_speed: f64) -> Result<Vec<ComparisonRow>> {
    let air = Temperature::from_celsius(truth.air_temperature_c);
    let marks = run
        .maps
        .first()
        .map(|m| m.summary.marks.as_slice())
        .unwrap_or(&[]);
    let mut rows = Vec::new();
    for p in &truth.points {
        let Some(ours) = marks
            .iter()
            .find(|m| m.name.as_deref() == Some(p.name.as_str()))
        else {
            continue;
        };
        let tg = globe_temperature(
            &Globe::STANDARD,
            Temperature::from_celsius(p.mrt_c),
            air,
            air_speed,
            GlobeMethod::MixedConvection,
        )?;
        let reading = GlobeReading {
            globe: tg,
            air,
            air_speed_m_s: air_speed,
        };
        let globe_c = mrt_from_globe(&Globe::STANDARD, &reading, GlobeMethod::ISO)?
            .mrt
            .celsius();
        rows.push(ComparisonRow {
            name: p.name.clone(),
            truth_c: p.mrt_c,
            globe_c,
            ours_c: ours.mrt_c,
            diff_k: ours.mrt_c - p.mrt_c,
        });
    }
    Ok(rows)
}

/// Ours against the truth on its grid (nodes where either has no value are left out); the truth's
/// nodes are in the scan's frame, carried into the scene's room frame.
fn compare_grid(scene: &RadiantScene, truth: &Truth) -> Result<GridError> {
    let engine = engine(scene, GRID_RAYS)?;
    let room_from_world = scene
        .world_from_room
        .map(|w| w.inverse())
        .unwrap_or_else(mrtmap_geometry::nalgebra::Isometry3::identity);
    let diffs: Vec<f64> = truth
        .grid
        .nodes
        .iter()
        .enumerate()
        .filter_map(|(k, n)| {
            let t = n.mrt_c?;
            let at = room_from_world * Point3::from(n.xyz_world);
            let o = engine.at(&at, GRID_STREAM0 + k as u64).ok()?;
            Some(o.mrt.celsius() - t)
        })
        .collect();
    let max_abs = diffs.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let rmse = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len().max(1) as f64).sqrt();
    Ok(GridError {
        nodes: diffs.len(),
        max_abs_error_k: max_abs,
        rmse_k: rmse,
    })
}

/// demo.json.
#[derive(Serialize)]
struct DemoFile<'a> {
    points: &'a [ComparisonRow],
    grid: GridError,
    stages: &'a [StageOutcome],
    seconds: f64,
    simulate_seconds: f64,
    scan_seconds: f64,
}

/// Writes the run's report (with the comparison) and `out/demo.json`.
fn write_demo_outputs(
    out: &Path,
    s: &DemoSettings,
    d: &DemoOutcome,
    project: &Project,
    seconds: f64,
) -> Result<()> {
    let mut data = report_data(
        &d.run,
        &format!(
            "mrtmap demo: simulated {:.0} s scan of the {} room",
            s.seconds, d.room
        ),
        &d.recording.display().to_string(),
        project,
    );
    data.comparison = d.rows.clone();
    let cloud = crate::export::run_cloud(&d.run_dir, &d.run.scene);
    data.view3d = Some(crate::report::view3d_for_run(
        &d.run_dir,
        &d.run,
        cloud.as_ref(),
    ));
    data.grid_error = Some((d.grid.max_abs_error_k, d.grid.rmse_k, d.grid.nodes));
    let reused = if d.simulate.skipped { " (reused)" } else { "" };
    data.timing.insert(
        0,
        ("simulate".into(), format!("{:.1}{reused}", d.simulate.secs)),
    );
    mrtmap_io::write_atomic(
        &RunLayout::new(&d.run_dir).report_html(),
        mrtmap_report::render_html(&data).as_bytes(),
    )?;
    write_json(
        &DemoLayout::new(out).demo_json(),
        &DemoFile {
            points: &d.rows,
            grid: d.grid,
            stages: &d.run.stages,
            seconds,
            simulate_seconds: d.simulate.secs,
            scan_seconds: s.seconds,
        },
    )
}

/// `mrtmap demo`: the flags.
#[derive(Debug, Clone, clap::Args)]
pub struct DemoArgs {
    /// Output folder (the recording goes in DIR/recording, the run in DIR/run); about 200 MB for
    /// the default 30 s scan, 380 MB for 60 s, 2 GB with --full. The default folder is git-ignored
    /// in mrtmap's own repository.
    #[arg(long, value_name = "DIR", default_value = "mrtmap-demo")]
    pub(crate) out: PathBuf,
    /// Length of the simulated scan (s): 15 at least for the office (a shorter walk has not seen
    /// the whole room).
    #[arg(long, default_value_t = 30.0)]
    pub(crate) seconds: f64,
    /// Simulate the seed paper's full 343 s scan (overrides --seconds).
    #[arg(long)]
    pub(crate) full: bool,
    /// The preset room.
    #[arg(long, default_value = "office")]
    pub(crate) room: String,
    /// Sensor noise.
    #[arg(long, value_enum, default_value_t = NoiseLevel::Realistic)]
    pub(crate) noise: NoiseLevel,
    /// Air speed at the simulated globes (m/s).
    #[arg(long, default_value_t = 0.1)]
    pub(crate) air_speed: f64,
    /// Depth image size of the simulated scan, WIDTHxHEIGHT (smaller runs faster).
    #[arg(long, default_value = "640x480", value_parser = crate::parse::parse_grid)]
    pub(crate) depth_size: (usize, usize),
    /// Depth frame rate of the simulated scan (Hz); 15 Hz is what many D4xx rigs record.
    #[arg(long, default_value_t = 15.0)]
    pub(crate) depth_hz: f64,
    /// Random seed of the simulation.
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    #[command(flatten)]
    pub(crate) camera: crate::simulation::CameraErrorArgs,
    /// Rerun every stage.
    #[arg(long)]
    pub(crate) force: bool,
}

impl DemoArgs {
    /// The demo's settings.
    fn settings(&self) -> DemoSettings {
        DemoSettings {
            room: self.room.clone(),
            seconds: if self.full { 343.0 } else { self.seconds },
            seed: self.seed,
            noise: self.noise,
            air_speed_m_s: self.air_speed,
            depth_size: self.depth_size,
            depth_hz: self.depth_hz,
            radiometric: self.camera.model(self.noise),
            references: self.camera.references(self.noise),
            force: self.force,
        }
    }

    /// Where the demo writes and about how much, for people to read before it starts.
    pub fn size_note(&self) -> String {
        // Measured (2026-12-03, with glass and late stamps): 15 s at 640×480 and 30 Hz wrote 154 MB
        // (depth 94 MB, colour 32, thermal 4, the run 20), 60 s 577 MB; at 15 Hz 30 s wrote 197 MB
        // and 60 s 373 MB: about 20 MB for the run, 2.7 MB per second of scan plus 6.6 MB per
        // second of 640×480 depth at 30 Hz.
        // Depth data per second against 640×480 at 30 Hz.
        let depth_share =
            (self.depth_size.0 * self.depth_size.1) as f64 / (640.0 * 480.0) * self.depth_hz / 30.0;
        let estimate_mb = 20.0 + self.settings().seconds * (2.7 + 6.6 * depth_share);
        format!(
            "writing into {} (about {:.0} MB; remove it when done)",
            self.out.display(),
            estimate_mb
        )
    }
}

/// `mrtmap demo`: the scan simulated, the pipeline run, and the comparison with the exact truth,
/// into the folder `a` names; gives what the CLI prints.
pub fn run_demo(a: &DemoArgs, progress: &dyn Progress) -> Result<Vec<String>> {
    let t0 = std::time::Instant::now();
    let s = a.settings();
    let d = demo(&a.out, &s, progress)?;
    Ok(d.lines(&s, &a.out, t0.elapsed().as_secs_f64()))
}

/// Runs the demo into `out` (recording in `out/recording`, the run in `out/run`).
pub(crate) fn demo(out: &Path, s: &DemoSettings, progress: &dyn Progress) -> Result<DemoOutcome> {
    let t0 = std::time::Instant::now();
    let (simulated, room) = simulate_stage(out, s, progress)?;
    let layout = DemoLayout::new(out);
    let recording = layout.recording_dir();
    let truth: Truth = read_json(&layout.truth_json())?;
    let project = demo_project(&truth, s);
    let run_dir = layout.run().root().to_path_buf();
    let outcome = run(&recording, &run_dir, &project, s.force, progress)?;
    progress.begin("comparing with the truth");
    let rows = compare_points(&outcome, &truth, s.air_speed_m_s)?;
    let grid = compare_grid(&outcome.scene, &truth)?;
    let d = DemoOutcome {
        room,
        simulate: simulated,
        recording,
        run_dir,
        run: outcome,
        rows,
        grid,
    };
    write_demo_outputs(out, s, &d, &project, t0.elapsed().as_secs_f64())?;
    Ok(d)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// Issue 41: a 15 s walk of each preset room must see every wall. The L-shaped room needs 30 s
    /// at a careful 0.5 m/s, so a 15 s walk walks faster; a long walk stays careful; a walk too
    /// short even at 1 m/s is refused with the shortest that would do.
    #[test]
    fn a_short_walk_walks_faster_to_see_every_wall() {
        for name in ["office", "radiant-ceiling", "l-shaped"] {
            let room = load_room(name).unwrap();
            let v = walk_speed_for(&room, 1, 15.0).unwrap();
            assert!((0.5..=1.0).contains(&v), "{name}: {v}");
            assert_eq!(walk_speed_for(&room, 1, 60.0).unwrap(), 0.5, "{name}");
            assert_eq!(walk_speed_for(&room, 1, 10.0), Err(15.0), "{name}");
        }
        let l = load_room("l-shaped").unwrap();
        assert!(shortest_walk_s(&l, 1, 0.5) > 15.0);
        assert!(walk_speed_for(&l, 1, 15.0).unwrap() > 0.5);
    }
}
