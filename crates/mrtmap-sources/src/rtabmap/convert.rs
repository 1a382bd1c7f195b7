//! RTAB-Map databases → the recording layout: poses (saved optimised ones, else the `Link` graph
//! optimised here when it has loop closures, else odometry), colour and depth per node, the
//! calibration blob's camera, thermal frames from another source and the thermal camera from a
//! rig.toml.

use std::collections::BTreeMap;
use std::path::Path;

use mrtmap_geometry::nalgebra::{Isometry3, Matrix6};
use mrtmap_geometry::pose_graph::{Edge, optimise};
use mrtmap_io::{Image16, LayoutWriter, Recording, RgbCamera, Rig, read_image16};

use crate::convert::{Conversion, ConvertError as Error, Result, SourceOptions};
use crate::ros::{self, Container};
use crate::rtabmap::{self, Calibration, DbSummary};
use crate::{SourceKind, resolve_source};

/// Pretty JSON with a trailing newline.
fn json_text<T: serde::Serialize>(value: &T) -> String {
    // Serialising plain data (maps with string keys, numbers, strings) cannot fail.
    serde_json::to_string_pretty(value).unwrap_or_default() + "\n"
}

/// What a scan needs besides the database.
pub fn missing(s: &DbSummary, o: &SourceOptions) -> Vec<String> {
    let mut m = Vec::new();
    if s.calibration.is_none() {
        m.push("camera calibration (Data.calibration)".to_string());
    }
    if s.depths == 0 {
        m.push("depth images".into());
    }
    if o.thermal.is_none() {
        m.push("thermal frames: an RTAB-Map database holds none; give --thermal SRC (a bag/MCAP with a mono16 topic, a recording folder, or a folder of 16-bit images named by timestamp)".into());
    }
    if o.rig.is_none() {
        m.push(
            "the thermal camera and its pose on the rig: give --rig (from mrtmap calibrate)".into(),
        );
    }
    m
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

/// Poses from the `Link` graph, and what was done in words.
struct GraphPoses {
    poses: Option<Poses>,
    said: String,
    notes: Vec<String>,
}

/// Without saved optimised poses, the `Link` graph (odometry and loop closures) optimised here
/// when it has loop closures.
fn optimise_graph(source: &Path) -> Result<GraphPoses> {
    let (odom, links, unread) = rtabmap::graph(source)?;
    let notes = unread
        .iter()
        .take(3)
        .map(|u| format!("graph: skipped {u}"))
        .collect();
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
        return Ok(GraphPoses {
            poses: None,
            said: "odometry (Node.pose; no optimised poses saved, no loop closures to optimise)"
                .into(),
            notes,
        });
    }
    let r = optimise(&odom, &edges)
        .map_err(|e| Error::source(source, format!("the Link graph: {e}")))?;
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
    Ok(GraphPoses {
        poses: Some(r.poses),
        said,
        notes,
    })
}

/// Thermal frames of another source: (where they came from, frames).
type ThermalFrames = (String, Vec<(f64, Image16)>);

/// A folder of 16-bit images named by timestamp.
fn image_folder(src: &Path) -> Result<ThermalFrames> {
    let mut files: Vec<_> = std::fs::read_dir(src)
        .map_err(|e| mrtmap_io::FileError::io(src, e))?
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
        let t =
            stem_time(&p).ok_or_else(|| Error::source(&p, "the file name is not a timestamp"))?;
        frames.push((t, read_image16(&p)?));
    }
    Ok((
        format!("{} (images named by timestamp)", src.display()),
        frames,
    ))
}

/// Thermal frames from another source: a recording folder, a bag / MCAP / ROS 2 bag, or a folder
/// of images named by timestamp.
fn thermal_frames(src: &Path, o: &SourceOptions) -> Result<ThermalFrames> {
    match resolve_source(src)? {
        (SourceKind::Folder, _)
            if mrtmap_io::RecordingFile::Thermal.path_in(src).is_file()
                && mrtmap_io::RecordingFile::Rig.path_in(src).is_file() =>
        {
            let rec = Recording::open(src)?;
            let frames = rec
                .thermal
                .iter()
                .map(|e| Ok((e.t, rec.read_thermal(e)?)))
                .collect::<Result<Vec<_>>>()?;
            Ok((format!("{} (thermal.txt)", src.display()), frames))
        }
        (SourceKind::Folder, _) => image_folder(src),
        // A ROS 2 bag folder resolves to its one storage file (or stays a split bag's folder).
        (k @ (SourceKind::Bag | SourceKind::Mcap | SourceKind::Db3), file) => {
            let c = k.container().unwrap_or(Container::Bag);
            let (topic, frames) =
                ros::image_frames(&file, c, file.as_path(), o.thermal_topic.as_deref())?;
            Ok((format!("{} {topic}", src.display()), frames))
        }
        (SourceKind::RtabMap, _) => Err(Error::source(
            src,
            "an RTAB-Map database holds no thermal frames",
        )),
    }
}

