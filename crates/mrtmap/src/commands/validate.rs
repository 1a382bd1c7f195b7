//! `mrtmap validate`: a map against black-globe readings.

use mrtmap_pipeline::validation::validate_map;
use mrtmap_report::{ISO_DESIRED_K, ISO_REQUIRED_K};

use crate::cli::ValidateArgs;

pub fn run(a: &ValidateArgs) -> anyhow::Result<()> {
    let out = a.out.clone().unwrap_or_else(|| a.map.clone());
    let v = validate_map(&a.map, &a.globe, a.frame, &out)?;
    let (scene_path, result) = (&v.scene, &v.rows);
    println!("scene: {}", scene_path.display());
    println!(
        "{:<10} {:>7} {:>7} {:>5} {:>9} {:>9} {:>15} {:>8} {:>8}  ISO 7726",
        "location", "Tg °C", "Ta °C", "v", "ISO °C", "mixed °C", "mrtmap °C", "Δ ISO", "Δ mixed"
    );
    for r in result {
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
