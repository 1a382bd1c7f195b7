//! `mrtmap mrt`: MRT at points with view-factor tables.

use mrtmap_radiation::{ENCLOSURE_TOLERANCE, PointRecord};
use mrtmap_report::numbers::{fixed, uncertainty};
use serde::Serialize;

use mrtmap_pipeline::maps::{load_scene, to_scene_frame};

use crate::cli::MrtArgs;
use crate::output::json;

#[derive(Serialize)]
struct MrtOut {
    scene: String,
    method: mrtmap_radiation::Method,
    points: Vec<PointRecord>,
}

pub fn run(a: &MrtArgs) -> anyhow::Result<()> {
    let (scene, source) = load_scene(a.scene.scene.as_deref())?;
    let section = a.method.section();
    let method = section.method(&scene)?;
    let engine = section.engine(&scene)?;
    let mut points = Vec::with_capacity(a.at.len());
    for (k, p) in a.at.iter().enumerate() {
        let at = to_scene_frame(*p, a.frame, &scene, &source)?;
        let r = engine.at(&at, k as u64)?;
        points.push(PointRecord::new(None, &r, engine.patches()));
    }
    if a.json {
        out!(
            "{}",
            json(&MrtOut {
                scene: source,
                method,
                points
            })?
        );
        return Ok(());
    }
    outln!("scene: {source}");
    outln!("method: {}", method.describe(engine.ray_engine()));
    for p in &points {
        outln!();
        outln!(
            "point ({}, {}, {}): MRT {:.2} °C ± {} K   (ΣF = {:.4})",
            fixed(p.xyz[0], 3),
            fixed(p.xyz[1], 3),
            fixed(p.xyz[2], 3),
            p.mrt_c,
            uncertainty(p.std_error_k, 2),
            p.view_factor_sum
        );
        if (p.view_factor_sum - 1.0).abs() > ENCLOSURE_TOLERANCE {
            outln!(
                "  warning: the scene covers only {:.1} % of the view here (asked for with --allow-open): the MRT leaves the rest out",
                p.view_factor_sum * 100.0
            );
        }
        outln!(
            "  {:<28} {:<18} {:>9} {:>9} {:>8}",
            "id",
            "label",
            "F",
            "±",
            "T (°C)"
        );
        for v in &p.view_factors {
            let label = if v.label.is_empty() {
                "-"
            } else {
                v.label.as_str()
            };
            let id = match &v.host {
                Some(h) => format!("{} (on {h})", v.id),
                None => v.id.clone(),
            };
            outln!(
                "  {:<28} {:<18} {:>9.5} {:>9.5} {:>8.2}",
                id,
                label,
                v.view_factor,
                v.view_factor_std_error,
                v.temperature_c
            );
        }
    }
    Ok(())
}
