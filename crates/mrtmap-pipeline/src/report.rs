//! The run's report: tables assembled from the stages' outcomes, `report.html` and `run.json`.

use std::path::Path;

use mrtmap_report::numbers::{fixed, signed, uncertainty};
use mrtmap_report::view3d::GridLayer;
use mrtmap_report::{KeyValues, ReportData, ReportMap};
/// Numbers for people, and the ± parts and unseen patches in words (mrtmap-report's).
pub use mrtmap_report::{parts_line, unseen_line};
use mrtmap_scan::FusionReport;
use mrtmap_scan::segment::SegmentReport;
use serde::Serialize;

use crate::cache::{StageOutcome, write_json};
use crate::comfort::value_of;
use crate::error::Result;
use crate::layout::RunLayout;
use crate::run::{ComfortResult, RunOutcome};
use crate::settings::Project;

/// What ± covers, in words.
const WHAT_PLUS_MINUS_COVERS: &str = "five parts in quadrature: view-factor sampling, the fused surface \
     temperatures' random error, the point's placement relative to the surfaces (the MRT's gradient \
     times [mrt] placement_std_m), the areas the scan never saw (each unseen patch anywhere between \
     the temperatures seen around it) and the uncertainty of the temperatures' common level (the \
     references' fit, or the camera's stated accuracy: a common offset passes one to one into MRT); \
     not emissivity or the room's shape: check against a black globe (mrtmap validate)";

/// A surface temperature with its ± ("11.52 ± 0.3"), or a dash.
fn surface_cell(t: Option<f64>, std_k: Option<f64>) -> String {
    match t {
        Some(t) => format!("{t:.2} ± {}", uncertainty(std_k.unwrap_or(0.0), 2)),
        None => "—".into(),
    }
}

fn surface_rows(s: &SegmentReport) -> Vec<[String; 8]> {
    s.surfaces
        .iter()
        .map(|x| {
            [
                if s.inferred_walls.contains(&x.id) {
                    format!("{} (inferred: not seen, placed at the floor's edge)", x.id)
                } else {
                    x.id.clone()
                },
                x.kind.as_str().to_string(),
                x.temperature_c
                    .map_or("not observed".into(), |t| format!("{t:.2}")),
                format!("{:.3}", x.temperature_std_k),
                x.emissivity.map_or("—".into(), |e| format!("{e:.2}")),
                surface_cell(x.surface_temperature_c, x.surface_temperature_std_k),
                format!(
                    "{:.0} % ({:.0} % texturing only; {:.0} % unseen)",
                    x.observed_fraction * 100.0,
                    x.textured_fraction * 100.0,
                    (1.0 - x.observed_fraction).max(0.0) * 100.0
                ),
                format!("{:.2}", x.area_m2),
            ]
        })
        .collect()
}

fn feature_rows(s: &SegmentReport) -> Vec<[String; 8]> {
    s.features
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
                f.emissivity.map_or("—".into(), |e| format!("{e:.2}")),
                surface_cell(f.surface_temperature_c, f.surface_temperature_std_k),
                signed(f.contrast_k, 2),
                if f.completed_m2 > 0.0 {
                    format!(
                        "{:.2} (completed: {:.2} not seen)",
                        f.area_m2, f.completed_m2
                    )
                } else {
                    format!("{:.2}", f.area_m2)
                },
            ]
        })
        .collect()
}

fn furniture_rows(s: &SegmentReport) -> Vec<[String; 4]> {
    s.furniture
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
        .collect()
}

fn icp_summary(f: &FusionReport) -> String {
    if !f.icp.enabled {
        return "off".into();
    }
    format!(
        "{} of {} (final correction {:.1} cm, {:.2}°)",
        f.icp.accepted,
        f.icp.attempted,
        f.icp.final_correction_m * 100.0,
        f.icp.final_correction_deg
    )
}

