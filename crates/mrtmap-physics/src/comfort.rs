//! Operative temperature (ISO 7726 / ASHRAE 55), PMV and PPD (ISO 7730), radiant asymmetry.

use serde::{Deserialize, Serialize};

use crate::error::{PhysicsError, finite, in_range};
use crate::units::Temperature;

/// How to weight air and mean radiant temperature in the operative temperature.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OperativeMethod {
    /// ISO 7726: to = (ta·√(10v) + tr) / (1 + √(10v)).
    Iso,
    /// ASHRAE 55: to = A·ta + (1 − A)·tr, A = 0.5 / 0.6 / 0.7 below 0.2 / 0.6 / 1.0 m/s.
    Ashrae55,
}

/// Operative temperature from air temperature, mean radiant temperature and air speed.
pub fn operative_temperature(
    air: Temperature,
    mrt: Temperature,
    air_speed_m_s: f64,
    method: OperativeMethod,
) -> Result<Temperature, PhysicsError> {
    finite("air temperature", air.kelvin())?;
    finite("mean radiant temperature", mrt.kelvin())?;
    let (ta, tr) = (air.kelvin(), mrt.kelvin());
    let to = match method {
        OperativeMethod::Iso => {
            let v = in_range("air speed (m/s)", air_speed_m_s, 0.0, 100.0)?;
            let s = (10.0 * v).sqrt();
            (ta * s + tr) / (1.0 + s)
        }
        OperativeMethod::Ashrae55 => {
            let v = in_range(
                "air speed (m/s) for ASHRAE 55 weights",
                air_speed_m_s,
                0.0,
                1.0 - 1e-12,
            )?;
            let a = if v < 0.2 {
                0.5
            } else if v < 0.6 {
                0.6
            } else {
                0.7
            };
            a * ta + (1.0 - a) * tr
        }
    };
    Ok(Temperature::from_kelvin(to))
}

/// Inputs of Fanger's PMV model (ISO 7730).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PmvInputs {
    /// Air temperature.
    pub air: Temperature,
    /// Mean radiant temperature.
    pub mrt: Temperature,
    /// Relative air speed (m/s).
    pub relative_air_speed_m_s: f64,
    /// Relative humidity (%).
    pub relative_humidity_pct: f64,
    /// Metabolic rate (met).
    pub met: f64,
    /// Clothing insulation (clo).
    pub clo: f64,
    /// External work (met), usually 0.
    pub external_work_met: f64,
}

/// PMV and PPD, and whether the inputs lie in ISO 7730's validity ranges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pmv {
    /// Predicted mean vote.
    pub pmv: f64,
    /// Predicted percentage dissatisfied (%).
    pub ppd_pct: f64,
    /// Whether every input and the PMV lie within ISO 7730's ranges (10 ≤ ta ≤ 30, 10 ≤ tr ≤ 40,
    /// 0 ≤ vr ≤ 1, 0.8 ≤ met ≤ 4, 0 ≤ clo ≤ 2, water vapour pressure 0–2700 Pa, −2 ≤ PMV ≤ 2).
    pub within_iso_ranges: bool,
}

/// PPD (%) from PMV: 100 − 95·exp(−0.03353·PMV⁴ − 0.2179·PMV²).
pub fn ppd_from_pmv(pmv: f64) -> f64 {
    100.0 - 95.0 * (-0.03353 * pmv.powi(4) - 0.2179 * pmv.powi(2)).exp()
}

/// The edition of ISO 7730 whose annex D code computes the PMV. The two differ only in the first
/// guess of the clothing surface temperature; the iteration stops within 0.015 K of its fixed
/// point, so the guess moves the PMV by up to 0.002.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Iso7730Edition {
    /// ISO 7730:2005's code: t_cl,0 = t_a + (35.5 − t_a)/(3.5·I_cl + 0.1), I_cl in m²K/W.
    Y2005,
    /// ISO 7730:2025's code: t_cl,0 = t_a + (35.5 − t_a)/(3.5·(6.45·I_cl + 0.1)). pythermalcomfort
    /// 4's `pmv_ppd_iso` uses it (for both of its `model`s), so the PMV equals its to 1e-9.
    #[default]
    Y2025,
}

