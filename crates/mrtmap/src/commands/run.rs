//! `mrtmap run`: the whole pipeline on a recording.

use std::time::Instant;

use anyhow::bail;
use mrtmap_io::write_atomic;
use serde_json::json;

use crate::cli::{OnOff, RunArgs};
use crate::output::json;
use crate::pipeline::{RunOutcome, report_data, run_pipeline};
use crate::project::{PointEntry, Project};

/// The project from the file and the flags.
fn settings(a: &RunArgs) -> anyhow::Result<Project> {
    let mut p = match &a.config {
        Some(f) => Project::load(f)?,
        None => Project::default(),
    };
    if let Some((x, y)) = a.grid {
        p.map.grid = [x, y];
    }
    if !a.heights.is_empty() {
        p.map.heights_m = a.heights.clone();
    }
    if let Some(m) = a.margin_m {
        p.map.margin_m = m;
    }
    for (name, c) in &a.marks {
        if c.len() != 3 {
            bail!("--mark {name}: give X,Y,Z in the scan's frame");
        }
        p.points.retain(|q| &q.name != name);
        p.points.push(PointEntry {
            name: name.clone(),
            xyz: [c[0], c[1], c[2]],
        });
    }
    if let Some(v) = a.voxel_m {
        p.fuse.voxel_m = v;
    }
    if let Some(i) = a.icp {
        p.fuse.icp = i == OnOff::On;
    }
    if a.no_masks {
        p.segment.masks = false;
    }
    if let Some(t) = a.air_c {
        p.air.temperature_c = Some(t);
    }
    if p.map.heights_m.is_empty() || p.map.heights_m.iter().any(|h| !(h.is_finite() && *h > 0.0)) {
        bail!(
            "map heights must be positive numbers, got {:?}",
            p.map.heights_m
        );
    }
    Ok(p)
}

/// Prints the end-of-run summary.
pub(crate) fn print_summary(o: &RunOutcome, out: &std::path::Path, secs: f64) {
    for st in &o.stages {
        println!(
            "  {:<14} {:>7.1} s{}",
            st.stage,
            st.secs,
            if st.skipped {
                "  (inputs unchanged: reused)"
            } else {
                ""
            }
        );
    }
    for (s, _) in &o.maps {
        crate::commands::map::print_map(s);
    }
    for w in &o.warnings {
        println!("warning: {w}");
    }
    println!(
        "done in {secs:.1} s; report: {}",
        out.join("report.html").display()
    );
}

pub fn run(a: &RunArgs) -> anyhow::Result<()> {
    let p = settings(a)?;
    let t0 = Instant::now();
    let bar = crate::commands::fuse::progress_bar("");
    let recording = super::source::recording_dir(&a.recording, &a.out, &a.src)?;
    let outcome = run_pipeline(&recording, &a.out, &p, a.force, &|stage, done, total| {
        bar.set_message(stage.to_string());
        bar.set_length(total);
        bar.set_position(done);
    })?;
    bar.finish_and_clear();
    let data = report_data(
        &outcome,
        "Mean radiant temperature of a scanned room",
        &a.recording.display().to_string(),
        &p,
    );
    write_atomic(
        &a.out.join("report.html"),
        mrtmap_report::render_html(&data).as_bytes(),
    )?;
    let secs = t0.elapsed().as_secs_f64();
    write_atomic(
        &a.out.join("run.json"),
        json(&json!({ "recording": a.recording.display().to_string(), "stages": outcome.stages, "warnings": outcome.warnings, "seconds": secs, "project": p }))?.as_bytes(),
    )?;
    println!("ran {} into {}", a.recording.display(), a.out.display());
    print_summary(&outcome, &a.out, secs);
    Ok(())
}
