//! A map against black-globe readings: `validation.csv` and `validation.json`.

use std::path::{Path, PathBuf};

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_radiation::{Method, MonteCarlo, MrtEngine, RadiantScene};
use mrtmap_report::{ValidationRow, parse_globe_csv, validate, validation_csv};

use crate::cache::write_json;
use crate::error::{Error, Result};
use crate::maps::to_scene_frame;
use crate::settings::PointFrame;

/// Rays per globe location: a standard error well below the globes' own.
const RAYS: usize = 200_000;

/// The validation of a map.
pub struct Validation {
    /// The scene the map came from.
    pub scene: PathBuf,
    /// One row per globe reading.
    pub rows: Vec<ValidationRow>,
}

/// The scene of a `run` output folder or of a folder holding scene.json.
fn scene_of(map: &Path) -> Result<PathBuf> {
    [map.join("scene.json"), map.join("segment").join("scene.json")]
        .into_iter()
        .find(|p| p.exists())
        .ok_or_else(|| {
            Error::source(
                map,
                "has no scene.json (nor segment/scene.json): give a `mrtmap run` output or a folder with scene.json",
            )
        })
}

/// Compares the MRT of the scene in `map` with the globe readings of `globe`, writing
/// validation.csv and validation.json into `out`.
pub fn validate_map(map: &Path, globe: &Path, frame: PointFrame, out: &Path) -> Result<Validation> {
    let scene_path = scene_of(map)?;
    let scene = RadiantScene::load(&scene_path)?;
    let text = std::fs::read_to_string(globe).map_err(|e| mrtmap_io::FileError::io(globe, e))?;
    let mut readings = parse_globe_csv(&text, &globe.display().to_string())?;
    let engine = MrtEngine::new(
        &scene,
        Method::Auto(MonteCarlo {
            rays: RAYS,
            ..MonteCarlo::default()
        }),
    )?;
    for r in &mut readings {
        let p = to_scene_frame(r.xyz, frame, &scene, &scene_path.display().to_string())?;
        engine.check_inside(&p).map_err(|e| Error::Config {
            path: globe.to_path_buf(),
            line: r.line as usize,
            message: format!(
                "reading '{}': {e}; give x, y, z in metres from the room's origin corner (the report's room coordinates){}",
                r.label,
                match frame {
                    PointFrame::Room => ", or in the scan's frame with --frame scan",
                    PointFrame::Scan => "",
                }
            ),
        })?;
        r.xyz = [p.x, p.y, p.z];
    }
    let ours = |x: &[f64; 3]| {
        engine
            .at(&Point3::from(*x), 0)
            .map(|r| (r.mrt.celsius(), r.std_error_k))
            .map_err(|e| e.to_string())
    };
    let rows = validate(&readings, &ours);
    mrtmap_io::write_atomic(
        &out.join("validation.csv"),
        validation_csv(&rows)?.as_bytes(),
    )?;
    write_json(&out.join("validation.json"), &rows)?;
    Ok(Validation {
        scene: scene_path,
        rows,
    })
}
