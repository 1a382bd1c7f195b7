//! Recording sources from the command line: `thermal` on real FLIR files, `convert` between the
//! recording layout and bags, MCAP files and RTAB-Map databases, `inspect`, and `fuse` / `run`
//! reading those sources directly with the same results as from the folder.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde_json::Value;

use crate::{mrtmap, ok};

fn shared(sub: &str) -> Option<PathBuf> {
    let dir = std::env::var_os("MRTMAP_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let d = dir.join(sub);
    d.is_dir().then_some(d)
}

fn fails(args: &[&str]) -> String {
    let o = mrtmap(args);
    assert!(!o.status.success(), "mrtmap {args:?} should fail");
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// A 6 s office scan at 160×120, with its bag, MCAP file and databases, made once.
fn sources() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap().keep();
        let s = |p: &str| dir.join(p).to_str().unwrap().to_string();
        ok(&[
            "simulate",
            "--room",
            "office",
            "--out",
            &s("scan"),
            "--seconds",
            "6",
            "--depth-size",
            "160x120",
            "--noise",
            "none",
            "--truth-rays",
            "200",
        ]);
        ok(&[
            "convert",
            &s("scan"),
            "--out",
            &s("scan.bag"),
            "--compression",
            "bz2",
        ]);
        ok(&[
            "convert",
            &s("scan"),
            "--out",
            &s("scan.mcap"),
            "--compression",
            "lz4",
        ]);
        ok(&["convert", &s("scan"), "--out", &s("scan.db")]);
        ok(&["convert", &s("scan"), "--out", &s("scan.db3")]);
        ok(&[
            "convert",
            &s("scan"),
            "--out",
            &s("legacy.db"),
            "--schema",
            "legacy",
        ]);
        dir
    })
}

#[test]
fn thermal_prints_metadata_and_exports_a_flir_jpeg() {
    let Some(dir) = shared("flir-rjpeg") else {
        return;
    };
    let out = tempfile::tempdir().unwrap();
    let csv = out.path().join("t.csv");
    let png = out.path().join("t.png");
    let f = dir.join("ax8.jpg");
    let text = ok(&[
        "thermal",
        f.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
    ]);
    assert!(text.contains("FLIR radiometric JPEG, 80×60"), "{text}");
    assert!(
        text.contains("PlanckR1") && text.contains("FLIR AX8"),
        "{text}"
    );
    assert!(
        text.contains("min 24.36") && text.contains("max 25.47"),
        "{text}"
    );
    let rows: Vec<&str> = std::fs::read_to_string(&csv)
        .unwrap()
        .leak()
        .lines()
        .collect();
    assert_eq!(rows.len(), 60);
    assert_eq!(rows[0].split(',').count(), 80);
    let first: f64 = rows[0].split(',').next().unwrap().parse().unwrap();
    assert!((first - 24.7915).abs() < 0.01, "{first}");
    assert_eq!(image::image_dimensions(&png).unwrap(), (80, 60));
    let j: Value = serde_json::from_str(&ok(&[
        "thermal",
        f.to_str().unwrap(),
        "--json",
        "--emissivity",
        "0.5",
    ]))
    .unwrap();
    assert!(
        j["mean_c"].as_f64().unwrap() > 25.5,
        "a lower emissivity reads warmer here: {j}"
    );
    let e = fails(&["thermal", f.to_str().unwrap(), "--emissivity", "1.5"]);
    assert!(e.contains("--emissivity 1.5"), "{e}");
    // Below absolute zero is refused (it was read as a reflected temperature); a negative
    // distance is named by its range, not taken for a flag.
    let e = fails(&["thermal", f.to_str().unwrap(), "--reflected", "-300"]);
    assert!(
        e.contains("--reflected -300") && e.contains("−273.15"),
        "{e}"
    );
    let e = fails(&["thermal", f.to_str().unwrap(), "--atmospheric", "-300"]);
    assert!(e.contains("--atmospheric -300"), "{e}");
    let e = fails(&["thermal", f.to_str().unwrap(), "--distance", "-5"]);
    assert!(
        e.contains("--distance -5") && e.contains("0 or more"),
        "{e}"
    );
    let e = fails(&["thermal", "no-such-file.jpg"]);
    assert!(e.contains("no-such-file.jpg"), "{e}");
}

