//! `RunLayout`: the pipeline's [`RunLayout`] for Python, each path as a `str`, so that the Python
//! layer asks where a run's files are instead of spelling their names.

use std::path::{Path, PathBuf};

use mrtmap_pipeline::RunLayout;
use mrtmap_pipeline::export::ExportFormat;
use mrtmap_pipeline::settings::Quantity;
use pyo3::prelude::*;

use crate::MrtmapError;

/// A path as Python's `str` of it.
fn text(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// A quantity's name in files (`pmv`, `mrt_seated`, …).
fn quantity_of(name: &str) -> PyResult<Quantity> {
    serde_json::from_value(serde_json::Value::String(name.to_string()))
        .map_err(|e| MrtmapError::new_err(format!("quantity {name:?}: {e}")))
}

/// Where a run's files are (`mrtmap run … --out root`); every path is a `str`.
#[pyclass(name = "RunLayout", module = "mrtmap._mrtmap", frozen)]
pub(crate) struct PyRunLayout {
    layout: RunLayout,
}

#[pymethods]
impl PyRunLayout {
    #[new]
    fn new(root: PathBuf) -> Self {
        Self {
            layout: RunLayout::new(root),
        }
    }

    fn __repr__(&self) -> String {
        format!("RunLayout({:?})", text(self.layout.root()))
    }

    /// The run folder.
    fn root(&self) -> String {
        text(self.layout.root())
    }

    /// The name of the map folder at `height_m` (`map-1.10m`).
    #[staticmethod]
    fn map_dir_name(height_m: f64) -> String {
        RunLayout::map_dir_name(height_m)
    }

    fn report_html(&self) -> String {
        text(&self.layout.report_html())
    }

    fn run_json(&self) -> String {
        text(&self.layout.run_json())
    }

    fn recording_dir(&self) -> String {
        text(&self.layout.recording_dir())
    }

    fn recording_stage_json(&self) -> String {
        text(&self.layout.recording_stage_json())
    }

    fn track_dir(&self) -> String {
        text(&self.layout.track_dir())
    }

    fn trajectory_txt(&self) -> String {
        text(&self.layout.trajectory_txt())
    }

    fn track_json(&self) -> String {
        text(&self.layout.track_json())
    }

    fn fuse_dir(&self) -> String {
        text(&self.layout.fuse_dir())
    }

    fn cloud_ply(&self) -> String {
        text(&self.layout.cloud_ply())
    }

    fn fusion_json(&self) -> String {
        text(&self.layout.fusion_json())
    }

    fn poses_txt(&self) -> String {
        text(&self.layout.poses_txt())
    }

    fn frames_json(&self) -> String {
        text(&self.layout.frames_json())
    }

    fn segment_dir(&self) -> String {
        text(&self.layout.segment_dir())
    }

    fn scene_json(&self) -> String {
        text(&self.layout.scene_json())
    }

    fn segment_json(&self) -> String {
        text(&self.layout.segment_json())
    }

    fn segments_ply(&self) -> String {
        text(&self.layout.segments_ply())
    }

    fn level_json(&self) -> String {
        text(&self.layout.level_json())
    }

    fn map_dir(&self, height_m: f64) -> String {
        text(&self.layout.map_dir(height_m))
    }

    fn mrt_grid_csv(&self, height_m: f64) -> String {
        text(&self.layout.mrt_grid_csv(height_m))
    }

    fn mrt_map_png(&self, height_m: f64) -> String {
        text(&self.layout.mrt_map_png(height_m))
    }

    fn mrt_map_svg(&self, height_m: f64) -> String {
        text(&self.layout.mrt_map_svg(height_m))
    }

    fn summary_json(&self, height_m: f64) -> String {
        text(&self.layout.summary_json(height_m))
    }

    fn comfort_dir(&self) -> String {
        text(&self.layout.comfort_dir())
    }

    fn comfort_json(&self) -> String {
        text(&self.layout.comfort_json())
    }

    /// `comfort/<quantity>.png`; `quantity` as in `[map] quantities` ("pmv").
    fn comfort_png(&self, quantity: &str) -> PyResult<String> {
        Ok(text(&self.layout.comfort_png(quantity_of(quantity)?)))
    }

    fn comfort_svg(&self, quantity: &str) -> PyResult<String> {
        Ok(text(&self.layout.comfort_svg(quantity_of(quantity)?)))
    }

    fn comfort_csv(&self, quantity: &str) -> PyResult<String> {
        Ok(text(&self.layout.comfort_csv(quantity_of(quantity)?)))
    }

    fn export_dir(&self) -> String {
        text(&self.layout.export_dir())
    }

    /// `export/room.<extension>`; `format` hbjson, gbxml, gltf or rad.
    fn export_file(&self, format: &str) -> PyResult<String> {
        let f = ExportFormat::from_name(format).ok_or_else(|| {
            MrtmapError::new_err(format!(
                "format {format:?}: the formats are hbjson, gbxml, gltf and rad"
            ))
        })?;
        Ok(text(&self.layout.export_file(f)))
    }

    fn validation_csv(&self) -> String {
        text(&self.layout.validation_csv())
    }

    fn validation_json(&self) -> String {
        text(&self.layout.validation_json())
    }
}
