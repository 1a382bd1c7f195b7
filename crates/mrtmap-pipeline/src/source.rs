//! Scan sources: what a source holds ([`inspect`]), turning a bag, MCAP file, ROS 2 bag or RTAB-Map
//! database into the recording layout, or a recording folder into one of those ([`convert_any`]),
//! and the recording folder `fuse` and `run` read (`prepare`: the
//! source itself, or its conversion, reused while the source and options are unchanged).

use std::path::{Path, PathBuf};

use mrtmap_io::{FileError, Recording, Rig, StreamEntry};
/// What a source holds and how it is written (mrtmap-sources' types).
pub(crate) use mrtmap_sources::SourceKind;
use mrtmap_sources::resolve_source;
use mrtmap_sources::ros::Container;
pub use mrtmap_sources::ros::Plan;
pub(crate) use mrtmap_sources::ros::PoseSource;
pub use mrtmap_sources::ros::bag::Compression;
use mrtmap_sources::ros::{self, RosWriteOptions, Survey};
use mrtmap_sources::rtabmap;
pub(crate) use mrtmap_sources::rtabmap::DbSummary;
pub use mrtmap_sources::rtabmap::Schema;
use serde::Serialize;

use crate::cache::{Fingerprint, Stage, run_or_reuse};
pub use crate::conversion::{Conversion, SourceOptions};
use crate::error::{Error, Result};
use crate::layout::RunLayout;

/// One stream of a recording folder.
#[derive(Clone, Debug, Serialize)]
pub(crate) struct StreamSummary {
    /// "depth", "thermal", "rgb", "masks" or "trajectory".
    pub name: &'static str,
    /// Frames or poses.
    pub count: usize,
    /// First stamp (s).
    pub t0: f64,
    /// Last stamp (s); below `t0` when empty.
    pub t1: f64,
}

impl StreamSummary {
    fn of(name: &'static str, v: &[StreamEntry]) -> Self {
        let (t0, t1) = match (v.first(), v.last()) {
            (Some(f), Some(l)) => (f.t, l.t),
            _ => (0.0, -1.0),
        };
        Self {
            name,
            count: v.len(),
            t0,
            t1,
        }
    }

    /// Frames per second over the span.
    pub fn rate_hz(&self) -> f64 {
        if self.count > 1 && self.t1 > self.t0 {
            (self.count - 1) as f64 / (self.t1 - self.t0)
        } else {
            0.0
        }
    }
}

/// A recording folder at a glance.
#[derive(Clone, Debug)]
pub(crate) struct FolderSummary {
    /// Depth, thermal, colour, masks, trajectory.
    pub streams: Vec<StreamSummary>,
    /// The rig.
    pub rig: Rig,
    /// What the reader noticed.
    pub warnings: Vec<String>,
}

/// A bag, MCAP file or ROS 2 bag at a glance.
#[derive(Clone, Debug)]
pub(crate) struct RosSummary {
    /// The container.
    pub container: Container,
    /// A ROS 2 bag split over several files.
    pub split: bool,
    /// Bytes in the file (or the split files).
    pub bytes: u64,
    /// Topics, transforms.
    pub survey: Survey,
    /// The streams a scan would use, and what it lacks.
    pub plan: Plan,
}

impl RosSummary {
    /// The container in words.
    pub fn describe(&self) -> &'static str {
        match (self.container, self.split) {
            (Container::Bag, _) => "ROS 1 bag",
            (Container::Mcap, false) => "MCAP",
            (Container::Mcap, true) => "ROS 2 bag split over several MCAP files",
            (Container::Db3, false) => "ROS 2 bag (SQLite storage)",
            (Container::Db3, true) => "ROS 2 bag split over several SQLite files",
        }
    }
}

/// What a source holds, by kind.
#[derive(Clone, Debug)]
pub(crate) enum Inspected {
    /// A recording folder.
    Folder(FolderSummary),
    /// A ROS 1 bag, MCAP file or ROS 2 bag.
    Ros(Box<RosSummary>),
    /// An RTAB-Map database, and what a scan still needs besides it.
    RtabMap {
        /// The database.
        summary: DbSummary,
        /// What a scan lacks.
        missing: Vec<String>,
    },
}

