//! `mrtmap fuse`: recording → thermal point cloud.

use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::FuseArgs;
use crate::output::{Bar, print_lines};

/// The project: the defaults, then the file, then the flags given.
pub(crate) fn settings(a: &FuseArgs) -> anyhow::Result<Project> {
    let mut o = Overrides::new();
    a.fuse.add_to(&mut o);
    Ok(Project::resolve(a.config.as_deref(), &o)?)
}

pub fn run(a: &FuseArgs) -> anyhow::Result<()> {
    let bar = Bar::new("");
    let done = Pipeline::new(settings(a)?)
        .source(a.src.clone())
        .progress(&bar)
        .fuse(&a.recording, &a.out)?;
    bar.finish();
    for w in &done.warnings {
        eprintln!("warning: {w}");
    }
    print_lines(done.lines(&a.recording, &a.out));
    Ok(())
}
