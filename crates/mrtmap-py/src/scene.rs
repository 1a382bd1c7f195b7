//! `Scene`: a radiant scene for Python — loaded, made from JSON text, pickled (by its JSON),
//! changed one temperature at a time, and asked for MRT at points and over grids.

use std::path::PathBuf;

use mrtmap_pipeline::export::{ExportFormat, export_scene};
use mrtmap_pipeline::maps::{GridSpec, RadiantScene, SceneSource, load_scene, map_arrays};
use mrtmap_pipeline::points::{FACES, Facing, PointQuery, Posture, mrt_at_points};
use numpy::{AllowTypeChange, PyArray1, PyArrayLike2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde_json::Value;

use crate::{MrtKeywords, MrtmapError, frame_of, must_exist, points_of, py_err, serde_py};

/// The most nodes a map may have (the command line's limit: a 2000 × 2000 map).
const MAX_GRID_NODES: usize = 4_000_000;

/// A radiant scene (scene.json, format mrtmap-scene/1) and where it came from.
#[pyclass(name = "Scene", module = "mrtmap._mrtmap", frozen)]
pub(crate) struct PyScene {
    scene: RadiantScene,
    source: String,
}

/// A JSON object's list under `key` (empty when absent).
fn list_mut<'a>(v: &'a mut Value, key: &str) -> impl Iterator<Item = &'a mut Value> {
    v.get_mut(key)
        .and_then(Value::as_array_mut)
        .into_iter()
        .flatten()
}

/// Sets the temperature of the surface, feature or occluder `id` in scene.json's data; false
/// when nothing has that id. A surface's raster and a measured surface temperature would
/// contradict the new value, so they go.
fn set_temperature(file: &mut Value, id: &str, t_c: f64) -> bool {
    let mut found = false;
    let mut set = |o: &mut Value| {
        if o.get("id").and_then(Value::as_str) == Some(id)
            && let Some(m) = o.as_object_mut()
        {
            m.insert("temperature_c".into(), t_c.into());
            m.remove("raster");
            m.remove("surface_temperature_c");
            m.remove("surface_temperature_std_k");
            found = true;
        }
    };
    for s in list_mut(file, "surfaces") {
        set(s);
        for f in list_mut(s, "features") {
            set(f);
        }
    }
    for o in list_mut(file, "occluders") {
        set(o);
    }
    found
}

/// Every id in the scene, for the message when one is not there.
fn ids(scene: &RadiantScene) -> Vec<&str> {
    let mut ids = Vec::new();
    for s in &scene.surfaces {
        ids.push(s.id.as_str());
        ids.extend(s.features.iter().map(|f| f.id.as_str()));
    }
    ids.extend(scene.occluders.iter().map(|o| o.id.as_str()));
    ids
}

/// The grid's node counts: at least one each way and at most [`MAX_GRID_NODES`] in all, as the
/// command line's `--grid` (Python said 2 to 2000 each way).
fn grid_counts(nx: i64, ny: i64) -> PyResult<(usize, usize)> {
    match (usize::try_from(nx), usize::try_from(ny)) {
        (Ok(x), Ok(y)) if x >= 1 && y >= 1 && x.saturating_mul(y) <= MAX_GRID_NODES => Ok((x, y)),
        _ => Err(MrtmapError::new_err(format!(
            "grid ({nx}, {ny}) must have at least 1 node each way and at most {MAX_GRID_NODES} in all"
        ))),
    }
}

impl PyScene {
    /// The pipeline's answers at `points`: MRT, with a person's or the plane radiant
    /// temperatures when asked (what `mrt`, `person` and `plane_radiant` share).
    fn answers(
        &self,
        py: Python<'_>,
        points: &PyArrayLike2<'_, f64, AllowTypeChange>,
        frame: &str,
        kw: &MrtKeywords,
        person: Option<(Posture, Facing)>,
        planes: bool,
    ) -> PyResult<mrtmap_pipeline::points::PointAnswers> {
        let q = PointQuery {
            at: points_of(points)?,
            frame: frame_of(frame)?,
            person,
            planes,
            sun: None,
        };
        let mrt = kw.resolve()?;
        py.detach(|| mrt_at_points(&self.scene, &self.source, &mrt, &q))
            .map_err(py_err)
    }
}