fn coverage_rows(o: &RunOutcome) -> Vec<(String, String)> {
    let (f, s) = (&o.fusion, &o.segment);
    vec![
        (
            "thermal frames fused".into(),
            format!(
                "{} of {}{}",
                f.used_frames,
                f.thermal_frames,
                f.skipped
                    .iter()
                    .map(|(why, n)| format!("; {n} left out: {why}"))
                    .collect::<String>()
            ),
        ),
        ("thermal clock".into(), f.clock.describe()),
        (
            "poses dropped (jumped away from their neighbours' motion and back)".into(),
            format!(
                "{} of {}{}",
                f.pose_check.dropped,
                f.pose_check.poses,
                f.pose_check
                    .examples
                    .iter()
                    .map(|d| format!("; at {:.3} s, {:.2} m and {:.1}° off", d.t, d.off_m, d.off_deg))
                    .collect::<String>()
            ),
        ),
        (
            "depth frame per thermal frame within".into(),
            format!("{:.0} ms", f.sync_tolerance_used_s * 1000.0),
        ),
        ("voxels".into(), f.voxels.to_string()),
        ("ICP refinements accepted".into(), icp_summary(f)),
        (
            "thermal texturing on the room model".into(),
            s.texture.as_ref().map_or("off".into(), |t| {
                format!(
                    "{} frames cast, {} pixels used, {} hidden by something nearer than the model, {} texels the cloud left empty filled",
                    t.frames,
                    t.pixels_used,
                    t.pixels_occluded,
                    t.texels_filled.iter().sum::<usize>()
                )
            }),
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
                .and_then(|m| m.summary.map.field.as_ref())
                .map_or("—".into(), |f| {
                    format!("{} K", uncertainty(f.max_std_error_k, 3))
                }),
        ),
        (
            "its parts, the largest of each on the map".into(),
            o.maps
                .first()
                .and_then(|m| m.summary.map.field.as_ref())
                .map_or("—".into(), |f| {
                    parts_line(&f.max_std_error_parts, 3)
                }),
        ),
        (
            "unseen areas that matter most for the map".into(),
            o.maps
                .first()
                .and_then(|m| m.summary.map.field.as_ref())
                .map_or("—".into(), |f| {
                    if f.unseen_patches.is_empty() {
                        "none: every surface was seen where the map can see it".into()
                    } else {
                        f.unseen_patches
                            .iter()
                            .take(5)
                            .map(unseen_line)
                            .collect::<Vec<_>>()
                            .join("; ")
                    }
                }),
        ),
        ("what ± covers".into(), WHAT_PLUS_MINUS_COVERS.into()),
    ]
}

/// Each rastered surface drawn by what the scan saw of it, with its unseen share.
fn coverage_drawings(o: &RunOutcome) -> Vec<(String, String)> {
    o.scene
        .surfaces
        .iter()
        .filter_map(|s| {
            let r = &s.raster.as_ref()?.file;
            let on: usize = r.temperature_c.iter().filter(|t| t.is_some()).count();
            let unseen: usize = r.unseen.iter().map(|p| p.texels.len()).sum();
            Some((
                format!(
                    "{}: {:.0} % never seen",
                    s.id,
                    100.0 * unseen as f64 / on.max(1) as f64
                ),
                mrtmap_report::coverage_svg(r),
            ))
        })
        .collect()
}

/// The room frame in words, its corners and its walls (room frame, corner 1 first).
#[allow(clippy::type_complexity)]
fn room_rows(s: &SegmentReport) -> (String, Vec<[String; 3]>, Vec<[String; 4]>) {
    let c = &s.floor_corners;
    let n = c.len();
    if n < 3 {
        return (String::new(), Vec::new(), Vec::new());
    }
    let k = s.room.origin_corner;
    let how = if s.room.chosen {
        "chosen in the settings"
    } else {
        "the longest wall with the room on its left, seen from above"
    };
    let text = format!(
        "All coordinates (maps, points, grid CSV, scene.json) are in the room's own frame: the origin is floor corner {k} (marked on the maps), x runs along wall-{k} ({how}), y across the room, z up from the floor. Measure them with a tape from that corner. The room is {:.2} m high; the scan's own frame is kept in scene.json (world_from_room) for scan-frame input (--frame scan).",
        s.height_m
    );
    let corners = c
        .iter()
        .enumerate()
        .map(|(i, p)| [(i + 1).to_string(), fixed(p[0], 2), fixed(p[1], 2)])
        .collect();
    let walls = (0..n)
        .map(|i| {
            let (a, b) = (c[i], c[(i + 1) % n]);
            let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            [
                format!("wall-{}", i + 1),
                (i + 1).to_string(),
                ((i + 1) % n + 1).to_string(),
                format!("{len:.2}"),
            ]
        })
        .collect();
    (text, corners, walls)
}

