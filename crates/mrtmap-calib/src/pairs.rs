//! Matching colour and thermal images into pairs.
//!
//! Two layouts are read:
//! - sub-folders `rgb/` (or `color/`, `colour/`) and `thermal/` (or `ir/`, `lwir/`): images with
//!   the same file stem pair up; when the stems are all numbers (timestamps in seconds), each
//!   colour image pairs with the nearest thermal image within `max_dt`;
//! - one folder whose file stems carry a camera tag as a prefix or suffix (`0001_rgb.png` with
//!   `0001_thermal.png`, `color_12.jpg` with `ir_12.png`), paired by what remains.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::CalibError;

/// One matched pair.
#[derive(Clone, Debug, PartialEq)]
pub struct ImagePair {
    /// A name for reports (the shared stem, or the colour stem).
    pub name: String,
    /// Colour image.
    pub rgb: PathBuf,
    /// Thermal image.
    pub thermal: PathBuf,
}

/// Pairs and the images left without a partner.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Pairing {
    /// Matched pairs, by name.
    pub pairs: Vec<ImagePair>,
    /// Images without a partner.
    pub unmatched: Vec<PathBuf>,
}

const RGB_TAGS: [&str; 4] = ["rgb", "color", "colour", "vis"];
const THERMAL_TAGS: [&str; 4] = ["thermal", "ir", "lwir", "temp"];
const EXTENSIONS: [&str; 6] = ["png", "jpg", "jpeg", "tif", "tiff", "pgm"];

/// Image files of a folder, sorted by name.
pub fn list_images(dir: &Path) -> Result<Vec<PathBuf>, CalibError> {
    let rd = std::fs::read_dir(dir).map_err(|e| CalibError::file(dir, e.to_string()))?;
    let mut out: Vec<PathBuf> = rd
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.is_file()
                && p.extension()
                    .and_then(|e| e.to_str())
                    .is_some_and(|e| EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        })
        .collect();
    out.sort();
    Ok(out)
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn sub(dir: &Path, names: &[&str]) -> Option<PathBuf> {
    names.iter().map(|n| dir.join(n)).find(|p| p.is_dir())
}

/// Removes a camera tag (prefix or suffix, separated by `_`, `-` or `.`) from a stem.
fn untag(stem: &str, tags: &[&str]) -> Option<String> {
    let lower = stem.to_ascii_lowercase();
    for t in tags {
        for sep in ['_', '-', '.'] {
            let suffix = format!("{sep}{t}");
            if lower.ends_with(&suffix) {
                return Some(stem[..stem.len() - suffix.len()].to_string());
            }
            let prefix = format!("{t}{sep}");
            if lower.starts_with(&prefix) {
                return Some(stem[prefix.len()..].to_string());
            }
        }
    }
    None
}

/// Finds the pairs of `dir` (see the module documentation).
pub fn find_pairs(dir: &Path, max_dt: f64) -> Result<Pairing, CalibError> {
    if !dir.is_dir() {
        return Err(CalibError::file(dir, "is not a folder"));
    }
    if let (Some(rd), Some(td)) = (
        sub(dir, &["rgb", "color", "colour"]),
        sub(dir, &["thermal", "ir", "lwir"]),
    ) {
        let rgb = list_images(&rd)?;
        let th = list_images(&td)?;
        return Ok(pair_lists(&rgb, &th, max_dt));
    }
    let mut rgb = BTreeMap::new();
    let mut th = BTreeMap::new();
    let mut unmatched = Vec::new();
    for p in list_images(dir)? {
        let s = stem(&p);
        if let Some(k) = untag(&s, &THERMAL_TAGS) {
            th.insert(k, p);
        } else if let Some(k) = untag(&s, &RGB_TAGS) {
            rgb.insert(k, p);
        } else {
            unmatched.push(p);
        }
    }
    let mut pairs = Vec::new();
    for (k, r) in rgb {
        match th.remove(&k) {
            Some(t) => pairs.push(ImagePair {
                name: k,
                rgb: r,
                thermal: t,
            }),
            None => unmatched.push(r),
        }
    }
    unmatched.extend(th.into_values());
    if pairs.is_empty() {
        return Err(CalibError::file(
            dir,
            "holds no image pairs: expected rgb/ and thermal/ sub-folders, or files tagged like 0001_rgb.png and 0001_thermal.png",
        ));
    }
    Ok(Pairing { pairs, unmatched })
}

fn pair_lists(rgb: &[PathBuf], th: &[PathBuf], max_dt: f64) -> Pairing {
    let times = |v: &[PathBuf]| -> Option<Vec<f64>> {
        v.iter().map(|p| stem(p).parse::<f64>().ok()).collect()
    };
    let mut pairs = Vec::new();
    let mut unmatched = Vec::new();
    let mut used = vec![false; th.len()];
    if let (Some(tr), Some(tt)) = (times(rgb), times(th)) {
        for (r, t) in rgb.iter().zip(tr) {
            let best = tt
                .iter()
                .enumerate()
                .filter(|(k, _)| !used[*k])
                .min_by(|a, b| (a.1 - t).abs().total_cmp(&(b.1 - t).abs()));
            match best {
                Some((k, tk)) if (tk - t).abs() <= max_dt => {
                    used[k] = true;
                    pairs.push(ImagePair {
                        name: stem(r),
                        rgb: r.clone(),
                        thermal: th[k].clone(),
                    });
                }
                _ => unmatched.push(r.clone()),
            }
        }
    } else {
        for r in rgb {
            let s = stem(r);
            match th.iter().position(|t| stem(t) == s) {
                Some(k) => {
                    used[k] = true;
                    pairs.push(ImagePair {
                        name: s,
                        rgb: r.clone(),
                        thermal: th[k].clone(),
                    });
                }
                None => unmatched.push(r.clone()),
            }
        }
    }
    unmatched.extend(
        th.iter()
            .zip(used)
            .filter(|(_, u)| !u)
            .map(|(p, _)| p.clone()),
    );
    Pairing { pairs, unmatched }
}
