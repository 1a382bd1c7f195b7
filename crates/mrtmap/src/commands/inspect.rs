//! `mrtmap inspect`: what a scan source holds and what a scan still lacks.

use mrtmap_pipeline::source::inspect;

use crate::cli::InspectArgs;
use crate::output::{json, print_lines};

pub fn run(a: &InspectArgs) -> anyhow::Result<()> {
    let what = inspect(&a.source, &a.src)?;
    if a.json {
        out!("{}", json(&what.to_json(&a.source))?);
        return Ok(());
    }
    print_lines(what.lines(&a.source));
    Ok(())
}
