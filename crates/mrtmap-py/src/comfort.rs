//! The comfort formulas element by element over numpy arrays: in parallel without the GIL, NaN
//! at an element whose inputs a formula refuses, never an error for one element. The inputs come
//! as they were given, each in its own shape, with the shape they broadcast to: a column of air
//! temperatures against a row of radiant ones is read where it lies, not copied to the grid's
//! size (a copy made fresh memory, whose page faults cost as much as the PMVs). Each function
//! returns, beside its arrays, how many elements with no NaN among their inputs were refused and
//! the first one's message, for the Python layer's warning (a NaN in gives a NaN out silently, as
//! numpy's arithmetic does).

use mrtmap_pipeline::comfort::{
    Iso7730Edition, OperativeMethod, PmvInputs, SolarInputs, SolarPosture, operative_temperature,
    pmv_ppd_each, solar_gain as solarcal,
};
use mrtmap_pipeline::validation::{
    Convection, Globe, GlobeFormulaChoice, GlobeInput, MIXED_CONVECTION_DIAMETERS_M, Temperature,
    convert_globe,
};
use numpy::{AllowTypeChange, PyArray1, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::sync::{Mutex, PoisonError};

use crate::{MrtmapError, message};

/// Arrays out, then the refusals: (count, the first's message).
type Refusals = (usize, Option<String>);
type One<'py> = (Bound<'py, PyArray1<f64>>, usize, Option<String>);
type Two<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    usize,
    Option<String>,
);
/// An input as Python passes it: a C-contiguous array of any shape that broadcasts to the
/// elements' shape.
type Input<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// Elements per parallel block.
const BLOCK: usize = 2048;

/// One input read in the elements' broadcast shape (numpy's rules: shapes aligned at their last
/// axis, an axis of one repeated), element `k` in C order.
enum Column<'a> {
    /// One value for every element.
    One(f64),
    /// A value per element, in order.
    Flat(&'a [f64]),
    /// Fewer values, repeated along some axes: element k's is `data[Σ index_d(k) · strides[d]]`.
    Repeated {
        data: &'a [f64],
        shape: Vec<usize>,
        strides: Vec<usize>,
    },
}

/// A block's values of one column: borrowed where they lie in order, gathered otherwise.
enum Values<'a> {
    One(f64),
    Slice(&'a [f64]),
    Gathered(Vec<f64>),
}

impl Values<'_> {
    #[inline]
    fn at(&self, j: usize) -> f64 {
        match self {
            Values::One(v) => *v,
            Values::Slice(s) => s[j],
            Values::Gathered(v) => v[j],
        }
    }
}

impl<'a> Column<'a> {
    /// `data` (C order, of shape `own`) read in `shape`; None when `own` does not broadcast to it.
    fn new(data: &'a [f64], own: &[usize], shape: &[usize]) -> Option<Self> {
        if data.len() == 1 {
            return Some(Column::One(data[0]));
        }
        if own == shape {
            return Some(Column::Flat(data));
        }
        if own.len() > shape.len() {
            return None;
        }
        // Its shape padded with ones on the left, then its C-order strides, 0 where repeated.
        let mut padded = vec![1; shape.len() - own.len()];
        padded.extend_from_slice(own);
        let mut strides = vec![0; shape.len()];
        let mut step = 1;
        for d in (0..shape.len()).rev() {
            match (padded[d], shape[d]) {
                (1, _) => {}
                (a, b) if a == b => strides[d] = step,
                _ => return None,
            }
            step *= padded[d];
        }
        Some(Column::Repeated {
            data,
            shape: shape.to_vec(),
            strides,
        })
    }

    /// Elements `start..start + len`'s values.
    fn block(&self, start: usize, len: usize) -> Values<'a> {
        match self {
            Column::One(v) => Values::One(*v),
            Column::Flat(d) => Values::Slice(&d[start..start + len]),
            Column::Repeated {
                data,
                shape,
                strides,
            } => {
                // The first element's index, then one step at a time with carries.
                let mut index = vec![0; shape.len()];
                let mut rest = start;
                for d in (0..shape.len()).rev() {
                    index[d] = rest % shape[d];
                    rest /= shape[d];
                }
                let mut offset: usize = index.iter().zip(strides).map(|(i, s)| i * s).sum();
                let mut out = Vec::with_capacity(len);
                for _ in 0..len {
                    out.push(data[offset]);
                    for d in (0..shape.len()).rev() {
                        index[d] += 1;
                        offset += strides[d];
                        if index[d] < shape[d] {
                            break;
                        }
                        offset -= strides[d] * shape[d];
                        index[d] = 0;
                    }
                }
                Values::Gathered(out)
            }
        }
    }
}

