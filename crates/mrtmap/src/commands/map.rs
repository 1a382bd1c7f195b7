//! `mrtmap map`: MRT over a grid, written as CSV, PNG, SVG and JSON.

use std::time::Instant;

use anyhow::Context;
use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_radiation::{GridSpec, MapFrame, Method, MrtEngine, MrtField, PointRecord};
use mrtmap_report::{MapAxes, MapInput, MapMark, MapSummary, grid_csv, render_png, render_svg};
use serde::Serialize;

use super::{describe_method, load_scene, resolve_method};
use crate::cli::MapArgs;
use crate::output::{json, write_atomic};

#[derive(Serialize)]
struct Summary {
    scene: String,
    #[serde(flatten)]
    map: MapSummary,
    marks: Vec<PointRecord>,
}

pub fn run(a: &MapArgs) -> anyhow::Result<()> {
    let (scene, source) = load_scene(&a.scene)?;
    let method = resolve_method(&a.method, &scene)?;
    let engine = MrtEngine::new(&scene, method)?;
    let frame = MapFrame::of_scene(&scene).with_context(|| format!("cannot map {source}"))?;
    let spec = GridSpec {
        nx: a.grid.0,
        ny: a.grid.1,
        height_m: a.height,
        margin_m: a.margin_m,
    };
    let t0 = Instant::now();
    let field = MrtField::compute(&engine, frame, spec)?;
    let secs = t0.elapsed().as_secs_f64();

    // Marks: map coordinates at the map height, or scene points as given.
    let mut marks = Vec::new();
    let mut records = Vec::new();
    for (k, (name, c)) in a.marks.iter().enumerate() {
        let p = if c.len() == 2 {
            field.frame.point(&Point2::new(c[0], c[1]), a.height)
        } else {
            Point3::new(c[0], c[1], c[2])
        };
        let r = engine
            .at(&p, (a.grid.0 * a.grid.1 + k) as u64)
            .with_context(|| format!("cannot compute the MRT at mark {name}"))?;
        records.push(PointRecord::new(Some(name.clone()), &r, engine.patches()));
        marks.push(MapMark {
            name: name.clone(),
            uv: field.frame.uv(&p),
        });
    }

    let how = describe_method(&method, engine.ray_engine());
    let subtitle = format!("{source}; {}×{} grid, {how}", a.grid.0, a.grid.1);
    let input = MapInput {
        field: &field,
        scene: &scene,
        marks: &marks,
        subtitle,
    };
    let (rays, seed) = match method {
        Method::MonteCarlo(mc) | Method::Auto(mc) => (Some(mc.rays), Some(mc.seed)),
        Method::Exact => (None, None),
    };
    let summary = Summary {
        scene: source.clone(),
        map: MapSummary {
            height_m: a.height,
            grid: [a.grid.0, a.grid.1],
            margin_m: a.margin_m,
            method: method.name().to_string(),
            rays,
            seed,
            axes: MapAxes::of(&field),
            field: field.summary(),
            compute_secs: secs,
        },
        marks: records,
    };
    let out = &a.out;
    write_atomic(&out.join("mrt_grid.csv"), grid_csv(&field).as_bytes())?;
    write_atomic(&out.join("mrt_map.png"), &render_png(&input)?)?;
    write_atomic(&out.join("mrt_map.svg"), render_svg(&input)?.as_bytes())?;
    write_atomic(&out.join("summary.json"), json(&summary)?.as_bytes())?;

    println!("scene: {source}");
    println!("method: {how}");
    match &summary.map.field {
        Some(s) => {
            println!(
                "MRT at {:.2} m over {} nodes: min {:.2} °C at ({:.2}, {:.2}), max {:.2} °C at ({:.2}, {:.2}), mean {:.2} °C; largest standard error {:.3} K",
                a.height,
                s.nodes,
                s.min.mrt_c,
                s.min.uv[0],
                s.min.uv[1],
                s.max.mrt_c,
                s.max.uv[0],
                s.max.uv[1],
                s.mean_c,
                s.max_std_error_k
            );
            if s.skipped > 0 {
                println!(
                    "{} nodes skipped (inside occluders or failed): see the note column of mrt_grid.csv",
                    s.skipped
                );
            }
        }
        None => println!("no grid node could be computed"),
    }
    for m in &summary.marks {
        println!(
            "  {}: MRT {:.2} °C ± {:.2} K at ({:.2}, {:.2}, {:.2})",
            m.name.as_deref().unwrap_or("?"),
            m.mrt_c,
            m.std_error_k,
            m.xyz[0],
            m.xyz[1],
            m.xyz[2]
        );
    }
    println!(
        "computed in {:.3} s; wrote mrt_grid.csv, mrt_map.png, mrt_map.svg, summary.json in {}",
        secs,
        out.display()
    );
    Ok(())
}
