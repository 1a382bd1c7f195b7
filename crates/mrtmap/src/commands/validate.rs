//! `mrtmap validate`: a map against black-globe readings.

use anyhow::{Context, bail};
use mrtmap_geometry::nalgebra::Point3;
use mrtmap_io::write_atomic;
use mrtmap_radiation::{Method, MonteCarlo, MrtEngine, RadiantScene};
use mrtmap_report::{ISO_DESIRED_K, ISO_REQUIRED_K, parse_globe_csv, validate, validation_csv};

use crate::cli::ValidateArgs;
use crate::output::json;

pub fn run(a: &ValidateArgs) -> anyhow::Result<()> {
    let scene_path = [
        a.map.join("scene.json"),
        a.map.join("segment").join("scene.json"),
    ]
    .into_iter()
    .find(|p| p.exists());
    let Some(scene_path) = scene_path else {
        bail!(
            "{} has no scene.json (nor segment/scene.json): give a `mrtmap run` output or a folder with scene.json",
            a.map.display()
        );
    };
    let scene = RadiantScene::load(&scene_path)?;
    let text = std::fs::read_to_string(&a.globe)
        .with_context(|| format!("cannot read {}", a.globe.display()))?;
    let rows = parse_globe_csv(&text, &a.globe.display().to_string())?;
    let engine = MrtEngine::new(
        &scene,
        Method::Auto(MonteCarlo {
            rays: 200_000,
            ..MonteCarlo::default()
        }),
    )?;
    let ours = |x: &[f64; 3]| {
        engine
            .at(&Point3::from(*x), 0)
            .map(|r| (r.mrt.celsius(), r.std_error_k))
            .map_err(|e| e.to_string())
    };
    let result = validate(&rows, &ours);
    let out = a.out.clone().unwrap_or_else(|| a.map.clone());
    write_atomic(
        &out.join("validation.csv"),
        validation_csv(&result).as_bytes(),
    )?;
    write_atomic(&out.join("validation.json"), json(&result)?.as_bytes())?;
    println!("scene: {}", scene_path.display());
    println!(
        "{:<10} {:>7} {:>7} {:>5} {:>9} {:>9} {:>15} {:>8} {:>8}  ISO 7726",
        "location", "Tg °C", "Ta °C", "v", "ISO °C", "mixed °C", "mrtmap °C", "Δ ISO", "Δ mixed"
    );
    for r in &result {
        let f =
            |x: &Result<f64, String>| x.as_ref().map_or("—".to_string(), |v| format!("{v:.2}"));
        let class = match (r.meets_desired, r.meets_required) {
            (Some(true), _) => format!("meets desired ±{ISO_DESIRED_K} K"),
            (_, Some(true)) => format!("meets required ±{ISO_REQUIRED_K} K"),
            (_, Some(false)) => format!("outside ±{ISO_REQUIRED_K} K"),
            _ => "—".into(),
        };
        println!(
            "{:<10} {:>7.2} {:>7.2} {:>5.2} {:>9} {:>9} {:>15} {:>8} {:>8}  {class}",
            r.globe.label,
            r.globe.tg_c,
            r.globe.ta_c,
            r.globe.va_m_s,
            f(&r.mrt_iso_c),
            f(&r.mrt_mixed_c),
            r.ours_c
                .as_ref()
                .map_or_else(|e| e.clone(), |(o, s)| format!("{o:.2} ± {s:.2}")),
            r.diff_iso_k.map_or("—".into(), |v| format!("{v:+.2}")),
            r.diff_mixed_k.map_or("—".into(), |v| format!("{v:+.2}")),
        );
    }
    println!(
        "wrote validation.csv and validation.json in {}",
        out.display()
    );
    Ok(())
}
