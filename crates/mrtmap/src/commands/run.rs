//! `mrtmap run`: the whole pipeline on a recording.

use anyhow::bail;
use mrtmap_pipeline::settings::PointEntry;
use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::RunArgs;
use crate::output::{Bar, print_lines};

/// The project: the defaults, then the file, then the flags given.
pub(crate) fn settings(a: &RunArgs) -> anyhow::Result<Project> {
    let mut o = Overrides::new();
    o.set_some("map.grid", "--grid", a.grid.map(|(x, y)| [x, y]).as_ref())
        .set_some(
            "map.heights_m",
            "--height",
            (!a.heights.is_empty()).then_some(&a.heights),
        )
        .set_some("map.margin_m", "--margin-m", a.margin_m.as_ref())
        .set_some(
            "map.quantities",
            "--quantity",
            (!a.quantities.is_empty()).then_some(&a.quantities),
        )
        .set_some(
            "room.origin_corner",
            "--origin-corner",
            a.origin_corner.as_ref(),
        )
        .set_some("air.temperature_c", "--air-c", a.air_c.as_ref());
    a.track.add_to(&mut o);
    a.fuse.add_to(&mut o);
    a.segment.add_to(&mut o);
    for (name, c) in &a.marks {
        let &[x, y, z] = c.as_slice() else {
            bail!(
                "--mark {name}: give X,Y,Z (metres; the room frame, or the scan's with --frame scan)"
            );
        };
        o.point(PointEntry {
            name: name.clone(),
            xyz: [x, y, z],
            frame: a.frame,
        });
    }
    Ok(Project::resolve(a.config.as_deref(), &o)?)
}

pub fn run(a: &RunArgs) -> anyhow::Result<()> {
    let p = settings(a)?;
    let bar = Bar::new("");
    let done = Pipeline::new(p)
        .force(a.force)
        .source(a.src.clone())
        .progress(&bar)
        .run(&a.recording, &a.out)?;
    bar.finish();
    print_lines(done.lines(&a.recording, &a.out));
    Ok(())
}
