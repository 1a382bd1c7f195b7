//! `mrtmap mrt`: MRT at points with view-factor tables.

use mrtmap_radiation::{MrtEngine, PointRecord};
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
    let method = a.method.section().method(&scene)?;
    let engine = MrtEngine::new(&scene, method)?;
    let mut points = Vec::with_capacity(a.at.len());
    for (k, p) in a.at.iter().enumerate() {
        let at = to_scene_frame(*p, a.frame, &scene, &source)?;
        let r = engine.at(&at, k as u64)?;
        points.push(PointRecord::new(None, &r, engine.patches()));
    }
    if a.json {
        print!(
            "{}",
            json(&MrtOut {
                scene: source,
                method,
                points
            })?
        );
        return Ok(());
    }
    println!("scene: {source}");
    println!("method: {}", method.describe(engine.ray_engine()));
    for p in &points {
        println!();
        println!(
            "point ({:.3}, {:.3}, {:.3}): MRT {:.2} °C ± {:.2} K   (ΣF = {:.4})",
            p.xyz[0], p.xyz[1], p.xyz[2], p.mrt_c, p.std_error_k, p.view_factor_sum
        );
        println!(
            "  {:<28} {:<18} {:>9} {:>9} {:>8}",
            "id", "label", "F", "±", "T (°C)"
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
            println!(
                "  {:<28} {:<18} {:>9.5} {:>9.5} {:>8.2}",
                id, label, v.view_factor, v.view_factor_std_error, v.temperature_c
            );
        }
    }
    Ok(())
}
