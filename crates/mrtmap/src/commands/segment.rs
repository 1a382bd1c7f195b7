//! `mrtmap segment`: thermal cloud → radiant scene.

use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::SegmentArgs;
use crate::output::print_lines;

/// The project: the defaults, then the file, then the flags given.
pub(crate) fn settings(a: &SegmentArgs) -> anyhow::Result<Project> {
    let mut o = Overrides::new();
    a.section.add_to(&mut o);
    o.set_some(
        "room.origin_corner",
        "--origin-corner",
        a.origin_corner.as_ref(),
    );
    Ok(Project::resolve(a.config.as_deref(), &o)?)
}

pub fn run(a: &SegmentArgs) -> anyhow::Result<()> {
    let done = Pipeline::new(settings(a)?).segment(
        &a.fused,
        a.masks.as_deref(),
        a.recording.as_deref(),
        a.references.as_deref(),
        &a.out,
    )?;
    print_lines(done.lines(&a.out));
    Ok(())
}