impl Inspected {
    /// What `mrtmap inspect --json` prints: the source, its kind, what it holds and whether it
    /// is ready to be a scan.
    pub fn to_json(&self, source: &Path) -> serde_json::Value {
        let source = source.display().to_string();
        match self {
            Inspected::Folder(f) => serde_json::json!({
                "source": source,
                "kind": SourceKind::Folder,
                "streams": f.streams,
                "warnings": f.warnings,
                "ready": f.warnings.is_empty(),
            }),
            Inspected::Ros(r) => serde_json::json!({
                "source": source,
                "kind": match r.container {
                    Container::Bag => SourceKind::Bag,
                    Container::Mcap => SourceKind::Mcap,
                    Container::Db3 => SourceKind::Db3,
                },
                "topics": r.survey.topics.values().collect::<Vec<_>>(),
                "static_transforms": r.survey.static_tf.iter().map(|t| format!("{} → {}", t.parent, t.child)).collect::<Vec<_>>(),
                "plan": r.plan,
                "ready": r.plan.missing.is_empty() && r.plan.rig.is_some(),
            }),
            Inspected::RtabMap { summary, missing } => serde_json::json!({
                "source": source,
                "kind": SourceKind::RtabMap,
                "database": summary,
                "missing": missing,
                "ready": missing.is_empty(),
            }),
        }
    }
}

impl Inspected {
    /// What `mrtmap inspect` prints about `source`, in lines.
    pub fn lines(&self, source: &Path) -> Vec<String> {
        match self {
            Inspected::Folder(f) => folder_lines(source, f),
            Inspected::Ros(r) => ros_lines(source, r),
            Inspected::RtabMap { summary, missing } => {
                let mut lines = database_lines(source, summary);
                lines.extend(missing_lines(missing));
                lines
            }
        }
    }
}

/// A time span in words ("—" when empty).
fn fmt_span(t0: f64, t1: f64) -> String {
    if t1 >= t0 {
        format!("{t0:.3} … {t1:.3} s ({:.2} s)", t1 - t0)
    } else {
        "—".into()
    }
}

/// A recording folder's streams and rig, in lines.
fn folder_lines(source: &Path, f: &FolderSummary) -> Vec<String> {
    let mut lines = Vec::new();
    lines.push(format!("{}: recording folder", source.display()));
    for s in &f.streams {
        lines.push(format!(
            "  {:<10} {:>6} {:>8.2} Hz  {}",
            s.name,
            s.count,
            s.rate_hz(),
            fmt_span(s.t0, s.t1)
        ));
    }
    lines.push(format!(
        "  rig: depth {}×{}, thermal {}×{}{}",
        f.rig.depth.width,
        f.rig.depth.height,
        f.rig.thermal.width,
        f.rig.thermal.height,
        if f.rig.rgb.is_some() { ", colour" } else { "" }
    ));
    for w in &f.warnings {
        lines.push(format!("  warning: {w}"));
    }
    lines
}

/// A bag's topics and the plan for a scan, in lines.
fn ros_lines(source: &Path, r: &RosSummary) -> Vec<String> {
    let mut lines = Vec::new();
    let s = &r.survey;
    lines.push(format!(
        "{}: {} ({} bytes){}",
        source.display(),
        r.describe(),
        r.bytes,
        if s.unfinished {
            ", cut or never closed"
        } else {
            ""
        }
    ));
    let w = s.topics.keys().map(|k| k.len()).max().unwrap_or(5).max(5);
    lines.push(format!(
        "{:<w$}  {:<28} {:>6} {:>8}  {:<14} span",
        "topic", "type", "count", "rate Hz", "encoding"
    ));
    for t in s.topics.values() {
        lines.push(format!(
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
        ));
    }
    for tf in &s.static_tf {
        lines.push(format!("static transform {} → {}", tf.parent, tf.child));
    }
    lines.extend(plan_lines(&r.plan));
    lines
}

