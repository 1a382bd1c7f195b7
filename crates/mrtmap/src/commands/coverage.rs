//! `mrtmap coverage`: is a scan good enough, and where to scan more.

use std::time::Instant;

use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::CoverageArgs;
use crate::output::{Bar, print_lines};

pub fn run(a: &CoverageArgs) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let bar = Bar::new("");
    let c = Pipeline::new(Project::resolve(a.config.as_deref(), &Overrides::new())?)
        .source(a.src.clone())
        .progress(&bar)
        .coverage(&a.recording, a.out.as_deref(), a.target_k)?;
    bar.finish();
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&c)?);
    } else {
        print_lines(c.lines(t0.elapsed().as_secs_f64()));
    }
    Ok(())
}
