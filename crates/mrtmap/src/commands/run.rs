//! `mrtmap run`: the whole pipeline on a recording.

use anyhow::bail;
use mrtmap_pipeline::Project;
use mrtmap_pipeline::report::run_recording;
use mrtmap_pipeline::settings::PointEntry;

use crate::cli::RunArgs;
use crate::output::{Bar, print_lines};

/// The project from the file and the flags.
fn settings(a: &RunArgs) -> anyhow::Result<Project> {
    let mut p = match &a.config {
        Some(f) => Project::load(f)?,
        None => Project::default(),
    };
    if let Some((x, y)) = a.grid {
        p.map.grid = [x, y];
    }
    if !a.heights.is_empty() {
        p.map.heights_m = a.heights.clone();
    }
    if let Some(m) = a.margin_m {
        p.map.margin_m = m;
    }
    if !a.quantities.is_empty() {
        p.map.quantities = a.quantities.clone();
    }
    for (name, c) in &a.marks {
        let &[x, y, z] = c.as_slice() else {
            bail!(
                "--mark {name}: give X,Y,Z (metres; the room frame, or the scan's with --frame scan)"
            );
        };
        p.points.retain(|q| &q.name != name);
        p.points.push(PointEntry {
            name: name.clone(),
            xyz: [x, y, z],
            frame: a.frame,
        });
    }
    if let Some(v) = a.voxel_m {
        p.fuse.voxel_m = v;
    }
    if let Some(i) = a.icp {
        p.fuse.icp = i;
    }
    if let Some(s) = a.self_calibrate {
        p.fuse.self_calibrate = s;
    }
    if a.no_masks {
        p.segment.masks = false;
    }
    if let Some(c) = a.origin_corner {
        p.room.origin_corner = Some(c);
    }
    if let Some(t) = a.air_c {
        p.air.temperature_c = Some(t);
    }
    p.check()?;
    Ok(p)
}

pub fn run(a: &RunArgs) -> anyhow::Result<()> {
    let p = settings(a)?;
    let bar = Bar::new("");
    let done = run_recording(&a.recording, &a.out, &p, a.force, &a.src, &bar)?;
    bar.finish();
    print_lines(done.lines(&a.recording, &a.out));
    Ok(())
}
