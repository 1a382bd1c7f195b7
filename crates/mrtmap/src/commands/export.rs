//! `mrtmap export`: a measured room for Honeybee, gbXML, glTF or Radiance.

use mrtmap_pipeline::export::export_file;

use crate::cli::ExportArgs;
use crate::output::print_lines;

pub fn run(a: &ExportArgs) -> anyhow::Result<()> {
    let t = a.temperatures.as_deref();
    let lines = export_file(a.input.as_deref(), a.to, &a.out, t, a.max_points)?;
    print_lines(lines);
    Ok(())
}
