//! `mrtmap track`: poses for a recording without a pose source.

use mrtmap_pipeline::settings::TrackSection;
use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::TrackArgs;
use crate::output::{Bar, print_lines};

pub fn run(a: &TrackArgs) -> anyhow::Result<()> {
    let project = Project {
        track: TrackSection {
            loop_closure: !a.no_loops,
            use_imu: !a.no_imu,
            fast_threshold: a.fast_threshold,
            ..TrackSection::default()
        },
        ..Project::default()
    };
    let bar = Bar::new(" frames");
    let done = Pipeline::new(Project::resolve_over(project, &Overrides::new())?)
        .progress(&bar)
        .track(&a.recording, &a.out)?;
    bar.finish();
    for w in done
        .warnings
        .iter()
        .map(ToString::to_string)
        .chain(done.report.warnings())
    {
        eprintln!("warning: {w}");
    }
    print_lines(done.lines(&a.out));
    Ok(())
}