/// Fanger's PMV/PPD as printed in ISO 7730:2025 (annex D; 273 as the Kelvin offset, like the
/// standard). See [`pmv_ppd_edition`] for ISO 7730:2005's.
pub fn pmv_ppd(inp: &PmvInputs) -> Result<Pmv, PhysicsError> {
    pmv_ppd_edition(inp, Iso7730Edition::Y2025)
}

/// Fanger's PMV/PPD as printed in annex D of the given edition of ISO 7730.
pub fn pmv_ppd_edition(inp: &PmvInputs, edition: Iso7730Edition) -> Result<Pmv, PhysicsError> {
    let f = Fanger::new(inp, edition)?;
    let mut it = Iteration::start(&f);
    for _ in 0..MAX_ITERATIONS {
        if it.step(&f) {
            return Ok(f.finish(&it));
        }
    }
    Err(no_convergence())
}

/// [`pmv_ppd_edition`] over many inputs: the same numbers, element by element, computed several
/// at a time (the clothing temperature's iterations of eight inputs interleaved, so that their
/// square roots and divisions overlap: on 345,000 random inputs, 8 lanes took 36–38 ms on one
/// thread, 4 lanes 42–43 ms, 16 lanes 50–67 ms (a lane waits for the slowest of its group)).
pub fn pmv_ppd_many(
    inputs: &[PmvInputs],
    edition: Iso7730Edition,
) -> Vec<Result<Pmv, PhysicsError>> {
    let mut out = Vec::with_capacity(inputs.len());
    pmv_ppd_each(inputs.len(), |k| inputs[k], edition, |_, r| out.push(r));
    out
}

/// [`pmv_ppd_many`] without the vectors: the inputs `input(0..n)` are read as needed, and each
/// answer is handed to `answer(k, …)` in order (a binding writes them into its arrays).
pub fn pmv_ppd_each(
    n: usize,
    input: impl Fn(usize) -> PmvInputs,
    edition: Iso7730Edition,
    mut answer: impl FnMut(usize, Result<Pmv, PhysicsError>),
) {
    for start in (0..n).step_by(LANES) {
        let len = LANES.min(n - start);
        let mut lanes: [Option<(Fanger, Iteration, bool)>; LANES] = [None; LANES];
        let mut errors: [Option<PhysicsError>; LANES] = Default::default();
        for k in 0..len {
            match Fanger::new(&input(start + k), edition) {
                Ok(f) => lanes[k] = Some((f, Iteration::start(&f), false)),
                Err(e) => errors[k] = Some(e),
            }
        }
        step_lanes(&mut lanes);
        for k in 0..len {
            answer(
                start + k,
                match (&lanes[k], errors[k].take()) {
                    (Some((f, it, true)), _) => Ok(f.finish(it)),
                    (_, Some(e)) => Err(e),
                    _ => Err(no_convergence()),
                },
            );
        }
    }
}

/// The iterations of up to `LANES` inputs in lock step, branch-free so that the compiler can keep
/// them in vector registers: every lane computes each step, and a lane that has converged keeps
/// its values (the same numbers as [`Iteration::step`] one input at a time).
fn step_lanes(lanes: &mut [Option<(Fanger, Iteration, bool)>; LANES]) {
    let mut c = [[0.0f64; LANES]; 6]; // taa, hcf, p2, p3, p4, p5
    let (mut xn, mut xf, mut hc) = ([1.0f64; LANES], [1.0f64; LANES], [0.0f64; LANES]);
    let mut done = [true; LANES];
    for (l, lane) in lanes.iter().enumerate() {
        if let Some((f, it, _)) = lane {
            for (k, v) in [f.taa, f.hcf, f.p2, f.p3, f.p4, f.p5]
                .into_iter()
                .enumerate()
            {
                c[k][l] = v;
            }
            (xn[l], xf[l], hc[l], done[l]) = (it.xn, it.xf, it.hc, false);
        }
    }
    let [taa, hcf, p2, p3, p4, p5] = c;
    for _ in 0..MAX_ITERATIONS {
        for l in 0..LANES {
            let x = (xf[l] + xn[l]) / 2.0;
            let hcn = 2.38 * (100.0 * x - taa[l]).abs().sqrt().sqrt();
            let h = hcf[l].max(hcn);
            let n = (p5[l] + p4[l] * h - p2[l] * x.powi(4)) / (100.0 + p3[l] * h);
            let keep = done[l];
            xf[l] = if keep { xf[l] } else { x };
            xn[l] = if keep { xn[l] } else { n };
            hc[l] = if keep { hc[l] } else { h };
            done[l] = keep || (n - x).abs() <= 0.00015;
        }
        if done.iter().all(|d| *d) {
            break;
        }
    }
    for (l, lane) in lanes.iter_mut().enumerate() {
        if let Some((_, it, converged)) = lane {
            *it = Iteration {
                xn: xn[l],
                xf: xf[l],
                hc: hc[l],
            };
            *converged = done[l];
        }
    }
}

