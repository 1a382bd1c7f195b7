//! `mrtmap map`: MRT over a grid, written as CSV, PNG, SVG and JSON; with `--quantity`, a
//! person's comfort maps beside it.

use mrtmap_pipeline::maps::{Mark, MarkAt, load_scene};
use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::MapArgs;
use crate::output::print_lines;

/// The project: the defaults, then the file, then the flags given.
pub(crate) fn settings(a: &MapArgs) -> anyhow::Result<Project> {
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
    Ok(Project::resolve(a.config.as_deref(), &o)?)
}

pub fn run(a: &MapArgs) -> anyhow::Result<()> {
    let project = settings(a)?;
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
    print_lines(maps.lines(&source, &front.project().map.quantities, &a.out));
    Ok(())
}