#[pymethods]
impl PyScene {
    /// A scene from scene.json's text; `source` says where it came from (for messages).
    #[new]
    #[pyo3(signature = (json, source=None))]
    fn new(json: &str, source: Option<String>) -> PyResult<Self> {
        let scene = RadiantScene::from_json(json)
            .map_err(|e| MrtmapError::new_err(format!("scene JSON: {}", crate::message(&e))))?;
        Ok(Self {
            scene,
            source: source.unwrap_or_else(|| "a scene given as JSON".into()),
        })
    }

    /// Pickles as its JSON (Dask ships scenes to worker processes so).
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let me = slf.get();
        let args = PyTuple::new(slf.py(), [me.scene.to_json(), me.source.clone()])?;
        Ok((slf.get_type().into_any(), args))
    }

    /// Reads a scene file.
    #[staticmethod]
    #[pyo3(signature = (path, temperatures=None, room=None))]
    fn load(path: PathBuf, temperatures: Option<PathBuf>, room: Option<String>) -> PyResult<Self> {
        must_exist(&path, "scene")?;
        if let Some(t) = &temperatures {
            must_exist(t, "temperatures")?;
        }
        let src = SceneSource {
            scene: Some(path),
            temperatures,
            room,
        };
        let (scene, source) = load_scene(&src).map_err(py_err)?;
        Ok(Self { scene, source })
    }

    /// The built-in example office.
    #[staticmethod]
    fn example() -> PyResult<Self> {
        let (scene, source) = load_scene(&SceneSource::default()).map_err(py_err)?;
        Ok(Self { scene, source })
    }

    /// Where the scene came from, in words.
    #[getter]
    fn source(&self) -> String {
        self.source.clone()
    }

    /// The scene as scene.json text.
    fn to_json(&self) -> String {
        self.scene.to_json()
    }

    /// Every surface's, feature's and occluder's id, surfaces each followed by their features.
    fn ids(&self) -> Vec<String> {
        ids(&self.scene).into_iter().map(Into::into).collect()
    }

    /// A copy whose surface, feature or occluder `id` is at `temperature_c` (°C).
    fn with_surface_temperature(&self, id: &str, temperature_c: f64) -> PyResult<Self> {
        if !temperature_c.is_finite() {
            return Err(MrtmapError::new_err(format!(
                "temperature {temperature_c} °C for '{id}' is not a finite number"
            )));
        }
        let mut file: Value = serde_json::from_str(&self.scene.to_json()).map_err(py_err)?;
        if !set_temperature(&mut file, id, temperature_c) {
            return Err(MrtmapError::new_err(format!(
                "the scene has no surface, feature or occluder '{id}': its ids are {}",
                ids(&self.scene).join(", ")
            )));
        }
        let scene = RadiantScene::from_json(&file.to_string()).map_err(py_err)?;
        Ok(Self {
            scene,
            source: format!("{} with '{id}' at {temperature_c} °C", self.source),
        })
    }

    /// Writes the scene for another tool (hbjson, gbxml, gltf, rad; by default from the
    /// extension); returns the bytes written.
    #[pyo3(signature = (path, to=None, name=None))]
    fn export(&self, path: PathBuf, to: Option<String>, name: Option<String>) -> PyResult<usize> {
        let format = match to.as_deref() {
            None => None,
            Some(t) => Some(ExportFormat::from_name(t).ok_or_else(|| {
                MrtmapError::new_err(format!(
                    "to={t:?}: the formats are hbjson, gbxml, gltf and rad"
                ))
            })?),
        };
        let name = name.unwrap_or_else(|| "room".into());
        let done = export_scene(&self.scene, &name, format, &path).map_err(py_err)?;
        Ok(done.bytes)
    }

    /// Sphere MRT at points: a dict of arrays `mrt_c` (°C), `std_error_k` (K),
    /// `view_factor_sum`.
    #[pyo3(signature = (points, *, frame="room", method=None, rays=None, seed=None,
        directions=None, replicates=None, allow_open=None, placement_std_m=None))]
    #[allow(clippy::too_many_arguments)]
    fn mrt<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'py, f64, AllowTypeChange>,
        frame: &str,
        method: Option<String>,
        rays: Option<i64>,
        seed: Option<i64>,
        directions: Option<String>,
        replicates: Option<i64>,
        allow_open: Option<bool>,
        placement_std_m: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let kw = MrtKeywords {
            method,
            rays,
            seed,
            directions,
            replicates,
            allow_open,
            placement_std_m,
        };
        let a = self.answers(py, &points, frame, &kw, None, false)?;
        let col = |f: fn(&mrtmap_pipeline::points::PointRecord) -> f64| {
            PyArray1::from_vec(py, a.points.iter().map(f).collect())
        };
        let d = PyDict::new(py);
        d.set_item("mrt_c", col(|r| r.mrt_c))?;
        d.set_item("std_error_k", col(|r| r.std_error_k))?;
        d.set_item("view_factor_sum", col(|r| r.view_factor_sum))?;
        Ok(d)
    }

    /// A person's MRT at body centres: a dict of arrays `mrt_c` (°C), `std_error_k` (K).
    #[pyo3(signature = (points, posture="seated", facing_deg=None, *, frame="room", method=None,
        rays=None, seed=None, directions=None, replicates=None, allow_open=None,
        placement_std_m=None))]
    #[allow(clippy::too_many_arguments)]
    fn person<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'py, f64, AllowTypeChange>,
        posture: &str,
        facing_deg: Option<f64>,
        frame: &str,
        method: Option<String>,
        rays: Option<i64>,
        seed: Option<i64>,
        directions: Option<String>,
        replicates: Option<i64>,
        allow_open: Option<bool>,
        placement_std_m: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let kw = MrtKeywords {
            method,
            rays,
            seed,
            directions,
            replicates,
            allow_open,
            placement_std_m,
        };
        let facing = match facing_deg {
            Some(d) if d.is_finite() => Facing::Azimuth(d),
            Some(d) => {
                return Err(MrtmapError::new_err(format!(
                    "facing_deg {d} is not a finite angle in degrees"
                )));
            }
            None => Facing::Any,
        };
        let posture = match posture {
            "seated" => Posture::Seated,
            "standing" => Posture::Standing,
            p => {
                return Err(MrtmapError::new_err(format!(
                    "posture '{p}' is neither 'seated' nor 'standing'"
                )));
            }
        };
        let a = self.answers(py, &points, frame, &kw, Some((posture, facing)), false)?;
        let d = PyDict::new(py);
        let col = |f: fn(&mrtmap_pipeline::points::PersonAnswer) -> f64| {
            PyArray1::from_vec(py, a.persons.iter().map(f).collect())
        };
        d.set_item("mrt_c", col(|p| p.mrt_c))?;
        d.set_item("std_error_k", col(|p| p.std_error_k))?;
        Ok(d)
    }

    /// Plane radiant temperatures at points: a dict of `faces` (their names, in the columns'
    /// order), `t_pr_c` (N, 6) °C, `std_error_k` (N, 6) K, the asymmetries (K) and the warm
    /// side's azimuth per point, and ISO 7730's `verdicts` (dicts).
    #[pyo3(signature = (points, *, frame="room", method=None, rays=None, seed=None,
        directions=None, replicates=None, allow_open=None, placement_std_m=None))]
    #[allow(clippy::too_many_arguments)]
    fn plane_radiant<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'py, f64, AllowTypeChange>,
        frame: &str,
        method: Option<String>,
        rays: Option<i64>,
        seed: Option<i64>,
        directions: Option<String>,
        replicates: Option<i64>,
        allow_open: Option<bool>,
        placement_std_m: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let kw = MrtKeywords {
            method,
            rays,
            seed,
            directions,
            replicates,
            allow_open,
            placement_std_m,
        };
        let a = self.answers(py, &points, frame, &kw, None, true)?;
        let n = a.planes.len();
        let grid = |f: fn(&(String, f64, f64)) -> f64| -> PyResult<Bound<'py, PyAny>> {
            let v: Vec<f64> = a
                .planes
                .iter()
                .flat_map(|p| p.faces.iter().map(f))
                .collect();
            Ok(PyArray1::from_vec(py, v)
                .reshape([n, FACES.len()])?
                .into_any())
        };
        let col = |f: fn(&mrtmap_pipeline::points::PlaneAnswer) -> f64| {
            PyArray1::from_vec(py, a.planes.iter().map(f).collect())
        };
        let d = PyDict::new(py);
        d.set_item("faces", PyTuple::new(py, FACES)?)?;
        d.set_item("t_pr_c", grid(|f| f.1)?)?;
        d.set_item("std_error_k", grid(|f| f.2)?)?;
        d.set_item("vertical_asymmetry_k", col(|p| p.vertical_k))?;
        d.set_item("horizontal_asymmetry_k", col(|p| p.horizontal_k))?;
        d.set_item(
            "horizontal_warm_azimuth_deg",
            col(|p| p.horizontal_warm_azimuth_deg),
        )?;
        let verdicts: Vec<_> = a
            .planes
            .iter()
            .map(|p| serde_json::json!({"vertical": p.vertical, "horizontal": p.horizontal}))
            .collect();
        d.set_item("verdicts", serde_py(py, &verdicts)?)?;
        Ok(d)
    }

    /// The MRT over a grid at a height: a dict of `mrt_c` and `std_error_k` (ny, nx), `xyz`
    /// (ny, nx, 3), `u_m` and `v_m`, and the map's `axes`, `refused` nodes, `summary`, `method`
    /// and `compute_secs`.
    #[pyo3(signature = (height_m, nx, ny, margin_m, *, method=None, rays=None, seed=None,
        directions=None, replicates=None, allow_open=None, placement_std_m=None))]
    #[allow(clippy::too_many_arguments)]
    fn map<'py>(
        &self,
        py: Python<'py>,
        height_m: f64,
        nx: i64,
        ny: i64,
        margin_m: f64,
        method: Option<String>,
        rays: Option<i64>,
        seed: Option<i64>,
        directions: Option<String>,
        replicates: Option<i64>,
        allow_open: Option<bool>,
        placement_std_m: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let kw = MrtKeywords {
            method,
            rays,
            seed,
            directions,
            replicates,
            allow_open,
            placement_std_m,
        };
        let (nx, ny) = grid_counts(nx, ny)?;
        if !(height_m.is_finite() && height_m > 0.0 && margin_m.is_finite() && margin_m >= 0.0) {
            return Err(MrtmapError::new_err(format!(
                "height {height_m} m must be positive and margin {margin_m} m not negative"
            )));
        }
        let spec = GridSpec {
            nx,
            ny,
            height_m,
            margin_m,
        };
        let mrt = kw.resolve()?;
        let mut m = py
            .detach(|| map_arrays(&self.scene, &self.source, &mrt, spec))
            .map_err(py_err)?;
        let d = PyDict::new(py);
        let take = |v: &mut Vec<f64>| PyArray1::from_vec(py, std::mem::take(v));
        d.set_item("mrt_c", take(&mut m.mrt_c).reshape([ny, nx])?)?;
        d.set_item("std_error_k", take(&mut m.std_error_k).reshape([ny, nx])?)?;
        d.set_item("xyz", take(&mut m.xyz).reshape([ny, nx, 3])?)?;
        d.set_item("u_m", take(&mut m.u))?;
        d.set_item("v_m", take(&mut m.v))?;
        d.set_item("axes", serde_py(py, &m.axes)?)?;
        d.set_item("refused", m.refused.clone())?;
        d.set_item("summary", serde_py(py, &m.summary)?)?;
        d.set_item("method", m.method.clone())?;
        d.set_item("compute_secs", m.compute_secs)?;
        Ok(d)
    }
}
