//! `mrtmap demo`: simulate the office scan, run the pipeline, compare with the exact truth.

use mrtmap_pipeline::demo::{DemoArgs, run_demo};

use crate::output::{Bar, print_lines};

pub fn run(a: &DemoArgs) -> anyhow::Result<()> {
    eprintln!("{}", a.size_note());
    let bar = Bar::new("");
    let lines = run_demo(a, &bar)?;
    bar.finish();
    print_lines(lines);
    Ok(())
}