/// The inputs as columns over the elements' shape `shape` (numpy's broadcast of theirs, found by
/// the Python layer), and the number of elements; an input that does not broadcast to it is
/// named.
fn columns<'a, const N: usize>(
    arrays: [&'a Input<'_>; N],
    names: [&str; N],
    shape: &[usize],
) -> PyResult<([Column<'a>; N], usize)> {
    let n = shape
        .iter()
        .try_fold(1usize, |n, &d| n.checked_mul(d))
        .ok_or_else(|| {
            pyo3::exceptions::PyMemoryError::new_err(format!(
                "the inputs broadcast to {shape:?}, more elements than memory can address"
            ))
        })?;
    let mut cols = Vec::with_capacity(N);
    for (a, name) in arrays.into_iter().zip(names) {
        let data = a.as_slice().map_err(|_| {
            MrtmapError::new_err(format!("{name} is not a contiguous array of numbers"))
        })?;
        let column = Column::new(data, a.shape(), shape).ok_or_else(|| {
            MrtmapError::new_err(format!(
                "{name} has shape {:?}, which does not broadcast to {shape:?}",
                a.shape()
            ))
        })?;
        cols.push(column);
    }
    let cols: [Column<'a>; N] = cols
        .try_into()
        .map_err(|_| MrtmapError::new_err("an input went missing"))?;
    Ok((cols, n))
}

/// An output of `n` values, or a `MemoryError` when it does not fit (a broadcast of a 100,000
/// column against a 100,000 row asks 80 GB; allocating it outright aborted the interpreter).
fn zeros(n: usize) -> PyResult<Vec<f64>> {
    // Asked first and given back (an address range, no page touched), then allocated zeroed:
    // `vec!` takes zeroed pages from the system that the workers fill in parallel, where filling
    // the reserved vector with zeros here would touch every page first, on one thread.
    Vec::<f64>::new().try_reserve_exact(n).map_err(|_| {
        pyo3::exceptions::PyMemoryError::new_err(format!(
            "{n} results of 8 bytes do not fit in memory: compute the inputs in smaller pieces"
        ))
    })?;
    Ok(vec![0.0; n])
}

/// Every column's values for the block of `len` elements from `start`.
fn block_values<'a, const N: usize>(
    cols: &[Column<'a>; N],
    start: usize,
    len: usize,
) -> [Values<'a>; N] {
    std::array::from_fn(|i| cols[i].block(start, len))
}

/// Block refusals merged in order: the total and the first message.
fn merge(blocks: Vec<Refusals>) -> Refusals {
    let count = blocks.iter().map(|b| b.0).sum();
    (count, blocks.into_iter().find_map(|b| b.1))
}

/// `f` of every item, in the items' order, computed on the calling thread and the pool's
/// threads, each taking the next item as it comes free. The calling thread starts at once; the
/// pool's join as they wake (on an idle machine that took milliseconds: a 777×444 PMV grid took
/// 16 ms after a pause against 9 ms back to back when the caller waited for the pool).
fn shared<T: Send, R: Send>(
    items: impl Iterator<Item = T> + Send,
    f: impl Fn(T) -> R + Sync,
) -> Vec<R> {
    let queue = Mutex::new(items.enumerate());
    let done = Mutex::new(Vec::new());
    let work = || {
        loop {
            // A panic in `f` elsewhere poisons nothing that matters here: the queue still hands
            // out items in order.
            let next = queue.lock().unwrap_or_else(PoisonError::into_inner).next();
            let Some((k, item)) = next else { break };
            let r = f(item);
            done.lock()
                .unwrap_or_else(PoisonError::into_inner)
                .push((k, r));
        }
    };
    rayon::in_place_scope(|s| {
        for _ in 1..rayon::current_num_threads() {
            s.spawn(|_| work());
        }
        work();
    });
    let mut done = done.into_inner().unwrap_or_else(PoisonError::into_inner);
    done.sort_unstable_by_key(|(k, _)| *k);
    done.into_iter().map(|(_, r)| r).collect()
}

/// Element `j` of a block's columns.
#[inline]
fn row<const N: usize>(values: &[Values<'_>; N], j: usize) -> [f64; N] {
    std::array::from_fn(|i| values[i].at(j))
}

/// Counts a refusal of element `k` (unless one of its inputs `x` is NaN), keeping the first
/// message.
fn refuse<const N: usize>(r: &mut Refusals, x: &[f64; N], k: usize, e: &dyn std::error::Error) {
    if x.iter().any(|v| v.is_nan()) {
        return;
    }
    r.0 += 1;
    if r.1.is_none() {
        r.1 = Some(format!("element {k}: {}", message(e)));
    }
}

/// `f(inputs)` for every element in parallel, NaN where it refuses.
fn each<const N: usize, E: std::error::Error>(
    py: Python<'_>,
    cols: &[Column<'_>; N],
    n: usize,
    f: impl Fn(&[f64; N]) -> Result<f64, E> + Sync,
) -> PyResult<(Vec<f64>, Refusals)> {
    let mut out = zeros(n)?;
    let blocks = py.detach(|| {
        shared(out.chunks_mut(BLOCK).enumerate(), |(b, chunk)| {
            let start = b * BLOCK;
            let values = block_values(cols, start, chunk.len());
            let mut r = (0, None);
            for (j, o) in chunk.iter_mut().enumerate() {
                let x = row(&values, j);
                *o = f(&x).unwrap_or_else(|e| {
                    refuse(&mut r, &x, start + j, &e);
                    f64::NAN
                });
            }
            r
        })
    });
    Ok((out, merge(blocks)))
}

/// PMV and PPD element by element; with `limit`, NaN where the inputs or the PMV lie outside ISO
/// 7730's ranges (pythermalcomfort's `limit_inputs`); with `round`, PMV to 2 and PPD to 1
/// decimal as numpy's `round` does (x·10ᵈ rounded half to even, then ÷ 10ᵈ), in the parallel
/// loop rather than two more passes over the arrays. NaN where the formula refuses an element.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub(crate) fn pmv_ppd<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    tdb: Input<'py>,
    tr: Input<'py>,
    vr: Input<'py>,
    rh: Input<'py>,
    met: Input<'py>,
    clo: Input<'py>,
    wme: Input<'py>,
    edition: u32,
    limit: bool,
    round: bool,
) -> PyResult<Two<'py>> {
    let edition = match edition {
        2005 => Iso7730Edition::Y2005,
        2025 => Iso7730Edition::Y2025,
        e => {
            return Err(MrtmapError::new_err(format!(
                "ISO 7730 edition {e} is neither 2005 nor 2025"
            )));
        }
    };
    let (cols, n) = columns(
        [&tdb, &tr, &vr, &rh, &met, &clo, &wme],
        ["tdb", "tr", "vr", "rh", "met", "clo", "wme"],
        &shape,
    )?;
    // Blocks of inputs in parallel, written in place; within a block, several PMVs iterate
    // interleaved.
    let mut pmv = zeros(n)?;
    let mut ppd = zeros(n)?;
    let blocks: Vec<Refusals> = py.detach(|| {
        shared(
            pmv.chunks_mut(BLOCK).zip(ppd.chunks_mut(BLOCK)).enumerate(),
            |(b, (pmv, ppd))| {
                let start = b * BLOCK;
                let values = block_values(&cols, start, pmv.len());
                let mut r = (0, None);
                pmv_ppd_each(
                    pmv.len(),
                    |j| {
                        let [ta, tr, vr, rh, met, clo, wme] = row(&values, j);
                        PmvInputs {
                            air: Temperature::from_celsius(ta),
                            mrt: Temperature::from_celsius(tr),
                            relative_air_speed_m_s: vr,
                            relative_humidity_pct: rh,
                            met,
                            clo,
                            external_work_met: wme,
                        }
                    },
                    edition,
                    |j, answer| match answer {
                        Ok(p) if limit && !p.within_iso_ranges => {
                            (pmv[j], ppd[j]) = (f64::NAN, f64::NAN);
                        }
                        Ok(p) if round => {
                            pmv[j] = (p.pmv * 100.0).round_ties_even() / 100.0;
                            ppd[j] = (p.ppd_pct * 10.0).round_ties_even() / 10.0;
                        }
                        Ok(p) => (pmv[j], ppd[j]) = (p.pmv, p.ppd_pct),
                        Err(e) => {
                            (pmv[j], ppd[j]) = (f64::NAN, f64::NAN);
                            refuse(&mut r, &row(&values, j), start + j, &e);
                        }
                    },
                );
                r
            },
        )
    });
    let (count, first) = merge(blocks);
    Ok((
        PyArray1::from_vec(py, pmv),
        PyArray1::from_vec(py, ppd),
        count,
        first,
    ))
}

/// Operative temperature (°C) element by element: ISO 7726's formula, or ASHRAE 55's.
#[pyfunction]
pub(crate) fn operative<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    tdb: Input<'py>,
    tr: Input<'py>,
    v: Input<'py>,
    ashrae: bool,
) -> PyResult<One<'py>> {
    let (cols, n) = columns([&tdb, &tr, &v], ["tdb", "tr", "v"], &shape)?;
    let method = if ashrae {
        OperativeMethod::Ashrae55
    } else {
        OperativeMethod::Iso
    };
    let (out, (count, first)) = each(py, &cols, n, |x| {
        operative_temperature(
            Temperature::from_celsius(x[0]),
            Temperature::from_celsius(x[1]),
            x[2],
            method,
        )
        .map(|t| t.celsius())
    })?;
    Ok((PyArray1::from_vec(py, out), count, first))
}

