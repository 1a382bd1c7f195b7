//! Reading a scene: JSON text or a file into a validated [`RadiantScene`].
//!
//! 1. The text is parsed into a [`SceneFile`]; a parse error names the element it is in
//!    (`surfaces[3] (id 'wall-east')`), its line and column.
//! 2. The file is validated ([`RadiantScene::new`]).
//!
//! A file that cannot be read says why by the kind of failure, with its path.

use std::path::Path;

use super::error::{SceneError, SceneLoadError, SceneLoadErrorKind};
use super::file::SceneFile;
use super::model::RadiantScene;

/// The element at `path` in scene JSON `text`, for people: "surfaces[3] (id 'wall-east')"; `None`
/// at the top level.
fn element_named(text: &str, path: &serde_path_to_error::Path) -> Option<String> {
    use serde_path_to_error::Segment;
    let segments: Vec<&Segment> = path.iter().collect();
    if segments.is_empty() || path.to_string() == "." {
        return None;
    }
    let root: Option<serde_json::Value> = serde_json::from_str(text).ok();
    let mut at = root.as_ref();
    let mut id = None;
    for seg in &segments {
        at = match seg {
            Segment::Seq { index } => at.and_then(|v| v.get(*index)),
            Segment::Map { key } => at.and_then(|v| v.get(key.as_str())),
            _ => None,
        };
        if let Some(i) = at.and_then(|v| v.get("id")).and_then(|v| v.as_str()) {
            id = Some(i.to_string());
        }
    }
    Some(match id {
        Some(id) => format!("{path} (id '{id}')"),
        None => path.to_string(),
    })
}

impl RadiantScene {
    /// Parses and validates JSON text.
    pub fn from_json(text: &str) -> Result<Self, SceneError> {
        // A byte-order mark (Windows editors, Excel's exports) is read past, as in every text
        // file mrtmap reads.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut de = serde_json::Deserializer::from_str(text);
        let file: SceneFile = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let element = element_named(text, e.path());
            let e = e.into_inner();
            let message = e
                .to_string()
                .split(" at line ")
                .next()
                .unwrap_or_default()
                .to_string();
            SceneError::Json {
                message: match element {
                    Some(el) => format!("{el}: {message}"),
                    None => message,
                },
                line: e.line(),
                column: e.column(),
            }
        })?;
        Self::new(&file)
    }

    /// Reads, parses and validates a scene file.
    pub fn load(path: &Path) -> Result<Self, SceneLoadError> {
        let wrap = |kind| SceneLoadError {
            path: path.display().to_string(),
            kind,
        };
        let text = std::fs::read_to_string(path).map_err(|e| wrap(SceneLoadErrorKind::Io(e)))?;
        Self::from_json(&text).map_err(|e| wrap(SceneLoadErrorKind::Invalid(e)))
    }
}
