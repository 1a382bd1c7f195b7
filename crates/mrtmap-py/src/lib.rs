//! # mrtmap-py
//!
//! The native module (`mrtmap._mrtmap`) of the Python package in `python/`: mrtmap-pipeline's
//! public API and nothing below it, with numpy arrays in and out. The Python layer
//! (`python/mrtmap/__init__.py`) broadcasts, names and documents; this module converts, checks,
//! releases the GIL and runs the pipeline's calls (rayon inside). `RunLayout` (`layout.rs`) gives
//! the run folder's paths, so that the Python layer spells no file name of it.
//!
//! Every error is a `mrtmap.MrtmapError` (a `ValueError`) carrying the message the CLI prints.
// PyO3's macros expand to unsafe FFI glue; this crate itself writes none.
#![allow(unsafe_code)]
// Python hands owned values (strings, lists) to the functions PyO3 wraps.
#![allow(clippy::needless_pass_by_value)]

mod layout;

/// Two float arrays (values and their standard errors).
type Pair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

use std::path::PathBuf;
use std::sync::Mutex;

use mrtmap_pipeline::comfort::{
    Iso7730Edition, OperativeMethod, PmvInputs, SolarInputs, SolarPosture, operative_temperature,
    pmv_ppd_each, solar_gain as solarcal,
};
use mrtmap_pipeline::export::{ExportFormat, export_scene};
use mrtmap_pipeline::maps::{GridSpec, RadiantScene, SceneSource, load_scene, map_arrays};
use mrtmap_pipeline::points::{Facing, PointQuery, Posture, mrt_at_points};
use mrtmap_pipeline::settings::PointFrame;
use mrtmap_pipeline::validation::{
    Convection, Globe, GlobeFormulaChoice, GlobeInput, MIXED_CONVECTION_DIAMETERS_M, Temperature,
    convert_globe,
};
use mrtmap_pipeline::{MrtSection, Overrides, Pipeline, Progress, Project};
use numpy::ndarray::ArrayView1;
use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArrayLike1, PyArrayLike2, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

create_exception!(
    _mrtmap,
    MrtmapError,
    PyValueError,
    "An error of mrtmap's: the one-sentence message the command line prints."
);

/// An error and its causes in one line, as the CLI prints them (`error: …` without the prefix).
fn message(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let s = c.to_string();
        if !text.contains(&s) {
            text.push_str(": ");
            text.push_str(&s);
        }
        cause = c.source();
    }
    text
}

fn py_err(e: impl std::error::Error) -> PyErr {
    MrtmapError::new_err(message(&e))
}

/// The view-factor settings from a JSON object of `[mrt]`'s keys (the Python layer's keywords),
/// resolved over the defaults as the CLI's flags are.
fn mrt_settings(json: &str) -> PyResult<MrtSection> {
    let keys: serde_json::Map<String, serde_json::Value> = serde_json::from_str(json)
        .map_err(|e| MrtmapError::new_err(format!("view-factor settings: {}", json_words(&e))))?;
    let mut o = Overrides::new();
    for (k, v) in &keys {
        o.set(&format!("mrt.{k}"), &format!("{k}="), v);
    }
    Ok(Project::resolve_over(Project::default(), &o)
        .map_err(py_err)?
        .mrt)
}

/// A serde_json error without its position in the JSON the Python layer wrote (the path names
/// the setting).
fn json_words(e: &serde_json::Error) -> String {
    let s = e.to_string();
    match s.find(" at line ") {
        Some(k) => s[..k].to_string(),
        None => s,
    }
}

/// Points from an (N, 3) array: every coordinate finite.
fn points_of(points: &PyArrayLike2<'_, f64, AllowTypeChange>) -> PyResult<Vec<[f64; 3]>> {
    let a = points.as_array();
    if a.ncols() != 3 {
        return Err(MrtmapError::new_err(format!(
            "points must be an (N, 3) array of x, y, z in metres; got shape ({}, {})",
            a.nrows(),
            a.ncols()
        )));
    }
    a.rows()
        .into_iter()
        .enumerate()
        .map(|(k, r)| {
            let p = [r[0], r[1], r[2]];
            if p.iter().all(|v| v.is_finite()) {
                Ok(p)
            } else {
                Err(MrtmapError::new_err(format!(
                    "point {k} ({}, {}, {}) is not a finite position: give x, y, z in metres",
                    p[0], p[1], p[2]
                )))
            }
        })
        .collect()
}

