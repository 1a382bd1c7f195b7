//! `mrtmap track`: poses for a recording without a pose source.

use mrtmap_pipeline::layout::TrackDir;
use mrtmap_pipeline::settings::TrackSection;
use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::TrackArgs;
use crate::output::Bar;

pub fn run(a: &TrackArgs) -> anyhow::Result<()> {
    let project = Project {
        track: TrackSection {
            loop_closure: !a.no_loops,
            use_imu: !a.no_imu,
            fast_threshold: a.fast_threshold,
            ..TrackSection::default()
        },
        ..Project::default()
    };
    let bar = Bar::new(" frames");
    let done = Pipeline::new(Project::resolve_over(project, &Overrides::new())?)
        .progress(&bar)
        .track(&a.recording, &a.out)?;
    bar.finish();
    for w in &done.warnings {
        eprintln!("warning: {w}");
    }
    let (traj, r) = (&done.trajectory, &done.report);
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
