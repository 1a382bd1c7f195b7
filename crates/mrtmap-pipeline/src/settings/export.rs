//! `[export]`: the formats a run also writes the measured room in, and the formats themselves.

use std::path::Path;

use serde::{Deserialize, Serialize};

/// The formats a room is exported to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
#[value(rename_all = "snake_case")]
pub enum ExportFormat {
    /// Honeybee model (Ladybug Tools), `.hbjson`.
    Hbjson,
    /// gbXML 6.01, `.xml`.
    Gbxml,
    /// glTF 2.0 binary with the thermal cloud, `.glb`.
    Gltf,
    /// Radiance scene description, `.rad`.
    Rad,
}

impl ExportFormat {
    /// Every format.
    pub const ALL: [Self; 4] = [Self::Hbjson, Self::Gbxml, Self::Gltf, Self::Rad];

    /// The file name extension.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Hbjson => "hbjson",
            Self::Gbxml => "xml",
            Self::Gltf => "glb",
            Self::Rad => "rad",
        }
    }

    /// The format a file name's extension names (.hbjson, .xml or .gbxml, .glb, .rad).
    pub fn from_path(path: &Path) -> Option<Self> {
        let e = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match e.as_str() {
            "hbjson" => Self::Hbjson,
            "xml" | "gbxml" => Self::Gbxml,
            "glb" => Self::Gltf,
            "rad" => Self::Rad,
            _ => return None,
        })
    }

    /// The format named `name` (hbjson, gbxml, gltf, rad; as in flags and files).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.as_str() == name)
    }

    /// Its name in flags and files.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Hbjson => "hbjson",
            Self::Gbxml => "gbxml",
            Self::Gltf => "gltf",
            Self::Rad => "rad",
        }
    }
}

/// `[export]` in project.toml: what `mrtmap run` also writes (into `export/` of its output).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExportSection {
    /// Formats to write (`["hbjson", "gbxml", "gltf", "rad"]`); none by default.
    pub formats: Vec<ExportFormat>,
    /// Most points of the thermal cloud in the glTF (evenly thinned; 0 leaves the cloud out).
    pub max_points: Option<usize>,
}

/// Most cloud points in a glTF by default: about 5 MB.
pub const DEFAULT_MAX_POINTS: usize = 200_000;