fn frame_of(frame: &str) -> PyResult<PointFrame> {
    match frame {
        "room" => Ok(PointFrame::Room),
        "scan" => Ok(PointFrame::Scan),
        other => Err(MrtmapError::new_err(format!(
            "frame '{other}' is neither 'room' nor 'scan'"
        ))),
    }
}

/// A radiant scene (scene.json, format mrtmap-scene/1) and where it came from.
#[pyclass(name = "Scene", module = "mrtmap._mrtmap", frozen)]
struct PyScene {
    scene: RadiantScene,
    source: String,
}

#[pymethods]
impl PyScene {
    /// Reads a scene file.
    #[staticmethod]
    #[pyo3(signature = (path, temperatures=None, room=None))]
    fn load(path: PathBuf, temperatures: Option<PathBuf>, room: Option<String>) -> PyResult<Self> {
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

    /// Sphere MRT at points: (mrt °C, standard error K, ΣF, the answers as JSON).
    #[pyo3(signature = (points, frame, mrt_json))]
    #[allow(clippy::type_complexity)]
    fn mrt<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'py, f64, AllowTypeChange>,
        frame: &str,
        mrt_json: &str,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let q = PointQuery {
            at: points_of(&points)?,
            frame: frame_of(frame)?,
            person: None,
            planes: false,
            sun: None,
        };
        let mrt = mrt_settings(mrt_json)?;
        let a = py
            .detach(|| mrt_at_points(&self.scene, &self.source, &mrt, &q))
            .map_err(py_err)?;
        let col = |f: &dyn Fn(&mrtmap_pipeline::points::PointRecord) -> f64| {
            PyArray1::from_vec(py, a.points.iter().map(f).collect())
        };
        Ok((
            col(&|r| r.mrt_c),
            col(&|r| r.std_error_k),
            col(&|r| r.view_factor_sum),
        ))
    }

    /// A person's MRT at body centres: (mrt °C, standard error K).
    #[pyo3(signature = (points, standing, facing_deg, frame, mrt_json))]
    fn person<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'py, f64, AllowTypeChange>,
        standing: bool,
        facing_deg: Option<f64>,
        frame: &str,
        mrt_json: &str,
    ) -> PyResult<Pair<'py>> {
        let facing = match facing_deg {
            Some(d) if d.is_finite() => Facing::Azimuth(d),
            Some(d) => {
                return Err(MrtmapError::new_err(format!(
                    "facing_deg {d} is not a finite angle in degrees"
                )));
            }
            None => Facing::Any,
        };
        let posture = if standing {
            Posture::Standing
        } else {
            Posture::Seated
        };
        let q = PointQuery {
            at: points_of(&points)?,
            frame: frame_of(frame)?,
            person: Some((posture, facing)),
            planes: false,
            sun: None,
        };
        let mrt = mrt_settings(mrt_json)?;
        let a = py
            .detach(|| mrt_at_points(&self.scene, &self.source, &mrt, &q))
            .map_err(py_err)?;
        Ok((
            PyArray1::from_vec(py, a.persons.iter().map(|p| p.mrt_c).collect()),
            PyArray1::from_vec(py, a.persons.iter().map(|p| p.std_error_k).collect()),
        ))
    }

    /// Plane radiant temperatures at points: (T_pr (N, 6) °C, standard errors (N, 6) K, the
    /// answers as JSON).
    #[pyo3(signature = (points, frame, mrt_json))]
    #[allow(clippy::type_complexity)]
    fn plane_radiant<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'py, f64, AllowTypeChange>,
        frame: &str,
        mrt_json: &str,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, String)> {
        let q = PointQuery {
            at: points_of(&points)?,
            frame: frame_of(frame)?,
            person: None,
            planes: true,
            sun: None,
        };
        let mrt = mrt_settings(mrt_json)?;
        let a = py
            .detach(|| mrt_at_points(&self.scene, &self.source, &mrt, &q))
            .map_err(py_err)?;
        let n = a.planes.len();
        let grid = |f: &dyn Fn(&(String, f64, f64)) -> f64| -> PyResult<Bound<'py, PyArray2<f64>>> {
            let v: Vec<f64> = a
                .planes
                .iter()
                .flat_map(|p| p.faces.iter().map(f))
                .collect();
            PyArray1::from_vec(py, v).reshape([n, 6])
        };
        let json = serde_json::to_string(&a.planes).map_err(py_err)?;
        Ok((grid(&|f| f.1)?, grid(&|f| f.2)?, json))
    }

    /// The MRT over a grid at a height: (mrt (ny, nx) °C, standard error (ny, nx) K, node points
    /// (ny, nx, 3), u, v, the rest as JSON).
    #[pyo3(signature = (height_m, nx, ny, margin_m, mrt_json))]
    #[allow(clippy::type_complexity)]
    fn map<'py>(
        &self,
        py: Python<'py>,
        height_m: f64,
        nx: usize,
        ny: usize,
        margin_m: f64,
        mrt_json: &str,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyAny>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        String,
    )> {
        if !(2..=2000).contains(&nx) || !(2..=2000).contains(&ny) {
            return Err(MrtmapError::new_err(format!(
                "grid ({nx}, {ny}) must have 2 to 2000 nodes each way"
            )));
        }
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
        let mrt = mrt_settings(mrt_json)?;
        let mut m = py
            .detach(|| map_arrays(&self.scene, &self.source, &mrt, spec))
            .map_err(py_err)?;
        let mrt_c = PyArray1::from_vec(py, std::mem::take(&mut m.mrt_c)).reshape([ny, nx])?;
        let se = PyArray1::from_vec(py, std::mem::take(&mut m.std_error_k)).reshape([ny, nx])?;
        let xyz = PyArray1::from_vec(py, std::mem::take(&mut m.xyz))
            .reshape([ny, nx, 3])?
            .into_any();
        let u = PyArray1::from_vec(py, std::mem::take(&mut m.u));
        let v = PyArray1::from_vec(py, std::mem::take(&mut m.v));
        let json = serde_json::to_string(&m).map_err(py_err)?;
        Ok((mrt_c, se, xyz, u, v, json))
    }
}

