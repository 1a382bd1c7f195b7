//! `mrtmap mrt`: MRT at points with view-factor tables.

use mrtmap_pipeline::maps::load_scene;
use mrtmap_pipeline::points::{Facing, PointQuery, SunQuery, mrt_at_points};

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
    let answers = mrt_at_points(&scene, &source, &a.method.section()?, &query)?;
    if a.json {
        out!("{}", json(&answers)?);
    } else {
        print_lines(answers.lines());
    }
    Ok(())
}
