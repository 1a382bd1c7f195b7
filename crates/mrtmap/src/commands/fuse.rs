//! `mrtmap fuse`: recording → thermal point cloud.

use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::FuseArgs;
use crate::output::{Bar, print_lines};

pub fn run(a: &FuseArgs) -> anyhow::Result<()> {
    let project = Project::resolve_over(
        Project {
            fuse: a.fuse.clone(),
            ..Project::default()
        },
        &Overrides::new(),
    )?;
    let bar = Bar::new("");
    let done = Pipeline::new(project)
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
