//! Scans that cannot be used are refused before or at the stage that finds it, saying why (the
//! outside campaign of issue 54): a fusion that places nothing, a bad contact reading.

use std::path::Path;

use crate::mrtmap;
use crate::pipeline::recording;

/// A fusion that places nothing is refused, saying what became of the frames (thermal stamps in
/// milliseconds fused nothing, exited 0, and `run` then blamed the scan for finding no floor).
#[test]
fn a_fusion_that_places_nothing_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("scan");
    linked_copy(recording(), &rec);
    let list = std::fs::read_to_string(rec.join("thermal.txt")).unwrap();
    let ms: String = list
        .lines()
        .map(|l| match l.split_once(' ') {
            Some((t, p)) if !l.starts_with('#') => {
                format!("{:.3} {p}\n", t.parse::<f64>().unwrap() * 1000.0)
            }
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::remove_file(rec.join("thermal.txt")).unwrap();
    std::fs::write(rec.join("thermal.txt"), ms).unwrap();
    for cmd in ["fuse", "run"] {
        let out = dir.path().join(cmd);
        let o = mrtmap(&[cmd, rec.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{cmd}: {err}");
        assert!(
            err.contains("0 of") && err.contains("no depth frame within the sync tolerance"),
            "{cmd}: {err}"
        );
        assert!(!out.join("fuse/stage.json").exists() && !out.join("stage.json").exists());
    }
    std::fs::remove_file(rec.join("thermal.txt")).unwrap();
    std::fs::write(rec.join("thermal.txt"), "# no frames\n").unwrap();
    let o = mrtmap(&[
        "run",
        rec.to_str().unwrap(),
        "--out",
        dir.path().join("e").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("thermal.txt lists no frames"),
        "{err}"
    );
}

/// A bad contact reading is refused before any stage runs (it was refused after fusion's
/// seconds), naming the file and line.
#[test]
fn a_bad_reference_row_is_refused_before_fusion() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("scan");
    linked_copy(recording(), &rec);
    let _ = std::fs::remove_file(rec.join("references.csv"));
    std::fs::write(
        rec.join("references.csv"),
        "label,x,y,z,temperature_c,emissivity\nwall,1,1,1,20.5,1.5\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = mrtmap(&["run", rec.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("references.csv:2"),
        "{err}"
    );
    assert!(!out.join("fuse").exists(), "fusion ran first");
}

/// Issue 63: `run --out` into a folder holding the user's own report.html and run.json is refused
/// (they were overwritten), before any stage; a folder a run made is run into again.
#[test]
fn run_keeps_out_of_a_folder_it_did_not_make() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mine");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("report.html"), "my report").unwrap();
    std::fs::write(out.join("run.json"), "{}").unwrap();
    let o = mrtmap(&[
        "run",
        recording().to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("mrtmap did not write there"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("report.html")).unwrap(),
        "my report"
    );
    assert!(!out.join("fuse").exists());
}

/// `src` copied to `dst` with every file hard-linked.
pub(crate) fn linked_copy(src: &Path, dst: &Path) {
    std::fs::create_dir_all(dst).unwrap();
    for e in std::fs::read_dir(src).unwrap() {
        let e = e.unwrap();
        let to = dst.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            linked_copy(&e.path(), &to);
        } else {
            std::fs::hard_link(e.path(), &to).unwrap();
        }
    }
}