/// Inputs whose iterations run interleaved (see [`pmv_ppd_many`] for the measurement behind 8).
const LANES: usize = 8;

/// The iteration's cap (ISO 7730's code iterates until it converges; pythermalcomfort stops at
/// 150).
const MAX_ITERATIONS: usize = 150;

fn no_convergence() -> PhysicsError {
    PhysicsError::NoConvergence {
        what: "clothing surface temperature (PMV)",
    }
}

/// One PMV's inputs checked and its constants (annex D's names).
#[derive(Clone, Copy, Debug)]
struct Fanger {
    ta: f64,
    tr: f64,
    vr: f64,
    met: f64,
    clo: f64,
    pa: f64,
    m: f64,
    mw: f64,
    fcl: f64,
    hcf: f64,
    taa: f64,
    tra: f64,
    tcla: f64,
    p2: f64,
    p3: f64,
    p4: f64,
    p5: f64,
}

/// The clothing surface temperature's iteration: xn, xf (temperatures / 100) and hc.
#[derive(Clone, Copy, Debug)]
struct Iteration {
    xn: f64,
    xf: f64,
    hc: f64,
}

impl Iteration {
    fn start(f: &Fanger) -> Self {
        Self {
            xn: f.tcla / 100.0,
            xf: f.tcla / 50.0,
            hc: f.hcf,
        }
    }

    /// One step; whether it has converged (|xn − xf| ≤ 0.00015, annex D's test).
    fn step(&mut self, f: &Fanger) -> bool {
        self.xf = (self.xf + self.xn) / 2.0;
        // x^0.25 as two square roots: within an ulp of powf, at a third of its cost.
        let hcn = 2.38 * (100.0 * self.xf - f.taa).abs().sqrt().sqrt();
        self.hc = f.hcf.max(hcn);
        self.xn = (f.p5 + f.p4 * self.hc - f.p2 * self.xf.powi(4)) / (100.0 + f.p3 * self.hc);
        (self.xn - self.xf).abs() <= 0.00015
    }
}

