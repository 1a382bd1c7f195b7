//! project.toml: what a user sets once per scan. Every key is optional; flags override them.

use serde::{Deserialize, Serialize};

/// The documented example, shown by `mrtmap run --help`.
pub const PROJECT_EXAMPLE: &str = r#"# project.toml: every key is optional (defaults shown); flags override them.
[map]
grid = [20, 20]           # nodes across and along the floor's bounding rectangle
heights_m = [1.1]         # one map per height above the floor (1.1 m seated head, 1.7 m standing)
margin_m = 0.1            # distance kept from the walls

[[points]]                # named points (e.g. globe locations) in the scan's frame, metres
name = "A"
xyz = [1.0, 0.2, 2.0]

[air]
temperature_c = 21.0      # for the report's operative temperature and globe comparisons
speed_m_s = 0.1

[fuse]
voxel_m = 0.03
icp = true                # refine poses by ICP against the map (as the seed paper)
sync_tolerance_ms = 20.0  # thermal frame ↔ nearest depth frame
depth_stride = 2          # every 2nd depth pixel

[segment]
feature_threshold_k = 0.3 # a texel differing from its surface's background by more is a feature
feature_min_area_m2 = 0.04
masks = true              # label features by the recording's instance masks when it has masks.txt

[mrt]
method = "auto"           # auto | exact | montecarlo
rays = 20000              # Monte Carlo rays per point
seed = 1
"#;

/// `[map]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapSection {
    /// Grid nodes.
    pub grid: [usize; 2],
    /// Heights (m).
    pub heights_m: Vec<f64>,
    /// Margin (m).
    pub margin_m: f64,
}

impl Default for MapSection {
    fn default() -> Self {
        Self {
            grid: [20, 20],
            heights_m: vec![1.1],
            margin_m: 0.1,
        }
    }
}

/// `[[points]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointEntry {
    /// Name.
    pub name: String,
    /// Scan-frame position (m).
    pub xyz: [f64; 3],
}

/// `[air]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AirSection {
    /// Air temperature (°C).
    pub temperature_c: Option<f64>,
    /// Air speed (m/s).
    pub speed_m_s: f64,
}

impl Default for AirSection {
    fn default() -> Self {
        Self {
            temperature_c: None,
            speed_m_s: 0.1,
        }
    }
}

/// `[fuse]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FuseSection {
    /// Voxel (m).
    pub voxel_m: f64,
    /// ICP.
    pub icp: bool,
    /// Sync tolerance (ms).
    pub sync_tolerance_ms: f64,
    /// Depth stride.
    pub depth_stride: u32,
}

impl Default for FuseSection {
    fn default() -> Self {
        Self {
            voxel_m: 0.03,
            icp: true,
            sync_tolerance_ms: 20.0,
            depth_stride: 2,
        }
    }
}

/// `[segment]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SegmentSection {
    /// Feature threshold (K).
    pub feature_threshold_k: f64,
    /// Smallest feature (m²).
    pub feature_min_area_m2: f64,
    /// Use masks when the recording has them.
    pub masks: bool,
}

impl Default for SegmentSection {
    fn default() -> Self {
        Self {
            feature_threshold_k: 0.3,
            feature_min_area_m2: 0.04,
            masks: true,
        }
    }
}

/// `[mrt]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MrtSection {
    /// "auto", "exact" or "montecarlo".
    pub method: String,
    /// Rays.
    pub rays: usize,
    /// Seed.
    pub seed: u64,
}

impl Default for MrtSection {
    fn default() -> Self {
        Self {
            method: "auto".into(),
            rays: 20_000,
            seed: 1,
        }
    }
}

/// A project.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Project {
    /// Maps.
    pub map: MapSection,
    /// Points.
    pub points: Vec<PointEntry>,
    /// Air.
    pub air: AirSection,
    /// Fusion.
    pub fuse: FuseSection,
    /// Segmentation.
    pub segment: SegmentSection,
    /// MRT.
    pub mrt: MrtSection,
}

impl Project {
    /// Reads project.toml; errors name the file and line.
    pub fn load(path: &std::path::Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("{}: cannot read it: {e}", path.display()))?;
        toml::from_str(&text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1)
                .unwrap_or(0);
            anyhow::anyhow!("{}:{line}: {}", path.display(), e.message())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_example_parses_to_the_defaults_plus_its_point() {
        let p: Project = toml::from_str(PROJECT_EXAMPLE).unwrap();
        assert_eq!(p.map, MapSection::default());
        assert_eq!(p.fuse, FuseSection::default());
        assert_eq!(p.segment, SegmentSection::default());
        assert_eq!(p.mrt, MrtSection::default());
        assert_eq!(p.points.len(), 1);
        assert_eq!(p.air.temperature_c, Some(21.0));
        assert!(
            toml::from_str::<Project>("[map]\ngird = [1, 2]\n").is_err(),
            "unknown keys are refused"
        );
    }
}
