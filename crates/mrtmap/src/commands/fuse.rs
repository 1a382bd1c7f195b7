//! `mrtmap fuse`: recording → thermal point cloud.

use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::FuseArgs;
use crate::output::{Bar, print_lines};

pub fn run(a: &FuseArgs) -> anyhow::Result<()> {
    let project = Project::resolve_over(
        Project {
            fuse: a.fuse.clone(),
            ..Project::default()
        },
        &Overrides::new(),
    )?;
    let bar = Bar::new("");
    let done = Pipeline::new(project)
        .source(a.src.clone())
        .progress(&bar)
        .fuse(&a.recording, &a.out)?;
    bar.finish();
    if let Some(c) = &done.prepared.conversion {
        print_lines(c.lines());
    } else if done.prepared.reused {
        outln!(
            "using {} (converted earlier from {})",
            done.prepared.dir.display(),
            a.recording.display()
        );
    }
    for w in &done.warnings {
        eprintln!("warning: {w}");
    }
    let r = &done.report;
    outln!(
        "fused {} of {} thermal frames into {} voxels of {} m in {:.1} s ({:.0} frames/s)",
        r.used_frames,
        r.thermal_frames,
        r.voxels,
        a.fuse.voxel_m,
        r.timing_s.total,
        r.frames_per_second
    );
    outln!("  {}", r.clock.describe());
    for line in r.pose_check.jump_lines() {
        outln!("  warning: {line}");
    }
    if r.pose_check.dropped > 0 {
        outln!(
            "  dropped {} of {} poses that jumped away from their neighbours' motion and back (the largest {:.2} m)",
            r.pose_check.dropped,
            r.pose_check.poses,
            r.pose_check
                .examples
                .iter()
                .fold(0.0f64, |m, d| m.max(d.off_m))
        );
    }
    for (why, n) in &r.skipped {
        outln!("  skipped {n} frames: {why}");
    }
    for p in &r.problems {
        outln!("  problem: {p}");
    }
    let o = &r.observations;
    outln!(
        "  depth points: {} kept, {} outside the thermal view, {} hidden from it, {} grazing, {} on strong thermal edges",
        o.kept,
        o.outside,
        o.occluded,
        o.grazing,
        o.edge
    );
    if r.icp.enabled {
        outln!(
            "  ICP: {} of {} refinements accepted (mean fitness {:.2}, inlier RMSE {:.1} mm); final correction {:.1} cm, {:.2}°",
            r.icp.accepted,
            r.icp.attempted,
            r.icp.mean_fitness,
            r.icp.mean_inlier_rmse_m * 1e3,
            r.icp.final_correction_m * 100.0,
            r.icp.final_correction_deg
        );
        for (why, n) in &r.icp.rejected {
            outln!("    rejected {n}: {why}");
        }
    }
    outln!(
        "wrote cloud.ply, fusion.json, poses.txt in {}",
        a.out.display()
    );
    Ok(())
}