/// MRT (°C) from globe readings element by element: ISO 7726 (`mixed` false) or mixed
/// convection; NaN where the mixed-convection model is undefined (globes outside 40–150 mm).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub(crate) fn mrt_from_globe<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    tg: Input<'py>,
    tdb: Input<'py>,
    v: Input<'py>,
    d: Input<'py>,
    emissivity: Input<'py>,
    mixed: bool,
) -> PyResult<One<'py>> {
    let (cols, n) = columns(
        [&tg, &tdb, &v, &d, &emissivity],
        ["tg", "tdb", "v", "d", "emissivity"],
        &shape,
    )?;
    let method = if mixed {
        GlobeFormulaChoice::Mixed
    } else {
        GlobeFormulaChoice::Iso
    }
    .method(Convection::Larger);
    let (out, (count, first)) = each(py, &cols, n, |x| {
        let globe = Globe {
            diameter_m: x[3],
            emissivity: x[4],
        };
        if mixed && !MIXED_CONVECTION_DIAMETERS_M.contains(&globe.diameter_m) {
            return Ok(f64::NAN);
        }
        convert_globe(GlobeInput::Globe(x[0]), &globe, x[1], x[2], method).map(|c| c.mrt_c)
    })?;
    Ok((PyArray1::from_vec(py, out), count, first))
}

