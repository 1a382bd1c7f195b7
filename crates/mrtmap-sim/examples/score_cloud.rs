//! Scores a fused cloud against the truth of the simulated recording it came from.
//! `cargo run --release -p mrtmap-sim --example score_cloud -- RECORDING CLOUD.ply [VOXEL_M]`
#![allow(clippy::unwrap_used, clippy::print_stdout)]

use mrtmap_geometry::nalgebra::{Isometry3, Translation3};
use mrtmap_sim::{Room, RoomFile, Truth, score_cloud};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rec = std::path::Path::new(&args[1]);
    let cloud = mrtmap_io::read_cloud_ply(std::path::Path::new(&args[2]))
        .unwrap()
        .cloud;
    let voxel: f64 = args.get(3).map_or(0.03, |v| v.parse().unwrap());
    let file: RoomFile =
        toml::from_str(&std::fs::read_to_string(rec.join("room.toml")).unwrap()).unwrap();
    // A recording's room.toml gives the emissivities simulated: the room as the camera saw it.
    let room = Room::new(file)
        .unwrap()
        .with_surfaces(mrtmap_sim::Surfaces::Black, 0, mrtmap_sim::IRRADIANCE_RAYS)
        .unwrap();
    let truth: Truth =
        serde_json::from_str(&std::fs::read_to_string(rec.join("truth.json")).unwrap()).unwrap();
    let q = mrtmap_io::unit_quaternion(truth.world_from_room.rotation_xyzw).unwrap();
    let t = truth.world_from_room.translation;
    let wfr = Isometry3::from_parts(Translation3::new(t[0], t[1], t[2]), q);
    println!(
        "{}",
        serde_json::to_string_pretty(&score_cloud(&room, &wfr, &cloud, voxel)).unwrap()
    );
}