/// The comfort section's rows: the person and model, category shares, the worst asymmetry; the
/// marked points' values; the maps.
#[allow(clippy::type_complexity)]
fn comfort_rows(
    c: &ComfortResult,
) -> (
    KeyValues,
    Vec<String>,
    Vec<Vec<String>>,
    Vec<(String, Vec<u8>, String)>,
) {
    let s = &c.summary;
    let pct = |x: f64| format!("{:.0} %", 100.0 * x);
    let mut rows: KeyValues = vec![
        (
            "person".into(),
            format!(
                "{}, {}; {:.1} met, {:.2} clo, {:.0} % relative humidity",
                s.comfort.posture.as_str(),
                s.comfort.facing().describe(),
                s.comfort.met,
                s.comfort.clo,
                s.comfort.relative_humidity_pct
            ),
        ),
        ("PMV/PPD model".into(), s.pmv_model.clone()),
        (
            "nodes".into(),
            format!(
                "{} computed, {} left out (inside furniture…)",
                s.nodes, s.skipped
            ),
        ),
    ];
    if let Some(sh) = s.pmv_category_share {
        rows.push((
            "floor by ISO 7730 PMV category".into(),
            format!(
                "A (|PMV| < 0.2) {}, B (< 0.5) {}, C (< 0.7) {}, outside C {}",
                pct(sh[0]),
                pct(sh[1]),
                pct(sh[2]),
                pct(sh[3])
            ),
        ));
    }
    if let Some(sh) = s.asymmetry_category_share {
        rows.push((
            "floor by radiant-asymmetry category (ISO 7730 Table A.4)".into(),
            format!(
                "A/B {}, C {}, outside C {}",
                pct(sh[0]),
                pct(sh[1]),
                pct(sh[2])
            ),
        ));
    }
    if let Some((a, xy)) = &s.worst_asymmetry {
        rows.push((
            "worst radiant asymmetry".into(),
            format!(
                "{:.2} K ({}) at ({}, {}): PD {:.1} %, category {}",
                a.worst.delta_k,
                asymmetry_words(a.worst.kind),
                fixed(xy[0], 2),
                fixed(xy[1], 2),
                a.worst.pd_pct,
                a.worst.category.as_str()
            ),
        ));
    }
    let columns: Vec<String> = s.quantities.iter().map(|q| q.name().to_string()).collect();
    let points = s
        .marks
        .iter()
        .map(|(name, p)| {
            let mut row = vec![name.clone()];
            row.extend(s.quantities.iter().map(|q| {
                value_of(p, *q).map_or("—".into(), |(v, e)| {
                    format!("{v:.2} ± {}", uncertainty(e, 2))
                })
            }));
            row
        })
        .collect();
    let maps = c
        .maps
        .iter()
        .map(|(q, title, png)| {
            (
                title.clone(),
                png.clone(),
                RunLayout::name_in_run(|r| r.comfort_csv(*q)),
            )
        })
        .collect();
    (rows, columns, points, maps)
}

fn asymmetry_words(k: mrtmap_physics::AsymmetryKind) -> &'static str {
    use mrtmap_physics::AsymmetryKind as K;
    match k {
        K::WarmCeiling => "warm ceiling",
        K::CoolCeiling => "cool ceiling",
        K::WarmWall => "warm wall",
        K::CoolWall => "cool wall",
    }
}

/// Without two readings at different temperatures the camera's gain is not known, and it
/// stretches every difference between places: how much, for the first map's range of MRT.
fn gain_row(l: &crate::level::Level, o: &RunOutcome) -> Option<(String, String)> {
    if l.basis == crate::level::LevelBasis::OffsetAndGain {
        return None;
    }
    let m = o.maps.first()?;
    let f = m.summary.map.field.as_ref()?;
    let span = f.max.mrt_c - f.min.mrt_c;
    Some((
        "differences between places".into(),
        format!(
            "rest on the camera's gain too, which only two readings at different temperatures reveal: each 1 % of gain error stretches the map's {span:.2} K of MRT range (at {:.2} m) by {:.3} K (a Lepton-class camera's gain may be a few percent off)",
            m.summary.map.height_m,
            span / 100.0
        ),
    ))
}

