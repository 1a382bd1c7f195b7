//! `mrtmap simulate`: a handheld scan of a room, with exact truth.

use mrtmap_pipeline::simulation::{SimulateArgs, simulate_recording};

use crate::output::{Bar, print_lines};

pub fn run(a: &SimulateArgs) -> anyhow::Result<()> {
    let bar = Bar::new(" frames");
    let lines = simulate_recording(a, &bar)?;
    bar.finish();
    print_lines(lines);
    Ok(())
}
