//! `mrtmap validate`: a map against black-globe readings.

use mrtmap_pipeline::validation::validate_map;

use crate::cli::ValidateArgs;
use crate::output::print_lines;

pub fn run(a: &ValidateArgs) -> anyhow::Result<()> {
    let out = a.out.clone().unwrap_or_else(|| a.map.clone());
    let sun = match &a.config {
        Some(f) => {
            let p = mrtmap_pipeline::Project::resolve(Some(f), &mrtmap_pipeline::Overrides::new())?;
            p.sun.query()?
        }
        None => None,
    };
    let v = validate_map(
        &a.map,
        &a.globe,
        a.frame,
        &a.calibrate_with,
        sun.as_ref(),
        &out,
    )?;
    print_lines(v.lines(&a.calibrate_with, &out));
    if v.judged() == 0 {
        anyhow::bail!(
            "{}: none of its {} globe readings could be judged against the map (the table above says why); validate needs at least one reading that is neither missing a value, in the sun, nor used to fix the level",
            a.globe.display(),
            v.rows.len()
        );
    }
    Ok(())
}
