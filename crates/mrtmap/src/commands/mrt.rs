//! `mrtmap mrt`: MRT at points with view-factor tables.

use mrtmap_pipeline::maps::load_scene;
use mrtmap_pipeline::points::{Facing, PointQuery, SunQuery};
use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::MrtArgs;
use crate::output::{json, print_lines};

pub fn run(a: &MrtArgs) -> anyhow::Result<()> {
    let (scene, source) = load_scene(&a.scene)?;
    let query = PointQuery {
        at: a.at.clone(),
        frame: a.frame,
        person: a
            .person
            .map(|p| (p, a.facing.map_or(Facing::Any, Facing::Azimuth))),
        planes: a.plane,
        sun: a.sun.map(|[alt, az]| {
            SunQuery::new(
                alt,
                az,
                a.dni.unwrap_or_default(),
                a.transmittance.unwrap_or_default(),
            )
        }),
    };
    let mut flags = Overrides::new();
    a.method.add_to(&mut flags);
    let answers = Pipeline::new(Project::resolve(None, &flags)?).mrt(&scene, &source, &query)?;
    if a.json {
        out!("{}", json(&answers)?);
    } else {
        print_lines(answers.lines());
    }
    Ok(())
}