/// Progress to a Python callable `(stage: str, done: int, total: int)`; errors it raises are
/// printed and otherwise ignored (a progress bar must not stop a run).
struct PyProgress {
    callback: Py<PyAny>,
    stage: Mutex<String>,
}

impl Progress for PyProgress {
    fn begin(&self, what: &str) {
        if let Ok(mut s) = self.stage.lock() {
            *s = what.to_string();
        }
        self.advance(0, 0);
    }

    fn advance(&self, done: u64, total: u64) {
        let stage = self.stage.lock().map(|s| s.clone()).unwrap_or_default();
        Python::attach(|py| {
            if let Err(e) = self.callback.call1(py, (stage, done, total)) {
                e.print(py);
            }
        });
    }
}

/// The project: None (the defaults), a path to project.toml, or its settings as JSON text.
fn project_of(config: Option<&Bound<'_, PyAny>>) -> PyResult<Project> {
    let Some(c) = config else {
        return Ok(Project::default());
    };
    if let Ok(json) = c.getattr("__mrtmap_json__").and_then(|f| f.call0()) {
        let text: String = json.extract()?;
        let de = &mut serde_json::Deserializer::from_str(&text);
        let p: Project = serde_path_to_error::deserialize(de).map_err(|e| {
            MrtmapError::new_err(format!("config [{}]: {}", e.path(), json_words(e.inner())))
        })?;
        return Project::resolve_over(p, &Overrides::new()).map_err(py_err);
    }
    let path: PathBuf = c.extract().map_err(|_| {
        MrtmapError::new_err(
            "config must be None, a path to project.toml, or a dict of its sections",
        )
    })?;
    Project::resolve(Some(&path), &Overrides::new()).map_err(py_err)
}

/// `mrtmap run` on `recording` into `out`: (the run's lines, run.json's path, seconds, the
/// outcome's figures as JSON).
#[pyfunction]
#[pyo3(signature = (recording, out, config=None, force=false, progress=None))]
fn run(
    py: Python<'_>,
    recording: PathBuf,
    out: PathBuf,
    config: Option<&Bound<'_, PyAny>>,
    force: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Vec<String>, f64, String)> {
    let project = project_of(config)?;
    let progress: Box<dyn Progress + Send> = match progress {
        Some(callback) => Box::new(PyProgress {
            callback,
            stage: Mutex::new(String::new()),
        }),
        None => Box::new(mrtmap_pipeline::Silent),
    };
    let done = py
        .detach(|| {
            Pipeline::new(project)
                .force(force)
                .progress(progress.as_ref())
                .run(&recording, &out)
        })
        .map_err(py_err)?;
    let figures = outcome_json(&done.outcome).map_err(py_err)?;
    Ok((done.lines(&recording, &out), done.secs, figures))
}

