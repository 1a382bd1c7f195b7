//! Scores a segmented scene.json against the truth of the simulated recording.
//! `cargo run --release -p mrtmap-sim --example score_scene -- RECORDING SCENE.json [--json]`
#![allow(clippy::unwrap_used, clippy::print_stdout)]

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let truth: mrtmap_sim::Truth = serde_json::from_str(
        &std::fs::read_to_string(std::path::Path::new(&args[1]).join("truth.json")).unwrap(),
    )
    .unwrap();
    let scene = mrtmap_radiation::RadiantScene::load(std::path::Path::new(&args[2])).unwrap();
    let s = mrtmap_sim::score_scene(&scene, &truth).unwrap();
    if args.iter().any(|a| a == "--json") {
        println!("{}", serde_json::to_string(&s).unwrap());
        return;
    }
    for x in &s.surfaces {
        println!(
            "surface {:<9} -> {:<8} angle {:6.3}° offset {:6.1} mm  ΔT {:+.3} K",
            x.truth_id,
            x.id.clone().unwrap_or_default(),
            x.angle_deg,
            x.offset_m * 1e3,
            x.temperature_error_k
        );
    }
    println!("corners: max error {:.1} mm", s.corner_max_error_m * 1e3);
    for f in &s.features {
        println!(
            "feature {:<18} ({:<15}) -> {:<22} IoU {:.3}  ΔT {}",
            f.truth_id,
            f.truth_label,
            f.found
                .as_ref()
                .map(|x| format!("{} ({})", x.0, x.1))
                .unwrap_or("-".into()),
            f.iou,
            f.temperature_error_k
                .map(|t| format!("{t:+.3} K"))
                .unwrap_or("-".into())
        );
    }
    println!("spurious features: {:?}", s.spurious_features);
    for p in &s.points {
        println!(
            "MRT {}: truth {:.3} °C, scene {:.3} °C, error {:+.3} K",
            p.name, p.truth_c, p.found_c, p.error_k
        );
    }
}
