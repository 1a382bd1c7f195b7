//! `mrtmap export`: a measured room for Honeybee, gbXML, glTF or Radiance.

use mrtmap_pipeline::export::export_file;

use crate::cli::ExportArgs;
use crate::output::print_lines;

pub fn run(a: &ExportArgs) -> anyhow::Result<()> {
    let lines = export_file(&a.source, a.to, &a.out, a.max_points)?;
    print_lines(lines);
    Ok(())
}
