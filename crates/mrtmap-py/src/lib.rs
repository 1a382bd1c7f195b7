//! # mrtmap-py
//!
//! The native module (`mrtmap._mrtmap`) of the Python package in `python/`: mrtmap-pipeline's
//! public API and nothing below it, with numpy arrays in and out. The Python layer
//! (`python/mrtmap/__init__.py`) broadcasts, names and documents; this module converts, checks,
//! releases the GIL and runs the pipeline's calls (rayon inside). Results that are not arrays come
//! back as Python dicts and lists built here from the pipeline's own types (`to_py`), so that the
//! Python layer reads named fields and guesses nothing. `RunLayout` (`layout.rs`) gives the run
//! folder's paths, so that the Python layer spells no file name of it.
//!
//! ```text
//! scene.rs    Scene: load, from JSON, pickle, change a temperature, MRT at points / over a grid
//! run.rs      run: the whole pipeline, progress to a callable, Ctrl-C honoured
//! comfort.rs  PMV/PPD, operative temperature, MRT from a globe, SolarCal: NaN where refused
//! layout.rs   RunLayout: where a run's files are
//! ```
//!
//! Every error is a `mrtmap.MrtmapError` (a `ValueError`) carrying the message the CLI prints; a
//! missing file is a `mrtmap.MrtmapFileNotFoundError`, also a `FileNotFoundError`.
// PyO3's macros expand to unsafe FFI glue; this crate itself writes none.
#![allow(unsafe_code)]
// Python hands owned values (strings, lists) to the functions PyO3 wraps.
#![allow(clippy::needless_pass_by_value)]

mod comfort;
mod layout;
mod run;
mod scene;

use std::path::Path;

use mrtmap_pipeline::settings::PointFrame;
use mrtmap_pipeline::{MrtSection, Overrides, Project};
use numpy::{AllowTypeChange, PyArrayLike2};
use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyBool, PyDict, PyList, PyString, PyTuple, PyType};

create_exception!(
    _mrtmap,
    MrtmapError,
    PyValueError,
    "An error of mrtmap's: the one-sentence message the command line prints."
);

/// `MrtmapFileNotFoundError(MrtmapError, FileNotFoundError)`, made when the module loads (a class
/// of two exception bases is beyond `create_exception!`).
static FILE_NOT_FOUND: PyOnceLock<Py<PyType>> = PyOnceLock::new();

fn file_not_found_type(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    FILE_NOT_FOUND
        .get_or_try_init(py, || {
            let bases = PyTuple::new(
                py,
                [
                    py.get_type::<MrtmapError>(),
                    py.get_type::<PyFileNotFoundError>(),
                ],
            )?;
            let attrs = PyDict::new(py);
            attrs.set_item("__module__", "mrtmap")?;
            attrs.set_item(
                "__doc__",
                "A file mrtmap was given does not exist: both a MrtmapError and a FileNotFoundError.",
            )?;
            let ty = py
                .get_type::<PyType>()
                .call1(("MrtmapFileNotFoundError", bases, attrs))?;
            Ok::<_, PyErr>(ty.cast_into::<PyType>()?.unbind())
        })
        .map(|t| t.bind(py))
}

/// A `MrtmapFileNotFoundError` with `msg`.
fn file_not_found(msg: String) -> PyErr {
    Python::attach(|py| match file_not_found_type(py) {
        Ok(ty) => PyErr::from_type(ty.clone(), msg),
        Err(e) => e,
    })
}

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

/// `MrtmapFileNotFoundError` when `path` does not exist (`what` names it), checked before the
/// pipeline reads it so that Python's `except FileNotFoundError` catches it.
fn must_exist(path: &Path, what: &str) -> PyResult<()> {
    if path.symlink_metadata().is_err() && !path.exists() {
        return Err(file_not_found(format!(
            "{what} {} does not exist: check the path",
            path.display()
        )));
    }
    Ok(())
}

