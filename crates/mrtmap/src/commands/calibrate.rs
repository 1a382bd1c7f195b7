//! `mrtmap calibrate`: one camera's intrinsics, or the rig (both cameras and the thermal
//! camera's pose) into rig.toml.

use mrtmap_pipeline::calibration::CalibrateArgs;

use crate::output::print_lines;

pub fn run(a: &CalibrateArgs) -> anyhow::Result<()> {
    let d = a.detect()?;
    for p in d.problems() {
        eprintln!("skipped: {p}");
    }
    print_lines(d.lines());
    print_lines(d.calibrate(a)?);
    Ok(())
}