/// An RTAB-Map database's summary, in lines.
fn database_lines(path: &Path, s: &DbSummary) -> Vec<String> {
    let mut lines = Vec::new();
    lines.push(format!(
        "{}: RTAB-Map database, schema {}",
        path.display(),
        s.version
    ));
    lines.push(format!(
        "  nodes {}  colour {}  depth {} ({} RVL)  span {:.3} … {:.3} s ({:.2} s)",
        s.nodes,
        s.images,
        s.depths,
        s.rvl,
        s.span.0,
        s.span.1,
        s.span.1 - s.span.0
    ));
    if s.nodes > 1 && s.span.1 > s.span.0 {
        lines.push(format!(
            "  node rate {:.2} Hz",
            (s.nodes - 1) as f64 / (s.span.1 - s.span.0)
        ));
    }
    lines.push(format!("  poses: {}", s.poses));
    for (name, n) in &s.links {
        lines.push(format!("  links: {n} {name}"));
    }
    match &s.calibration {
        Some(c) => lines.push(format!(
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
        )),
        None => lines.push("  camera: no calibration".to_string()),
    }
    for n in &s.notes {
        lines.push(format!("  note: {n}"));
    }
    lines
}

/// The streams chosen for a scan and what is missing, in lines.
pub fn plan_lines(p: &Plan) -> Vec<String> {
    let mut lines = Vec::new();
    let show = |o: &Option<String>| o.clone().unwrap_or_else(|| "—".into());
    lines.push("for a scan:".to_string());
    lines.push(format!("  depth    {}", show(&p.depth)));
    lines.push(format!("  thermal  {}", show(&p.thermal)));
    lines.push(format!("  colour   {}", show(&p.rgb)));
    lines.push(format!(
        "  poses    {}",
        match &p.poses {
            Some(PoseSource::Topic(t)) => t.clone(),
            Some(PoseSource::Tf(a, b)) => format!("/tf {a} → {b}"),
            None => "—".into(),
        }
    ));
    for n in &p.notes {
        lines.push(format!("  note: {n}"));
    }
    lines.extend(missing_lines(&p.missing));
    lines
}

/// Whether a source is ready for a scan, or what it lacks, in lines.
pub(crate) fn missing_lines(missing: &[String]) -> Vec<String> {
    let mut lines = Vec::new();
    if missing.is_empty() {
        lines.push("ready: mrtmap convert / fuse / run can use it".to_string());
    } else {
        lines.push("missing for a scan:".to_string());
        for m in missing {
            lines.push(format!("  - {m}"));
        }
    }
    lines
}

/// Bytes in a source file, or in a split bag's storage files.
fn source_bytes(file: &Path, c: Container) -> Result<u64> {
    let files = if file.is_dir() {
        ros::storage_files(file, c).map_err(|e| e.in_file(file))?
    } else {
        vec![file.to_path_buf()]
    };
    files.iter().try_fold(0, |n, f| {
        Ok(n + std::fs::metadata(f).map_err(|e| FileError::io(f, e))?.len())
    })
}

/// What a source holds: its streams, counts and what a scan still lacks, as lines for people and
/// as JSON.
#[derive(Clone, Debug)]
pub struct Inspection(Inspected);

impl Inspection {
    /// What `mrtmap inspect --json` prints: the source, its kind, what it holds and whether it
    /// is ready to be a scan.
    pub fn to_json(&self, source: &Path) -> serde_json::Value {
        self.0.to_json(source)
    }

    /// What `mrtmap inspect` prints about `source`, in lines.
    pub fn lines(&self, source: &Path) -> Vec<String> {
        self.0.lines(source)
    }
}

/// Says what `source` holds (a recording folder, bag, MCAP file, ROS 2 bag or RTAB-Map database)
/// and whether it can be made into a scan.
pub fn inspect(source: &Path, o: &SourceOptions) -> Result<Inspection> {
    inspect_source(source, o).map(Inspection)
}