#[test]
fn inspect_lists_streams_and_what_is_missing() {
    let d = sources();
    let s = |p: &str| d.join(p).to_str().unwrap().to_string();
    let text = ok(&["inspect", &s("scan.bag")]);
    assert!(text.contains("ROS 1 bag"), "{text}");
    assert!(
        text.contains("/thermal/image_raw") && text.contains("mono16 160×120"),
        "{text}"
    );
    assert!(text.contains("ready"), "{text}");
    let j: Value = serde_json::from_str(&ok(&["inspect", &s("scan.mcap"), "--json"])).unwrap();
    assert_eq!(j["ready"], true);
    let depth = j["topics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["topic"] == "/camera/aligned_depth_to_color/image_raw")
        .unwrap();
    assert_eq!(depth["count"], 180);
    // A ROS 2 bag in SQLite storage lists the same streams.
    let text = ok(&["inspect", &s("scan.db3")]);
    assert!(
        text.contains("ROS 2 bag (SQLite storage)")
            && text.contains("sensor_msgs/msg/Image")
            && text.contains("ready"),
        "{text}"
    );
    assert!((depth["t1"].as_f64().unwrap() - depth["t0"].as_f64().unwrap() - 5.967).abs() < 0.01);
    // A database lacks thermal frames and the thermal camera until they are given.
    let text = ok(&["inspect", &s("scan.db")]);
    assert!(
        text.contains("optimised (Admin.opt_poses)") && text.contains("30 RVL"),
        "{text}"
    );
    assert!(
        text.contains("missing for a scan") && text.contains("--thermal"),
        "{text}"
    );
    let text = ok(&[
        "inspect",
        &s("legacy.db"),
        "--rig",
        &s("scan/rig.toml"),
        "--thermal",
        &s("scan"),
    ]);
    assert!(
        text.contains("odometry (Node.pose")
            && text.contains("1 loop closure: convert optimises it")
            && text.contains("ready"),
        "{text}"
    );
    let text = ok(&["inspect", &s("scan")]);
    assert!(text.contains("thermal") && text.contains("8.7"), "{text}");
    let e = fails(&["inspect", &s("scan/rig.toml")]);
    assert!(e.contains("not a scan source"), "{e}");
}

#[test]
fn convert_round_trips_every_source() {
    let d = sources();
    let s = |p: &str| d.join(p).to_str().unwrap().to_string();
    let out = tempfile::tempdir().unwrap();
    let o = |p: &str| out.path().join(p).to_str().unwrap().to_string();
    let orig = json(&d.join("scan/truth.json"));
    assert!(orig.is_object());
    for (src, extra) in [
        ("scan.bag", vec![]),
        ("scan.mcap", vec![]),
        ("scan.db3", vec![]),
        (
            "scan.db",
            vec![
                "--rig".to_string(),
                s("scan/rig.toml"),
                "--thermal".into(),
                s("scan.bag"),
            ],
        ),
        (
            "legacy.db",
            vec![
                "--rig".to_string(),
                s("scan/rig.toml"),
                "--thermal".into(),
                s("scan"),
            ],
        ),
    ] {
        let name = src.replace('.', "-");
        let mut args = vec!["convert".to_string(), s(src), "--out".into(), o(&name)];
        args.extend(extra);
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let text = ok(&a);
        assert!(text.contains("52 thermal"), "{src}: {text}");
        let conv = out.path().join(&name);
        assert!(conv.join("source.json").is_file());
        // Depth and thermal frames are the originals, byte for byte after decoding.
        let first_depth = |dir: &Path| {
            let list = std::fs::read_to_string(dir.join("depth.txt")).unwrap();
            let line = list
                .lines()
                .find(|l| !l.starts_with('#'))
                .unwrap()
                .to_string();
            let mut it = line.split_whitespace();
            let t: f64 = it.next().unwrap().parse().unwrap();
            (
                t,
                image::open(dir.join(it.next().unwrap()))
                    .unwrap()
                    .to_luma16(),
            )
        };
        let (tc, ic) = first_depth(&conv);
        let list = std::fs::read_to_string(d.join("scan/depth.txt")).unwrap();
        let line = list
            .lines()
            .filter(|l| !l.starts_with('#'))
            .min_by(|a, b| {
                let ta: f64 = a.split_whitespace().next().unwrap().parse().unwrap();
                let tb: f64 = b.split_whitespace().next().unwrap().parse().unwrap();
                (ta - tc).abs().total_cmp(&(tb - tc).abs())
            })
            .unwrap();
        let io = image::open(d.join("scan").join(line.split_whitespace().nth(1).unwrap()))
            .unwrap()
            .to_luma16();
        assert_eq!(ic, io, "{src}");
        let rig = std::fs::read_to_string(conv.join("rig.toml")).unwrap();
        assert!(rig.contains("fx = 96.25"), "{src}: {rig}");
        // Poses are the scan's: saved optimised poses (scan.db), or the graph optimised here from
        // odometry drifting 1 cm per node and one loop closure (legacy.db: 29 cm by the end).
        if src.ends_with(".db") {
            assert_eq!(
                text.contains("graph optimised here"),
                src == "legacy.db",
                "{src}: {text}"
            );
            let a = mrtmap_io::Recording::open(&d.join("scan")).unwrap();
            let b = mrtmap_io::Recording::open(&conv).unwrap();
            let limits = mrtmap_io::InterpolationLimits::default();
            let worst = b
                .trajectory
                .stamps
                .iter()
                .zip(&b.trajectory.poses)
                .map(|(t, p)| {
                    let want = a.trajectory.interpolate(*t, &limits).unwrap();
                    (p.translation.vector - want.translation.vector).norm()
                })
                .fold(0.0, f64::max);
            // Optimising spreads the drift between positions and headings, so the truth is not
            // the least-squares optimum exactly: within a tenth of the odometry's final drift.
            let drift = 0.01 * (b.trajectory.len() - 1) as f64;
            let bound = if src == "legacy.db" {
                0.1 * drift
            } else {
                1e-3
            };
            println!("{src}: poses off by up to {worst:.4} m (odometry drift {drift:.2} m)");
            assert!(worst < bound, "{src}: poses off by up to {worst} m");
        }
    }
    // Without the thermal frames a database cannot become a scan, and nothing is written.
    let e = fails(&["convert", &s("scan.db"), "--out", &o("no")]);
    assert!(e.contains("--thermal") && e.contains("--rig"), "{e}");
    assert!(!out.path().join("no").exists());
    // A bag cut in the middle names the file and the byte.
    let bag = std::fs::read(d.join("scan.bag")).unwrap();
    let cut = out.path().join("cut.bag");
    std::fs::write(&cut, &bag[..bag.len() / 2]).unwrap();
    let e = fails(&["convert", cut.to_str().unwrap(), "--out", &o("cut")]);
    assert!(e.contains("cut.bag") && e.contains("at byte"), "{e}");
}

#[test]
fn fuse_reads_a_bag_and_a_database_directly() {
    let d = sources();
    let s = |p: &str| d.join(p).to_str().unwrap().to_string();
    let out = tempfile::tempdir().unwrap();
    let o = |p: &str| out.path().join(p).to_str().unwrap().to_string();
    ok(&["fuse", &s("scan"), "--out", &o("folder")]);
    let text = ok(&["fuse", &s("scan.mcap"), "--out", &o("mcap")]);
    assert!(
        text.contains("wrote") && out.path().join("mcap/recording/rig.toml").is_file(),
        "{text}"
    );
    let a = json(&out.path().join("folder/fusion.json"));
    let b = json(&out.path().join("mcap/fusion.json"));
    assert_eq!(a["voxels"], b["voxels"]);
    assert_eq!(a["observations"], b["observations"]);
    assert_eq!(a["used_frames"], b["used_frames"]);
    // A second fuse reuses the conversion.
    let text = ok(&["fuse", &s("scan.mcap"), "--out", &o("mcap")]);
    assert!(text.contains("converted earlier"), "{text}");
    // A ROS 2 bag folder: reused while its files are unchanged, converted again when one changes
    // (the folder's own size and time do not change when a file inside is rewritten).
    let ros2 = out.path().join("rosbag2_scan");
    std::fs::create_dir_all(&ros2).unwrap();
    std::fs::write(ros2.join("metadata.yaml"), "rosbag2_bagfile_information:\n").unwrap();
    let db3 = std::fs::read(d.join("scan.db3")).unwrap();
    std::fs::write(ros2.join("rosbag2_scan_0.db3"), &db3).unwrap();
    let r2 = ros2.to_str().unwrap();
    let text = ok(&["fuse", r2, "--out", &o("ros2")]);
    assert!(!text.contains("converted earlier"), "{text}");
    let c = json(&out.path().join("ros2/fusion.json"));
    assert_eq!(a["voxels"], c["voxels"]);
    let text = ok(&["fuse", r2, "--out", &o("ros2")]);
    assert!(text.contains("converted earlier"), "{text}");
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::write(ros2.join("rosbag2_scan_0.db3"), &db3).unwrap();
    let text = ok(&["fuse", r2, "--out", &o("ros2")]);
    assert!(!text.contains("converted earlier"), "{text}");
    let text = ok(&[
        "fuse",
        &s("scan.db"),
        "--out",
        &o("db"),
        "--rig",
        &s("scan/rig.toml"),
        "--thermal",
        &s("scan.db3"),
    ]);
    assert!(text.contains("optimised"), "{text}");
    let c = json(&out.path().join("db/fusion.json"));
    assert!(c["used_frames"].as_u64().unwrap() >= 5, "{c}");
}

#[test]
fn run_on_an_mcap_file_maps_the_same_as_on_the_folder() {
    let rec = crate::pipeline::recording();
    let out = tempfile::tempdir().unwrap();
    let mcap = out.path().join("scan.mcap");
    let r = rec.to_str().unwrap();
    ok(&["convert", r, "--out", mcap.to_str().unwrap()]);
    let a = out.path().join("folder");
    let b = out.path().join("mcap");
    ok(&["run", r, "--out", a.to_str().unwrap(), "--grid", "6x5"]);
    ok(&[
        "run",
        mcap.to_str().unwrap(),
        "--out",
        b.to_str().unwrap(),
        "--grid",
        "6x5",
    ]);
    let ga = std::fs::read_to_string(a.join("map-1.10m/mrt_grid.csv")).unwrap();
    let gb = std::fs::read_to_string(b.join("map-1.10m/mrt_grid.csv")).unwrap();
    // The same map. Only the ± differs: the simulated rig states its camera's absolute accuracy
    // (exact), which MCAP does not carry, so the converted scan assumes a Lepton's ±5 K (and the
    // unseen-areas part moved by 0.0001 K at one node of 30 on 2026-12-04).
    let header: Vec<&str> = ga.lines().next().unwrap().split(',').collect();
    let se_columns: Vec<usize> = header
        .iter()
        .enumerate()
        .filter(|(_, h)| h.ends_with("std_error_k"))
        .map(|(k, _)| k)
        .collect();
    assert_eq!(se_columns.len(), 6, "{header:?}");
    let without_se = |g: &str| -> Vec<String> {
        g.lines()
            .map(|l| {
                l.split(',')
                    .enumerate()
                    .filter(|(k, _)| !se_columns.contains(k))
                    .map(|(_, c)| c)
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .collect()
    };
    assert_eq!(without_se(&ga), without_se(&gb));
    let se = |g: &str| -> Vec<f64> {
        g.lines()
            .skip(1)
            .filter_map(|l| l.split(',').nth(4)?.parse().ok())
            .collect()
    };
    // The folder's ± is sampling, temperatures and a centimetre of placement (a tenth of a kelvin
    // or more beside the window); the converted scan's adds the camera's ±5 K.
    let (max_a, min_b) = (
        se(&ga).into_iter().fold(0.0, f64::max),
        se(&gb).into_iter().fold(f64::INFINITY, f64::min),
    );
    assert!(
        max_a < 1.0 && min_b > 4.9,
        "folder ± up to {max_a} K, MCAP ± from {min_b} K"
    );
}
