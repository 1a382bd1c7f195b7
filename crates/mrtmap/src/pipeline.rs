//! The pipeline behind `mrtmap run` and `mrtmap demo`: fuse → segment → maps, each stage in its own
//! folder with a `stage.json` fingerprint (its inputs' sizes and modification times, and its
//! parameters). A stage whose fingerprint is unchanged is skipped; the fingerprint is written
//! last, so an interrupted run resumes at the first unfinished stage.

use std::path::Path;
use std::time::{Instant, UNIX_EPOCH};

use anyhow::Context;
use mrtmap_geometry::sampling::DirectionSet;
use mrtmap_io::{Recording, Trajectory, read_cloud_ply, write_atomic, write_cloud_ply};
use mrtmap_radiation::{GridSpec, Method, MonteCarlo, RadiantScene};
use mrtmap_report::ReportMap;
use mrtmap_scan::segment::{MaskInput, SegmentParams, SegmentReport, refined_poses, segment};
use mrtmap_scan::{FuseParams, FusionReport, fuse};
use serde::{Deserialize, Serialize};
use serde_json::json;

use crate::maps::{Summary, make_map};
use crate::output::json;
use crate::project::Project;

/// A stage's fingerprint and outcome.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct StageFile {
    fingerprint: serde_json::Value,
    secs: f64,
}

fn file_stamp(p: &Path) -> serde_json::Value {
    match std::fs::metadata(p) {
        Ok(m) => json!({
            "path": p.display().to_string(),
            "bytes": m.len(),
            "modified_ns": m.modified().ok().and_then(|t| t.duration_since(UNIX_EPOCH).ok()).map(|d| d.as_nanos() as u64),
        }),
        Err(_) => json!({ "path": p.display().to_string(), "missing": true }),
    }
}

/// What one stage did.
#[derive(Clone, Debug, Serialize)]
pub struct StageOutcome {
    /// Stage name.
    pub stage: String,
    /// Skipped (inputs unchanged).
    pub skipped: bool,
    /// Seconds (of the run that produced the outputs).
    pub secs: f64,
}

/// Runs `work` unless `dir/stage.json` holds `fingerprint` and every `outputs` exists.
fn stage(
    name: &str,
    dir: &Path,
    fingerprint: serde_json::Value,
    outputs: &[&str],
    force: bool,
    work: impl FnOnce() -> anyhow::Result<()>,
) -> anyhow::Result<StageOutcome> {
    let file = dir.join("stage.json");
    if !force
        && let Ok(text) = std::fs::read_to_string(&file)
        && let Ok(old) = serde_json::from_str::<StageFile>(&text)
        && old.fingerprint == fingerprint
        && outputs.iter().all(|o| dir.join(o).exists())
    {
        return Ok(StageOutcome {
            stage: name.into(),
            skipped: true,
            secs: old.secs,
        });
    }
    let _ = std::fs::remove_file(&file);
    let t0 = Instant::now();
    work()?;
    let secs = t0.elapsed().as_secs_f64();
    write_atomic(&file, json(&StageFile { fingerprint, secs })?.as_bytes())?;
    Ok(StageOutcome {
        stage: name.into(),
        skipped: false,
        secs,
    })
}

/// The method of the project.
pub fn project_method(p: &Project) -> anyhow::Result<Method> {
    let mc = MonteCarlo {
        rays: p.mrt.rays,
        seed: p.mrt.seed,
        directions: DirectionSet::Fibonacci,
        replicates: 8,
    };
    Ok(match p.mrt.method.as_str() {
        "auto" => Method::Auto(mc),
        "exact" => Method::Exact,
        "montecarlo" => Method::MonteCarlo(mc),
        other => anyhow::bail!("[mrt] method = '{other}' is not auto, exact or montecarlo"),
    })
}

/// The outcome of a run.
pub struct RunOutcome {
    /// Stages.
    pub stages: Vec<StageOutcome>,
    /// The scene.
    pub scene: RadiantScene,
    /// Fusion's report.
    pub fusion: FusionReport,
    /// Segmentation's report.
    pub segment: SegmentReport,
    /// Maps, by height.
    pub maps: Vec<(Summary, ReportMap)>,
    /// Warnings gathered.
    pub warnings: Vec<String>,
}

