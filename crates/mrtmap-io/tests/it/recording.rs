use mrtmap_io::{Image16, Recording, encode_png16};

const RIG: &str = "[depth]\nwidth = 4\nheight = 3\nfx = 3.0\nfy = 3.0\ncx = 1.5\ncy = 1.0\ndepth_scale = 1000.0\n\n[thermal]\nwidth = 2\nheight = 2\nfx = 2.0\nfy = 2.0\ncx = 0.5\ncy = 0.5\nencoding = \"centikelvin\"\ndepth_from_thermal = { translation = [0.0, 0.0, 0.0], rotation_xyzw = [0.0, 0.0, 0.0, 1.0] }\n";

fn tiny(dir: &std::path::Path) {
    std::fs::create_dir_all(dir.join("depth")).unwrap();
    std::fs::create_dir_all(dir.join("thermal")).unwrap();
    std::fs::write(dir.join("rig.toml"), RIG).unwrap();
    std::fs::write(
        dir.join("depth/0.png"),
        encode_png16(&Image16 {
            width: 4,
            height: 3,
            data: vec![1500; 12],
        })
        .unwrap(),
    )
    .unwrap();
    std::fs::write(
        dir.join("thermal/0.png"),
        encode_png16(&Image16 {
            width: 2,
            height: 2,
            data: vec![29415; 4],
        })
        .unwrap(),
    )
    .unwrap();
    std::fs::write(dir.join("depth.txt"), "1.00 depth/0.png\n").unwrap();
    std::fs::write(dir.join("thermal.txt"), "1.01 thermal/0.png\n").unwrap();
    std::fs::write(
        dir.join("trajectory.txt"),
        "0.9 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 0 1\n",
    )
    .unwrap();
}

#[test]
fn a_minimal_recording_opens_without_warnings_and_reads_frames() {
    let dir = tempfile::tempdir().unwrap();
    tiny(dir.path());
    let r = Recording::open(dir.path()).unwrap();
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    assert_eq!(r.read_depth(&r.depth[0]).unwrap().get(3, 2), 1500);
    assert_eq!(
        r.rig
            .thermal_encoding
            .kelvin(r.read_thermal(&r.thermal[0]).unwrap().get(1, 1)),
        294.15
    );
    assert!(r.groundtruth.is_none() && r.rgb.is_empty());
}

#[test]
fn missing_and_mismatched_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    tiny(dir.path());
    std::fs::write(
        dir.path().join("thermal.txt"),
        "1.01 thermal/0.png\n1.02 thermal/9.png\n",
    )
    .unwrap();
    let e = Recording::open(dir.path()).unwrap_err().to_string();
    assert!(
        e.ends_with("thermal.txt:2: listed file thermal/9.png does not exist"),
        "{e}"
    );

    tiny(dir.path());
    std::fs::remove_file(dir.path().join("trajectory.txt")).unwrap();
    assert!(
        Recording::open(dir.path())
            .unwrap_err()
            .to_string()
            .contains("trajectory.txt")
    );

    tiny(dir.path());
    std::fs::write(
        dir.path().join("depth/0.png"),
        encode_png16(&Image16 {
            width: 5,
            height: 3,
            data: vec![1; 15],
        })
        .unwrap(),
    )
    .unwrap();
    let r = Recording::open(dir.path()).unwrap();
    let e = r.read_depth(&r.depth[0]).unwrap_err().to_string();
    assert!(
        e.ends_with("depth/0.png: image is 5×3 pixels but the rig says 4×3"),
        "{e}"
    );

    tiny(dir.path());
    std::fs::write(dir.path().join("trajectory.txt"), "5.0 0 0 0 0 0 0 1\n").unwrap();
    let r = Recording::open(dir.path()).unwrap();
    assert_eq!(
        r.warnings,
        vec![mrtmap_io::RecordingWarning::ThermalWithoutPose {
            uncovered: 1,
            total: 1
        }]
    );
}

/// Issue 54: a misspelt key was reported as the missing one alone ("missing field `fy`"), and a
/// misspelt optional key was read past without a word.
#[test]
fn a_misspelt_rig_key_is_named() {
    let dir = tempfile::tempdir().unwrap();
    tiny(dir.path());
    let typo = RIG.replace(
        "[thermal]\nwidth = 2\nheight = 2\nfx = 2.0\nfy = 2.0",
        "[thermal]\nwidth = 2\nheight = 2\nfx = 2.0\nfyy = 2.0",
    );
    std::fs::write(dir.path().join("rig.toml"), &typo).unwrap();
    let e = Recording::open(dir.path()).unwrap_err().to_string();
    assert!(e.contains("`fy`") && e.contains("[thermal] fyy"), "{e}");
    // An optional key misspelt, and a section misnamed: the recording opens, with a warning.
    let extra = format!("{RIG}time_ofset_s = -0.05\n\n[colour]\nwidth = 4\n");
    std::fs::write(dir.path().join("rig.toml"), extra).unwrap();
    let r = Recording::open(dir.path()).unwrap();
    assert_eq!(
        r.warnings,
        vec![mrtmap_io::RecordingWarning::UnknownRigKeys(vec![
            "[colour]".to_string(),
            "[thermal] time_ofset_s".to_string()
        ])]
    );
    assert!(
        r.warnings[0]
            .to_string()
            .contains("[colour], [thermal] time_ofset_s")
    );
}

/// A line that repeats the one before (a recorder's retry, a copy-paste) is left out with a
/// warning naming the list and line: a thermal frame listed twice was fused twice without a word.
#[test]
fn a_repeated_line_is_left_out_and_named() {
    let dir = tempfile::tempdir().unwrap();
    tiny(dir.path());
    std::fs::write(
        dir.path().join("thermal.txt"),
        "# t path\n1.01 thermal/0.png\n1.01 thermal/0.png\n1.01 thermal/0.png\n",
    )
    .unwrap();
    let r = Recording::open(dir.path()).unwrap();
    assert_eq!(r.thermal.len(), 1);
    assert_eq!(
        r.warnings,
        vec![mrtmap_io::RecordingWarning::RepeatedLines {
            list: "thermal.txt",
            count: 2,
            first_line: 3
        }]
    );
    let said = r.warnings[0].to_string();
    assert!(
        said.contains("thermal.txt: 2 lines repeat") && said.contains("line 3"),
        "{said}"
    );
}
