//! `mrtmap track`: poses for a recording without a pose source.

use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::TrackArgs;
use crate::output::{Bar, print_lines};

/// The project: the defaults, then the file, then the flags given.
pub(crate) fn settings(a: &TrackArgs) -> anyhow::Result<Project> {
    let mut o = Overrides::new();
    a.track.add_to(&mut o);
    Ok(Project::resolve(a.config.as_deref(), &o)?)
}

pub fn run(a: &TrackArgs) -> anyhow::Result<()> {
    let bar = Bar::new(" frames");
    let done = Pipeline::new(settings(a)?)
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
