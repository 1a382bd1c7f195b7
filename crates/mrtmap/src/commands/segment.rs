//! `mrtmap segment`: thermal cloud → radiant scene.

use mrtmap_pipeline::run::{SegmentJob, SegmentReport, Votes, segment_folder};

use crate::cli::SegmentArgs;

pub fn run(a: &SegmentArgs) -> anyhow::Result<()> {
    let report = segment_folder(&SegmentJob {
        fused: &a.fused,
        masks: a.masks.as_deref(),
        recording: a.recording.as_deref(),
        section: a.section.clone(),
        origin_corner: a.origin_corner,
        references: a.references.as_deref(),
        out: &a.out,
    })?;
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
