//! The run's report: tables assembled from the stages' outcomes, `report.html` and `run.json`.

use std::path::Path;

use mrtmap_report::{ReportData, ReportMap};
use mrtmap_scan::FusionReport;
use mrtmap_scan::segment::SegmentReport;
use serde::Serialize;

use crate::cache::{StageOutcome, write_json};
use crate::error::Result;
use crate::run::RunOutcome;
use crate::settings::Project;

/// What ± covers, in words.
const WHAT_PLUS_MINUS_COVERS: &str = "view-factor sampling and the fused surface temperatures' random error; not the \
     thermal camera's absolute accuracy (a common offset passes one to one into MRT), \
     emissivity, or the room's geometry: check against a black globe (mrtmap validate)";

fn surface_rows(s: &SegmentReport) -> Vec<[String; 6]> {
    s.surfaces
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
        .collect()
}

fn feature_rows(s: &SegmentReport) -> Vec<[String; 6]> {
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
                format!("{:+.2}", f.contrast_k),
                format!("{:.2}", f.area_m2),
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
            format!("{} of {}", f.used_frames, f.thermal_frames),
        ),
        ("voxels".into(), f.voxels.to_string()),
        ("ICP refinements accepted".into(), icp_summary(f)),
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
                .map_or("—".into(), |f| format!("{:.3} K", f.max_std_error_k)),
        ),
        ("what ± covers".into(), WHAT_PLUS_MINUS_COVERS.into()),
    ]
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
        warnings: o.warnings.clone(),
        timing: timing_rows(&o.stages),
        parameters: p.to_toml(),
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

/// Writes `report.html` of `data` and `run.json` into `out`.
pub fn write_run_outputs(
    out: &Path,
    data: &ReportData,
    o: &RunOutcome,
    recording: &Path,
    p: &Project,
    seconds: f64,
) -> Result<()> {
    mrtmap_io::write_atomic(
        &out.join("report.html"),
        mrtmap_report::render_html(data).as_bytes(),
    )?;
    write_json(
        &out.join("run.json"),
        &RunFile {
            recording: recording.display().to_string(),
            stages: &o.stages,
            warnings: &o.warnings,
            seconds,
            project: p,
        },
    )
}
