//! Instance masks from a detector (or the simulator): per frame a 16-bit PNG of instance ids
//! (0 = no instance) and a JSON beside it, `{"<id>": {"label": "window", "score": 0.93}, …}`, listed
//! in `masks.txt` like the other streams (`timestamp masks/NAME.png`; the JSON is
//! `masks/NAME.json`). Masks are in the colour camera's image (the depth camera's when a recording
//! has no colour camera).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{FileError, FileErrorKind};

/// One instance of a mask frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InstanceInfo {
    /// Semantic label.
    pub label: String,
    /// Detector confidence 0…1.
    pub score: f64,
}

/// The JSON of one mask frame: instance id → label and score.
pub type MaskLabels = BTreeMap<u16, InstanceInfo>;

/// The JSON path that goes with a mask PNG.
pub fn labels_path(png: &Path) -> PathBuf {
    png.with_extension("json")
}

/// Reads a mask frame's JSON.
pub fn read_mask_labels(path: &Path) -> Result<MaskLabels, FileError> {
    let text = std::fs::read_to_string(path).map_err(|e| FileError::io(path, e))?;
    let raw: BTreeMap<String, InstanceInfo> = serde_json::from_str(&text)
        .map_err(|e| FileError::new(path, Some(e.line()), FileErrorKind::Syntax(e.to_string())))?;
    let mut out = MaskLabels::new();
    for (k, v) in raw {
        let id: u16 = k.parse().ok().filter(|i| *i > 0).ok_or_else(|| {
            FileError::new(
                path,
                None,
                FileErrorKind::Syntax(format!("instance id '{k}' is not 1…65535")),
            )
        })?;
        if !(0.0..=1.0).contains(&v.score) {
            return Err(FileError::new(
                path,
                None,
                FileErrorKind::Syntax(format!("instance {id}: score {} is outside 0…1", v.score)),
            ));
        }
        out.insert(id, v);
    }
    Ok(out)
}

/// JSON text of a mask frame's labels.
pub fn mask_labels_json(labels: &MaskLabels) -> String {
    let m: BTreeMap<String, &InstanceInfo> =
        labels.iter().map(|(k, v)| (k.to_string(), v)).collect();
    serde_json::to_string(&m).unwrap_or_default()
}
