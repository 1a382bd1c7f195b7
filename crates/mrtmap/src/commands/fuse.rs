//! `mrtmap fuse`: recording → thermal point cloud.

use mrtmap_pipeline::files::Recording;
use mrtmap_pipeline::run::fuse_into;
use mrtmap_pipeline::source::prepare;

use crate::cli::FuseArgs;
use crate::output::{Bar, print_lines};

pub fn run(a: &FuseArgs) -> anyhow::Result<()> {
    let params = a.fuse.params()?;
    mrtmap_pipeline::run::check_out_apart(&a.recording, &a.out)?;
    let prepared = prepare(&a.recording, &a.out, &a.src)?;
    if let Some(c) = &prepared.conversion {
        print_lines(c.lines());
    } else if prepared.reused {
        outln!(
            "using {} (converted earlier from {})",
            prepared.dir.display(),
            a.recording.display()
        );
    }
    let rec = Recording::open(&prepared.dir)?;
    for w in &rec.warnings {
        eprintln!("warning: {w}");
    }
    let bar = Bar::new("");
    let r = fuse_into(&rec, &params, &a.out, &bar)?;
    bar.finish();
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
