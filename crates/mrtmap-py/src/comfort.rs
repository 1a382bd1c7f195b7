//! The comfort formulas element by element over 1-D arrays (the Python layer broadcasts): in
//! parallel without the GIL, NaN at an element whose inputs a formula refuses, never an error for
//! one element. Each returns, beside its arrays, how many elements with no NaN among their inputs
//! were refused and the first one's message, for the Python layer's warning (a NaN in gives a NaN
//! out silently, as numpy's arithmetic does).

use mrtmap_pipeline::comfort::{
    Iso7730Edition, OperativeMethod, PmvInputs, SolarInputs, SolarPosture, operative_temperature,
    pmv_ppd_each, solar_gain as solarcal,
};
use mrtmap_pipeline::validation::{
    Convection, Globe, GlobeFormulaChoice, GlobeInput, MIXED_CONVECTION_DIAMETERS_M, Temperature,
    convert_globe,
};
use numpy::ndarray::ArrayView1;
use numpy::{AllowTypeChange, PyArray1, PyArrayLike1};
use pyo3::prelude::*;
use rayon::prelude::*;

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

/// Elements per parallel block.
const BLOCK: usize = 2048;

/// Views of 1-D arrays of one length `n` (broadcast already by the Python layer) or of one value
/// (a scalar, the same for every element: no copy of it n times), named in the error when one
/// differs. Views, not copies: the arrays stay borrowed while the GIL is released.
fn columns<'a, const N: usize>(
    arrays: [&'a PyArrayLike1<'_, f64, AllowTypeChange>; N],
    names: [&str; N],
) -> PyResult<[ArrayView1<'a, f64>; N]> {
    let cols = arrays.map(|a| a.as_array());
    let n = elements(&cols);
    match cols
        .iter()
        .zip(names)
        .find(|(c, _)| c.len() != n && c.len() != 1)
    {
        Some((c, name)) => Err(MrtmapError::new_err(format!(
            "{name} has {} values where the others have {n}",
            c.len()
        ))),
        None => Ok(cols),
    }
}

