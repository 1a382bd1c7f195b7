//! `mrtmap mrt`: MRT at points with view-factor tables.

use mrtmap_pipeline::points::AsymmetryKind;
use mrtmap_pipeline::points::{AsymmetryVerdict, ENCLOSURE_TOLERANCE, Facing};
use mrtmap_pipeline::report::numbers::{fixed, uncertainty};

use mrtmap_pipeline::maps::load_scene;
use mrtmap_pipeline::points::{PersonAnswer, PlaneAnswer, PointAnswers, PointQuery, mrt_at_points};

use crate::cli::MrtArgs;
use crate::output::json;

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
    let section = a.method;
    let query = PointQuery {
        at: a.at.clone(),
        frame: a.frame,
        person: a
            .person
            .map(|p| (p, a.facing.map_or(Facing::Any, Facing::Azimuth))),
        planes: a.plane,
    };
    let answers = mrt_at_points(&scene, &source, &section, &query)?;
    if a.json {
        out!("{}", json(&answers)?);
        return Ok(());
    }
    let PointAnswers {
        method_description,
        points,
        persons,
        planes,
        ..
    } = answers;
    if a.person.is_some() || a.plane {
        print_person_and_planes(&source, &persons, &planes);
        if points.is_empty() {
            return Ok(());
        }
    }
    outln!("scene: {source}");
    outln!("method: {method_description}");
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
        outln!(
            "  ± in parts: {}",
            mrtmap_pipeline::report::parts_line(&p.parts(), 2)
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

fn print_person_and_planes(source: &str, persons: &[PersonAnswer], planes: &[PlaneAnswer]) {
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
