//! Exports of a measured room for the building trade's tools (`mrtmap export`, `[export]` in
//! project.toml), and Honeybee models read as scenes (`--scene model.hbjson --temperatures t.csv`).

use std::path::{Path, PathBuf};

use mrtmap_io::{read_cloud_ply, write_atomic};

pub use mrtmap_export::CloudPoints;
use mrtmap_export::{ImportError, gbxml, gltf, hbjson, radiance};
use mrtmap_radiation::RadiantScene;

use crate::layout::{FuseDir, RunLayout, SegmentDir};
pub(crate) use crate::settings::ExportSection;
pub use crate::settings::export::{DEFAULT_MAX_POINTS, ExportFormat};
use crate::{Error, Result};

/// What an export starts from.
#[derive(Clone, Debug)]
pub(crate) struct ExportInput {
    /// The scene.
    pub scene: RadiantScene,
    /// Where it came from, for people.
    pub source: String,
    /// The run's thermal cloud in the scene's frame, when the input was a run with one.
    pub cloud: Option<CloudPoints>,
    /// The name given to the room in the exports.
    pub name: String,
}

/// One file written by an export (`mrtmap export`, or a run's `[export]`).
#[derive(Clone, Debug, PartialEq)]
pub struct ExportDone {
    /// The format.
    pub format: ExportFormat,
    /// The file.
    pub path: PathBuf,
    /// Its size (bytes).
    pub bytes: usize,
}

fn import_error(path: &Path, e: ImportError) -> Error {
    match e {
        ImportError::Table { line, problem } => Error::Config {
            path: path.to_path_buf(),
            line,
            message: problem,
        },
        ImportError::Model { at, problem } => Error::source(path, format!("{at}: {problem}")),
        _ => Error::source(path, e.to_string()),
    }
}

/// Whether `path` names a Honeybee model (by its extension).
pub(crate) fn is_hbjson(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("hbjson"))
}

/// A Honeybee model's room as a scene, with temperatures from `temperatures` (a table by
/// identifier) or the model's own; `room` picks one of several rooms. The string says what was
/// read, for people.
pub(crate) fn load_hbjson(
    path: &Path,
    temperatures: Option<&Path>,
    room: Option<&str>,
) -> Result<(RadiantScene, String)> {
    let text = std::fs::read_to_string(path).map_err(|e| mrtmap_io::FileError::io(path, e))?;
    let table = match temperatures {
        Some(t) => {
            let tt = std::fs::read_to_string(t).map_err(|e| mrtmap_io::FileError::io(t, e))?;
            Some(hbjson::parse_temperatures(&tt).map_err(|e| import_error(t, e))?)
        }
        None => None,
    };
    let read = hbjson::read(&text, room, table.as_ref()).map_err(|e| match (&e, temperatures) {
        // A row of the table that names nothing in the model: the table's line.
        (ImportError::Table { .. }, Some(t)) => import_error(t, e),
        _ => import_error(path, e),
    })?;
    let scene = RadiantScene::new(&read.scene).map_err(|e| {
        Error::source(
            path,
            format!("room `{}` is not a valid radiant scene: {e}", read.room),
        )
    })?;
    let mut source = format!("{}, room {}", path.display(), read.room);
    if read.shades_left_out > 0 {
        source.push_str(&format!(
            " ({} indoor shades left out: furniture must be closed)",
            read.shades_left_out
        ));
    }
    Ok((scene, source))
}

fn thin(cloud: &CloudPoints, max_points: usize) -> CloudPoints {
    let keep = mrtmap_report::view3d::evenly_spaced(cloud.positions.len(), max_points);
    CloudPoints {
        positions: keep.iter().map(|&i| cloud.positions[i]).collect(),
        temperature_c: keep.iter().map(|&i| cloud.temperature_c[i]).collect(),
    }
}

