//! `mrtmap segment`: thermal cloud → radiant scene.

use mrtmap_pipeline::run::{SegmentJob, segment_folder, segment_lines};

use crate::cli::SegmentArgs;
use crate::output::print_lines;

pub fn run(a: &SegmentArgs) -> anyhow::Result<()> {
    let report = segment_folder(&SegmentJob {
        fused: &a.fused,
        masks: a.masks.as_deref(),
        recording: a.recording.as_deref(),
        section: a.section.clone(),
        origin_corner: a.origin_corner,
        references: a.references.as_deref(),
        out: &a.out,
    })?;
    print_lines(segment_lines(&report));
    outln!(
        "wrote scene.json, segments.ply, segment.json in {}",
        a.out.display()
    );
    Ok(())
}
