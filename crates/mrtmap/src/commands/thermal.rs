//! `mrtmap thermal`: one thermal image → metadata, statistics, CSV / PNG.

use mrtmap_pipeline::thermal_image::{ThermalExports, thermal_image};

use crate::cli::ThermalArgs;
use crate::output::{json, print_lines};

pub fn run(a: &ThermalArgs) -> anyhow::Result<()> {
    let exports = ThermalExports {
        csv: a.csv.clone(),
        png: a.png.clone(),
        centikelvin: a.centikelvin.clone(),
    };
    let summary = thermal_image(&a.file, &a.reading, &exports)?;
    if a.json {
        out!("{}", json(&summary)?);
    } else {
        print_lines(summary.lines());
    }
    Ok(())
}
