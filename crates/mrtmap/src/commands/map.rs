//! `mrtmap map`: MRT over a grid, written as CSV, PNG, SVG and JSON; with `--quantity`, a
//! person's comfort maps beside it.

use mrtmap_geometry::nalgebra::Point3;
use mrtmap_pipeline::Project;
use mrtmap_pipeline::comfort::{make_comfort_maps, value_of};
use mrtmap_pipeline::maps::{Mark, MarkAt, load_scene, make_map};
use mrtmap_pipeline::settings::Quantity;
use mrtmap_radiation::{GridSpec, MapFrame};
use mrtmap_report::numbers::{fixed, uncertainty};

use crate::cli::MapArgs;
use crate::output::print_map;

pub fn run(a: &MapArgs) -> anyhow::Result<()> {
    let mut project = match &a.config {
        Some(f) => Project::load(f)?,
        None => Project::default(),
    };
    if !a.quantities.is_empty() {
        project.map.quantities = a.quantities.clone();
    }
    if a.air_c.is_some() {
        project.air.temperature_c = a.air_c;
    }
    let person = Quantity::person(&project.map.quantities);
    project.comfort.check(&project.air, &person)?;
    let (scene, source) = load_scene(a.scene.scene.as_deref())?;
    let section = a.method.section();
    let spec = GridSpec {
        nx: a.grid.0,
        ny: a.grid.1,
        height_m: a.height,
        margin_m: a.margin_m,
    };
    let marks: Vec<Mark> = a
        .marks
        .iter()
        .map(|(name, c)| Mark {
            name: name.clone(),
            at: match c.as_slice() {
                [u, v] => MarkAt::Map([*u, *v]),
                _ => MarkAt::Scene([c[0], c[1], c[2]]),
            },
        })
        .collect();
    let m = make_map(&scene, &source, &section, spec, &marks, &a.out)?;
    outln!("scene: {source}");
    outln!("method: {}", m.method);
    print_map(&m.summary);
    outln!(
        "computed in {:.3} s; wrote mrt_grid.csv, mrt_map.png, mrt_map.svg, summary.json in {}",
        m.summary.map.compute_secs,
        a.out.display()
    );
    if person.is_empty() {
        return Ok(());
    }
    let engine = section.engine(&scene)?;
    let frame = MapFrame::of_scene(&scene)?;
    let xy_marks: Vec<(String, [f64; 2])> = marks
        .iter()
        .map(|mk| {
            let uv = match mk.at {
                MarkAt::Map(uv) => uv,
                MarkAt::Scene(p) => {
                    let q = frame.uv(&Point3::from(p));
                    [q.x, q.y]
                }
            };
            (mk.name.clone(), uv)
        })
        .collect();
    let c = make_comfort_maps(
        &engine,
        &scene,
        &source,
        ([spec.nx, spec.ny], spec.margin_m),
        &project.comfort,
        &project.air,
        &person,
        &xy_marks,
        &a.out,
    )?;
    let s = &c.summary;
    outln!();
    outln!(
        "a {} person, {}: {} nodes in {:.1} s",
        s.comfort.posture.as_str(),
        s.comfort.facing().describe(),
        s.nodes,
        s.compute_secs
    );
    if let Some(sh) = s.pmv_category_share {
        outln!(
            "  floor by ISO 7730 PMV category: A {:.0} %, B {:.0} %, C {:.0} %, outside {:.0} %",
            100.0 * sh[0],
            100.0 * sh[1],
            100.0 * sh[2],
            100.0 * sh[3]
        );
    }
    if let Some((w, xy)) = &s.worst_asymmetry {
        outln!(
            "  worst radiant asymmetry {:.2} K at ({}, {}): PD {:.1} %, category {}",
            w.worst.delta_k,
            fixed(xy[0], 2),
            fixed(xy[1], 2),
            w.worst.pd_pct,
            w.worst.category.as_str()
        );
    }
    for (name, p) in &s.marks {
        let cells: Vec<String> = person
            .iter()
            .filter_map(|q| {
                value_of(p, *q).map(|(v, e)| format!("{} {v:.2} ± {}", q.name(), uncertainty(e, 2)))
            })
            .collect();
        outln!("  {name}: {}", cells.join(", "));
    }
    let names: Vec<String> = person.iter().map(|q| format!("{}.png", q.name())).collect();
    outln!(
        "wrote {} and comfort.json in {}",
        names.join(", "),
        a.out.display()
    );
    Ok(())
}