/// Checks that every thermal frame has the rig's thermal size.
fn check_thermal_sizes(src: &Path, frames: &[(f64, Image16)], rig: &Rig) -> Result<()> {
    if frames.is_empty() {
        return Err(Error::source(src, "no thermal frames found"));
    }
    for (t, img) in frames {
        if (img.width, img.height) != (rig.thermal.width, rig.thermal.height) {
            return Err(Error::source(
                src,
                format!(
                    "the thermal frame at {t:.3} s is {}×{} but the rig's thermal camera is {}×{}",
                    img.width, img.height, rig.thermal.width, rig.thermal.height
                ),
            ));
        }
    }
    Ok(())
}

/// The depth camera: registered to the colour camera, and maybe stored decimated.
fn depth_camera(
    cal: &Calibration,
    depth_size: Option<(u32, u32)>,
) -> mrtmap_geometry::camera::PinholeCamera {
    let (dw, dh) = depth_size.unwrap_or((cal.camera.width, cal.camera.height));
    let sx = dw as f64 / cal.camera.width as f64;
    let sy = dh as f64 / cal.camera.height as f64;
    let mut depth_cam = cal.camera;
    depth_cam.width = dw;
    depth_cam.height = dh;
    depth_cam.fx *= sx;
    depth_cam.cx = (cal.camera.cx + 0.5) * sx - 0.5;
    depth_cam.fy *= sy;
    depth_cam.cy = (cal.camera.cy + 0.5) * sy - 0.5;
    depth_cam
}

/// What [`write_nodes`] found.
struct NodesWritten {
    /// The depth images' size (all the same).
    depth_size: Option<(u32, u32)>,
    /// Nodes skipped, by id, and why.
    skipped: Vec<(i64, String)>,
}

/// Writes every node's pose, depth and colour.
fn write_nodes(
    source: &Path,
    graph: Option<&Poses>,
    cal: &Calibration,
    w: &mut LayoutWriter,
) -> Result<NodesWritten> {
    let mut depth_size = None;
    let mut err = None;
    let bad = rtabmap::for_each_node(source, graph, &mut |n| {
        w.pose(n.stamp, n.pose * cal.local);
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
    match err {
        Some(e) => Err(Error::source(source, e)),
        None => Ok(NodesWritten {
            depth_size,
            skipped: bad,
        }),
    }
}

/// Converts an RTAB-Map database with thermal frames from `o.thermal` and the rig `o.rig`.
pub fn convert(source: &Path, out: &Path, o: &SourceOptions) -> Result<Conversion> {
    let s = rtabmap::summarize(source)?;
    let m = missing(&s, o);
    let (Some(cal), Some(thermal_src), Some(rig_path), true) =
        (s.calibration, &o.thermal, &o.rig, m.is_empty())
    else {
        return Err(Error::NotAScan {
            path: source.to_path_buf(),
            missing: m,
        });
    };
    let given = Rig::read(rig_path)?;
    let (thermal_name, thermal) = thermal_frames(thermal_src, o)?;
    check_thermal_sizes(thermal_src, &thermal, &given)?;
    let mut w = LayoutWriter::create(
        out,
        &format!("converted by mrtmap from {}", source.display()),
    )?;
    let graph = if s.optimised == 0 {
        optimise_graph(source)?
    } else {
        GraphPoses {
            poses: None,
            said: s.poses.clone(),
            notes: Vec::new(),
        }
    };
    let nodes = write_nodes(source, graph.poses.as_ref(), &cal, &mut w)?;
    for (t, img) in &thermal {
        w.thermal(*t, img)?;
    }
    let rig = Rig {
        depth: depth_camera(&cal, nodes.depth_size),
        depth_scale: o.depth_scale.unwrap_or(1000.0),
        thermal: given.thermal,
        thermal_encoding: given.thermal_encoding,
        thermal_accuracy_k: given.thermal_accuracy_k,
        thermal_time_offset_s: given.thermal_time_offset_s,
        depth_from_thermal: given.depth_from_thermal,
        rgb: Some(RgbCamera {
            camera: cal.camera,
            depth_from_rgb: Isometry3::identity(),
        }),
    };
    let (depth, nt, rgb, poses) = w.counts();
    let skipped: Vec<String> = nodes
        .skipped
        .iter()
        .map(|(id, e)| format!("node {id}: {e}"))
        .collect();
    let source_json = json_text(&serde_json::json!({
        "format": "mrtmap-source/1",
        "source": source.display().to_string(),
        "container": "rtabmap",
        "database": s,
        "poses": graph.said,
        "thermal": thermal_name,
        "rig": rig_path.display().to_string(),
        "skipped_nodes": skipped,
    }));
    w.finish(&rig, &source_json)?;
    Ok(Conversion {
        out: out.to_path_buf(),
        depth,
        thermal: nt,
        rgb,
        poses,
        imu: 0,
        thermal_from: Some(thermal_name),
        poses_from: Some(graph.said),
        skipped: skipped.len(),
        skipped_unit: "nodes",
        skipped_reasons: skipped.into_iter().take(5).collect(),
        notes: graph.notes,
    })
}
