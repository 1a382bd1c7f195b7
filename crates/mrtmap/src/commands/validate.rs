//! `mrtmap validate`: a map against black-globe readings.

use mrtmap_pipeline::report::numbers::{signed, uncertainty};
use mrtmap_pipeline::validation::validate_map;
use mrtmap_pipeline::validation::{ISO_DESIRED_K, ISO_REQUIRED_K};

use crate::cli::ValidateArgs;

pub fn run(a: &ValidateArgs) -> anyhow::Result<()> {
    let out = a.out.clone().unwrap_or_else(|| a.map.clone());
    let sun = match &a.config {
        Some(f) => {
            let p = mrtmap_pipeline::Project::resolve(Some(f), &mrtmap_pipeline::Overrides::new())?;
            p.sun.query()?
        }
        None => None,
    };
    let v = validate_map(
        &a.map,
        &a.globe,
        a.frame,
        &a.calibrate_with,
        sun.as_ref(),
        &out,
    )?;
    let (scene_path, result) = (&v.scene, &v.rows);
    outln!("scene: {}", scene_path.display());
    outln!(
        "{:<10} {:>7} {:>7} {:>5} {:>9} {:>9} {:>15} {:>8} {:>8}  ISO 7726",
        "location",
        "Tg °C",
        "Ta °C",
        "v",
        "ISO °C",
        "mixed °C",
        "mrtmap °C",
        "Δ ISO",
        "Δ mixed"
    );
    let mut notes = Vec::new();
    for r in result {
        let label = &r.globe.label;
        let mut f = |what: &str, x: Result<f64, String>| match x {
            Ok(v) => format!("{v:.2}"),
            Err(e) => {
                notes.push(format!("{label}: no {what}: {e}"));
                format!("— ({})", notes.len())
            }
        };
        let words = |x: &Result<f64, _>| {
            x.clone()
                .map_err(|e: mrtmap_pipeline::validation::PhysicsError| e.to_string())
        };
        let iso = f("ISO 7726 MRT", words(&r.mrt_iso_c));
        let mixed = f("mixed-convection MRT", words(&r.mrt_mixed_c));
        let ours = match &r.ours_c {
            Ok((o, s)) => format!("{o:.2} ± {}", uncertainty(*s, 2)),
            Err(e) => {
                notes.push(format!("{label}: no mrtmap MRT: {e}"));
                format!("— ({})", notes.len())
            }
        };
        let class = match (r.meets_desired, r.meets_required) {
            _ if r.in_sun.is_some() => {
                mrtmap_pipeline::validation::IN_SUN_NOTE.to_string() + " (not judged)"
            }
            _ if r.calibrates => "fixed the level: not judged".into(),
            (Some(true), _) => format!("meets desired ±{ISO_DESIRED_K} K"),
            (_, Some(true)) => format!("meets required ±{ISO_REQUIRED_K} K"),
            (_, Some(false)) => format!("outside ±{ISO_REQUIRED_K} K"),
            _ => "not judged: a value is missing (see the notes)".into(),
        };
        outln!(
            "{:<10} {:>7.2} {:>7.2} {:>5.2} {:>9} {:>9} {:>15} {:>8} {:>8}  {class}",
            label,
            r.globe.tg_c,
            r.globe.ta_c,
            r.globe.va_m_s,
            iso,
            mixed,
            ours,
            r.diff_iso_k.map_or("—".into(), |v| signed(v, 2)),
            r.diff_mixed_k.map_or("—".into(), |v| signed(v, 2)),
        );
    }
    if let Some(s) = v.level_shift_k {
        outln!(
            "every temperature shifted by {s:+.2} K so that the map matches {} (ISO 7726); the others are compared",
            a.calibrate_with.join(", ")
        );
    }
    for (k, n) in notes.iter().enumerate() {
        outln!("({}) {n}", k + 1);
    }
    outln!(
        "wrote validation.csv and validation.json in {}",
        out.display()
    );
    let judged = result
        .iter()
        .filter(|r| r.meets_required.is_some() && r.in_sun.is_none() && !r.calibrates)
        .count();
    if judged == 0 {
        anyhow::bail!(
            "{}: none of its {} globe readings could be judged against the map (the table above says why); validate needs at least one reading that is neither missing a value, in the sun, nor used to fix the level",
            a.globe.display(),
            result.len()
        );
    }
    Ok(())
}
