//! Writes small seed inputs for every fuzz target into corpus/<target>/ (run by fuzz/run).
use std::path::Path;

use mrtmap_sources::ros::bag::{BagWriter, Compression};
use mrtmap_sources::ros::mcap::{McapCompression, McapWriter};
use mrtmap_sources::ros::msg::{Wire, encode};
use mrtmap_io::Image16;
use mrtmap_sources::rtabmap::{self, rvl};
use nalgebra::{Isometry3, Vector3};

fn put(target: &str, name: &str, bytes: &[u8]) {
    let d = Path::new("corpus").join(target);
    std::fs::create_dir_all(&d).expect("corpus folder");
    std::fs::write(d.join(name), bytes).expect("seed");
}

fn messages(wire: Wire) -> Vec<(&'static str, &'static str, Vec<u8>)> {
    let cam = mrtmap_geometry::camera::PinholeCamera::new(4, 3, 3.0, 3.0, 1.5, 1.0);
    let p = Isometry3::new(Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.0, 0.1, 0.0));
    let px: Vec<u8> = (0..24u8).collect();
    vec![
        (
            "/tf_static",
            "tf2_msgs/TFMessage",
            encode::tf_message(wire, &[(1.0, "a", "b", p), (1.0, "b", "c", p)]),
        ),
        (
            "/camera/aligned_depth_to_color/camera_info",
            "sensor_msgs/CameraInfo",
            encode::camera_info(wire, 1.0, "b", &cam),
        ),
        (
            "/camera/aligned_depth_to_color/image_raw",
            "sensor_msgs/Image",
            encode::image(wire, 1.0, "b", 4, 3, "16UC1", 8, &px),
        ),
        (
            "/thermal/image_raw",
            "sensor_msgs/Image",
            encode::image(wire, 1.1, "c", 4, 3, "mono16", 8, &px),
        ),
        (
            "/camera/color/image_raw/compressed",
            "sensor_msgs/CompressedImage",
            encode::compressed_image(wire, 1.0, "b", "jpeg", &px),
        ),
        (
            "/camera/odom/sample",
            "nav_msgs/Odometry",
            encode::odometry(wire, 1.0, "odom", "a", &p),
        ),
        (
            "/tf",
            "tf2_msgs/TFMessage",
            encode::tf_message(wire, &[(1.2, "map", "a", p)]),
        ),
    ]
}