/// "What the temperatures rest on": the level and the self-calibration; the references table.
#[allow(clippy::type_complexity)]
fn level_rows(o: &RunOutcome) -> (KeyValues, Vec<[String; 7]>) {
    let mut rows: KeyValues = Vec::new();
    let mut refs = Vec::new();
    if let Some(l) = &o.level {
        let text = if l.basis == crate::level::LevelBasis::Camera {
            format!(
                "the thermal camera's own level: no usable reference reading, so its stated absolute accuracy (±{:.1} K) is part of every ± (add references.csv or [[references]] to fix it)",
                l.std_k
            )
        } else {
            format!(
                "{}: the camera read {} K at the scene's mean temperature, gain {:.3}; the level is known to ±{} K, part of every ±",
                l.basis,
                signed(l.offset_at_mean_k, 2),
                l.beta,
                uncertainty(l.std_k, 2)
            )
        };
        rows.push(("absolute level".into(), text));
        if let Some(row) = gain_row(l, o) {
            rows.push(row);
        }
        refs = l
            .references
            .iter()
            .map(|r| {
                [
                    r.label.clone(),
                    format!("{:.2}", r.reference_c),
                    format!("{:.2}", r.emissivity),
                    format!("{:.2}", r.radiant_c),
                    r.camera_c.map_or("not seen".into(), |c| format!("{c:.2}")),
                    r.residual_k.map_or("—".into(), |x| signed(x, 2)),
                    if r.used {
                        "yes".into()
                    } else {
                        r.note.clone().unwrap_or_else(|| "no".into())
                    },
                ]
            })
            .collect();
    }
    let r = &o.fusion.radiometric;
    if r.enabled {
        rows.push((
            "frames' self-calibration".into(),
            format!(
                "{} frames got their own offset ({} kept the previous one); offsets removed {}…{} K; vignetting {} K at the corners; residual against the map {:.3} → {:.3} K rms",
                r.frames_calibrated,
                r.frames_carried,
                signed(r.offset_range_k[0], 2),
                signed(r.offset_range_k[1], 2),
                signed(r.vignetting_k, 2),
                r.residual_rms_before_k,
                r.residual_rms_after_k
            ),
        ));
    } else {
        rows.push((
            "frames' self-calibration".into(),
            "off ([fuse] self_calibrate = false): each frame's offset and the vignetting stay in the temperatures".into(),
        ));
    }
    (rows, refs)
}

/// When (UTC), by which mrtmap version and by which command: "on 2026-12-01 15:50 UTC by
/// mrtmap 0.1.0: mrtmap run scan --out out".
pub fn provenance() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    let (hh, mm) = ((secs % 86_400) / 3600, (secs % 3600) / 60);
    let mut command: Vec<String> = std::env::args_os()
        .map(|a| {
            let a = a.to_string_lossy().into_owned();
            if a.contains(char::is_whitespace) {
                format!("'{a}'")
            } else {
                a
            }
        })
        .collect();
    if let Some(first) = command.first_mut()
        && let Some(name) = Path::new(first.as_str()).file_name()
    {
        *first = name.to_string_lossy().into_owned();
    }
    format!(
        "on {y:04}-{m:02}-{d:02} {hh:02}:{mm:02} UTC by mrtmap {}: {}",
        env!("CARGO_PKG_VERSION"),
        command.join(" ")
    )
}

/// The proleptic Gregorian date of a day count since 1970-01-01 (H. Hinnant's `civil_from_days`).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

/// Seconds per stage, saying which were reused.
pub fn timing_rows(stages: &[StageOutcome]) -> Vec<(String, String)> {
    stages
        .iter()
        .map(|st| {
            let reused = if st.skipped {
                " (unchanged, reused)"
            } else {
                ""
            };
            (st.stage.clone(), format!("{:.1}{reused}", st.secs))
        })
        .collect()
}

