//! # mrtmap-export
//!
//! The measured room for the tools of the building trade, and their models back as rooms to map:
//!
//! ```text
//!  RadiantScene ──► hbjson::write  ──► Honeybee model (Ladybug Tools), temperatures in user_data
//!               ──► gbxml::write   ──► gbXML 6.01 (Revit, IES, OpenStudio), temperatures in Descriptions
//!               ──► gltf::write    ──► glTF 2.0 binary (Blender, web viewers), temperature vertex colours
//!               ──► radiance::write──► Radiance polygons and materials (daylight, glare)
//!  Honeybee model + temperatures.csv ──► hbjson::read ──► SceneFile
//! ```
//!
//! Every writer takes the scene in its own frame (the room's, for a scan: z up, metres) and
//! returns bytes or text; nothing here touches files.

pub mod gbxml;
pub mod gltf;
pub mod hbjson;
pub mod radiance;

use mrtmap_radiation::ElementKind;
use std::collections::HashSet;

/// Errors of reading a Honeybee model or a temperatures table.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ImportError {
    /// The model is not what Honeybee writes.
    #[error("{at}: {problem}")]
    Model {
        /// Where in the model (a JSON path such as `rooms[0].faces[3].geometry`).
        at: String,
        /// What is wrong and what to do.
        problem: String,
    },
    /// A line of the temperatures table is wrong.
    #[error("line {line}: {problem}")]
    Table {
        /// 1-based line.
        line: usize,
        /// What is wrong and what to do.
        problem: String,
    },
}

/// A point cloud to export beside the scene: positions in the scene's frame (m) and temperatures.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CloudPoints {
    /// Positions (m).
    pub positions: Vec<[f32; 3]>,
    /// Temperature of each point (°C).
    pub temperature_c: Vec<f32>,
}

/// Identifiers as Honeybee and gbXML accept them: letters, digits, `.`, `_` and `-`, at most
/// 100 characters, unique (a clash gets `_2`, `_3` …).
#[derive(Debug, Default)]
pub(crate) struct Identifiers {
    used: HashSet<String>,
}

impl Identifiers {
    /// A valid, unused identifier for `name`.
    pub(crate) fn make(&mut self, name: &str) -> String {
        let mut base: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') {
                    c
                } else {
                    '_'
                }
            })
            .take(90)
            .collect();
        if base.is_empty() || !base.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
            base.insert(0, '_');
        }
        let mut id = base.clone();
        let mut k = 2;
        while !self.used.insert(id.clone()) {
            id = format!("{base}_{k}");
            k += 1;
        }
        id
    }
}

/// What kind of opening in its surface a feature is, for Honeybee and gbXML.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Opening {
    /// Glazing: a Honeybee Aperture, a gbXML window or skylight.
    Window,
    /// A door (a glass door too): a Honeybee Door, a gbXML door.
    Door,
}

/// The opening a feature's label names, if any ([`ElementKind`], the one vocabulary): a door when
/// it is a door (a glazed door too), else a window when it is glazing; lights, paintings and
/// radiators are no openings.
pub fn opening(label: &str) -> Option<Opening> {
    let kind = ElementKind::of_label(label);
    if kind.is_door() {
        Some(Opening::Door)
    } else if kind.is_glazing() {
        Some(Opening::Window)
    } else {
        None
    }
}

/// Whether a feature's label names glazing (glass for Radiance; see [`opening`]).
pub fn is_glazing(label: &str) -> bool {
    ElementKind::of_label(label).is_glazing()
}

/// A number as text with at most `digits` decimals and no "-0".
pub(crate) fn num(x: f64, digits: usize) -> String {
    let s = format!("{x:.digits$}");
    let t = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if t == "-0" { "0".to_string() } else { t }
}
