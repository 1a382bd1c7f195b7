//! `mrtmap map`: MRT over a grid, written as CSV, PNG, SVG and JSON; with `--quantity`, a
//! person's comfort maps beside it.

use mrtmap_pipeline::comfort::value_of;
use mrtmap_pipeline::maps::{Mark, MarkAt, load_scene};
use mrtmap_pipeline::report::numbers::{fixed, uncertainty};
use mrtmap_pipeline::settings::Quantity;
use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::MapArgs;
use crate::output::print_lines;

pub fn run(a: &MapArgs) -> anyhow::Result<()> {
    let mut o = Overrides::new();
    o.set_some("map.grid", "--grid", a.grid.map(|(x, y)| [x, y]).as_ref())
        .set_some(
            "map.heights_m",
            "--height",
            a.height.map(|h| vec![h]).as_ref(),
        )
        .set_some("map.margin_m", "--margin-m", a.margin_m.as_ref())
        .set_some(
            "map.quantities",
            "--quantity",
            (!a.quantities.is_empty()).then_some(&a.quantities),
        )
        .set_some("air.temperature_c", "--air-c", a.air_c.as_ref());
    a.method.add_to(&mut o);
    let project = Project::resolve(a.config.as_deref(), &o)?;
    let (scene, source) = load_scene(&a.scene)?;
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
    let front = Pipeline::new(project);
    let maps = front.map(&scene, &source, &marks, &a.out)?;
    let project = front.project();
    let m = &maps.map;
    outln!("scene: {source}");
    outln!("method: {}", m.method);
    print_lines(m.summary.lines());
    outln!(
        "computed in {:.3} s; wrote mrt_grid.csv, mrt_map.png, mrt_map.svg, summary.json in {}",
        m.summary.map.compute_secs,
        a.out.display()
    );
    let Some(c) = &maps.comfort else {
        return Ok(());
    };
    let person = Quantity::person(&project.map.quantities);
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
    if let Some(share) = s.outside_iso_ranges_share.filter(|x| *x > 0.0) {
        outln!(
            "  PMV inputs outside ISO 7730's ranges on {:.0} % of the floor: PMV and PPD there are indicative only",
            100.0 * share
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
    if let Some(sun) = &s.sun {
        outln!(
            "  the sun (SolarCal): the beam reaches the person on {:.0} % of the floor; ΔMRT up to {:.2} K at ({}, {})",
            100.0 * sun.sunlit_share,
            sun.max_delta_mrt_k,
            fixed(sun.max_at[0], 2),
            fixed(sun.max_at[1], 2)
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