/// A run's thermal cloud (`out/fuse/cloud.ply`) in its scene's frame, read once for the report's
/// 3D view and the exports; `None` when it cannot be read (they then go without it).
pub fn run_cloud(out: &Path, scene: &RadiantScene) -> Option<CloudPoints> {
    let run = RunLayout::new(out);
    cloud_in_scene(&run.cloud_ply(), scene, level_of(out).as_ref()).ok()
}

/// The temperatures' level a run or segmentation folder found (`segment/level.json` or
/// `level.json`), when there is one.
fn level_of(dir: &Path) -> Option<crate::level::Level> {
    [RunLayout::new(dir).level_json(), dir.join("level.json")]
        .iter()
        .find_map(|p| crate::cache::read_json(p).ok())
}

/// The thermal cloud at `ply` in `scene`'s frame (through its `world_from_room`), its
/// temperatures at `level` (the camera's raw level corrected as the scene's surfaces are: the
/// cloud and the surfaces then share one scale).
fn cloud_in_scene(
    ply: &Path,
    scene: &RadiantScene,
    level: Option<&crate::level::Level>,
) -> Result<CloudPoints> {
    let c = read_cloud_ply(ply)?.cloud;
    let room_from_world = scene.world_from_room.map(|w| w.inverse());
    let positions = c
        .positions
        .iter()
        .map(|p| {
            let q = mrtmap_geometry::nalgebra::Point3::new(
                f64::from(p[0]),
                f64::from(p[1]),
                f64::from(p[2]),
            );
            let r = room_from_world.map_or(q, |t| t * q);
            [r.x as f32, r.y as f32, r.z as f32]
        })
        .collect();
    let temperature_c = c
        .temperature_k
        .iter()
        .map(|t| {
            let camera_c = f64::from(t - 273.15);
            level.map_or(camera_c, |l| l.correct(camera_c)) as f32
        })
        .collect();
    Ok(CloudPoints {
        positions,
        temperature_c,
    })
}

/// Writes `scene` (named `name`) to `out` in `to`, or in the format `out`'s extension names:
/// the library call behind the Python binding's `Scene.export`.
pub fn export_scene(
    scene: &RadiantScene,
    name: &str,
    to: Option<ExportFormat>,
    out: &Path,
) -> Result<ExportDone> {
    let format = to.or_else(|| ExportFormat::from_path(out)).ok_or_else(|| {
        Error::setting(
            out.display().to_string(),
            "does not tell the format: name it .hbjson, .xml, .glb or .rad, or give the format",
        )
    })?;
    let input = ExportInput {
        scene: scene.clone(),
        source: name.to_string(),
        cloud: None,
        name: name.to_string(),
    };
    export(&input, format, out)
}

/// The built-in example office, to export.
pub(crate) fn example_for_export() -> ExportInput {
    ExportInput {
        scene: mrtmap_radiation::example_office(),
        source: "the built-in example office".into(),
        cloud: None,
        name: "example-office".into(),
    }
}