fn inspect_source(source: &Path, o: &SourceOptions) -> Result<Inspected> {
    let (kind, file) = resolve_source(source)?;
    match kind {
        SourceKind::Folder => {
            let rec = Recording::open(source)?;
            let traj = &rec.trajectory;
            let poses = StreamSummary {
                name: "trajectory",
                count: traj.len(),
                t0: traj.stamps.first().copied().unwrap_or(0.0),
                t1: traj.stamps.last().copied().unwrap_or(-1.0),
            };
            Ok(Inspected::Folder(FolderSummary {
                streams: vec![
                    StreamSummary::of("depth", &rec.depth),
                    StreamSummary::of("thermal", &rec.thermal),
                    StreamSummary::of("rgb", &rec.rgb),
                    StreamSummary::of("masks", &rec.masks),
                    poses,
                ],
                rig: rec.rig,
                warnings: rec.warnings.iter().map(ToString::to_string).collect(),
            }))
        }
        SourceKind::RtabMap => {
            let summary = rtabmap::summarize(source)?;
            let missing = rtabmap::convert::missing(&summary, o);
            Ok(Inspected::RtabMap { summary, missing })
        }
        SourceKind::Bag | SourceKind::Mcap | SourceKind::Db3 => {
            let c = container_of(kind);
            let bytes = source_bytes(&file, c)?;
            let survey = ros::survey(c, file.as_path()).map_err(|e| e.in_file(&file))?;
            let plan = ros::plan(&survey, &o.ros()?);
            Ok(Inspected::Ros(Box::new(RosSummary {
                container: c,
                split: file.is_dir(),
                bytes,
                survey,
                plan,
            })))
        }
    }
}

fn container_of(kind: SourceKind) -> Container {
    kind.container().unwrap_or(Container::Bag)
}

/// Converts `source` (a bag, MCAP file, ROS 2 bag or RTAB-Map database) into the recording layout
/// at `out`.
pub(crate) fn convert(source: &Path, out: &Path, o: &SourceOptions) -> Result<Conversion> {
    let (kind, file) = resolve_source(source)?;
    let source = file.as_path();
    match kind {
        SourceKind::Folder => Err(Error::source(
            source,
            "is already a recording folder (convert to a .bag, .mcap, .db3 or .db file by naming one as --out)",
        )),
        SourceKind::RtabMap => Ok(rtabmap::convert::convert(source, out, o)?),
        SourceKind::Bag | SourceKind::Mcap | SourceKind::Db3 => {
            let c = container_of(kind);
            let s = ros::survey(c, source).map_err(|e| e.in_file(source))?;
            let p = ros::plan(&s, &o.ros()?);
            if !p.missing.is_empty() || p.rig.is_none() {
                return Err(Error::NotAScan {
                    path: source.to_path_buf(),
                    missing: p.missing.clone(),
                    plan: Some(Box::new(p)),
                });
            }
            let rep = ros::export(source, source, &s, &p, out)?;
            Ok(Conversion {
                out: out.to_path_buf(),
                depth: rep.depth,
                thermal: rep.thermal,
                rgb: rep.rgb,
                poses: rep.poses,
                imu: rep.imu,
                skipped: rep.skipped,
                skipped_unit: "messages",
                skipped_reasons: rep.skipped_reasons,
                notes: p.notes,
                ..Conversion::default()
            })
        }
    }
}

/// `mrtmap convert`: `source` written as the container `out`'s extension names when it names one
/// (`.bag`, `.mcap`, `.db3` with `compression`; `.db`, an RTAB-Map-layout database with `schema`;
/// the source must then be a recording folder), else `source` (a bag, MCAP file, ROS 2 bag or
/// RTAB-Map database) converted into the recording folder `out`; gives what the CLI prints.
pub fn convert_any(
    source: &Path,
    out: &Path,
    compression: Compression,
    schema: Schema,
    o: &SourceOptions,
) -> Result<Vec<String>> {
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let what = match ext.as_str() {
        "db" => ContainerOut::RtabMap(schema),
        "bag" => ContainerOut::Ros(Container::Bag, compression),
        "mcap" => ContainerOut::Ros(Container::Mcap, compression),
        "db3" => ContainerOut::Ros(Container::Db3, compression),
        _ => return Ok(convert(source, out, o)?.lines()),
    };
    let w = write_container(source, out, what)?;
    let [d, t, c, p] = w.counts;
    Ok(vec![match (w.nodes, what) {
        (Some(n), ContainerOut::RtabMap(schema)) => {
            format!("wrote {} ({n} nodes, {schema:?} schema)", out.display())
        }
        _ => format!(
            "wrote {} ({} bytes): {d} depth, {t} thermal, {c} colour frames, {p} poses",
            out.display(),
            w.bytes.unwrap_or(0)
        ),
    }])
}

