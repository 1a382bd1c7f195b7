//! `mrtmap track`: poses for a recording without a pose source.

use mrtmap_pipeline::files::Recording;
use mrtmap_pipeline::layout::TrackDir;
use mrtmap_pipeline::run::track_into;
use mrtmap_pipeline::settings::TrackSection;

use crate::cli::TrackArgs;
use crate::output::Bar;

pub fn run(a: &TrackArgs) -> anyhow::Result<()> {
    mrtmap_pipeline::run::check_out_apart(&a.recording, &a.out)?;
    let rec = Recording::open(&a.recording)?;
    for w in &rec.warnings {
        eprintln!("warning: {w}");
    }
    let params = TrackSection {
        loop_closure: !a.no_loops,
        use_imu: !a.no_imu,
        fast_threshold: a.fast_threshold,
        ..TrackSection::default()
    }
    .params();
    let bar = Bar::new(" frames");
    let (traj, r) = track_into(&rec, &params, &a.out, &bar)?;
    bar.finish();
    for w in r.warnings() {
        eprintln!("warning: {w}");
    }
    outln!(
        "tracked {} of {} colour frames in {:.1} s: {} keyframes, {} loop closures accepted of {} tried, {} frames lost, {} found again, {} placed by depth alone",
        r.tracked,
        r.frames,
        r.seconds,
        r.keyframes,
        r.loops_accepted,
        r.loops_tried,
        r.lost,
        r.relocalised,
        r.depth_only
    );
    outln!(
        "  {:.0} corners per frame, {:.0} inliers per tracked frame, reprojection {:.2} px; {} frames without depth near in time; {}",
        r.mean_corners,
        r.mean_inliers,
        r.mean_reprojection_px,
        r.unsynced,
        if r.gyro_samples > 0 {
            format!(
                "rotation predicted from {} gyro samples (imu.txt)",
                r.gyro_samples
            )
        } else {
            "no gyro: constant-velocity prediction".to_string()
        }
    );
    if let Some(e) = r.accuracy {
        outln!(
            "  against groundtruth.txt ({} poses): ATE RMSE {:.1} mm (max {:.1} mm), {:.2}° after alignment; frame to frame {:.2} mm, {:.3}°; over {:.2} s: {:.1} mm, {:.2}° (RMSE)",
            e.poses,
            e.ate_rmse_m * 1000.0,
            e.ate_max_m * 1000.0,
            e.ate_rotation_rmse_deg,
            e.rpe_translation_rmse_m * 1000.0,
            e.rpe_rotation_rmse_deg,
            e.drift_span_s,
            e.drift_translation_rmse_m * 1000.0,
            e.drift_rotation_rmse_deg
        );
    }
    outln!(
        "wrote {} poses to {}",
        traj.len(),
        TrackDir::new(&a.out).trajectory_txt().display()
    );
    Ok(())
}
