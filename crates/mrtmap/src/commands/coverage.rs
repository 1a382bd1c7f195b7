//! `mrtmap coverage`: is a scan good enough, and where to scan more.

use std::time::Instant;

use anyhow::bail;
use mrtmap_pipeline::Project;
use mrtmap_pipeline::coverage::{Coverage, coverage};
use mrtmap_pipeline::source::prepare;

use crate::cli::CoverageArgs;
use crate::output::Bar;

pub fn run(a: &CoverageArgs) -> anyhow::Result<()> {
    if !(a.target_k.is_finite() && a.target_k > 0.0 && a.target_k <= 10.0) {
        bail!(
            "--target-k {}: give the map's target as a positive number of kelvin (2σ), at most 10",
            a.target_k
        );
    }
    let p = match &a.config {
        Some(f) => Project::load(f)?,
        None => Project::default(),
    };
    p.check()?;
    let temp = match &a.out {
        Some(_) => None,
        None => Some(tempfile::tempdir()?),
    };
    let out = match (&a.out, &temp) {
        (Some(o), _) => o.clone(),
        (None, Some(t)) => t.path().join("coverage"),
        (None, None) => unreachable!("one of the two is set"),
    };
    mrtmap_pipeline::run::check_out_dir(&out)?;
    let t0 = Instant::now();
    let prepared = prepare(&a.recording, &out, &a.src)?;
    let bar = Bar::new("");
    let c = coverage(&prepared.dir, &out, &p, a.target_k, &bar)?;
    bar.finish();
    let secs = t0.elapsed().as_secs_f64();
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&c)?);
    } else {
        print(&c, secs);
    }
    Ok(())
}

fn print(c: &Coverage, secs: f64) {
    if c.surfaces.is_empty() {
        outln!(
            "not good enough for a ±{} K map (checked in {secs:.1} s):",
            c.target_k
        );
        for r in &c.reasons {
            outln!("  - {r}");
        }
        return;
    }
    outln!(
        "{:<10} {:>8} {:>16} {:>14} {:>8}",
        "surface",
        "area m²",
        "seen with depth",
        "textured only",
        "unseen"
    );
    for s in &c.surfaces {
        outln!(
            "{:<10} {:>8.1} {:>15.0} % {:>12.0} % {:>6.0} %{}",
            s.id,
            s.area_m2,
            100.0 * s.seen_with_depth,
            100.0 * s.textured_only,
            100.0 * s.unseen,
            if s.inferred { "  (never seen)" } else { "" }
        );
    }
    outln!(
        "{} of {} thermal frames fused; the temperatures' level rests on {} (±{:.2} K)",
        c.frames[0],
        c.frames[1],
        c.level_basis,
        c.level_std_k
    );
    outln!(
        "what the scan did not see: up to ±{:.2} K (2σ) on the map at 1.1 m",
        2.0 * c.max_unseen_k
    );
    if c.good_enough {
        outln!(
            "good enough for a ±{} K map (checked in {secs:.1} s)",
            c.target_k
        );
    } else {
        outln!(
            "not good enough for a ±{} K map (checked in {secs:.1} s):",
            c.target_k
        );
        for r in &c.reasons {
            outln!("  - {r}");
        }
    }
    for n in &c.notes {
        outln!("note: {n}");
    }
    if !c.look_at.is_empty() {
        outln!("where to point the camera, most important first:");
        for l in &c.look_at {
            outln!("  - {l}");
        }
    }
}