/// Runs the pipeline on `recording` into `out`.
pub fn run_pipeline(
    recording: &Path,
    out: &Path,
    p: &Project,
    force: bool,
    progress: &(dyn Fn(&str, u64, u64) + Sync),
) -> anyhow::Result<RunOutcome> {
    let rec = Recording::open(recording)?;
    let mut warnings: Vec<String> = rec
        .warnings
        .iter()
        .map(|w| format!("recording: {w}"))
        .collect();
    let mut stages = Vec::new();
    if !(p.fuse.voxel_m > 0.001 && p.fuse.voxel_m <= 1.0) {
        anyhow::bail!("[fuse] voxel_m = {} is outside 0.001…1 m", p.fuse.voxel_m);
    }
    // Fuse.
    let fuse_dir = out.join("fuse");
    let mut fp = FuseParams {
        voxel_m: p.fuse.voxel_m,
        sync_tolerance_s: p.fuse.sync_tolerance_ms / 1000.0,
        ..FuseParams::default()
    };
    fp.icp.enabled = p.fuse.icp;
    fp.depth.stride = p.fuse.depth_stride.max(1);
    let lists: Vec<serde_json::Value> = ["rig.toml", "depth.txt", "thermal.txt", "trajectory.txt"]
        .iter()
        .map(|f| file_stamp(&recording.join(f)))
        .collect();
    stages.push(stage(
        "fuse",
        &fuse_dir,
        json!({ "inputs": lists, "params": p.fuse }),
        &["cloud.ply", "fusion.json", "poses.txt"],
        force,
        || {
            let fused = fuse(&rec, &fp, &|d, t| progress("fusing thermal frames", d, t));
            write_cloud_ply(
                &fuse_dir.join("cloud.ply"),
                &fused.cloud,
                &format!("mrtmap thermal cloud of {}", recording.display()),
                &[],
            )?;
            write_atomic(
                &fuse_dir.join("fusion.json"),
                json(&fused.report)?.as_bytes(),
            )?;
            let traj = Trajectory {
                stamps: fused.poses.iter().map(|x| x.0).collect(),
                poses: fused.poses.iter().map(|x| x.1).collect(),
            };
            write_atomic(
                &fuse_dir.join("poses.txt"),
                traj.to_tum("refined world_from_depth of the fused frames")
                    .as_bytes(),
            )?;
            Ok(())
        },
    )?);
    let fusion: FusionReport =
        serde_json::from_str(&std::fs::read_to_string(fuse_dir.join("fusion.json"))?)
            .context("fuse/fusion.json")?;
    for (why, n) in &fusion.skipped {
        warnings.push(format!("fusion skipped {n} thermal frames: {why}"));
    }
    // Segment.
    let seg_dir = out.join("segment");
    let use_masks = p.segment.masks && !rec.masks.is_empty();
    let inputs = [
        file_stamp(&fuse_dir.join("cloud.ply")),
        file_stamp(&fuse_dir.join("poses.txt")),
        if use_masks {
            file_stamp(&recording.join("masks.txt"))
        } else {
            json!(null)
        },
    ];
    stages.push(stage(
        "segment",
        &seg_dir,
        json!({ "inputs": inputs, "params": p.segment }),
        &["scene.json", "segment.json", "segments.ply"],
        force,
        || {
            progress("segmenting surfaces and features", 0, 1);
            let cloud = read_cloud_ply(&fuse_dir.join("cloud.ply"))?.cloud;
            let poses = Trajectory::read(&fuse_dir.join("poses.txt"))?;
            let params = SegmentParams {
                feature_threshold_k: p.segment.feature_threshold_k,
                feature_min_area_m2: p.segment.feature_min_area_m2,
                ..SegmentParams::default()
            };
            let pose_fn = refined_poses(&rec, &poses);
            let masks = use_masks.then_some(MaskInput {
                recording: &rec,
                world_from_depth: &pose_fn,
            });
            let seg =
                segment(&cloud, &poses.poses, masks.as_ref(), &params).with_context(|| {
                    format!("cannot segment {}", fuse_dir.join("cloud.ply").display())
                })?;
            write_atomic(
                &seg_dir.join("scene.json"),
                (seg.scene.to_json() + "\n").as_bytes(),
            )?;
            write_cloud_ply(
                &seg_dir.join("segments.ply"),
                &cloud,
                "mrtmap segments",
                &[
                    ("surface_id", &seg.surface_id),
                    ("feature_id", &seg.feature_id),
                ],
            )?;
            write_atomic(&seg_dir.join("segment.json"), json(&seg.report)?.as_bytes())?;
            Ok(())
        },
    )?);
    let segment_report: SegmentReport =
        serde_json::from_str(&std::fs::read_to_string(seg_dir.join("segment.json"))?)
            .context("segment/segment.json")?;
    warnings.extend(
        segment_report
            .warnings
            .iter()
            .map(|w| format!("segmentation: {w}")),
    );
    let scene_path = seg_dir.join("scene.json");
    let scene = RadiantScene::load(&scene_path)?;
    // Maps.
    let method = project_method(p)?;
    let marks: Vec<(String, Vec<f64>)> = p
        .points
        .iter()
        .map(|pt| (pt.name.clone(), pt.xyz.to_vec()))
        .collect();
    let mut maps = Vec::new();
    for &h in &p.map.heights_m {
        let dir = out.join(format!("map-{h:.2}m"));
        let spec = GridSpec {
            nx: p.map.grid[0],
            ny: p.map.grid[1],
            height_m: h,
            margin_m: p.map.margin_m,
        };
        // This map's own settings only: adding another height leaves it unchanged.
        let fpr = json!({ "inputs": [file_stamp(&scene_path)], "grid": p.map.grid, "margin_m": p.map.margin_m, "mrt": p.mrt, "points": p.points, "height": h });
        let mut made = None;
        stages.push(stage(
            &format!("map at {h:.2} m"),
            &dir,
            fpr,
            &["summary.json", "mrt_map.png", "mrt_grid.csv"],
            force,
            || {
                progress(&format!("mapping MRT at {h:.2} m"), 0, 1);
                made = Some(make_map(
                    &scene,
                    "the scanned room",
                    method,
                    spec,
                    &marks,
                    &dir,
                )?);
                Ok(())
            },
        )?);
        let summary: Summary = match made {
            Some(m) => m.summary,
            None => serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json"))?)?,
        };
        let png = std::fs::read(dir.join("mrt_map.png"))?;
        maps.push((
            summary.clone(),
            ReportMap {
                png,
                summary: summary.map,
                csv: format!("map-{h:.2}m/mrt_grid.csv"),
            },
        ));
    }
    Ok(RunOutcome {
        stages,
        scene,
        fusion,
        segment: segment_report,
        maps,
        warnings,
    })
}

