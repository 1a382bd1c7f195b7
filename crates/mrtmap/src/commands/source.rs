//! `mrtmap inspect` and `mrtmap convert`, and turning any scan source into a recording folder for
//! `fuse` and `run`.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mrtmap_io::Rig;
use mrtmap_io::bag::Compression;
use mrtmap_io::ros_scan::{self, Container, RosOptions, RosWriteOptions, SourceKind};
use serde_json::json;

use crate::cli::{CompressionArg, ConvertArgs, InspectArgs, SchemaArg, SourceArgs};
use crate::output::{json, write_atomic};

fn ros_options(a: &SourceArgs) -> anyhow::Result<RosOptions> {
    if let Some(s) = a.depth_scale
        && !(s > 0.0 && s.is_finite())
    {
        bail!("--depth-scale {s} must be a positive number of raw units per metre");
    }
    Ok(RosOptions {
        depth_topic: a.depth_topic.clone(),
        thermal_topic: a.thermal_topic.clone(),
        rgb_topic: a.rgb_topic.clone(),
        pose_topic: a.pose_topic.clone(),
        depth_scale: a.depth_scale,
        rig: a.rig.as_deref().map(Rig::read).transpose()?,
    })
}

/// Bytes in a source file, or in a split bag's storage files.
fn source_bytes(file: &Path, c: Container) -> anyhow::Result<u64> {
    let files = if file.is_dir() {
        ros_scan::storage_files(file, c).map_err(|e| e.in_file(file))?
    } else {
        vec![file.to_path_buf()]
    };
    files.iter().try_fold(0, |n, f| {
        Ok(n + std::fs::metadata(f)
            .with_context(|| format!("{}: cannot read", f.display()))?
            .len())
    })
}

fn fmt_span(t0: f64, t1: f64) -> String {
    if t1 >= t0 {
        format!("{t0:.3} … {t1:.3} s ({:.2} s)", t1 - t0)
    } else {
        "—".into()
    }
}

