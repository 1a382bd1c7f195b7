//! `mrtmap segment`: thermal cloud → radiant scene.

use mrtmap_pipeline::settings::RoomSection;
use mrtmap_pipeline::{Pipeline, Project};

use crate::cli::SegmentArgs;
use crate::output::print_lines;

pub fn run(a: &SegmentArgs) -> anyhow::Result<()> {
    let project = Project {
        segment: a.section.clone(),
        room: RoomSection {
            origin_corner: a.origin_corner,
        },
        ..Project::default()
    };
    let done = Pipeline::new(project).segment(
        &a.fused,
        a.masks.as_deref(),
        a.recording.as_deref(),
        a.references.as_deref(),
        &a.out,
    )?;
    print_lines(done.lines(&a.out));
    Ok(())
}