/// The report's tables from a run.
pub fn report_data(
    o: &RunOutcome,
    title: &str,
    source: &str,
    p: &Project,
) -> mrtmap_report::ReportData {
    let s = &o.segment;
    mrtmap_report::ReportData {
        title: title.into(),
        source: source.into(),
        maps: o
            .maps
            .iter()
            .map(|(_, m)| ReportMap {
                png: m.png.clone(),
                summary: m.summary.clone(),
                csv: m.csv.clone(),
            })
            .collect(),
        points: o
            .maps
            .first()
            .map(|m| m.0.marks.clone())
            .unwrap_or_default(),
        surfaces: s
            .surfaces
            .iter()
            .map(|x| {
                [
                    x.id.clone(),
                    x.kind.as_str().to_string(),
                    x.temperature_c
                        .map_or("not observed".into(), |t| format!("{t:.2}")),
                    format!("{:.3}", x.temperature_std_k),
                    format!("{:.0} %", x.observed_fraction * 100.0),
                    format!("{:.2}", x.area_m2),
                ]
            })
            .collect(),
        features: s
            .features
            .iter()
            .map(|f| {
                let share = f
                    .votes
                    .as_ref()
                    .map(|v| format!(", {:.0} % of votes", v.share * 100.0))
                    .unwrap_or_default();
                [
                    f.id.clone(),
                    f.host.clone(),
                    format!("{} ({}{share})", f.label, f.label_source),
                    format!("{:.2}", f.temperature_c),
                    format!("{:+.2}", f.contrast_k),
                    format!("{:.2}", f.area_m2),
                ]
            })
            .collect(),
        furniture: s
            .furniture
            .iter()
            .map(|f| {
                [
                    f.id.clone(),
                    f.label.clone(),
                    format!(
                        "{:.2} × {:.2} × {:.2}",
                        f.size_m[0], f.size_m[1], f.size_m[2]
                    ),
                    format!("{:.2}", f.temperature_c),
                ]
            })
            .collect(),
        coverage: vec![
            (
                "thermal frames fused".into(),
                format!("{} of {}", o.fusion.used_frames, o.fusion.thermal_frames),
            ),
            ("voxels".into(), o.fusion.voxels.to_string()),
            (
                "ICP refinements accepted".into(),
                if o.fusion.icp.enabled {
                    format!(
                        "{} of {} (final correction {:.1} cm, {:.2}°)",
                        o.fusion.icp.accepted,
                        o.fusion.icp.attempted,
                        o.fusion.icp.final_correction_m * 100.0,
                        o.fusion.icp.final_correction_deg
                    )
                } else {
                    "off".into()
                },
            ),
            (
                "cloud points on no surface".into(),
                format!("{:.0} %", s.unassigned_fraction * 100.0),
            ),
            ("room height".into(), format!("{:.2} m", s.height_m)),
            (
                "largest MRT standard error on the map".into(),
                o.maps
                    .first()
                    .and_then(|m| m.0.map.field.as_ref())
                    .map_or("—".into(), |f| format!("{:.3} K", f.max_std_error_k)),
            ),
            (
                "what ± covers".into(),
                "view-factor sampling and the fused surface temperatures' random error; not the \
                 thermal camera's absolute accuracy (a common offset passes one to one into MRT), \
                 emissivity, or the room's geometry: check against a black globe (mrtmap validate)"
                    .into(),
            ),
        ],
        warnings: o.warnings.clone(),
        timing: o
            .stages
            .iter()
            .map(|st| {
                (
                    st.stage.clone(),
                    format!(
                        "{:.1}{}",
                        st.secs,
                        if st.skipped {
                            " (unchanged, reused)"
                        } else {
                            ""
                        }
                    ),
                )
            })
            .collect(),
        parameters: toml::to_string(p).unwrap_or_default(),
        ..Default::default()
    }
}