/// The report's tables from a run.
pub fn report_data(o: &RunOutcome, title: &str, source: &str, p: &Project) -> ReportData {
    let (room_frame, corners, walls) = room_rows(&o.segment);
    let (comfort, comfort_point_columns, comfort_points, comfort_maps) =
        o.comfort.as_ref().map(comfort_rows).unwrap_or_default();
    let (level, references) = level_rows(o);
    ReportData {
        title: title.into(),
        source: source.into(),
        maps: o
            .maps
            .iter()
            .map(|m| ReportMap {
                png: m.png.clone(),
                summary: m.summary.map.clone(),
                csv: m.csv.clone(),
            })
            .collect(),
        points: o
            .maps
            .first()
            .map(|m| m.summary.marks.clone())
            .unwrap_or_default(),
        surfaces: surface_rows(&o.segment),
        features: feature_rows(&o.segment),
        furniture: furniture_rows(&o.segment),
        coverage: coverage_rows(o),
        coverage_drawings: coverage_drawings(o),
        warnings: o.warnings.clone(),
        timing: timing_rows(&o.stages),
        parameters: p.to_toml(),
        made: provenance(),
        room_frame,
        corners,
        walls,
        comfort,
        comfort_point_columns,
        comfort_points,
        comfort_maps,
        level,
        references,
        ..Default::default()
    }
}

/// run.json.
#[derive(Serialize)]
struct RunFile<'a> {
    recording: String,
    stages: &'a [StageOutcome],
    warnings: &'a [String],
    seconds: f64,
    project: &'a Project,
}

/// Writes `report.html` of `data`, the exports `[export]` asks for (with the run's `cloud`) and
/// `run.json` into `out`.
pub fn write_run_outputs(
    out: &Path,
    data: &ReportData,
    o: &RunOutcome,
    recording: &Path,
    p: &Project,
    seconds: f64,
    cloud: Option<&crate::export::CloudPoints>,
) -> Result<Vec<crate::export::ExportDone>> {
    let layout = RunLayout::new(out);
    mrtmap_io::write_atomic(
        &layout.report_html(),
        mrtmap_report::render_html(data).as_bytes(),
    )?;
    let exports = crate::export::export_run(out, &o.scene, &p.export, cloud)?;
    write_json(
        &layout.run_json(),
        &RunFile {
            recording: recording.display().to_string(),
            stages: &o.stages,
            warnings: &o.warnings,
            seconds,
            project: p,
        },
    )?;
    Ok(exports)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn civil_dates_from_day_counts() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(59), (1970, 3, 1));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(20_788), (2026, 12, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
    }

    #[test]
    fn provenance_names_the_version_and_date() {
        let p = provenance();
        assert!(p.starts_with("on 20"), "{p}");
        assert!(p.contains(" UTC by mrtmap "), "{p}");
    }
}

/// What [`run_recording`] did: the recording used (converted or not), the run's outcome and its
/// seconds.
#[derive(Clone, Debug)]
pub struct RunDone {
    /// The recording folder and what converting the source into it did.
    pub prepared: crate::source::Prepared,
    /// The run.
    pub outcome: RunOutcome,
    /// Seconds, conversion included.
    pub secs: f64,
    /// The exports `[export]` asked for.
    pub exports: Vec<crate::export::ExportDone>,
}

impl RunDone {
    /// What `mrtmap run` prints: the conversion, where the run went, each stage, each map.
    pub fn lines(&self, recording: &Path, out: &Path) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(c) = &self.prepared.conversion {
            lines.extend(c.lines());
        } else if self.prepared.reused {
            lines.push(format!(
                "using {} (converted earlier from {})",
                self.prepared.dir.display(),
                recording.display()
            ));
        }
        lines.push(format!(
            "ran {} into {}",
            recording.display(),
            out.display()
        ));
        lines.extend(self.outcome.lines(out, self.secs));
        for e in &self.exports {
            lines.push(format!(
                "wrote {} ({}, {:.1} kB)",
                e.path.display(),
                e.format.as_str(),
                e.bytes as f64 / 1e3
            ));
        }
        lines
    }
}

