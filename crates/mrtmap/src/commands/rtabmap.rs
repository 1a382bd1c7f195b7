//! RTAB-Map databases in `inspect` and `convert` (and so in `fuse` / `run`).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, bail};
use mrtmap_geometry::nalgebra::{Isometry3, Matrix6};
use mrtmap_io::layout_writer::LayoutWriter;
use mrtmap_io::ros_scan::{self, Container, SourceKind};
use mrtmap_io::rtabmap::{self, DbSummary};
use mrtmap_io::{Image16, Recording, RgbCamera, Rig, read_image16};
use serde_json::json;

use crate::cli::{InspectArgs, SourceArgs};
use crate::output::json;

fn print_summary(path: &Path, s: &DbSummary) {
    println!(
        "{}: RTAB-Map database, schema {}",
        path.display(),
        s.version
    );
    println!(
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
        println!(
            "  node rate {:.2} Hz",
            (s.nodes - 1) as f64 / (s.span.1 - s.span.0)
        );
    }
    println!("  poses: {}", s.poses);
    for (name, n) in &s.links {
        println!("  links: {n} {name}");
    }
    match &s.calibration {
        Some(c) => println!(
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
        None => println!("  camera: no calibration"),
    }
    for n in &s.notes {
        println!("  note: {n}");
    }
}

fn missing(s: &DbSummary, a: &SourceArgs) -> Vec<String> {
    let mut m = Vec::new();
    if s.calibration.is_none() {
        m.push("camera calibration (Data.calibration)".to_string());
    }
    if s.depths == 0 {
        m.push("depth images".into());
    }
    if a.thermal.is_none() {
        m.push("thermal frames: an RTAB-Map database holds none; give --thermal SRC (a bag/MCAP with a mono16 topic, a recording folder, or a folder of 16-bit images named by timestamp)".into());
    }
    if a.rig.is_none() {
        m.push(
            "the thermal camera and its pose on the rig: give --rig (from mrtmap calibrate)".into(),
        );
    }
    m
}

pub fn inspect(a: &InspectArgs) -> anyhow::Result<()> {
    let s = rtabmap::summarize(&a.source)?;
    let m = missing(&s, &a.src);
    if a.json {
        print!(
            "{}",
            json(&json!({
                "source": a.source.display().to_string(),
                "kind": SourceKind::RtabMap,
                "database": s,
                "missing": m,
                "ready": m.is_empty(),
            }))?
        );
        return Ok(());
    }
    print_summary(&a.source, &s);
    if m.is_empty() {
        println!("ready: mrtmap convert / fuse / run can use it");
    } else {
        println!("missing for a scan:");
        for x in &m {
            println!("  - {x}");
        }
    }
    Ok(())
}

/// Stamp from a file stem: seconds, or nanoseconds / microseconds / milliseconds by magnitude.
fn stem_time(p: &Path) -> Option<f64> {
    let v: f64 = p.file_stem()?.to_str()?.parse().ok()?;
    Some(if v > 1e17 {
        v * 1e-9
    } else if v > 1e14 {
        v * 1e-6
    } else if v > 1e11 {
        v * 1e-3
    } else {
        v
    })
}

/// Node poses by id.
type Poses = BTreeMap<i64, Isometry3<f64>>;

/// Without saved optimised poses, the `Link` graph (odometry and loop closures) optimised here,
/// when it has loop closures: the poses and what was done, in words.
fn optimise_graph(source: &Path) -> anyhow::Result<(Option<Poses>, String)> {
    use mrtmap_scan::pose_graph::{Edge, optimise};
    let (odom, links, unread) = rtabmap::graph(source)?;
    for u in unread.iter().take(3) {
        println!("  graph: skipped {u}");
    }
    // Neighbour, loop-closure, user and merged links; virtual links, priors, landmarks and
    // gravity are not relative-pose constraints between two nodes.
    let edges: Vec<Edge> = links
        .iter()
        .filter(|l| matches!(l.kind, 0..=4 | 6))
        .filter(|l| odom.contains_key(&l.from) && odom.contains_key(&l.to))
        .map(|l| Edge {
            from: l.from,
            to: l.to,
            measured: l.transform,
            information: Matrix6::from_row_slice(&l.information),
        })
        .collect();
    let closures = links
        .iter()
        .filter(|l| rtabmap::is_loop_closure(l.kind))
        .count();
    if closures == 0 {
        return Ok((
            None,
            "odometry (Node.pose; no optimised poses saved, no loop closures to optimise)".into(),
        ));
    }
    let r = optimise(&odom, &edges)
        .map_err(|e| anyhow::anyhow!("{}: the Link graph: {e}", source.display()))?;
    let mut said = format!(
        "graph optimised here: {} nodes, {} links of which {closures} loop closures, weighted squared error {:.3e} → {:.3e}",
        r.poses.len(),
        r.edges,
        r.cost_before,
        r.cost_after
    );
    if r.identity_weighted > 0 {
        said += &format!(
            "; {} links without a usable information matrix weighted as identity",
            r.identity_weighted
        );
    }
    if r.poses.len() < odom.len() {
        said += &format!(
            "; {} nodes not linked to the first are left out",
            odom.len() - r.poses.len()
        );
    }
    Ok((Some(r.poses), said))
}

/// Thermal frames from another source.
fn thermal_frames(src: &Path, a: &SourceArgs) -> anyhow::Result<(String, Vec<(f64, Image16)>)> {
    match ros_scan::resolve_source(src) {
        Ok((SourceKind::Folder, _))
            if src.join("thermal.txt").is_file() && src.join("rig.toml").is_file() =>
        {
            let rec = Recording::open(src)?;
            let frames = rec
                .thermal
                .iter()
                .map(|e| Ok((e.t, rec.read_thermal(e)?)))
                .collect::<anyhow::Result<Vec<_>>>()?;
            Ok((format!("{} (thermal.txt)", src.display()), frames))
        }
        // A ROS 2 bag folder resolves to its one storage file (or stays a split bag's folder).
        Ok((k @ (SourceKind::Bag | SourceKind::Mcap | SourceKind::Db3), file)) => {
            let c = k.container().unwrap_or(Container::Bag);
            let (topic, frames) =
                ros_scan::image_frames(&file, c, file.as_path(), a.thermal_topic.as_deref())?;
            Ok((format!("{} {topic}", src.display()), frames))
        }
        Ok((SourceKind::Folder, _)) => {
            let mut files: Vec<_> = std::fs::read_dir(src)
                .with_context(|| format!("{}: cannot list", src.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    matches!(
                        p.extension()
                            .and_then(|e| e.to_str())
                            .map(str::to_ascii_lowercase)
                            .as_deref(),
                        Some("png" | "tif" | "tiff")
                    )
                })
                .collect();
            files.sort();
            let mut frames = Vec::new();
            for p in files {
                let t = stem_time(&p).with_context(|| {
                    format!("{}: the file name is not a timestamp", p.display())
                })?;
                frames.push((t, read_image16(&p)?));
            }
            Ok((
                format!("{} (images named by timestamp)", src.display()),
                frames,
            ))
        }
        Ok((SourceKind::RtabMap, _)) => bail!(
            "{}: an RTAB-Map database holds no thermal frames",
            src.display()
        ),
        Err(e) => Err(e.into()),
    }
}

pub fn convert(source: &Path, out: &Path, a: &SourceArgs) -> anyhow::Result<()> {
    let s = rtabmap::summarize(source)?;
    let m = missing(&s, a);
    if !m.is_empty() {
        bail!(
            "{}: cannot make a scan of it: {}",
            source.display(),
            m.join("; ")
        );
    }
    let (Some(cal), Some(thermal_src), Some(rig_path)) = (s.calibration, &a.thermal, &a.rig) else {
        bail!(
            "{}: calibration, --thermal and --rig are all needed",
            source.display()
        );
    };
    let given = Rig::read(rig_path)?;
    let (thermal_name, thermal) = thermal_frames(thermal_src, a)?;
    if thermal.is_empty() {
        bail!("{}: no thermal frames found", thermal_src.display());
    }
    for (t, img) in &thermal {
        if (img.width, img.height) != (given.thermal.width, given.thermal.height) {
            bail!(
                "{}: the thermal frame at {t:.3} s is {}×{} but the rig's thermal camera is {}×{}",
                thermal_src.display(),
                img.width,
                img.height,
                given.thermal.width,
                given.thermal.height
            );
        }
    }
    let mut w = LayoutWriter::create(
        out,
        &format!("converted by mrtmap from {}", source.display()),
    )?;
    let (graph, poses_said) = if s.optimised == 0 {
        optimise_graph(source)?
    } else {
        (None, s.poses.clone())
    };
    let mut depth_size = None;
    let mut err = None;
    let bad = rtabmap::for_each_node(source, graph.as_ref(), &mut |n| {
        let world_from_cam = n.pose * cal.local;
        w.pose(n.stamp, world_from_cam);
        if let Some(d) = &n.depth {
            match depth_size {
                None => depth_size = Some((d.width, d.height)),
                Some(sz) if sz != (d.width, d.height) => {
                    err.get_or_insert(format!(
                        "node {}: depth is {}×{}, earlier ones {}×{}",
                        n.id, d.width, d.height, sz.0, sz.1
                    ));
                    return Ok(());
                }
                _ => {}
            }
            w.depth(n.stamp, d)?;
        }
        if let Some(img) = &n.image {
            let ext = if img.starts_with(b"\x89PNG") {
                "png"
            } else {
                "jpg"
            };
            w.rgb(n.stamp, img, ext)?;
        }
        Ok(())
    })?;
    if let Some(e) = err {
        bail!("{}: {e}", source.display());
    }
    for (t, img) in &thermal {
        w.thermal(*t, img)?;
    }
    let (dw, dh) = depth_size.unwrap_or((cal.camera.width, cal.camera.height));
    // Depth is registered to the colour camera; RTAB-Map may store it decimated.
    let sx = dw as f64 / cal.camera.width as f64;
    let sy = dh as f64 / cal.camera.height as f64;
    let mut depth_cam = cal.camera;
    depth_cam.width = dw;
    depth_cam.height = dh;
    depth_cam.fx *= sx;
    depth_cam.cx = (cal.camera.cx + 0.5) * sx - 0.5;
    depth_cam.fy *= sy;
    depth_cam.cy = (cal.camera.cy + 0.5) * sy - 0.5;
    let rig = Rig {
        depth: depth_cam,
        depth_scale: a.depth_scale.unwrap_or(1000.0),
        thermal: given.thermal,
        thermal_encoding: given.thermal_encoding,
        depth_from_thermal: given.depth_from_thermal,
        rgb: Some(RgbCamera {
            camera: cal.camera,
            depth_from_rgb: ros_scan::identity(),
        }),
    };
    let (nd, nt, nc, np) = w.counts();
    let source_json = json(&json!({
        "format": "mrtmap-source/1",
        "source": source.display().to_string(),
        "container": "rtabmap",
        "database": s,
        "poses": poses_said,
        "thermal": thermal_name,
        "rig": rig_path.display().to_string(),
        "skipped_nodes": bad.iter().map(|(id, e)| format!("node {id}: {e}")).collect::<Vec<_>>(),
    }))?;
    w.finish(&rig, &source_json)?;
    println!(
        "wrote {}: {nd} depth, {nt} thermal ({thermal_name}), {nc} colour frames, {np} poses ({poses_said})",
        out.display(),
    );
    if !bad.is_empty() {
        println!("  skipped {} nodes:", bad.len());
        for (id, e) in bad.iter().take(5) {
            println!("    node {id}: {e}");
        }
    }
    Ok(())
}
