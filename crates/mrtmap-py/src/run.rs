//! `run`: the whole pipeline from Python, its progress to a callable, and Ctrl-C honoured.
//!
//! The pipeline runs on a thread of its own while the calling thread waits for it, asking Python
//! every [`SIGNAL_POLL`] whether a signal came (only the main thread's call runs Python's signal
//! handlers). A `KeyboardInterrupt` — from Ctrl-C, or raised by the progress callback — asks the
//! pipeline to stop before its next stage ([`Progress::stopped`]); the completed stages stay
//! (their stamps are written last), and the interrupt is raised in Python once the run has
//! stopped.

use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use mrtmap_pipeline::{Overrides, Pipeline, Progress, Project, RunLayout};
use pyo3::exceptions::{PyKeyboardInterrupt, PySystemExit};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::{MrtmapError, must_exist, py_err, serde_py};

/// How often the waiting thread asks Python whether a signal came.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Progress to an optional Python callable `(stage: str, done: int, total: int)`, and the
/// interrupt that stops the run. Ordinary exceptions the callable raises are printed and
/// otherwise ignored (a progress bar must not stop a run); `KeyboardInterrupt` and `SystemExit`
/// stop it.
struct PyProgress {
    callback: Option<Py<PyAny>>,
    stage: Mutex<String>,
    stop: AtomicBool,
    /// The exception that stopped the run, raised when it has.
    interrupt: Mutex<Option<PyErr>>,
}

impl PyProgress {
    fn stop_with(&self, e: PyErr) {
        if let Ok(mut slot) = self.interrupt.lock()
            && slot.is_none()
        {
            *slot = Some(e);
        }
        self.stop.store(true, Ordering::SeqCst);
    }
}

impl Progress for PyProgress {
    fn begin(&self, what: &str) {
        if let Ok(mut s) = self.stage.lock() {
            *s = what.to_string();
        }
        self.advance(0, 0);
    }

    fn advance(&self, done: u64, total: u64) {
        let Some(callback) = &self.callback else {
            return;
        };
        if self.stopped() {
            return;
        }
        let stage = self.stage.lock().map(|s| s.clone()).unwrap_or_default();
        Python::attach(|py| {
            if let Err(e) = callback.call1(py, (stage, done, total)) {
                if e.is_instance_of::<PyKeyboardInterrupt>(py)
                    || e.is_instance_of::<PySystemExit>(py)
                {
                    self.stop_with(e);
                } else {
                    e.print(py);
                }
            }
        });
    }

    fn stopped(&self) -> bool {
        self.stop.load(Ordering::SeqCst)
    }
}

/// The project: None (the defaults), a path to project.toml, or its settings as a dict.
fn project_of(config: Option<&Bound<'_, PyAny>>) -> PyResult<Project> {
    let Some(c) = config else {
        return Ok(Project::default());
    };
    if c.is_instance_of::<PyDict>() {
        // A dict of project.toml's sections: the same keys and the same checks as the file's.
        let value = crate::from_py(c, "config")?;
        let p: Project = serde_path_to_error::deserialize(value)
            .map_err(|e| MrtmapError::new_err(format!("config [{}]: {}", e.path(), e.inner())))?;
        return Project::resolve_over(p, &Overrides::new()).map_err(py_err);
    }
    let path: PathBuf = c.extract().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "config must be None, a path to project.toml, or a dict of its sections; got {}",
            c.get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        ))
    })?;
    must_exist(&path, "config")?;
    Project::resolve(Some(&path), &Overrides::new()).map_err(py_err)
}