pub fn inspect(a: &InspectArgs) -> anyhow::Result<()> {
    let (kind, file) = ros_scan::resolve_source(&a.source)?;
    match kind {
        SourceKind::Folder => inspect_folder(a),
        SourceKind::RtabMap => super::rtabmap::inspect(a),
        SourceKind::Bag | SourceKind::Mcap | SourceKind::Db3 => {
            let c = kind.container().unwrap_or(Container::Bag);
            let size = source_bytes(&file, c)?;
            let s = ros_scan::survey(c, file.as_path()).map_err(|e| e.in_file(&file))?;
            let p = ros_scan::plan(&s, &ros_options(&a.src)?);
            if a.json {
                print!(
                    "{}",
                    json(&json!({
                        "source": a.source.display().to_string(),
                        "kind": kind,
                        "topics": s.topics.values().collect::<Vec<_>>(),
                        "static_transforms": s.static_tf.iter().map(|t| format!("{} → {}", t.parent, t.child)).collect::<Vec<_>>(),
                        "plan": p,
                        "ready": p.missing.is_empty() && p.rig.is_some(),
                    }))?
                );
                return Ok(());
            }
            println!(
                "{}: {} ({} bytes){}",
                a.source.display(),
                match (c, file.is_dir()) {
                    (Container::Bag, _) => "ROS 1 bag",
                    (Container::Mcap, false) => "MCAP",
                    (Container::Mcap, true) => "ROS 2 bag split over several MCAP files",
                    (Container::Db3, false) => "ROS 2 bag (SQLite storage)",
                    (Container::Db3, true) => "ROS 2 bag split over several SQLite files",
                },
                size,
                if s.unfinished {
                    ", cut or never closed"
                } else {
                    ""
                }
            );
            let w = s.topics.keys().map(|k| k.len()).max().unwrap_or(5).max(5);
            println!(
                "{:<w$}  {:<28} {:>6} {:>8}  {:<14} span",
                "topic", "type", "count", "rate Hz", "encoding"
            );
            for t in s.topics.values() {
                println!(
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
                println!("static transform {} → {}", tf.parent, tf.child);
            }
            print_plan(&p);
            Ok(())
        }
    }
}

pub(crate) fn print_plan(p: &ros_scan::Plan) {
    let show = |o: &Option<String>| o.clone().unwrap_or_else(|| "—".into());
    println!("for a scan:");
    println!("  depth    {}", show(&p.depth));
    println!("  thermal  {}", show(&p.thermal));
    println!("  colour   {}", show(&p.rgb));
    println!(
        "  poses    {}",
        match &p.poses {
            Some(ros_scan::PoseSource::Topic(t)) => t.clone(),
            Some(ros_scan::PoseSource::Tf(a, b)) => format!("/tf {a} → {b}"),
            None => "—".into(),
        }
    );
    for n in &p.notes {
        println!("  note: {n}");
    }
    if p.missing.is_empty() {
        println!("ready: mrtmap convert / fuse / run can use it");
    } else {
        println!("missing for a scan:");
        for m in &p.missing {
            println!("  - {m}");
        }
    }
}

fn inspect_folder(a: &InspectArgs) -> anyhow::Result<()> {
    let rec = mrtmap_io::Recording::open(&a.source)?;
    let span = |v: &[mrtmap_io::StreamEntry]| match (v.first(), v.last()) {
        (Some(f), Some(l)) => (f.t, l.t),
        _ => (0.0, -1.0),
    };
    let streams = [
        ("depth", rec.depth.len(), span(&rec.depth)),
        ("thermal", rec.thermal.len(), span(&rec.thermal)),
        ("rgb", rec.rgb.len(), span(&rec.rgb)),
        ("masks", rec.masks.len(), span(&rec.masks)),
        (
            "trajectory",
            rec.trajectory.len(),
            (
                rec.trajectory.stamps.first().copied().unwrap_or(0.0),
                rec.trajectory.stamps.last().copied().unwrap_or(-1.0),
            ),
        ),
    ];
    if a.json {
        print!(
            "{}",
            json(&json!({
                "source": a.source.display().to_string(),
                "kind": SourceKind::Folder,
                "streams": streams.iter().map(|(n, c, (t0, t1))| json!({"name": n, "count": c, "t0": t0, "t1": t1})).collect::<Vec<_>>(),
                "warnings": rec.warnings,
                "ready": rec.warnings.is_empty(),
            }))?
        );
        return Ok(());
    }
    println!("{}: recording folder", a.source.display());
    for (n, c, (t0, t1)) in streams {
        let rate = if c > 1 && t1 > t0 {
            (c - 1) as f64 / (t1 - t0)
        } else {
            0.0
        };
        println!("  {n:<10} {c:>6} {rate:>8.2} Hz  {}", fmt_span(t0, t1));
    }
    println!(
        "  rig: depth {}×{}, thermal {}×{}{}",
        rec.rig.depth.width,
        rec.rig.depth.height,
        rec.rig.thermal.width,
        rec.rig.thermal.height,
        if rec.rig.rgb.is_some() {
            ", colour"
        } else {
            ""
        }
    );
    for w in &rec.warnings {
        println!("  warning: {w}");
    }
    Ok(())
}

/// Converts `source` into the recording layout at `out`; prints what it did.
pub(crate) fn to_layout(source: &Path, out: &Path, a: &SourceArgs) -> anyhow::Result<()> {
    let (kind, file) = ros_scan::resolve_source(source)?;
    let source = file.as_path();
    match kind {
        SourceKind::Folder => bail!(
            "{} is already a recording folder (convert to a .bag, .mcap, .db3 or .db file by naming one as --out)",
            source.display()
        ),
        SourceKind::RtabMap => super::rtabmap::convert(source, out, a),
        SourceKind::Bag | SourceKind::Mcap | SourceKind::Db3 => {
            let c = kind.container().unwrap_or(Container::Bag);
            let s = ros_scan::survey(c, source).map_err(|e| e.in_file(source))?;
            let p = ros_scan::plan(&s, &ros_options(a)?);
            if !p.missing.is_empty() || p.rig.is_none() {
                print_plan(&p);
                bail!(
                    "{}: cannot make a scan of it: {}",
                    source.display(),
                    p.missing.join("; ")
                );
            }
            let rep = ros_scan::export(source, source, &s, &p, out)?;
            println!(
                "wrote {}: {} depth, {} thermal, {} colour frames, {} poses{}",
                out.display(),
                rep.depth,
                rep.thermal,
                rep.rgb,
                rep.poses,
                if rep.skipped > 0 {
                    format!("; skipped {} messages", rep.skipped)
                } else {
                    String::new()
                }
            );
            for r in &rep.skipped_reasons {
                println!("  skipped: {r}");
            }
            for n in &p.notes {
                println!("  note: {n}");
            }
            Ok(())
        }
    }
}

pub fn convert(a: &ConvertArgs) -> anyhow::Result<()> {
    let ext = a
        .out
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "db" {
        let rec = mrtmap_io::Recording::open(&a.source).with_context(|| {
            format!(
                "writing {} needs a recording folder as the source",
                a.out.display()
            )
        })?;
        let schema = match a.schema {
            SchemaArg::Current => mrtmap_io::rtabmap::Schema::Current,
            SchemaArg::Legacy => mrtmap_io::rtabmap::Schema::Legacy,
        };
        // SQLite writes in place: build beside the target and rename when complete.
        let tmp = a.out.with_extension("db.partial");
        let n = mrtmap_io::rtabmap::write_recording(&rec, &tmp, schema)?;
        std::fs::rename(&tmp, &a.out)
            .with_context(|| format!("{}: cannot move into place", a.out.display()))?;
        println!("wrote {} ({n} nodes, {schema:?} schema)", a.out.display());
        return Ok(());
    }
    if matches!(ext.as_str(), "bag" | "mcap" | "db3") {
        let rec = mrtmap_io::Recording::open(&a.source).with_context(|| {
            format!(
                "writing {} needs a recording folder as the source",
                a.out.display()
            )
        })?;
        let o = RosWriteOptions::t265_like(
            match ext.as_str() {
                "bag" => Container::Bag,
                "mcap" => Container::Mcap,
                _ => Container::Db3,
            },
            match a.compression {
                CompressionArg::None => Compression::None,
                CompressionArg::Bz2 => Compression::Bz2,
                CompressionArg::Lz4 => Compression::Lz4,
            },
        );
        let bytes = ros_scan::write_ros(&rec, &o)?;
        write_atomic(&a.out, &bytes)?;
        println!(
            "wrote {} ({} bytes): {} depth, {} thermal, {} colour frames, {} poses",
            a.out.display(),
            bytes.len(),
            rec.depth.len(),
            rec.thermal.len(),
            if rec.rig.rgb.is_some() {
                rec.rgb.len()
            } else {
                0
            },
            rec.trajectory.len()
        );
        return Ok(());
    }
    to_layout(&a.source, &a.out, &a.src)
}

/// The recording folder for `fuse` / `run`: the source itself when it is a folder, else
/// `out/recording`, converted now unless it already holds this source's conversion.
pub(crate) fn recording_dir(source: &Path, out: &Path, a: &SourceArgs) -> anyhow::Result<PathBuf> {
    if ros_scan::source_kind(source)? == SourceKind::Folder {
        return Ok(source.to_path_buf());
    }
    let dir = out.join("recording");
    std::fs::metadata(source).with_context(|| format!("{}: cannot read", source.display()))?;
    // The source, the options, and the files the options name (a rig edited since, or new
    // thermal frames, mean converting again). A folder (a ROS 2 bag, thermal images) stands for
    // the files in it.
    let fingerprint = |p: &Path| -> Vec<(String, u64, Option<std::time::SystemTime>)> {
        let mut files = vec![p.to_path_buf()];
        if p.is_dir() {
            files = std::fs::read_dir(p)
                .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
                .unwrap_or_default();
            files.sort();
        }
        files
            .iter()
            .filter_map(|f| {
                let m = std::fs::metadata(f).ok()?;
                let name = f.file_name()?.to_string_lossy().into_owned();
                Some((name, m.len(), m.modified().ok()))
            })
            .collect()
    };
    let named = |p: &Option<PathBuf>| p.as_deref().map(fingerprint);
    let stamp = format!(
        "{} {:?} {:?} {:?} {:?}",
        source.display(),
        fingerprint(source),
        a,
        named(&a.rig),
        named(&a.thermal)
    );
    let stamp_path = out.join("recording.source");
    if dir.join("rig.toml").is_file()
        && std::fs::read_to_string(&stamp_path).ok().as_deref() == Some(stamp.as_str())
    {
        println!(
            "using {} (converted earlier from {})",
            dir.display(),
            source.display()
        );
        return Ok(dir);
    }
    to_layout(source, &dir, a)?;
    write_atomic(&stamp_path, stamp.as_bytes())?;
    Ok(dir)
}