/// The report's 3D view of a run in `out`: its scene, its thermal `cloud` (see
/// [`crate::export::run_cloud`]) and each map's grid (read back from its mrt_grid.csv); a grid
/// that cannot be read is left out of the view.
pub fn view3d_for_run(
    out: &Path,
    o: &RunOutcome,
    cloud: Option<&crate::export::CloudPoints>,
) -> mrtmap_report::view3d::View3d {
    let grids: Vec<GridLayer> = o
        .maps
        .iter()
        .filter_map(|m| {
            let nodes = crate::maps::read_grid_nodes(&out.join(&m.csv)).ok()?;
            Some(GridLayer {
                height_m: m.summary.map.height_m,
                nodes,
                u: m.summary.map.axes.u,
                v: m.summary.map.axes.v,
            })
        })
        .collect();
    mrtmap_report::view3d::view3d(
        &o.scene,
        cloud.map(|c| (c.positions.as_slice(), c.temperature_c.as_slice())),
        &grids,
        &globes_of_run(out),
        o.comfort
            .as_ref()
            .and_then(|c| c.summary.sunlit_patch.as_ref())
            .map(|p| mrtmap_report::view3d::PatchLayer {
                cells: p.cells.clone(),
                u: p.u,
                v: p.v,
                cell_m: p.cell_m,
            })
            .as_ref(),
    )
}

/// The black-globe readings `mrtmap validate` wrote into the run's folder (validation.json), when
/// they are newer than its scene (older ones compared another scene and are left out).
fn globes_of_run(out: &Path) -> Vec<mrtmap_report::view3d::ViewMark> {
    let layout = RunLayout::new(out);
    let file = layout.validation_json();
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let fresh = match (modified(&file), modified(&layout.scene_json())) {
        (Some(v), Some(s)) => v >= s,
        _ => false,
    };
    let rows: Vec<serde_json::Value> = if fresh {
        std::fs::read_to_string(&file)
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_default()
    } else {
        Vec::new()
    };
    rows.iter()
        .filter_map(|r| {
            let g = r.get("globe")?;
            let xyz: [f64; 3] = serde_json::from_value(g.get("xyz")?.clone()).ok()?;
            let label = g.get("label")?.as_str()?;
            let num = |k: &str| r.get(k).and_then(serde_json::Value::as_f64);
            let text = match (num("mrt_iso_c"), num("ours_c")) {
                (Some(t), Some(m)) => {
                    format!("globe {label}: {} °C (map {})", fixed(t, 2), fixed(m, 2))
                }
                (Some(t), None) => format!("globe {label}: {} °C", fixed(t, 2)),
                _ => format!("globe {label}"),
            };
            Some(mrtmap_report::view3d::ViewMark {
                text,
                xyz,
                kind: "globe",
            })
        })
        .collect()
}

/// `mrtmap run` in one call: `recording` (a folder, or a bag, MCAP file or RTAB-Map database
/// converted with `source` into `out/recording`) through every stage with `project` into `out`,
/// then report.html and run.json. `force` reruns stages whose inputs have not changed.
pub fn run_recording(
    recording: &Path,
    out: &Path,
    project: &Project,
    force: bool,
    source: &crate::source::SourceOptions,
    progress: &dyn crate::Progress,
) -> Result<RunDone> {
    project.check()?;
    project.check_heights_above_floor()?;
    crate::run::check_out_dir(out)?;
    let _lock = crate::lock::OutLock::take(out)?;
    mrtmap_io::claim_dir(out, &RunLayout::top_names(&project.map.heights_m))?;
    let t0 = std::time::Instant::now();
    let prepared = crate::source::prepare(recording, out, source)?;
    let outcome = crate::run::run(&prepared.dir, out, project, force, progress)?;
    if progress.stopped() {
        return Err(crate::Error::Stopped {
            stage: "the report",
        });
    }
    let data = report_data(
        &outcome,
        "Mean radiant temperature of a scanned room",
        &recording.display().to_string(),
        project,
    );
    let cloud = crate::export::run_cloud(out, &outcome.scene);
    let mut data = data;
    data.view3d = Some(view3d_for_run(out, &outcome, cloud.as_ref()));
    let secs = t0.elapsed().as_secs_f64();
    let exports = write_run_outputs(
        out,
        &data,
        &outcome,
        recording,
        project,
        secs,
        cloud.as_ref(),
    )?;
    Ok(RunDone {
        prepared,
        outcome,
        secs,
        exports,
    })
}