/// A serde value as Python's: dicts, lists, str, int, float, bool, None.
fn to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value as V;
    Ok(match v {
        V::Null => py.None().into_bound(py),
        V::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        V::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            _ => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        V::String(s) => s.into_pyobject(py)?.into_any(),
        V::Array(a) => {
            let items = a
                .iter()
                .map(|x| to_py(py, x))
                .collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        V::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// Any serialisable value of the pipeline's as Python's (see [`to_py`]).
fn serde_py<'py>(py: Python<'py>, v: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    to_py(py, &serde_json::to_value(v).map_err(py_err)?)
}

/// A Python value of plain data (dicts with str keys, lists, tuples, str, bool, numbers —
/// numpy's scalars too —, None) as a serde value; `at` names it in the TypeError otherwise.
fn from_py(v: &Bound<'_, PyAny>, at: &str) -> PyResult<serde_json::Value> {
    use serde_json::Value as V;
    if v.is_none() {
        return Ok(V::Null);
    }
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(V::Bool(b.is_true()));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(V::String(s.to_str()?.to_string()));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut m = serde_json::Map::new();
        for (k, x) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!("{at}: the keys must be str; got {k:?}"))
            })?;
            let inner = from_py(&x, &format!("{at}.{key}"))?;
            m.insert(key, inner);
        }
        return Ok(V::Object(m));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .enumerate()
            .map(|(k, x)| from_py(&x?, &format!("{at}[{k}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(V::Array(items));
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(V::from(i));
    }
    if let Ok(f) = v.extract::<f64>() {
        return Ok(serde_json::Number::from_f64(f).map_or(V::Null, V::Number));
    }
    let ty = v
        .get_type()
        .name()
        .map_or_else(|_| "?".into(), |n| n.to_string());
    Err(PyTypeError::new_err(format!(
        "{at} is a {ty}: give a dict, list, str, number, bool or None"
    )))
}

/// The view-factor keywords (`[mrt]`'s keys), each `None` when not given.
#[derive(Default)]
struct MrtKeywords {
    method: Option<String>,
    rays: Option<i64>,
    seed: Option<i64>,
    directions: Option<String>,
    replicates: Option<i64>,
    allow_open: Option<bool>,
    placement_std_m: Option<f64>,
}

impl MrtKeywords {
    /// The settings resolved over the defaults as the CLI's flags are.
    fn resolve(&self) -> PyResult<MrtSection> {
        let mut o = Overrides::new();
        o.set_some("mrt.method", "method=", self.method.as_ref())
            .set_some("mrt.rays", "rays=", self.rays.as_ref())
            .set_some("mrt.seed", "seed=", self.seed.as_ref())
            .set_some("mrt.directions", "directions=", self.directions.as_ref())
            .set_some("mrt.replicates", "replicates=", self.replicates.as_ref())
            .set_some("mrt.allow_open", "allow_open=", self.allow_open.as_ref())
            .set_some(
                "mrt.placement_std_m",
                "placement_std_m=",
                self.placement_std_m.as_ref(),
            );
        Ok(Project::resolve_over(Project::default(), &o)
            .map_err(py_err)?
            .mrt)
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
    let py = m.py();
    m.add("MrtmapError", py.get_type::<MrtmapError>())?;
    m.add("MrtmapFileNotFoundError", file_not_found_type(py)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<scene::PyScene>()?;
    m.add_class::<layout::PyRunLayout>()?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(comfort::pmv_ppd, m)?)?;
    m.add_function(wrap_pyfunction!(comfort::operative, m)?)?;
    m.add_function(wrap_pyfunction!(comfort::mrt_from_globe, m)?)?;
    m.add_function(wrap_pyfunction!(comfort::solar_gain, m)?)?;
    m.add_function(wrap_pyfunction!(comfort::f_svv, m)?)?;
    m.add_function(wrap_pyfunction!(cli_main, m)?)?;
    Ok(())
}
