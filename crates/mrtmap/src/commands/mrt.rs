//! `mrtmap mrt`: MRT at points with view-factor tables.

use mrtmap_pipeline::maps::load_scene;
use mrtmap_pipeline::points::{Facing, PointQuery, SunQuery};
use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::MrtArgs;
use crate::output::{json, print_lines};

/// The project: the defaults, then the file, then the flags given.
pub(crate) fn settings(a: &MrtArgs) -> anyhow::Result<Project> {
    let mut flags = Overrides::new();
    a.method.add_to(&mut flags);
    Ok(Project::resolve(a.config.as_deref(), &flags)?)
}

pub fn run(a: &MrtArgs) -> anyhow::Result<()> {
    let project = settings(a)?;
    let (scene, source) = load_scene(&a.scene)?;
    // --sun (with its --dni and --transmittance) overrides the project's [sun] as a whole.
    let sun = match a.sun {
        Some([alt, az]) => Some(SunQuery::new(
            alt,
            az,
            a.dni.unwrap_or_default(),
            a.transmittance.unwrap_or_default(),
        )),
        None => project.sun.query()?,
    };
    let query = PointQuery {
        at: a.at.clone(),
        frame: a.frame,
        person: a
            .person
            .map(|p| (p, a.facing.map_or(Facing::Any, Facing::Azimuth))),
        planes: a.plane,
        sun,
    };
    let answers = Pipeline::new(project).mrt(&scene, &source, &query)?;
    if a.json {
        out!("{}", json(&answers)?);
    } else {
        print_lines(answers.lines());
    }
    Ok(())
}