/// `mrtmap run` on `recording` into `out`: a dict of the run's `lines`, `seconds`, `stages`,
/// `maps` (each with its figures and grid CSV's path), `comfort`, `level`, `warnings`,
/// `surfaces`, `features` and the main files' `paths`.
#[pyfunction]
#[pyo3(signature = (recording, out, config=None, force=false, progress=None))]
pub(crate) fn run<'py>(
    py: Python<'py>,
    recording: PathBuf,
    out: PathBuf,
    config: Option<&Bound<'py, PyAny>>,
    force: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    must_exist(&recording, "recording")?;
    let project = project_of(config)?;
    let watch = PyProgress {
        callback: progress,
        stage: Mutex::new(String::new()),
        stop: AtomicBool::new(false),
        interrupt: Mutex::new(None),
    };
    let done = py.detach(|| {
        let waiting = std::thread::current();
        let (watch, recording, out) = (&watch, &recording, &out);
        std::thread::scope(|s| {
            let worker = s.spawn(move || {
                let done = Pipeline::new(project)
                    .force(force)
                    .progress(watch)
                    .run(recording, out);
                waiting.unpark();
                done
            });
            while !worker.is_finished() {
                std::thread::park_timeout(SIGNAL_POLL);
                if let Err(e) = Python::attach(|py| py.check_signals()) {
                    watch.stop_with(e);
                }
            }
            // A Ctrl-C that came while the last stage was finishing is raised all the same.
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                watch.stop_with(e);
            }
            worker.join()
        })
    });
    if let Some(e) = watch.interrupt.lock().ok().and_then(|mut s| s.take()) {
        return Err(e);
    }
    let done = match done {
        Ok(d) => d.map_err(py_err)?,
        Err(_) => {
            return Err(MrtmapError::new_err(
                "the run failed inside mrtmap (a bug: please report it with the recording)",
            ));
        }
    };
    outcome_dict(py, &done, &recording, &out)
}

/// A run's figures for Python, each under its own name.
fn outcome_dict<'py>(
    py: Python<'py>,
    done: &mrtmap_pipeline::RunDone,
    recording: &std::path::Path,
    out: &std::path::Path,
) -> PyResult<Bound<'py, PyDict>> {
    let o = &done.outcome;
    let layout = RunLayout::new(out);
    let text = |p: PathBuf| p.to_string_lossy().into_owned();
    let maps = PyList::empty(py);
    for m in &o.maps {
        let s = &m.summary.map;
        let d = PyDict::new(py);
        d.set_item("height_m", s.height_m)?;
        d.set_item("grid", s.grid.to_vec())?;
        d.set_item("csv", text(layout.mrt_grid_csv(s.height_m)))?;
        let f = s.field.as_ref();
        d.set_item("nodes", f.map_or(0, |f| f.nodes))?;
        d.set_item("min_c", f.map_or(f64::NAN, |f| f.min.mrt_c))?;
        d.set_item("max_c", f.map_or(f64::NAN, |f| f.max.mrt_c))?;
        d.set_item("mean_c", f.map_or(f64::NAN, |f| f.mean_c))?;
        d.set_item("max_std_error_k", f.map_or(f64::NAN, |f| f.max_std_error_k))?;
        d.set_item("summary", serde_py(py, &m.summary)?)?;
        maps.append(d)?;
    }
    let paths = PyDict::new(py);
    paths.set_item("report", text(layout.report_html()))?;
    paths.set_item("run_json", text(layout.run_json()))?;
    paths.set_item("scene", text(layout.scene_json()))?;
    let d = PyDict::new(py);
    d.set_item("lines", done.lines(recording, out))?;
    d.set_item("seconds", done.secs)?;
    d.set_item("stages", serde_py(py, &o.stages)?)?;
    d.set_item("maps", maps)?;
    d.set_item(
        "comfort",
        serde_py(py, &o.comfort.as_ref().map(|c| &c.summary))?,
    )?;
    d.set_item("level", serde_py(py, &o.level)?)?;
    d.set_item("warnings", o.warnings.clone())?;
    d.set_item("surfaces", o.scene.surfaces.len())?;
    d.set_item(
        "features",
        o.scene
            .surfaces
            .iter()
            .map(|s| s.features.len())
            .sum::<usize>(),
    )?;
    d.set_item("paths", paths)?;
    Ok(d)
}
