//! `mrtmap map`: MRT over a grid, written as CSV, PNG, SVG and JSON.

use mrtmap_pipeline::maps::{Mark, MarkAt, load_scene, make_map};
use mrtmap_radiation::GridSpec;

use crate::cli::MapArgs;
use crate::output::print_map;

pub fn run(a: &MapArgs) -> anyhow::Result<()> {
    let (scene, source) = load_scene(a.scene.scene.as_deref())?;
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
    let m = make_map(&scene, &source, &a.method.section(), spec, &marks, &a.out)?;
    outln!("scene: {source}");
    outln!("method: {}", m.method);
    print_map(&m.summary);
    outln!(
        "computed in {:.3} s; wrote mrt_grid.csv, mrt_map.png, mrt_map.svg, summary.json in {}",
        m.summary.map.compute_secs,
        a.out.display()
    );
    Ok(())
}