/// A run's figures for Python: stages, maps' summaries, comfort shares, level, warnings.
fn outcome_json(o: &mrtmap_pipeline::RunOutcome) -> serde_json::Result<String> {
    let maps: Vec<_> = o
        .maps
        .iter()
        .map(|m| serde_json::json!({"summary": m.summary, "csv": m.csv}))
        .collect();
    serde_json::to_string(&serde_json::json!({
        "stages": o.stages,
        "maps": maps,
        "comfort": o.comfort.as_ref().map(|c| &c.summary),
        "level": o.level,
        "warnings": o.warnings,
        "scene": {
            "surfaces": o.scene.surfaces.len(),
            "features": o.scene.surfaces.iter().map(|s| s.features.len()).sum::<usize>(),
        },
    }))
}

/// Views of 1-D arrays of one length (broadcast already by the Python layer), named in the error
/// when one differs. Views, not copies: the arrays stay borrowed while the GIL is released.
fn columns<'a, const N: usize>(
    arrays: [&'a PyArrayLike1<'_, f64, AllowTypeChange>; N],
    names: [&str; N],
) -> PyResult<[ArrayView1<'a, f64>; N]> {
    let cols = arrays.map(|a| a.as_array());
    let n = cols.first().map_or(0, ArrayView1::len);
    match cols.iter().zip(names).find(|(c, _)| c.len() != n) {
        Some((c, name)) => Err(MrtmapError::new_err(format!(
            "{name} has {} values where the others have {n}",
            c.len()
        ))),
        None => Ok(cols),
    }
}

/// PMV and PPD element by element over 1-D arrays; with `limit`, NaN where the inputs or the PMV
/// lie outside ISO 7730's ranges (pythermalcomfort's `limit_inputs`); with `round`, PMV to 2 and
/// PPD to 1 decimal as numpy's `round` does (x·10ᵈ rounded half to even, then ÷ 10ᵈ), in the
/// parallel loop rather than two more passes over the arrays.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn pmv_ppd<'py>(
    py: Python<'py>,
    tdb: PyArrayLike1<'py, f64, AllowTypeChange>,
    tr: PyArrayLike1<'py, f64, AllowTypeChange>,
    vr: PyArrayLike1<'py, f64, AllowTypeChange>,
    rh: PyArrayLike1<'py, f64, AllowTypeChange>,
    met: PyArrayLike1<'py, f64, AllowTypeChange>,
    clo: PyArrayLike1<'py, f64, AllowTypeChange>,
    wme: PyArrayLike1<'py, f64, AllowTypeChange>,
    edition: u32,
    limit: bool,
    round: bool,
) -> PyResult<Pair<'py>> {
    let edition = match edition {
        2005 => Iso7730Edition::Y2005,
        2025 => Iso7730Edition::Y2025,
        e => {
            return Err(MrtmapError::new_err(format!(
                "ISO 7730 edition {e} is neither 2005 nor 2025"
            )));
        }
    };
    let cols = columns(
        [&tdb, &tr, &vr, &rh, &met, &clo, &wme],
        ["tdb", "tr", "vr", "rh", "met", "clo", "wme"],
    )?;
    let n = cols[0].len();
    // Blocks of inputs in parallel, written in place; within a block, several PMVs iterate
    // interleaved. The first element refused, in order, is the one named.
    const BLOCK: usize = 2048;
    let mut pmv = vec![0.0; n];
    let mut ppd = vec![0.0; n];
    let refused: Option<String> = py.detach(|| {
        pmv.par_chunks_mut(BLOCK)
            .zip(ppd.par_chunks_mut(BLOCK))
            .enumerate()
            .map(|(b, (pmv, ppd))| {
                let start = b * BLOCK;
                let mut refused = None;
                pmv_ppd_each(
                    pmv.len(),
                    |j| {
                        let k = start + j;
                        PmvInputs {
                            air: Temperature::from_celsius(cols[0][k]),
                            mrt: Temperature::from_celsius(cols[1][k]),
                            relative_air_speed_m_s: cols[2][k],
                            relative_humidity_pct: cols[3][k],
                            met: cols[4][k],
                            clo: cols[5][k],
                            external_work_met: cols[6][k],
                        }
                    },
                    edition,
                    |j, r| match r {
                        Ok(p) if limit && !p.within_iso_ranges => {
                            (pmv[j], ppd[j]) = (f64::NAN, f64::NAN);
                        }
                        Ok(p) if round => {
                            pmv[j] = (p.pmv * 100.0).round_ties_even() / 100.0;
                            ppd[j] = (p.ppd_pct * 10.0).round_ties_even() / 10.0;
                        }
                        Ok(p) => (pmv[j], ppd[j]) = (p.pmv, p.ppd_pct),
                        Err(e) if refused.is_none() => {
                            refused = Some(format!("element {}: {}", start + j, message(&e)));
                        }
                        Err(_) => {}
                    },
                );
                refused
            })
            .collect::<Vec<Option<String>>>()
            .into_iter()
            .flatten()
            .next()
    });
    if let Some(e) = refused {
        return Err(MrtmapError::new_err(e));
    }
    Ok((PyArray1::from_vec(py, pmv), PyArray1::from_vec(py, ppd)))
}

