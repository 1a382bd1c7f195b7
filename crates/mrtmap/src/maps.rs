//! Computing and writing a map (shared by `map`, `run` and `demo`).

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_radiation::{
    GridSpec, MapFrame, Method, MrtEngine, MrtField, PointRecord, RadiantScene,
};
use mrtmap_report::{MapAxes, MapInput, MapMark, MapSummary, grid_csv, render_png, render_svg};
use serde::{Deserialize, Serialize};

use crate::commands::describe_method;
use crate::output::{json, write_atomic};

/// summary.json of a map.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Summary {
    /// Where the scene came from.
    pub scene: String,
    /// The map.
    #[serde(flatten)]
    pub map: MapSummary,
    /// The marked points.
    pub marks: Vec<PointRecord>,
}

/// A map computed and written.
pub struct MapOutput {
    /// Its summary (also in summary.json).
    pub summary: Summary,
    /// The method described for people.
    pub method: String,
}

/// Computes the MRT map of `scene` on `spec` with `marks` (NAME with U,V map coordinates at the
/// map height, or X,Y,Z scene coordinates) and writes mrt_grid.csv, mrt_map.png, mrt_map.svg and
/// summary.json into `out`.
pub fn make_map(
    scene: &RadiantScene,
    source: &str,
    method: Method,
    spec: GridSpec,
    marks: &[(String, Vec<f64>)],
    out: &Path,
) -> anyhow::Result<MapOutput> {
    let engine = MrtEngine::new(scene, method)?;
    let frame = MapFrame::of_scene(scene).with_context(|| format!("cannot map {source}"))?;
    let t0 = Instant::now();
    let field = MrtField::compute(&engine, frame, spec)?;
    let secs = t0.elapsed().as_secs_f64();
    let mut map_marks = Vec::new();
    let mut records = Vec::new();
    for (k, (name, c)) in marks.iter().enumerate() {
        let p = if c.len() == 2 {
            field.frame.point(&Point2::new(c[0], c[1]), spec.height_m)
        } else {
            Point3::new(c[0], c[1], c[2])
        };
        let r = engine
            .at(&p, (spec.nx * spec.ny + k) as u64)
            .with_context(|| format!("cannot compute the MRT at mark {name}"))?;
        records.push(PointRecord::new(Some(name.clone()), &r, engine.patches()));
        map_marks.push(MapMark {
            name: name.clone(),
            uv: field.frame.uv(&p),
        });
    }
    let how = match method {
        Method::Auto(mc) if !scene.occluders.is_empty() => {
            format!(
                "Monte Carlo view factors ({} rays per point; the scene has {} occluder(s))",
                mc.rays,
                scene.occluders.len()
            )
        }
        _ => describe_method(&method, engine.ray_engine()),
    };
    let input = MapInput {
        field: &field,
        scene,
        marks: &map_marks,
        subtitle: format!("{source}; {}×{} grid, {how}", spec.nx, spec.ny),
    };
    let (rays, seed) = match method {
        Method::MonteCarlo(mc) | Method::Auto(mc) => (Some(mc.rays), Some(mc.seed)),
        Method::Exact => (None, None),
    };
    let summary = Summary {
        scene: source.to_string(),
        map: MapSummary {
            height_m: spec.height_m,
            grid: [spec.nx, spec.ny],
            margin_m: spec.margin_m,
            method: method.name().to_string(),
            rays,
            seed,
            axes: MapAxes::of(&field),
            field: field.summary(),
            compute_secs: secs,
        },
        marks: records,
    };
    let png = render_png(&input)?;
    write_atomic(&out.join("mrt_grid.csv"), grid_csv(&field).as_bytes())?;
    write_atomic(&out.join("mrt_map.png"), &png)?;
    write_atomic(&out.join("mrt_map.svg"), render_svg(&input)?.as_bytes())?;
    write_atomic(&out.join("summary.json"), json(&summary)?.as_bytes())?;
    Ok(MapOutput {
        summary,
        method: how,
    })
}