/// The number of elements: the columns' length, 1 when all are single values, 0 when one is empty.
fn elements<const N: usize>(cols: &[ArrayView1<'_, f64>; N]) -> usize {
    if cols.iter().any(|c| c.is_empty()) {
        0
    } else {
        cols.iter().map(ArrayView1::len).max().unwrap_or(0)
    }
}

/// Element `k` of a column, or its single value.
#[inline]
fn at(c: &ArrayView1<'_, f64>, k: usize) -> f64 {
    if c.len() == 1 { c[0] } else { c[k] }
}

/// Whether any input of element `k` is NaN.
fn any_nan<const N: usize>(cols: &[ArrayView1<'_, f64>; N], k: usize) -> bool {
    cols.iter().any(|c| at(c, k).is_nan())
}

/// Counts a refusal of element `k` (unless an input of it is NaN), keeping the first message.
fn refuse<const N: usize>(
    r: &mut Refusals,
    cols: &[ArrayView1<'_, f64>; N],
    k: usize,
    e: &dyn std::error::Error,
) {
    if any_nan(cols, k) {
        return;
    }
    r.0 += 1;
    if r.1.is_none() {
        r.1 = Some(format!("element {k}: {}", message(e)));
    }
}

/// Block refusals merged in order: the total and the first message.
fn merge(blocks: Vec<Refusals>) -> Refusals {
    let count = blocks.iter().map(|b| b.0).sum();
    (count, blocks.into_iter().find_map(|b| b.1))
}

/// `f(k)` for every element in parallel blocks, NaN where it refuses.
fn each<const N: usize, E: std::error::Error>(
    py: Python<'_>,
    cols: &[ArrayView1<'_, f64>; N],
    f: impl Fn(usize) -> Result<f64, E> + Sync,
) -> (Vec<f64>, Refusals) {
    let n = elements(cols);
    let mut out = vec![0.0; n];
    let blocks = py.detach(|| {
        out.par_chunks_mut(BLOCK)
            .enumerate()
            .map(|(b, chunk)| {
                let mut r = (0, None);
                for (j, o) in chunk.iter_mut().enumerate() {
                    let k = b * BLOCK + j;
                    *o = f(k).unwrap_or_else(|e| {
                        refuse(&mut r, cols, k, &e);
                        f64::NAN
                    });
                }
                r
            })
            .collect::<Vec<_>>()
    });
    (out, merge(blocks))
}

/// PMV and PPD element by element; with `limit`, NaN where the inputs or the PMV lie outside ISO
/// 7730's ranges (pythermalcomfort's `limit_inputs`); with `round`, PMV to 2 and PPD to 1
/// decimal as numpy's `round` does (x·10ᵈ rounded half to even, then ÷ 10ᵈ), in the parallel
/// loop rather than two more passes over the arrays. NaN where the formula refuses an element.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub(crate) fn pmv_ppd<'py>(
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
    let cols = columns(
        [&tdb, &tr, &vr, &rh, &met, &clo, &wme],
        ["tdb", "tr", "vr", "rh", "met", "clo", "wme"],
    )?;
    let n = elements(&cols);
    // Blocks of inputs in parallel, written in place; within a block, several PMVs iterate
    // interleaved.
    let mut pmv = vec![0.0; n];
    let mut ppd = vec![0.0; n];
    let blocks: Vec<Refusals> = py.detach(|| {
        pmv.par_chunks_mut(BLOCK)
            .zip(ppd.par_chunks_mut(BLOCK))
            .enumerate()
            .map(|(b, (pmv, ppd))| {
                let start = b * BLOCK;
                let mut r = (0, None);
                pmv_ppd_each(
                    pmv.len(),
                    |j| {
                        let k = start + j;
                        PmvInputs {
                            air: Temperature::from_celsius(at(&cols[0], k)),
                            mrt: Temperature::from_celsius(at(&cols[1], k)),
                            relative_air_speed_m_s: at(&cols[2], k),
                            relative_humidity_pct: at(&cols[3], k),
                            met: at(&cols[4], k),
                            clo: at(&cols[5], k),
                            external_work_met: at(&cols[6], k),
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
                            refuse(&mut r, &cols, start + j, &e);
                        }
                    },
                );
                r
            })
            .collect()
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
    tdb: PyArrayLike1<'py, f64, AllowTypeChange>,
    tr: PyArrayLike1<'py, f64, AllowTypeChange>,
    v: PyArrayLike1<'py, f64, AllowTypeChange>,
    ashrae: bool,
) -> PyResult<One<'py>> {
    let cols = columns([&tdb, &tr, &v], ["tdb", "tr", "v"])?;
    let method = if ashrae {
        OperativeMethod::Ashrae55
    } else {
        OperativeMethod::Iso
    };
    let (out, (count, first)) = each(py, &cols, |k| {
        operative_temperature(
            Temperature::from_celsius(at(&cols[0], k)),
            Temperature::from_celsius(at(&cols[1], k)),
            at(&cols[2], k),
            method,
        )
        .map(|t| t.celsius())
    });
    Ok((PyArray1::from_vec(py, out), count, first))
}

/// MRT (°C) from globe readings element by element: ISO 7726 (`mixed` false) or mixed
/// convection; NaN where the mixed-convection model is undefined (globes outside 40–150 mm).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub(crate) fn mrt_from_globe<'py>(
    py: Python<'py>,
    tg: PyArrayLike1<'py, f64, AllowTypeChange>,
    tdb: PyArrayLike1<'py, f64, AllowTypeChange>,
    v: PyArrayLike1<'py, f64, AllowTypeChange>,
    d: PyArrayLike1<'py, f64, AllowTypeChange>,
    emissivity: PyArrayLike1<'py, f64, AllowTypeChange>,
    mixed: bool,
) -> PyResult<One<'py>> {
    let cols = columns(
        [&tg, &tdb, &v, &d, &emissivity],
        ["tg", "tdb", "v", "d", "emissivity"],
    )?;
    let method = if mixed {
        GlobeFormulaChoice::Mixed
    } else {
        GlobeFormulaChoice::Iso
    }
    .method(Convection::Larger);
    let (out, (count, first)) = each(py, &cols, |k| {
        let globe = Globe {
            diameter_m: at(&cols[3], k),
            emissivity: at(&cols[4], k),
        };
        if mixed && !MIXED_CONVECTION_DIAMETERS_M.contains(&globe.diameter_m) {
            return Ok(f64::NAN);
        }
        convert_globe(
            GlobeInput::Globe(at(&cols[0], k)),
            &globe,
            at(&cols[1], k),
            at(&cols[2], k),
            method,
        )
        .map(|c| c.mrt_c)
    });
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
    sol_altitude: PyArrayLike1<'py, f64, AllowTypeChange>,
    sharp: PyArrayLike1<'py, f64, AllowTypeChange>,
    sol_radiation_dir: PyArrayLike1<'py, f64, AllowTypeChange>,
    sol_transmittance: PyArrayLike1<'py, f64, AllowTypeChange>,
    f_svv: PyArrayLike1<'py, f64, AllowTypeChange>,
    f_bes: PyArrayLike1<'py, f64, AllowTypeChange>,
    asw: PyArrayLike1<'py, f64, AllowTypeChange>,
    floor_reflectance: PyArrayLike1<'py, f64, AllowTypeChange>,
    posture: &str,
) -> PyResult<Two<'py>> {
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
    let gain = |k: usize| {
        let inputs = SolarInputs {
            altitude_deg: at(&c[0], k),
            sharp_deg: at(&c[1], k),
            dni_w_m2: at(&c[2], k),
            transmittance: at(&c[3], k),
            f_svv: at(&c[4], k),
            f_bes: at(&c[5], k),
            asw: at(&c[6], k),
            posture,
            floor_reflectance: at(&c[7], k),
        };
        if !(0.0..=90.0).contains(&inputs.altitude_deg)
            || !(0.0..=180.0).contains(&inputs.sharp_deg)
        {
            return Ok((f64::NAN, f64::NAN));
        }
        solarcal(&inputs).map(|g| (g.erf_w_m2, g.delta_mrt_k))
    };
    let (erf, r) = each(py, &c, |k| gain(k).map(|g| g.0));
    // The second pass recomputes (SolarCal is cheap); its refusals are the first's.
    let (dmrt, _) = each(py, &c, |k| gain(k).map(|g| g.1));
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
    w: PyArrayLike1<'py, f64, AllowTypeChange>,
    h: PyArrayLike1<'py, f64, AllowTypeChange>,
    d: PyArrayLike1<'py, f64, AllowTypeChange>,
) -> PyResult<One<'py>> {
    let cols = columns([&w, &h, &d], ["w", "h", "d"])?;
    let (out, (count, first)) = each(py, &cols, |k| {
        mrtmap_pipeline::comfort::f_svv(at(&cols[0], k), at(&cols[1], k), at(&cols[2], k))
    });
    Ok((PyArray1::from_vec(py, out), count, first))
}