/// Opens what `mrtmap export` is given: a scene file (`scene.json`, or a Honeybee model with its
/// temperatures), a segmentation folder, or a run's output folder (its scene and thermal cloud).
pub(crate) fn open_for_export(
    path: &Path,
    src: &ExportSource,
    max_points: usize,
) -> Result<ExportInput> {
    let temperatures = src.temperatures.as_deref();
    let name = |p: &Path| {
        p.file_stem()
            .and_then(|s| s.to_str())
            .filter(|s| !s.is_empty() && *s != "scene")
            .unwrap_or("room")
            .to_string()
    };
    if path.is_dir() {
        let run = RunLayout::new(path);
        let scene_path = [run.scene_json(), SegmentDir::new(path).scene_json()]
            .into_iter()
            .find(|p| p.is_file())
            .ok_or_else(|| {
                Error::source(
                    path,
                    "has no scene.json (nor segment/scene.json): give a scene file, or the output folder of `mrtmap run` or `mrtmap segment`",
                )
            })?;
        let scene = RadiantScene::load(&scene_path)?;
        let ply = [run.cloud_ply(), FuseDir::new(path).cloud_ply()]
            .into_iter()
            .find(|p| p.is_file());
        let cloud = match ply {
            Some(p) => Some(thin(
                &cloud_in_scene(&p, &scene, level_of(path).as_ref())?,
                max_points,
            )),
            None => None,
        };
        let dir_name = path
            .canonicalize()
            .ok()
            .and_then(|p| p.file_name().and_then(|s| s.to_str()).map(str::to_string))
            .unwrap_or_else(|| "room".into());
        return Ok(ExportInput {
            scene,
            source: scene_path.display().to_string(),
            cloud,
            name: dir_name,
        });
    }
    let (scene, source) = if is_hbjson(path) {
        load_hbjson(path, temperatures, src.room.as_deref())?
    } else {
        if temperatures.is_some() || src.room.is_some() {
            return Err(Error::setting(
                "--temperatures and --room",
                format!(
                    "are for a Honeybee model (.hbjson); {} is a scene with its own temperatures",
                    path.display()
                ),
            ));
        }
        (RadiantScene::load(path)?, path.display().to_string())
    };
    Ok(ExportInput {
        scene,
        source,
        cloud: None,
        name: name(path),
    })
}

/// The bytes of `input` in `format`.
pub(crate) fn export_bytes(input: &ExportInput, format: ExportFormat) -> Vec<u8> {
    let s = &input.scene;
    match format {
        ExportFormat::Hbjson => hbjson::write(s, &input.name).into_bytes(),
        ExportFormat::Gbxml => gbxml::write(s, &input.name).into_bytes(),
        ExportFormat::Gltf => gltf::write(s, input.cloud.as_ref(), &input.name),
        ExportFormat::Rad => radiance::write(s, &input.name).into_bytes(),
    }
}

/// What `mrtmap export` reads (its positional argument, `--temperatures`, `--room`).
#[derive(Clone, Debug, Default, PartialEq, clap::Args)]
pub struct ExportSource {
    /// A scene file (scene.json, or a Honeybee model with --temperatures), a segmentation folder,
    /// or a run's output folder (its scene and, for glTF, its thermal cloud). Without it, the
    /// built-in example office.
    pub input: Option<PathBuf>,
    /// For a Honeybee model: its temperatures by identifier (CSV of `identifier,temperature_c`,
    /// optionally `temperature_std_k`, `emissivity`; a `*` row for the rest).
    #[arg(long, value_name = "CSV", requires = "input")]
    pub temperatures: Option<PathBuf>,
    /// For a Honeybee model with several rooms: the room's identifier.
    #[arg(long, value_name = "ID", requires = "input")]
    pub room: Option<String>,
}

/// `mrtmap export` in one call: `src` (a scene file, a Honeybee model with its temperatures, a
/// segmentation or run folder; no input: the built-in example office) written to `out` in `to`,
/// or in the format `out`'s extension names. Returns what it read and wrote, as lines for people.
pub fn export_file(
    src: &ExportSource,
    to: Option<ExportFormat>,
    out: &Path,
    max_points: usize,
) -> Result<Vec<String>> {
    // An extension that names another format than --to's would mislead whoever opens the file.
    if let (Some(to), Some(named)) = (to, ExportFormat::from_path(out))
        && to != named
    {
        return Err(Error::setting(
            format!("--to {} --out {}", to.as_str(), out.display()),
            format!(
                "disagree: the file's extension names {}; name it for {} or leave --to out",
                named.as_str(),
                to.as_str()
            ),
        ));
    }
    let Some(format) = to.or_else(|| ExportFormat::from_path(out)) else {
        return Err(Error::setting(
            format!("--out {}", out.display()),
            "does not tell the format: name it .hbjson, .xml, .glb or .rad, or give --to",
        ));
    };
    let input = match &src.input {
        Some(p) => open_for_export(p, src, max_points)?,
        None => example_for_export(),
    };
    let done = export(&input, format, out)?;
    let s = &input.scene;
    let mut what = format!(
        "{} surfaces, {} features, {} furniture",
        s.surfaces.len(),
        s.surfaces.iter().map(|x| x.features.len()).sum::<usize>(),
        s.occluders.len()
    );
    if let (Some(c), ExportFormat::Gltf) = (&input.cloud, format) {
        what.push_str(&format!(", {} cloud points", c.positions.len()));
    }
    Ok(vec![
        format!("scene: {}", input.source),
        what,
        format!(
            "wrote {} ({}, {:.1} kB)",
            done.path.display(),
            format.as_str(),
            done.bytes as f64 / 1e3
        ),
    ])
}