/// SolarCal's ERF (W/m²) and ΔMRT (K) element by element (pythermalcomfort's `solar_gain`,
/// unrounded): NaN where the altitude lies outside 0…90° or SHARP outside 0…180° (as
/// pythermalcomfort, so that a year of sun positions with its nights goes through), and where
/// any other input lies outside its range (counted as refused).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub(crate) fn solar_gain<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    sol_altitude: Input<'py>,
    sharp: Input<'py>,
    sol_radiation_dir: Input<'py>,
    sol_transmittance: Input<'py>,
    f_svv: Input<'py>,
    f_bes: Input<'py>,
    asw: Input<'py>,
    floor_reflectance: Input<'py>,
    posture: &str,
) -> PyResult<Two<'py>> {
    let posture = SolarPosture::from_name(posture).ok_or_else(|| {
        MrtmapError::new_err(format!(
            "posture '{posture}' is none of 'sitting', 'standing' and 'supine'"
        ))
    })?;
    let (c, n) = columns(
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
        &shape,
    )?;
    let gain = |x: &[f64; 8]| {
        let inputs = SolarInputs {
            altitude_deg: x[0],
            sharp_deg: x[1],
            dni_w_m2: x[2],
            transmittance: x[3],
            f_svv: x[4],
            f_bes: x[5],
            asw: x[6],
            posture,
            floor_reflectance: x[7],
        };
        if !(0.0..=90.0).contains(&inputs.altitude_deg)
            || !(0.0..=180.0).contains(&inputs.sharp_deg)
        {
            return Ok((f64::NAN, f64::NAN));
        }
        solarcal(&inputs).map(|g| (g.erf_w_m2, g.delta_mrt_k))
    };
    let (erf, r) = each(py, &c, n, |x| gain(x).map(|g| g.0))?;
    // The second pass recomputes (SolarCal is cheap); its refusals are the first's.
    let (dmrt, _) = each(py, &c, n, |x| gain(x).map(|g| g.1))?;
    Ok((
        PyArray1::from_vec(py, erf),
        PyArray1::from_vec(py, dmrt),
        r.0,
        r.1,
    ))
}

/// The sky-vault view fraction of a window `w` × `h` (m) straight ahead at distance `d` (m),
/// element by element (pythermalcomfort's `f_svv`).
#[pyfunction]
pub(crate) fn f_svv<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    w: Input<'py>,
    h: Input<'py>,
    d: Input<'py>,
) -> PyResult<One<'py>> {
    let (cols, n) = columns([&w, &h, &d], ["w", "h", "d"], &shape)?;
    let (out, (count, first)) = each(py, &cols, n, |x| {
        mrtmap_pipeline::comfort::f_svv(x[0], x[1], x[2])
    })?;
    Ok((PyArray1::from_vec(py, out), count, first))
}