/// Containers a recording folder can be written as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ContainerOut {
    /// A RealSense-style ROS 1 bag, MCAP file or ROS 2 `.db3`.
    Ros(Container, Compression),
    /// An RTAB-Map-layout database.
    RtabMap(Schema),
}

/// What [`write_container`] wrote.
#[derive(Clone, Debug)]
pub(crate) struct Written {
    /// Bytes written (bags, MCAP, `.db3`).
    pub bytes: Option<usize>,
    /// Depth, thermal, colour frames and poses in the recording.
    pub counts: [usize; 4],
    /// Database nodes written (RTAB-Map).
    pub nodes: Option<usize>,
}

/// Writes the recording folder `recording` as `out` (a bag, MCAP file, `.db3` or database).
pub(crate) fn write_container(recording: &Path, out: &Path, what: ContainerOut) -> Result<Written> {
    let rec = Recording::open(recording).map_err(|e| {
        Error::source(
            out,
            format!("writing it needs a recording folder as the source: {e}"),
        )
    })?;
    let rgb = if rec.rig.rgb.is_some() {
        rec.rgb.len()
    } else {
        0
    };
    let counts = [
        rec.depth.len(),
        rec.thermal.len(),
        rgb,
        rec.trajectory.len(),
    ];
    match what {
        ContainerOut::RtabMap(schema) => {
            // SQLite writes in place: build beside the target and rename when complete.
            let tmp = out.with_extension("db.partial");
            let n = rtabmap::write_recording(&rec, &tmp, schema)?;
            std::fs::rename(&tmp, out).map_err(|e| FileError::io(out, e))?;
            Ok(Written {
                bytes: None,
                counts,
                nodes: Some(n),
            })
        }
        ContainerOut::Ros(container, compression) => {
            let o = RosWriteOptions::t265_like(container, compression);
            let bytes = ros::write_ros(&rec, &o)?;
            mrtmap_io::write_atomic(out, &bytes)?;
            Ok(Written {
                bytes: Some(bytes.len()),
                counts,
                nodes: None,
            })
        }
    }
}

/// The recording folder to fuse.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The folder.
    pub dir: PathBuf,
    /// What a conversion wrote (when it ran now).
    pub conversion: Option<Conversion>,
    /// The conversion of an earlier run was reused.
    pub reused: bool,
}

/// The recording folder for `fuse` / `run`: `source` itself when it is a folder, else
/// `out/recording`, converted now unless it already holds this source's conversion with these
/// options (the files the options name, a rig or thermal frames, count as inputs too).
pub(crate) fn prepare(source: &Path, out: &Path, o: &SourceOptions) -> Result<Prepared> {
    if resolve_source(source)?.0 == SourceKind::Folder {
        return Ok(Prepared {
            dir: source.to_path_buf(),
            conversion: None,
            reused: false,
        });
    }
    // `mrtmap fuse`'s folder takes the conversion where a run's folder does.
    let layout = RunLayout::new(out);
    let dir = layout.recording_dir();
    let stage = Stage {
        name: "convert".into(),
        stamp: layout.recording_stage_json(),
        outputs: vec![mrtmap_io::RecordingFile::Rig.path_in(&dir)],
    };
    let fingerprint = Fingerprint::new()
        .file(source)
        .maybe_file(o.rig.as_deref())
        .maybe_file(o.thermal.as_deref())
        .setting("options", o);
    let mut conversion = None;
    let outcome = run_or_reuse(&stage, fingerprint, false, || {
        conversion = Some(convert(source, &dir, o)?);
        Ok(())
    })?;
    Ok(Prepared {
        dir,
        conversion,
        reused: outcome.skipped,
    })
}