fn main() {
    // A Honeybee model (the example office as mrtmap exports it), alone and with a table.
    let office = mrtmap_export::hbjson::write(&mrtmap_radiation::example_office(), "office");
    put("hbjson", "office", office.as_bytes());
    let mut with_table = office.into_bytes();
    with_table.extend_from_slice(b"\0identifier,temperature_c,temperature_std_k\nwindow-1,10.5,0.2\n*,21\n");
    put("hbjson", "office-table", &with_table);
    // The hand-written inputs: the formats' own examples.
    put(
        "references_csv",
        "example",
        b"# readings\nlabel,x,y,z,temperature_c,std_k,frame\nfloor,1.83,0.42,0.00,20.6,0.1,room\nwall x0,-1.30,0.95,0.41,21.0,0.2,scan\n",
    );
    put(
        "globe_csv",
        "example",
        b"label,x,y,z,globe_c,air_c,air_speed_m_s,diameter_m,emissivity\nA,0.75,1.40,1.10,19.94,21.0,0.1,0.15,0.95\n\"B, by the door\",2.1,1.8,1.1,20.7,21,0.1,0.15,0.95\n",
    );
    put(
        "project_toml",
        "example",
        b"[air]\ntemperature_c = 21.0\nspeed_m_s = 0.1\n\n[map]\nheights_m = [1.1, 0.6]\ngrid = [20, 20]\nquantities = [\"pmv\"]\n\n[comfort]\nmet = 1.2\nclo = 0.7\nposture = \"seated\"\n\n[[points]]\nname = \"A\"\nxyz = [0.75, 1.4, 1.1]\n",
    );
    for (i, (_, _, m)) in messages(Wire::Ros1).into_iter().enumerate() {
        put("ros_msg", &format!("ros1-{i}"), &m);
    }
    for (i, (_, _, m)) in messages(Wire::Cdr).into_iter().enumerate() {
        put("ros_msg", &format!("cdr-{i}"), &m);
    }
    for (name, c) in [
        ("none", Compression::None),
        ("bz2", Compression::Bz2),
        ("lz4", Compression::Lz4),
    ] {
        let mut w = BagWriter::new(c, 300);
        for (k, (topic, ty, m)) in messages(Wire::Ros1).into_iter().enumerate() {
            w.write(topic, ty, 1.0 + k as f64 * 0.01, &m);
        }
        put("bag", name, &w.finish().expect("finish"));
    }
    for (name, c) in [
        ("none", None),
        ("zstd", Some(McapCompression::Zstd)),
        ("lz4", Some(McapCompression::Lz4)),
    ] {
        let mut w = McapWriter::new(c, 300).expect("mcap");
        for (k, (topic, ty, m)) in messages(Wire::Cdr).into_iter().enumerate() {
            let (pkg, n) = ty.split_once('/').expect("type");
            w.write(topic, &format!("{pkg}/msg/{n}"), 1.0 + k as f64 * 0.01, &m)
                .expect("write");
        }
        put("mcap", name, &w.finish().expect("finish"));
    }
    for (name, zstd) in [("plain", false), ("zstd", true)] {
        let mut w = mrtmap_sources::ros::db3::Db3Writer::new().expect("db3");
        for (k, (topic, ty, m)) in messages(Wire::Cdr).into_iter().enumerate() {
            let (pkg, n) = ty.split_once('/').expect("type");
            let m = if zstd {
                ::zstd::encode_all(&m[..], 3).expect("zstd")
            } else {
                m
            };
            w.write(topic, &format!("{pkg}/msg/{n}"), 1.0 + k as f64 * 0.01, &m)
                .expect("write");
        }
        put("db3", name, &w.finish().expect("finish"));
    }
    let depth = Image16 {
        width: 8,
        height: 6,
        data: (0..48)
            .map(|i| if i % 5 == 0 { 0 } else { 900 + i * 7 })
            .collect(),
    };
    put(
        "rtabmap_blobs",
        "rvl",
        &rvl::encode_rtabmap(8, 6, &depth.data),
    );
    put("rtabmap_blobs", "png", &mrtmap_io::encode_png16(&depth).expect("encodes"));
    let cam = mrtmap_geometry::camera::PinholeCamera::new(8, 6, 6.0, 6.0, 3.5, 2.5);
    put(
        "rtabmap_blobs",
        "calibration",
        &rtabmap::calibration_blob(&cam, &rtabmap::base_from_optical(), [0, 23, 1]),
    );
    let mut raw = 48u16.to_le_bytes().to_vec();
    raw.extend(rvl::encode(&depth.data));
    put("rtabmap_blobs", "raw-rvl", &raw);
    let lepton: Vec<u8> = (0..160 * 120)
        .flat_map(|i: u32| (29_000 + (i % 160) as u16).to_le_bytes())
        .collect();
    put("thermal_file", "lepton.y16", &lepton);
    put(
        "thermal_file",
        "lepton.png",
        &mrtmap_io::encode_png16(&Image16 {
            width: 16,
            height: 12,
            data: (0..192).map(|i| 29_000 + i).collect(),
        }).expect("encodes"),
    );
    recording_seeds();
}

/// Packs a folder for the recording target: name length, name, 4-byte length, bytes, repeated.
fn pack(dir: &Path, skip: &[&str]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut names = Vec::new();
    for e in std::fs::read_dir(dir).expect("folder").flatten() {
        let p = e.path();
        if p.is_dir() {
            for f in std::fs::read_dir(&p).expect("folder").flatten() {
                names.push(f.path());
            }
        } else {
            names.push(p);
        }
    }
    names.sort();
    for p in names {
        let name = p.strip_prefix(dir).expect("inside").to_string_lossy().into_owned();
        if skip.contains(&name.as_str()) {
            continue;
        }
        let bytes = std::fs::read(&p).expect("file");
        out.push(name.len() as u8);
        out.extend(name.as_bytes());
        out.extend((bytes.len() as u32).to_le_bytes());
        out.extend(bytes);
    }
    out
}

/// A one-second simulated recording at small sizes (64×48 depth and colour, 40×30 thermal), with
/// poses and without; the 25-byte header of zeros is "no edit operations".
fn recording_seeds() {
    let room = mrtmap_sim::preset("office").expect("preset").expect("valid");
    let mut cfg = mrtmap_sim::SimConfig {
        seconds: 1.0,
        truth_rays: 200,
        noise: mrtmap_sim::NoiseLevel::Realistic,
        references: 2,
        ..mrtmap_sim::SimConfig::default()
    };
    cfg.depth_camera = cfg.depth_camera.scaled(0.1);
    cfg.thermal_camera = cfg.thermal_camera.scaled(0.25);
    let dir = std::env::temp_dir().join(format!("mrtmap-fuzz-seed-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    mrtmap_sim::simulate(&room, &cfg, &dir, &|_, _| {}).expect("simulate");
    let skip = ["truth.json", "radiometric_truth.json", "groundtruth.txt"];
    let mut with = vec![0u8; 25];
    with.extend(pack(&dir, &skip));
    put("recording", "sim", &with);
    let mut without = vec![0u8; 25];
    without.extend(pack(&dir, &[&skip[..], &["trajectory.txt"]].concat()));
    put("recording", "sim-no-poses", &without);
    let _ = std::fs::remove_dir_all(&dir);
}
