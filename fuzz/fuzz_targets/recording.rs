//! A recording folder (rig.toml, the stream lists, trajectory.txt, depth/thermal/colour PNGs) with
//! files missing, truncated, corrupted or replaced by frames of another size: opening it, fusing
//! it and tracking it answer or refuse, never panic, and what they count adds up.
//!
//! The input is a fixed header of up to four edit operations followed by a packed folder (see `pack` in
//! examples/seeds.rs: name length, name, 4-byte length, bytes, repeated); the seed is a small
//! simulated recording, so byte mutations exercise the parsers and the operations exercise
//! structure: a stream without its files, a frame of another size, a file cut short.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mrtmap_io::{Image16, Recording, encode_png16, encode_png_rgb8};
use mrtmap_pipeline::{Pipeline, Project};
use std::path::{Path, PathBuf};

/// Unpacks the folder; names that are not plain relative paths are skipped.
fn unpack(mut b: &[u8]) -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    while let Some((&n, rest)) = b.split_first() {
        let n = n as usize;
        if rest.len() < n + 4 {
            break;
        }
        let name = String::from_utf8_lossy(&rest[..n]).into_owned();
        let len = u32::from_le_bytes([rest[n], rest[n + 1], rest[n + 2], rest[n + 3]]) as usize;
        let data = &rest[n + 4..];
        let len = len.min(data.len());
        let plain = !name.is_empty()
            && !name.starts_with('/')
            && name.split('/').count() <= 2
            && name.split('/').all(|c| !c.is_empty() && c != "." && c != "..")
            && name
                .bytes()
                .all(|c| c.is_ascii_alphanumeric() || b"._-/".contains(&c));
        if plain {
            files.push((name, data[..len].to_vec()));
        }
        b = &data[len..];
    }
    files
}

/// Bytes before the packed folder: a count and four operations.
const HEADER: usize = 1 + 4 * 6;

fn scratch() -> PathBuf {
    std::env::temp_dir().join(format!("mrtmap-fuzz-recording-{}", std::process::id()))
}

fuzz_target!(|data: &[u8]| {
    // A fixed header: how many of the four operations apply, then four operations of 6 bytes
    // (kind, file, a (u16), b (u16)), so that the packed folder after it stays aligned whatever
    // the header says.
    if data.len() < HEADER {
        return;
    }
    let (header, packed) = data.split_at(HEADER);
    let n_ops = (header[0] % 5) as usize;
    let ops = &header[1..1 + 6 * n_ops];
    let mut files = unpack(packed);
    if files.is_empty() {
        return;
    }
    for op in ops.chunks(6) {
        let i = op[1] as usize % files.len();
        let a = u16::from_le_bytes([op[2], op[3]]) as usize;
        let b = u16::from_le_bytes([op[4], op[5]]) as usize;
        match op[0] % 4 {
            0 => {
                files.remove(i);
                if files.is_empty() {
                    return;
                }
            }
            1 => {
                let len = files[i].1.len();
                files[i].1.truncate(if len == 0 { 0 } else { a % len });
            }
            2 if files[i].0.ends_with(".png") => {
                // A valid frame of another size (1…320 × 1…240), of the stream's pixel type.
                let (w, h) = (1 + a % 320, 1 + b % 240);
                files[i].1 = if files[i].0.starts_with("rgb/") {
                    encode_png_rgb8(w as u32, h as u32, &vec![128; w * h * 3])
                } else {
                    encode_png16(&Image16 {
                        width: w as u32,
                        height: h as u32,
                        data: (0..w * h).map(|k| (1000 + k % 3000) as u16).collect(),
                    })
                }
                .expect("encode");
            }
            _ => {
                // A line of a text file doubled or dropped.
                let f = &mut files[i].1;
                if let Ok(text) = std::str::from_utf8(f) {
                    let mut lines: Vec<&str> = text.lines().collect();
                    if !lines.is_empty() {
                        let k = a % lines.len();
                        if b % 2 == 0 {
                            lines.insert(k, lines[k]);
                        } else {
                            lines.remove(k);
                        }
                        *f = (lines.join("\n") + "\n").into_bytes();
                    }
                }
            }
        }
    }
    let dir = scratch();
    let _ = std::fs::remove_dir_all(&dir);
    let rec_dir = dir.join("rec");
    for (name, bytes) in &files {
        let p = rec_dir.join(name);
        std::fs::create_dir_all(p.parent().unwrap_or(Path::new("."))).expect("scratch folder");
        std::fs::write(&p, bytes).expect("scratch file");
    }
    let Ok(rec) = Recording::open(&rec_dir) else {
        return;
    };
    let pipeline = Pipeline::new(Project::default());
    if let Ok(done) = pipeline.fuse(&rec_dir, &dir.join("fuse")) {
        let report = done.report;
        let skipped: usize = report.skipped.values().sum();
        assert_eq!(report.used_frames + skipped, report.thermal_frames);
        assert_eq!(report.thermal_frames, rec.thermal.len());
    }
    if !rec.rgb.is_empty()
        && let Ok(done) = pipeline.track(&rec_dir, &dir.join("track"))
    {
        let (traj, report) = (done.trajectory, done.report);
        assert!(traj.len() <= rec.rgb.len());
        assert!(report.wrong_size <= rec.rgb.len());
    }
});