/// Operative temperature (°C) element by element: ISO 7726's formula, or ASHRAE 55's.
#[pyfunction]
fn operative<'py>(
    py: Python<'py>,
    tdb: PyArrayLike1<'py, f64, AllowTypeChange>,
    tr: PyArrayLike1<'py, f64, AllowTypeChange>,
    v: PyArrayLike1<'py, f64, AllowTypeChange>,
    ashrae: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let [a, b, c] = columns([&tdb, &tr, &v], ["tdb", "tr", "v"])?;
    let n = a.len();
    let method = if ashrae {
        OperativeMethod::Ashrae55
    } else {
        OperativeMethod::Iso
    };
    let out: PyResult<Vec<f64>> = (0..n)
        .map(|k| {
            operative_temperature(
                Temperature::from_celsius(a[k]),
                Temperature::from_celsius(b[k]),
                c[k],
                method,
            )
            .map(|t| t.celsius())
            .map_err(|e| MrtmapError::new_err(format!("element {k}: {}", message(&e))))
        })
        .collect();
    Ok(PyArray1::from_vec(py, out?))
}

/// MRT (°C) from globe readings element by element: ISO 7726 (`mixed` false) or mixed
/// convection; NaN where the mixed-convection model is undefined (globes outside 40–150 mm).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn mrt_from_globe<'py>(
    py: Python<'py>,
    tg: PyArrayLike1<'py, f64, AllowTypeChange>,
    tdb: PyArrayLike1<'py, f64, AllowTypeChange>,
    v: PyArrayLike1<'py, f64, AllowTypeChange>,
    d: PyArrayLike1<'py, f64, AllowTypeChange>,
    emissivity: PyArrayLike1<'py, f64, AllowTypeChange>,
    mixed: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let cols = columns(
        [&tg, &tdb, &v, &d, &emissivity],
        ["tg", "tdb", "v", "d", "emissivity"],
    )?;
    let n = cols[0].len();
    let method = if mixed {
        GlobeFormulaChoice::Mixed
    } else {
        GlobeFormulaChoice::Iso
    }
    .method(Convection::Larger);
    let out: PyResult<Vec<f64>> = (0..n)
        .map(|k| {
            let globe = Globe {
                diameter_m: cols[3][k],
                emissivity: cols[4][k],
            };
            if mixed && !MIXED_CONVECTION_DIAMETERS_M.contains(&globe.diameter_m) {
                return Ok(f64::NAN);
            }
            convert_globe(
                GlobeInput::Globe(cols[0][k]),
                &globe,
                cols[1][k],
                cols[2][k],
                method,
            )
            .map(|c| c.mrt_c)
            .map_err(|e| MrtmapError::new_err(format!("element {k}: {}", message(&e))))
        })
        .collect();
    Ok(PyArray1::from_vec(py, out?))
}

