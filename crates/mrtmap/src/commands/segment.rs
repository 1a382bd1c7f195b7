//! `mrtmap segment`: thermal cloud → radiant scene.

use anyhow::bail;
use mrtmap_pipeline::files::Recording;
use mrtmap_pipeline::level::{DEFAULT_CAMERA_ACCURACY_K, read_references};
use mrtmap_pipeline::run::{LevelInputs, SegmentInputs, segment_into};
use mrtmap_pipeline::run::{SegmentReport, Votes};
use mrtmap_pipeline::settings::{RoomSection, SegmentSection};

use crate::cli::SegmentArgs;

pub fn run(a: &SegmentArgs) -> anyhow::Result<()> {
    if !a.fused.join("cloud.ply").exists() {
        bail!(
            "{} has no cloud.ply: give the output folder of `mrtmap fuse`",
            a.fused.display()
        );
    }
    let masks = match &a.masks {
        Some(dir) => {
            let r = Recording::open(dir)?;
            if r.masks.is_empty() {
                bail!("{} lists no masks (masks.txt)", dir.display());
            }
            Some(r)
        }
        None => None,
    };
    let recording = match (&a.recording, masks) {
        (Some(dir), _) => Some(Recording::open(dir)?),
        (None, m) => m,
    };
    let section = SegmentSection {
        feature_threshold_k: a.feature_threshold_k,
        feature_min_area_m2: a.feature_min_area_m2,
        raster_m: a.raster_m,
        masks: a.masks.is_some(),
        texture: recording.is_some(),
    };
    section.check()?;
    let inputs = SegmentInputs {
        recording: recording.as_ref(),
        masks: section.masks,
        texture: section.texture,
    };
    let room = RoomSection {
        origin_corner: a.origin_corner,
    };
    room.check()?;
    let level = LevelInputs {
        references: match &a.references {
            Some(f) => read_references(f)?,
            None => Vec::new(),
        },
        camera_accuracy_k: DEFAULT_CAMERA_ACCURACY_K,
    };
    let report = segment_into(&a.fused, &inputs, &section.params(&room), &level, &a.out)?;
    print_report(&report);
    for w in &report.warnings {
        outln!("  warning: {w}");
    }
    outln!(
        "wrote scene.json, segments.ply, segment.json in {}",
        a.out.display()
    );
    Ok(())
}

/// A label's vote share, in words.
fn votes_text(v: Option<&Votes>) -> String {
    v.map(|v| {
        format!(
            ", {:.0} % of {} votes",
            v.share * 100.0,
            v.votes.values().sum::<usize>()
        )
    })
    .unwrap_or_default()
}

/// The room, its surfaces, features and furniture.
fn print_report(r: &SegmentReport) {
    outln!(
        "room: {} walls, {:.2} m high; {:.0} % of the cloud on no surface (furniture, clutter)",
        r.surfaces.len() - 2,
        r.height_m,
        r.unassigned_fraction * 100.0
    );
    for s in &r.surfaces {
        outln!(
            "  {:<8} {:>6.2} m²  {}  ({:.0} % observed)",
            s.id,
            s.area_m2,
            s.temperature_c
                .map_or("not observed".to_string(), |t| format!(
                    "{t:6.2} °C ± {} K",
                    mrtmap_pipeline::report::numbers::uncertainty(s.temperature_std_k, 2)
                )),
            s.observed_fraction * 100.0
        );
    }
    for f in &r.features {
        outln!(
            "  {:<18} on {:<8} {:6.2} °C ({:+.1} K), {:.2} m², label by {}{}",
            f.id,
            f.host,
            f.temperature_c,
            f.contrast_k,
            f.area_m2,
            f.label_source,
            votes_text(f.votes.as_ref())
        );
    }
    for f in &r.furniture {
        outln!(
            "  {:<18} furniture {:.2} × {:.2} × {:.2} m, {:6.2} °C, label by {}{}",
            f.id,
            f.size_m[0],
            f.size_m[1],
            f.size_m[2],
            f.temperature_c,
            f.label_source,
            votes_text(f.votes.as_ref())
        );
    }
}