impl Fanger {
    fn new(inp: &PmvInputs, edition: Iso7730Edition) -> Result<Self, PhysicsError> {
        let ta = in_range("air temperature (°C)", inp.air.celsius(), -50.0, 100.0)?;
        let tr = in_range(
            "mean radiant temperature (°C)",
            inp.mrt.celsius(),
            -50.0,
            150.0,
        )?;
        // The metabolic rate first: the relative air speed is derived from it (v + 0.3 (met − 1)),
        // and `--met 50` should be refused as a metabolic rate.
        let met = in_range("metabolic rate (met)", inp.met, 0.1, 10.0)?;
        let vr = in_range(
            "relative air speed (m/s)",
            inp.relative_air_speed_m_s,
            0.0,
            10.0,
        )?;
        let rh = in_range(
            "relative humidity (%)",
            inp.relative_humidity_pct,
            0.0,
            100.0,
        )?;
        let clo = in_range("clothing (clo)", inp.clo, 0.0, 5.0)?;
        let wme = in_range("external work (met)", inp.external_work_met, 0.0, 10.0)?;

        let pa = rh * 10.0 * (16.6536 - 4030.183 / (ta + 235.0)).exp();
        let icl = 0.155 * clo;
        let m = met * 58.15;
        let w = wme * 58.15;
        let mw = m - w;
        let fcl = if icl <= 0.078 {
            1.0 + 1.29 * icl
        } else {
            1.05 + 0.645 * icl
        };
        let taa = ta + 273.0;
        let tra = tr + 273.0;
        let tcla = match edition {
            Iso7730Edition::Y2005 => taa + (35.5 - ta) / (3.5 * icl + 0.1),
            Iso7730Edition::Y2025 => taa + (35.5 - ta) / (3.5 * (6.45 * icl + 0.1)),
        };
        let p1 = icl * fcl;
        let p2 = p1 * 3.96;
        Ok(Self {
            ta,
            tr,
            vr,
            met,
            clo,
            pa,
            m,
            mw,
            fcl,
            hcf: 12.1 * vr.sqrt(),
            taa,
            tra,
            tcla,
            p2,
            p3: p1 * 100.0,
            p4: p1 * taa,
            p5: 308.7 - 0.028 * mw + p2 * (tra / 100.0).powi(4),
        })
    }

    /// The heat balance at the converged clothing temperature: PMV, PPD, ranges.
    fn finish(&self, it: &Iteration) -> Pmv {
        let (xn, hc) = (it.xn, it.hc);
        let (ta, m, mw, pa, fcl) = (self.ta, self.m, self.mw, self.pa, self.fcl);
        let tcl = 100.0 * xn - 273.0;
        let hl1 = 3.05e-3 * (5733.0 - 6.99 * mw - pa);
        let hl2 = if mw > 58.15 { 0.42 * (mw - 58.15) } else { 0.0 };
        let hl3 = 1.7e-5 * m * (5867.0 - pa);
        let hl4 = 0.0014 * m * (34.0 - ta);
        let hl5 = 3.96 * fcl * (xn.powi(4) - (self.tra / 100.0).powi(4));
        let hl6 = fcl * hc * (tcl - ta);
        let ts = 0.303 * (-0.036 * m).exp() + 0.028;
        let pmv = ts * (mw - hl1 - hl2 - hl3 - hl4 - hl5 - hl6);
        let within = (10.0..=30.0).contains(&ta)
            && (10.0..=40.0).contains(&self.tr)
            && (0.0..=1.0).contains(&self.vr)
            && (0.8..=4.0).contains(&self.met)
            && (0.0..=2.0).contains(&self.clo)
            && (0.0..=2700.0).contains(&pa)
            && (-2.0..=2.0).contains(&pmv);
        Pmv {
            pmv,
            ppd_pct: ppd_from_pmv(pmv),
            within_iso_ranges: within,
        }
    }
}

/// The four radiant-asymmetry situations of ISO 7730 (figure 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AsymmetryKind {
    /// Warm ceiling.
    WarmCeiling,
    /// Cool wall.
    CoolWall,
    /// Cool ceiling.
    CoolCeiling,
    /// Warm wall.
    WarmWall,
}

/// Percentage dissatisfied (%) from a radiant temperature asymmetry Δtpr (K), ISO 7730.
pub fn radiant_asymmetry_ppd(kind: AsymmetryKind, delta_k: f64) -> Result<f64, PhysicsError> {
    let dt = in_range("radiant asymmetry (K)", delta_k, 0.0, 100.0)?;
    let pd = match kind {
        AsymmetryKind::WarmCeiling => 100.0 / (1.0 + (2.84 - 0.174 * dt).exp()) - 5.5,
        AsymmetryKind::CoolWall => 100.0 / (1.0 + (6.61 - 0.345 * dt).exp()),
        AsymmetryKind::CoolCeiling => 100.0 / (1.0 + (9.93 - 0.50 * dt).exp()),
        AsymmetryKind::WarmWall => 100.0 / (1.0 + (3.72 - 0.052 * dt).exp()) - 3.5,
    };
    Ok(pd.max(0.0))
}
