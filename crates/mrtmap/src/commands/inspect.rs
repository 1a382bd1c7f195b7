//! `mrtmap inspect`: what a scan source holds and what a scan still lacks.

use mrtmap_pipeline::source::DbSummary;
use mrtmap_pipeline::source::{FolderSummary, Inspection, RosSummary, inspect};

use crate::cli::InspectArgs;
use crate::output::{json, print_missing, print_plan};

fn fmt_span(t0: f64, t1: f64) -> String {
    if t1 >= t0 {
        format!("{t0:.3} … {t1:.3} s ({:.2} s)", t1 - t0)
    } else {
        "—".into()
    }
}

pub fn run(a: &InspectArgs) -> anyhow::Result<()> {
    let what = inspect(&a.source, &a.src.options())?;
    if a.json {
        out!("{}", json(&what.to_json(&a.source))?);
        return Ok(());
    }
    match &what {
        Inspection::Folder(f) => print_folder(a, f),
        Inspection::Ros(r) => print_ros(a, r),
        Inspection::RtabMap { summary, missing } => {
            print_database(&a.source, summary);
            print_missing(missing);
        }
    }
    Ok(())
}

fn print_folder(a: &InspectArgs, f: &FolderSummary) {
    outln!("{}: recording folder", a.source.display());
    for s in &f.streams {
        outln!(
            "  {:<10} {:>6} {:>8.2} Hz  {}",
            s.name,
            s.count,
            s.rate_hz(),
            fmt_span(s.t0, s.t1)
        );
    }
    outln!(
        "  rig: depth {}×{}, thermal {}×{}{}",
        f.rig.depth.width,
        f.rig.depth.height,
        f.rig.thermal.width,
        f.rig.thermal.height,
        if f.rig.rgb.is_some() { ", colour" } else { "" }
    );
    for w in &f.warnings {
        outln!("  warning: {w}");
    }
}

fn print_ros(a: &InspectArgs, r: &RosSummary) {
    let s = &r.survey;
    outln!(
        "{}: {} ({} bytes){}",
        a.source.display(),
        r.describe(),
        r.bytes,
        if s.unfinished {
            ", cut or never closed"
        } else {
            ""
        }
    );
    let w = s.topics.keys().map(|k| k.len()).max().unwrap_or(5).max(5);
    outln!(
        "{:<w$}  {:<28} {:>6} {:>8}  {:<14} span",
        "topic",
        "type",
        "count",
        "rate Hz",
        "encoding"
    );
    for t in s.topics.values() {
        outln!(
            "{:<w$}  {:<28} {:>6} {:>8.2}  {:<14} {}{}",
            t.topic,
            t.datatype,
            t.count,
            t.rate_hz(),
            match t.size {
                Some((w, h)) if !t.encoding.is_empty() => format!("{} {w}×{h}", t.encoding),
                _ => t.encoding.clone(),
            },
            fmt_span(t.t0, t.t1),
            if t.undecodable > 0 {
                format!("  ({} do not decode)", t.undecodable)
            } else {
                String::new()
            }
        );
    }
    for tf in &s.static_tf {
        outln!("static transform {} → {}", tf.parent, tf.child);
    }
    print_plan(&r.plan);
}

fn print_database(path: &std::path::Path, s: &DbSummary) {
    outln!(
        "{}: RTAB-Map database, schema {}",
        path.display(),
        s.version
    );
    outln!(
        "  nodes {}  colour {}  depth {} ({} RVL)  span {:.3} … {:.3} s ({:.2} s)",
        s.nodes,
        s.images,
        s.depths,
        s.rvl,
        s.span.0,
        s.span.1,
        s.span.1 - s.span.0
    );
    if s.nodes > 1 && s.span.1 > s.span.0 {
        outln!(
            "  node rate {:.2} Hz",
            (s.nodes - 1) as f64 / (s.span.1 - s.span.0)
        );
    }
    outln!("  poses: {}", s.poses);
    for (name, n) in &s.links {
        outln!("  links: {n} {name}");
    }
    match &s.calibration {
        Some(c) => outln!(
            "  camera {}×{} fx {:.2} fy {:.2} cx {:.2} cy {:.2} (written by RTAB-Map {}.{}.{})",
            c.camera.width,
            c.camera.height,
            c.camera.fx,
            c.camera.fy,
            c.camera.cx,
            c.camera.cy,
            c.version[0],
            c.version[1],
            c.version[2]
        ),
        None => outln!("  camera: no calibration"),
    }
    for n in &s.notes {
        outln!("  note: {n}");
    }
}
