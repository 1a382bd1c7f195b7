//! `mrtmap segment`: thermal cloud → radiant scene.

use anyhow::{Context, bail};
use mrtmap_io::{Recording, Trajectory, read_cloud_ply, write_atomic, write_cloud_ply};
use mrtmap_scan::segment::{MaskInput, SegmentParams, refined_poses, segment};

use crate::cli::SegmentArgs;
use crate::output::json;

pub fn run(a: &SegmentArgs) -> anyhow::Result<()> {
    let cloud_path = a.fused.join("cloud.ply");
    if !cloud_path.exists() {
        bail!(
            "{} has no cloud.ply: give the output folder of `mrtmap fuse`",
            a.fused.display()
        );
    }
    let cloud = read_cloud_ply(&cloud_path)?.cloud;
    let poses = Trajectory::read(&a.fused.join("poses.txt"))
        .with_context(|| format!("{} has no usable poses.txt", a.fused.display()))?;
    let params = SegmentParams {
        feature_threshold_k: a.feature_threshold_k,
        feature_min_area_m2: a.feature_min_area_m2,
        ..SegmentParams::default()
    };
    let rec = match &a.masks {
        Some(dir) => {
            let r = Recording::open(dir)?;
            if r.masks.is_empty() {
                bail!("{} lists no masks (masks.txt)", dir.display());
            }
            Some(r)
        }
        None => None,
    };
    let pose_fn = rec.as_ref().map(|r| refined_poses(r, &poses));
    let mask_input = match (&rec, &pose_fn) {
        (Some(r), Some(f)) => Some(MaskInput {
            recording: r,
            world_from_depth: f,
        }),
        _ => None,
    };
    let seg = segment(&cloud, &poses.poses, mask_input.as_ref(), &params)
        .with_context(|| format!("cannot segment {}", cloud_path.display()))?;
    write_atomic(
        &a.out.join("scene.json"),
        (seg.scene.to_json() + "\n").as_bytes(),
    )?;
    write_cloud_ply(
        &a.out.join("segments.ply"),
        &cloud,
        "mrtmap segments: surface_id indexes segment.json's surfaces, feature_id its features (-1: none)",
        &[
            ("surface_id", &seg.surface_id),
            ("feature_id", &seg.feature_id),
        ],
    )?;
    write_atomic(&a.out.join("segment.json"), json(&seg.report)?.as_bytes())?;
    let r = &seg.report;
    println!(
        "room: {} walls, {:.2} m high; {:.0} % of the cloud on no surface (furniture, clutter)",
        r.surfaces.len() - 2,
        r.height_m,
        r.unassigned_fraction * 100.0
    );
    for s in &r.surfaces {
        println!(
            "  {:<8} {:>6.2} m²  {}  ({:.0} % observed)",
            s.id,
            s.area_m2,
            s.temperature_c
                .map_or("not observed".to_string(), |t| format!(
                    "{t:6.2} °C ± {:.2} K",
                    s.temperature_std_k
                )),
            s.observed_fraction * 100.0
        );
    }
    for f in &r.features {
        let votes = f
            .votes
            .as_ref()
            .map(|v| {
                format!(
                    ", {:.0} % of {} votes",
                    v.share * 100.0,
                    v.votes.values().sum::<usize>()
                )
            })
            .unwrap_or_default();
        println!(
            "  {:<18} on {:<8} {:6.2} °C ({:+.1} K), {:.2} m², label by {}{votes}",
            f.id, f.host, f.temperature_c, f.contrast_k, f.area_m2, f.label_source
        );
    }
    for f in &r.furniture {
        let votes = f
            .votes
            .as_ref()
            .map(|v| {
                format!(
                    ", {:.0} % of {} votes",
                    v.share * 100.0,
                    v.votes.values().sum::<usize>()
                )
            })
            .unwrap_or_default();
        println!(
            "  {:<18} furniture {:.2} × {:.2} × {:.2} m, {:6.2} °C, label by {}{votes}",
            f.id, f.size_m[0], f.size_m[1], f.size_m[2], f.temperature_c, f.label_source
        );
    }
    for w in &r.warnings {
        println!("  warning: {w}");
    }
    println!(
        "wrote scene.json, segments.ply, segment.json in {}",
        a.out.display()
    );
    Ok(())
}
