//! `mrtmap fuse`: recording → thermal point cloud.

use anyhow::bail;
use mrtmap_io::{Recording, Trajectory, write_atomic, write_cloud_ply};
use mrtmap_scan::{FuseParams, fuse};

use crate::cli::{FuseArgs, OnOff};
use crate::output::json;

pub(crate) fn progress_bar(what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

pub fn run(a: &FuseArgs) -> anyhow::Result<()> {
    if !(a.voxel_m > 0.001 && a.voxel_m <= 1.0) {
        bail!("--voxel-m {} is outside 0.001…1 m", a.voxel_m);
    }
    if !(a.sync_tolerance_ms > 0.0 && a.sync_tolerance_ms <= 1000.0) {
        bail!(
            "--sync-tolerance-ms {} is outside 0…1000",
            a.sync_tolerance_ms
        );
    }
    let dir = super::source::recording_dir(&a.recording, &a.out, &a.src)?;
    let rec = Recording::open(&dir)?;
    for w in &rec.warnings {
        eprintln!("warning: {w}");
    }
    let mut params = FuseParams {
        voxel_m: a.voxel_m,
        sync_tolerance_s: a.sync_tolerance_ms / 1000.0,
        ..FuseParams::default()
    };
    params.icp.enabled = a.icp == OnOff::On;
    params.depth.stride = a.depth_stride.max(1);
    let bar = progress_bar("fusing thermal frames");
    let fused = fuse(&rec, &params, &|done, total| {
        bar.set_length(total);
        bar.set_position(done);
    });
    bar.finish_and_clear();
    let r = &fused.report;
    let comment = format!(
        "mrtmap thermal cloud of {}\ntemperature_c: radiant (T^4) weighted average of the observations; temperature_std in K\nvoxel {} m, ICP {}",
        a.recording.display(),
        a.voxel_m,
        if params.icp.enabled { "on" } else { "off" }
    );
    write_cloud_ply(&a.out.join("cloud.ply"), &fused.cloud, &comment, &[])?;
    write_atomic(&a.out.join("fusion.json"), json(r)?.as_bytes())?;
    let traj = Trajectory {
        stamps: fused.poses.iter().map(|p| p.0).collect(),
        poses: fused.poses.iter().map(|p| p.1).collect(),
    };
    write_atomic(
        &a.out.join("poses.txt"),
        traj.to_tum("world_from_depth of each fused thermal frame's depth frame, after ICP")
            .as_bytes(),
    )?;
    println!(
        "fused {} of {} thermal frames into {} voxels of {} m in {:.1} s ({:.0} frames/s)",
        r.used_frames, r.thermal_frames, r.voxels, a.voxel_m, r.timing_s.total, r.frames_per_second
    );
    for (why, n) in &r.skipped {
        println!("  skipped {n} frames: {why}");
    }
    for p in &r.problems {
        println!("  problem: {p}");
    }
    let o = &r.observations;
    println!(
        "  depth points: {} kept, {} outside the thermal view, {} hidden from it, {} grazing, {} on strong thermal edges",
        o.kept, o.outside, o.occluded, o.grazing, o.edge
    );
    if r.icp.enabled {
        println!(
            "  ICP: {} of {} refinements accepted (mean fitness {:.2}, inlier RMSE {:.1} mm); final correction {:.1} cm, {:.2}°",
            r.icp.accepted,
            r.icp.attempted,
            r.icp.mean_fitness,
            r.icp.mean_inlier_rmse_m * 1e3,
            r.icp.final_correction_m * 100.0,
            r.icp.final_correction_deg
        );
        for (why, n) in &r.icp.rejected {
            println!("    rejected {n}: {why}");
        }
    }
    println!(
        "wrote cloud.ply, fusion.json, poses.txt in {}",
        a.out.display()
    );
    Ok(())
}
