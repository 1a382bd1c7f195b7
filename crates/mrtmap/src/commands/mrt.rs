//! `mrtmap mrt`: MRT at points with view-factor tables.

use mrtmap_physics::{AsymmetryKind, Posture};
use mrtmap_radiation::{
    AsymmetryVerdict, ENCLOSURE_TOLERANCE, Facing, PersonMrt, PointRecord, RadiantAsymmetry,
};
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
    #[serde(skip_serializing_if = "Vec::is_empty")]
    persons: Vec<PersonOut>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    planes: Vec<PlaneOut>,
}

/// A person's MRT at a point, for JSON.
#[derive(Serialize)]
struct PersonOut {
    centre: [f64; 3],
    posture: Posture,
    facing: Facing,
    mrt_c: f64,
    std_error_k: f64,
    angle_factor_sum: f64,
    angle_factors: Vec<(String, f64)>,
    rays: usize,
}

/// Plane radiant temperatures and asymmetry at a point, for JSON.
#[derive(Serialize)]
struct PlaneOut {
    point: [f64; 3],
    /// Faces up, down, +x, −x, +y, −y: T_pr (°C) and standard error (K).
    faces: Vec<(String, f64, f64)>,
    exact: bool,
    vertical_k: f64,
    horizontal_k: f64,
    horizontal_warm_azimuth_deg: f64,
    vertical: AsymmetryVerdict,
    horizontal: AsymmetryVerdict,
}

const FACES: [&str; 6] = ["up", "down", "+x", "-x", "+y", "-y"];

fn person_out(p: &PersonMrt, patches: &[mrtmap_radiation::Patch]) -> PersonOut {
    PersonOut {
        centre: [p.centre.x, p.centre.y, p.centre.z],
        posture: p.posture,
        facing: p.facing,
        mrt_c: p.mrt.celsius(),
        std_error_k: p.std_error_k,
        angle_factor_sum: p.angle_factor_sum,
        angle_factors: patches
            .iter()
            .zip(&p.angle_factors)
            .map(|(pa, f)| (pa.id.clone(), *f))
            .collect(),
        rays: p.rays,
    }
}

fn plane_out(a: &RadiantAsymmetry) -> PlaneOut {
    PlaneOut {
        point: [a.point.x, a.point.y, a.point.z],
        faces: FACES
            .iter()
            .zip(&a.six)
            .map(|(n, t)| (n.to_string(), t.temperature.celsius(), t.std_error_k))
            .collect(),
        exact: a.six.iter().all(|t| t.exact),
        vertical_k: a.vertical_k,
        horizontal_k: a.horizontal_k,
        horizontal_warm_azimuth_deg: a.horizontal_warm_azimuth_deg,
        vertical: a.vertical,
        horizontal: a.horizontal,
    }
}

fn verdict_text(v: &AsymmetryVerdict) -> String {
    let kind = match v.kind {
        AsymmetryKind::WarmCeiling => "warm ceiling",
        AsymmetryKind::CoolCeiling => "cool ceiling",
        AsymmetryKind::WarmWall => "warm wall",
        AsymmetryKind::CoolWall => "cool wall",
    };
    format!(
        "{:.2} K ({kind}): {:.1} % dissatisfied, ISO 7730 category {}",
        v.delta_k,
        v.pd_pct,
        v.category.as_str()
    )
}

pub fn run(a: &MrtArgs) -> anyhow::Result<()> {
    let (scene, source) = load_scene(a.scene.scene.as_deref())?;
    let section = a.method.section();
    let method = section.method(&scene)?;
    let engine = section.engine(&scene)?;
    let mut points = Vec::with_capacity(a.at.len());
    let (mut persons, mut planes) = (Vec::new(), Vec::new());
    for (k, p) in a.at.iter().enumerate() {
        let at = to_scene_frame(*p, a.frame, &scene, &source)?;
        if let Some(posture) = a.person {
            let facing = a.facing.map_or(Facing::Any, Facing::Azimuth);
            let r = engine.person_at(&at, posture, facing, k as u64)?;
            persons.push(person_out(&r, engine.patches()));
        } else {
            let r = engine.at(&at, k as u64)?;
            points.push(PointRecord::new(None, &r, engine.patches()));
        }
        if a.plane {
            planes.push(plane_out(&engine.asymmetry_at(&at, k as u64)?));
        }
    }
    if a.json {
        out!(
            "{}",
            json(&MrtOut {
                scene: source,
                method,
                points,
                persons,
                planes,
            })?
        );
        return Ok(());
    }
    if a.person.is_some() || a.plane {
        print_person_and_planes(&source, &persons, &planes);
        if points.is_empty() {
            return Ok(());
        }
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

fn print_person_and_planes(source: &str, persons: &[PersonOut], planes: &[PlaneOut]) {
    outln!("scene: {source}");
    for p in persons {
        outln!();
        outln!(
            "{} person, body centre ({}, {}, {}), {}: MRT {:.2} °C ± {} K",
            p.posture.as_str(),
            fixed(p.centre[0], 3),
            fixed(p.centre[1], 3),
            fixed(p.centre[2], 3),
            p.facing.describe(),
            p.mrt_c,
            uncertainty(p.std_error_k, 2)
        );
        outln!(
            "  angle factors (sum {:.4}; fp's closure is about 0.99, the MRT is normalised by it):",
            p.angle_factor_sum
        );
        for (id, f) in p.angle_factors.iter().filter(|(_, f)| *f > 0.0) {
            outln!("  {id:<28} {f:>9.5}");
        }
    }
    for pl in planes {
        outln!();
        outln!(
            "plane radiant temperatures at ({}, {}, {}) ({}):",
            fixed(pl.point[0], 3),
            fixed(pl.point[1], 3),
            fixed(pl.point[2], 3),
            if pl.exact { "exact" } else { "rays" }
        );
        for (face, t, e) in &pl.faces {
            outln!("  {face:<5} {t:>7.2} °C ± {} K", uncertainty(*e, 2));
        }
        outln!("  vertical asymmetry   {}", verdict_text(&pl.vertical));
        outln!(
            "  horizontal asymmetry {} (warmer side towards {:.0}°)",
            verdict_text(&pl.horizontal),
            pl.horizontal_warm_azimuth_deg
        );
    }
}