/// Writes `input` in `format` to `out` (atomically).
pub(crate) fn export(input: &ExportInput, format: ExportFormat, out: &Path) -> Result<ExportDone> {
    if out.is_dir() {
        return Err(Error::setting(
            out.display().to_string(),
            "is a folder: name the file to write in it (room.hbjson, room.xml, room.glb or room.rad)",
        ));
    }
    let bytes = export_bytes(input, format);
    write_atomic(out, &bytes)?;
    Ok(ExportDone {
        format,
        path: out.to_path_buf(),
        bytes: bytes.len(),
    })
}

/// The exports `[export]` asks of a run: `out/export/room.EXT`, with the run's `cloud` (see
/// [`run_cloud`]) in the glTF.
pub(crate) fn export_run(
    out: &Path,
    scene: &RadiantScene,
    section: &ExportSection,
    cloud: Option<&CloudPoints>,
) -> Result<Vec<ExportDone>> {
    if section.formats.is_empty() {
        return Ok(Vec::new());
    }
    let max_points = section.max_points.unwrap_or(DEFAULT_MAX_POINTS);
    let cloud = cloud
        .filter(|_| section.formats.contains(&ExportFormat::Gltf))
        .map(|c| thin(c, max_points));
    let input = ExportInput {
        scene: scene.clone(),
        source: out.display().to_string(),
        cloud,
        name: "room".into(),
    };
    let run = RunLayout::new(out);
    let dir = run.export_dir();
    std::fs::create_dir_all(&dir).map_err(|e| mrtmap_io::FileError::io(&dir, e))?;
    section
        .formats
        .iter()
        .map(|f| export(&input, *f, &run.export_file(*f)))
        .collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// Issue 54: the report's thermal cloud and the glTF's carried the camera's raw level (floor
    /// points 22.28 °C beside the floor surface's 20.36 °C on one colour scale): they are drawn
    /// and exported at the level the readings set, as the surfaces are.
    #[test]
    fn the_runs_cloud_is_at_the_corrected_level() {
        let dir = tempfile::tempdir().unwrap();
        let mut cloud = mrtmap_io::ThermalCloud::default();
        cloud.push([1.0, 1.0, 0.0], [0.0, 0.0, 1.0], 273.15 + 22.28, 0.1, 3);
        mrtmap_io::write_cloud_ply(&dir.path().join("fuse/cloud.ply"), &cloud, "t", &[]).unwrap();
        let scene = mrtmap_radiation::example_office();
        let raw = run_cloud(dir.path(), &scene).unwrap();
        assert!(
            (raw.temperature_c[0] - 22.28).abs() < 1e-3,
            "no level: as read"
        );
        let level = crate::level::Level {
            basis: crate::level::LevelBasis::Offset,
            alpha_c: 1.92,
            beta: 1.0,
            offset_at_mean_k: 1.92,
            std_k: 0.1,
            references: Vec::new(),
            warnings: Vec::new(),
        };
        crate::cache::write_json(&dir.path().join("segment/level.json"), &level).unwrap();
        let fixed = run_cloud(dir.path(), &scene).unwrap();
        assert!(
            (fixed.temperature_c[0] - 20.36).abs() < 1e-3,
            "{:?}",
            fixed.temperature_c
        );
    }
}