/// SolarCal's ERF (W/m²) and ΔMRT (K) element by element (pythermalcomfort's `solar_gain`,
/// unrounded): NaN where the altitude lies outside 0…90° or SHARP outside 0…180° (as
/// pythermalcomfort, so that a year of sun positions with its nights goes through); any other
/// input out of its range is refused, naming the element.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn solar_gain<'py>(
    py: Python<'py>,
    sol_altitude: PyArrayLike1<'py, f64, AllowTypeChange>,
    sharp: PyArrayLike1<'py, f64, AllowTypeChange>,
    sol_radiation_dir: PyArrayLike1<'py, f64, AllowTypeChange>,
    sol_transmittance: PyArrayLike1<'py, f64, AllowTypeChange>,
    f_svv: PyArrayLike1<'py, f64, AllowTypeChange>,
    f_bes: PyArrayLike1<'py, f64, AllowTypeChange>,
    asw: PyArrayLike1<'py, f64, AllowTypeChange>,
    floor_reflectance: PyArrayLike1<'py, f64, AllowTypeChange>,
    posture: &str,
) -> PyResult<Pair<'py>> {
    let posture = SolarPosture::from_name(posture).ok_or_else(|| {
        MrtmapError::new_err(format!(
            "posture '{posture}' is none of 'sitting', 'standing' and 'supine'"
        ))
    })?;
    let c = columns(
        [
            &sol_altitude,
            &sharp,
            &sol_radiation_dir,
            &sol_transmittance,
            &f_svv,
            &f_bes,
            &asw,
            &floor_reflectance,
        ],
        [
            "sol_altitude",
            "sharp",
            "sol_radiation_dir",
            "sol_transmittance",
            "f_svv",
            "f_bes",
            "asw",
            "floor_reflectance",
        ],
    )?;
    let n = c[0].len();
    // In parallel without the GIL; the first element refused, in order, is the one named.
    let out: Vec<Result<(f64, f64), String>> = py.detach(|| {
        (0..n)
            .into_par_iter()
            .map(|k| {
                let inputs = SolarInputs {
                    altitude_deg: c[0][k],
                    sharp_deg: c[1][k],
                    dni_w_m2: c[2][k],
                    transmittance: c[3][k],
                    f_svv: c[4][k],
                    f_bes: c[5][k],
                    asw: c[6][k],
                    posture,
                    floor_reflectance: c[7][k],
                };
                if !(0.0..=90.0).contains(&inputs.altitude_deg)
                    || !(0.0..=180.0).contains(&inputs.sharp_deg)
                {
                    return Ok((f64::NAN, f64::NAN));
                }
                solarcal(&inputs)
                    .map(|g| (g.erf_w_m2, g.delta_mrt_k))
                    .map_err(|e| format!("element {k}: {}", message(&e)))
            })
            .collect()
    });
    let (mut erf, mut dmrt) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for r in out {
        let (e, d) = r.map_err(MrtmapError::new_err)?;
        erf.push(e);
        dmrt.push(d);
    }
    Ok((PyArray1::from_vec(py, erf), PyArray1::from_vec(py, dmrt)))
}

/// The sky-vault view fraction of a window `w` × `h` (m) straight ahead at distance `d` (m),
/// element by element (pythermalcomfort's `f_svv`).
#[pyfunction]
fn f_svv<'py>(
    py: Python<'py>,
    w: PyArrayLike1<'py, f64, AllowTypeChange>,
    h: PyArrayLike1<'py, f64, AllowTypeChange>,
    d: PyArrayLike1<'py, f64, AllowTypeChange>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let [w, h, d] = columns([&w, &h, &d], ["w", "h", "d"])?;
    let out: PyResult<Vec<f64>> = (0..w.len())
        .map(|k| {
            mrtmap_pipeline::comfort::f_svv(w[k], h[k], d[k])
                .map_err(|e| MrtmapError::new_err(format!("element {k}: {}", message(&e))))
        })
        .collect();
    Ok(PyArray1::from_vec(py, out?))
}

/// The `mrtmap` command line with `argv` (the program's name first); returns the exit code.
#[pyfunction]
fn cli_main(py: Python<'_>, argv: Vec<String>) -> i32 {
    let args = argv.into_iter().map(Into::into).collect();
    let code = py.detach(|| mrtmap::main_with(args));
    // ExitCode has no accessor: success or the codes main_with gives.
    if code == std::process::ExitCode::SUCCESS {
        0
    } else if code == std::process::ExitCode::from(2) {
        2
    } else {
        1
    }
}

/// mrtmap's native module.
#[pymodule]
fn _mrtmap(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MrtmapError", m.py().get_type::<MrtmapError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<PyScene>()?;
    m.add_class::<layout::PyRunLayout>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(pmv_ppd, m)?)?;
    m.add_function(wrap_pyfunction!(operative, m)?)?;
    m.add_function(wrap_pyfunction!(mrt_from_globe, m)?)?;
    m.add_function(wrap_pyfunction!(solar_gain, m)?)?;
    m.add_function(wrap_pyfunction!(f_svv, m)?)?;
    m.add_function(wrap_pyfunction!(cli_main, m)?)?;
    Ok(())
}
