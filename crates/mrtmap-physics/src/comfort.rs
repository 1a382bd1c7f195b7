//! Operative temperature (ISO 7726 / ASHRAE 55), PMV and PPD (ISO 7730), radiant asymmetry.

use serde::{Deserialize, Serialize};
use wide::{CmpGt, CmpLe, f64x2};

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

/// [`pmv_ppd_edition`] over many inputs, computed several at a time: the inputs are checked one
/// by one, and the rest runs on vectors of two lanes, `LANES` inputs in lock step (their square
/// roots and divisions overlap), with the clothing temperature's step under forced convection
/// (a constant coefficient, most steps) without them, and exponentials by polynomial (`wide`).
/// The numbers equal [`pmv_ppd_edition`]'s within 1e-12 (an exponential can differ in its last
/// bit, and a division is a multiplication by the reciprocal).
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
        // Refused inputs keep a filler in their lane; the message is theirs.
        let mut lanes = [Checked::FILLER; LANES];
        let mut refused: [Option<PhysicsError>; LANES] = Default::default();
        for k in 0..len {
            match Checked::new(&input(start + k)) {
                Ok(c) => lanes[k] = c,
                Err(e) => refused[k] = Some(e),
            }
        }
        let mut block = Block::new(&lanes, edition);
        block.iterate();
        let done = block.finish();
        for (k, (c, refused)) in lanes.iter().zip(refused).take(len).enumerate() {
            answer(
                start + k,
                match refused {
                    Some(e) => Err(e),
                    None if !done.converged[k] => Err(no_convergence()),
                    None => Ok(c.judge(done.pmv[k], done.ppd[k], done.pa[k])),
                },
            );
        }
    }
}

/// A block's answers, lane by lane.
struct Finished {
    pmv: [f64; LANES],
    ppd: [f64; LANES],
    /// Water vapour pressure (Pa), for the range check.
    pa: [f64; LANES],
    converged: [bool; LANES],
}

/// Lanes per vector, and vectors per block.
const W: usize = 2;
const G: usize = LANES / W;
type V = f64x2;
type Vs = [V; G];

/// Whether any lane's mask is set.
fn any_lane(m: &Vs) -> bool {
    let mut or = m[0];
    for v in &m[1..] {
        or |= *v;
    }
    or.any()
}

/// Whether every lane's mask is set.
fn all_lanes(m: &Vs) -> bool {
    let mut and = m[0];
    for v in &m[1..] {
        and &= *v;
    }
    and.all()
}

/// One vector per `g` from `f(g)`.
fn each(f: impl FnMut(usize) -> V) -> Vs {
    std::array::from_fn(f)
}

/// `LANES` inputs' constants and iterates as vectors, annex D's names (a refused input's lane
/// computes a filler and is converged from the start).
struct Block {
    ta: Vs,
    m: Vs,
    mw: Vs,
    pa: Vs,
    fcl: Vs,
    /// (tra / 100)⁴.
    tra4: Vs,
    taa: Vs,
    hcf: Vs,
    /// (hcf / 2.38)⁴: natural convection wins (hcn > hcf) where |100·x − taa| exceeds it.
    natural_above: Vs,
    p2: Vs,
    p3: Vs,
    p4: Vs,
    p5: Vs,
    /// The numerator's constant part and the denominator's reciprocal with forced convection.
    forced_num: Vs,
    forced_inv_den: Vs,
    xn: Vs,
    xf: Vs,
    hc: Vs,
    /// All bits set in a converged lane.
    done: Vs,
}

impl Block {
    fn new(lanes: &[Checked; LANES], edition: Iso7730Edition) -> Self {
        let mut columns = [[0.0; LANES]; 8];
        for (l, c) in lanes.iter().enumerate() {
            let empty = if c.filler { f64::NAN } else { 0.0 };
            for (k, x) in [c.ta, c.tr, c.vr, c.rh, c.met, c.clo, c.wme, empty]
                .into_iter()
                .enumerate()
            {
                columns[k][l] = x;
            }
        }
        let [ta, tr, vr, rh, met, clo, wme, empty] =
            columns.map(|c| each(|g| V::new(std::array::from_fn(|l| c[W * g + l]))));
        let s = V::splat;
        let pa = each(|g| rh[g] * s(10.0) * (s(16.6536) - s(4030.183) / (ta[g] + s(235.0))).exp());
        let icl = each(|g| s(0.155) * clo[g]);
        let m = each(|g| met[g] * s(58.15));
        let mw = each(|g| m[g] - wme[g] * s(58.15));
        let fcl = each(|g| {
            icl[g]
                .cmp_le(s(0.078))
                .blend(s(1.0) + s(1.29) * icl[g], s(1.05) + s(0.645) * icl[g])
        });
        let hcf = each(|g| s(12.1) * vr[g].sqrt());
        let taa = each(|g| ta[g] + s(273.0));
        let tra = each(|g| (tr[g] + s(273.0)) / s(100.0));
        let tra4 = each(|g| (tra[g] * tra[g]) * (tra[g] * tra[g]));
        let tcla = each(|g| {
            let den = match edition {
                Iso7730Edition::Y2005 => s(3.5) * icl[g] + s(0.1),
                Iso7730Edition::Y2025 => s(3.5) * (s(6.45) * icl[g] + s(0.1)),
            };
            taa[g] + (s(35.5) - ta[g]) / den
        });
        let p1 = each(|g| icl[g] * fcl[g]);
        let p2 = each(|g| p1[g] * s(3.96));
        let p3 = each(|g| p1[g] * s(100.0));
        let p4 = each(|g| p1[g] * taa[g]);
        let p5 = each(|g| s(308.7) - s(0.028) * mw[g] + p2[g] * tra4[g]);
        let natural_above = each(|g| {
            let q = hcf[g] / s(2.38);
            (q * q) * (q * q)
        });
        Self {
            forced_num: each(|g| p5[g] + p4[g] * hcf[g]),
            forced_inv_den: each(|g| s(1.0) / (s(100.0) + p3[g] * hcf[g])),
            xn: each(|g| tcla[g] / s(100.0)),
            xf: each(|g| tcla[g] / s(50.0)),
            hc: hcf,
            done: empty.map(V::is_nan),
            ta,
            m,
            mw,
            pa,
            fcl,
            tra4,
            taa,
            hcf,
            natural_above,
            p2,
            p3,
            p4,
            p5,
        }
    }

    /// Steps every lane until all have converged or [`MAX_ITERATIONS`] have run: on vectors of
    /// four where the processor has AVX2 (found at run time; the same numbers, operation for
    /// operation), else on `wide`'s vectors of two.
    #[allow(unsafe_code)] // calling the AVX2 build once AVX2 is found: the only unsafe here
    fn iterate(&mut self) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has just been found to support AVX2.
            unsafe { avx2::iterate(self) };
            return;
        }
        self.iterate_portable();
    }

    /// [`Block::iterate`] on `wide`'s vectors, whatever the processor.
    fn iterate_portable(&mut self) {
        for _ in 0..MAX_ITERATIONS {
            if self.step() {
                break;
            }
        }
    }

    /// One step of [`Iteration::step`] in each lane not yet converged; whether all have.
    fn step(&mut self) -> bool {
        let s = V::splat;
        let x = each(|g| (self.xf[g] + self.xn[g]) / s(2.0));
        let d = each(|g| (s(100.0) * x[g] - self.taa[g]).abs());
        let x2 = each(|g| x[g] * x[g]);
        let x4 = each(|g| x2[g] * x2[g]);
        let natural = each(|g| d[g].cmp_gt(self.natural_above[g]));
        let mut h = self.hcf;
        let mut n = each(|g| (self.forced_num[g] - self.p2[g] * x4[g]) * self.forced_inv_den[g]);
        if any_lane(&natural) {
            // The square roots and the division only when natural convection wins somewhere.
            let r = each(|g| d[g].sqrt());
            let r = each(|g| r[g].sqrt());
            let hn = each(|g| self.hcf[g].fast_max(s(2.38) * r[g]));
            let num = each(|g| self.p5[g] + self.p4[g] * hn[g] - self.p2[g] * x4[g]);
            let nn = each(|g| num[g] / (s(100.0) + self.p3[g] * hn[g]));
            h = each(|g| natural[g].blend(hn[g], h[g]));
            n = each(|g| natural[g].blend(nn[g], n[g]));
        }
        let keep = self.done;
        self.xf = each(|g| keep[g].blend(self.xf[g], x[g]));
        self.xn = each(|g| keep[g].blend(self.xn[g], n[g]));
        self.hc = each(|g| keep[g].blend(self.hc[g], h[g]));
        self.done = each(|g| keep[g] | (n[g] - x[g]).abs().cmp_le(s(0.00015)));
        all_lanes(&self.done)
    }

    /// The heat balance at each lane's clothing temperature ([`Fanger::finish`]).
    fn finish(&self) -> Finished {
        let s = V::splat;
        let pmv = each(|g| {
            let (ta, m, mw, pa, fcl) = (self.ta[g], self.m[g], self.mw[g], self.pa[g], self.fcl[g]);
            let (xn, hc) = (self.xn[g], self.hc[g]);
            let tcl = s(100.0) * xn - s(273.0);
            let hl1 = s(3.05e-3) * (s(5733.0) - s(6.99) * mw - pa);
            let hl2 = mw.cmp_gt(s(58.15)).blend(s(0.42) * (mw - s(58.15)), s(0.0));
            let hl3 = s(1.7e-5) * m * (s(5867.0) - pa);
            let hl4 = s(0.0014) * m * (s(34.0) - ta);
            let xn2 = xn * xn;
            let hl5 = s(3.96) * fcl * (xn2 * xn2 - self.tra4[g]);
            let hl6 = fcl * hc * (tcl - ta);
            let ts = s(0.303) * (s(-0.036) * m).exp() + s(0.028);
            ts * (mw - hl1 - hl2 - hl3 - hl4 - hl5 - hl6)
        });
        let ppd = each(|g| {
            let p2 = pmv[g] * pmv[g];
            s(100.0) - s(95.0) * (s(-0.03353) * (p2 * p2) - s(0.2179) * p2).exp()
        });
        let lanes =
            |v: &Vs| -> [f64; LANES] { std::array::from_fn(|l| v[l / W].to_array()[l % W]) };
        Finished {
            pmv: lanes(&pmv),
            ppd: lanes(&ppd),
            pa: lanes(&self.pa),
            converged: lanes(&self.done).map(f64::is_nan),
        }
    }
}

/// [`Block::step`]'s iteration on AVX2's vectors of four lanes: the same operations in the same
/// order (IEEE additions, multiplications, divisions and square roots round alike at any width;
/// no fused multiply-adds), so every lane ends bit for bit where `wide`'s two-lane vectors end.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::{
        __m256d, _CMP_GT_OQ, _CMP_LE_OQ, _mm256_add_pd, _mm256_and_pd, _mm256_andnot_pd,
        _mm256_blendv_pd, _mm256_cmp_pd, _mm256_div_pd, _mm256_max_pd, _mm256_movemask_pd,
        _mm256_mul_pd, _mm256_or_pd, _mm256_set1_pd, _mm256_sqrt_pd, _mm256_sub_pd,
    };

    use super::{Block, LANES, MAX_ITERATIONS, V, Vs, W};

    /// Vectors of four per block.
    const Q: usize = LANES / 4;
    type Y = [__m256d; Q];

    fn wide(v: &Vs) -> Y {
        let a: [f64; LANES] = std::array::from_fn(|l| v[l / W].to_array()[l % W]);
        std::array::from_fn(|q| {
            bytemuck::cast([a[4 * q], a[4 * q + 1], a[4 * q + 2], a[4 * q + 3]])
        })
    }

    fn narrow(y: &Y) -> Vs {
        let a: [[f64; 4]; Q] = y.map(bytemuck::cast);
        std::array::from_fn(|g| {
            V::new(std::array::from_fn(|l| {
                let lane = W * g + l;
                a[lane / 4][lane % 4]
            }))
        })
    }

    /// |v|: the sign bit cleared, as `wide`'s `abs`.
    #[target_feature(enable = "avx2")]
    fn abs(v: __m256d) -> __m256d {
        _mm256_andnot_pd(_mm256_set1_pd(-0.0), v)
    }

    /// `mask ? t : f` lane by lane, as `wide`'s `blend`.
    #[target_feature(enable = "avx2")]
    fn blend(mask: __m256d, t: __m256d, f: __m256d) -> __m256d {
        _mm256_blendv_pd(f, t, mask)
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn iterate(b: &mut Block) {
        let s = _mm256_set1_pd;
        let (taa, hcf, natural_above) = (wide(&b.taa), wide(&b.hcf), wide(&b.natural_above));
        let (p2, p3, p4, p5) = (wide(&b.p2), wide(&b.p3), wide(&b.p4), wide(&b.p5));
        let (forced_num, forced_inv_den) = (wide(&b.forced_num), wide(&b.forced_inv_den));
        let (mut xf, mut xn, mut hc, mut done) =
            (wide(&b.xf), wide(&b.xn), wide(&b.hc), wide(&b.done));
        for _ in 0..MAX_ITERATIONS {
            let mut x = [s(0.0); Q];
            let mut d = [s(0.0); Q];
            let mut x4 = [s(0.0); Q];
            let mut natural = [s(0.0); Q];
            let mut n = [s(0.0); Q];
            for q in 0..Q {
                x[q] = _mm256_div_pd(_mm256_add_pd(xf[q], xn[q]), s(2.0));
                d[q] = abs(_mm256_sub_pd(_mm256_mul_pd(s(100.0), x[q]), taa[q]));
                let x2 = _mm256_mul_pd(x[q], x[q]);
                x4[q] = _mm256_mul_pd(x2, x2);
                natural[q] = _mm256_cmp_pd::<_CMP_GT_OQ>(d[q], natural_above[q]);
                n[q] = _mm256_mul_pd(
                    _mm256_sub_pd(forced_num[q], _mm256_mul_pd(p2[q], x4[q])),
                    forced_inv_den[q],
                );
            }
            let mut h = hcf;
            if _mm256_movemask_pd(
                natural
                    .into_iter()
                    .reduce(|a, b| _mm256_or_pd(a, b))
                    .unwrap_or(s(0.0)),
            ) != 0
            {
                for q in 0..Q {
                    let r = _mm256_sqrt_pd(_mm256_sqrt_pd(d[q]));
                    let hn = _mm256_max_pd(hcf[q], _mm256_mul_pd(s(2.38), r));
                    let num = _mm256_sub_pd(
                        _mm256_add_pd(p5[q], _mm256_mul_pd(p4[q], hn)),
                        _mm256_mul_pd(p2[q], x4[q]),
                    );
                    let nn = _mm256_div_pd(num, _mm256_add_pd(s(100.0), _mm256_mul_pd(p3[q], hn)));
                    h[q] = blend(natural[q], hn, h[q]);
                    n[q] = blend(natural[q], nn, n[q]);
                }
            }
            for q in 0..Q {
                let keep = done[q];
                xf[q] = blend(keep, xf[q], x[q]);
                xn[q] = blend(keep, xn[q], n[q]);
                hc[q] = blend(keep, hc[q], h[q]);
                let close = _mm256_cmp_pd::<_CMP_LE_OQ>(abs(_mm256_sub_pd(n[q], x[q])), s(0.00015));
                done[q] = _mm256_or_pd(keep, close);
            }
            if _mm256_movemask_pd(
                done.into_iter()
                    .reduce(|a, b| _mm256_and_pd(a, b))
                    .unwrap_or(s(0.0)),
            ) == 0b1111
            {
                break;
            }
        }
        (b.xf, b.xn, b.hc, b.done) = (narrow(&xf), narrow(&xn), narrow(&hc), narrow(&done));
    }
}

/// Inputs whose iterations run in lock step (see [`pmv_ppd_many`]).
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
    checked: Checked,
    ta: f64,
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

/// One PMV's inputs, each within the range the formulas accept (°C, m/s, %, met, clo).
#[derive(Clone, Copy, Debug)]
struct Checked {
    ta: f64,
    tr: f64,
    vr: f64,
    rh: f64,
    met: f64,
    clo: f64,
    wme: f64,
    /// A lane of a block with no input in it.
    filler: bool,
}

/// What the formulas accept, in the order inputs are checked (names for the messages).
const INPUT_RANGES: [(&str, f64, f64); 7] = [
    ("air temperature (°C)", -50.0, 100.0),
    ("mean radiant temperature (°C)", -50.0, 150.0),
    ("metabolic rate (met)", 0.1, 10.0),
    ("relative air speed (m/s)", 0.0, 10.0),
    ("relative humidity (%)", 0.0, 100.0),
    ("clothing (clo)", 0.0, 5.0),
    ("external work (met)", 0.0, 10.0),
];

impl Checked {
    /// Ordinary indoor values for a block's empty lanes.
    const FILLER: Self = Self {
        ta: 20.0,
        tr: 20.0,
        vr: 0.1,
        rh: 50.0,
        met: 1.2,
        clo: 0.5,
        wme: 0.0,
        filler: true,
    };

    #[inline]
    fn new(inp: &PmvInputs) -> Result<Self, PhysicsError> {
        let c = Self {
            ta: inp.air.celsius(),
            tr: inp.mrt.celsius(),
            vr: inp.relative_air_speed_m_s,
            rh: inp.relative_humidity_pct,
            met: inp.met,
            clo: inp.clo,
            wme: inp.external_work_met,
            filler: false,
        };
        // The metabolic rate before the air speed: the relative air speed is derived from it
        // (v + 0.3 (met − 1)), and `--met 50` should be refused as a metabolic rate.
        let values = [c.ta, c.tr, c.met, c.vr, c.rh, c.clo, c.wme];
        // All at once without a branch (NaN compares false); the message only for a refusal.
        let accepted = INPUT_RANGES
            .iter()
            .zip(values)
            .fold(true, |ok, ((_, min, max), v)| {
                ok & (v >= *min) & (v <= *max)
            });
        if accepted {
            return Ok(c);
        }
        for ((name, min, max), value) in INPUT_RANGES.into_iter().zip(values) {
            // NaN is outside every range; the message says which input and how.
            if !(min..=max).contains(&value) {
                in_range(name, value, min, max)?;
            }
        }
        Ok(c)
    }

    /// The answer, with whether the inputs, the vapour pressure `pa` (Pa) and the PMV lie in
    /// ISO 7730's ranges.
    fn judge(&self, pmv: f64, ppd_pct: f64, pa: f64) -> Pmv {
        let within = (10.0..=30.0).contains(&self.ta)
            && (10.0..=40.0).contains(&self.tr)
            && (0.0..=1.0).contains(&self.vr)
            && (0.8..=4.0).contains(&self.met)
            && (0.0..=2.0).contains(&self.clo)
            && (0.0..=2700.0).contains(&pa)
            && (-2.0..=2.0).contains(&pmv);
        Pmv {
            pmv,
            ppd_pct,
            within_iso_ranges: within,
        }
    }
}

impl Fanger {
    fn new(inp: &PmvInputs, edition: Iso7730Edition) -> Result<Self, PhysicsError> {
        let c = Checked::new(inp)?;
        let (ta, tr, vr, rh, met, clo, wme) = (c.ta, c.tr, c.vr, c.rh, c.met, c.clo, c.wme);
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
            checked: c,
            ta,
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
        self.checked.judge(pmv, ppd_from_pmv(pmv), pa)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 iteration ends every lane bit for bit where `wide`'s ends, over inputs that take
    /// natural and forced convection, blocks with refused (filler) lanes included.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn the_avx2_iteration_equals_the_portable_one_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = |lo: f64, hi: f64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
        };
        // Lanes that end under natural convection (hc above hcf) and under forced.
        let (mut natural, mut forced) = (0, 0);
        for block in 0..2000 {
            let lanes: [Checked; LANES] = std::array::from_fn(|l| {
                if block % 7 == 0 && l % 3 == 0 {
                    return Checked::FILLER;
                }
                Checked {
                    ta: uniform(5.0, 35.0),
                    tr: uniform(5.0, 45.0),
                    vr: uniform(0.0, 1.5),
                    rh: uniform(5.0, 95.0),
                    met: uniform(0.8, 4.0),
                    clo: uniform(0.0, 2.0),
                    wme: 0.0,
                    filler: false,
                }
            });
            for edition in [Iso7730Edition::Y2005, Iso7730Edition::Y2025] {
                let mut wide = Block::new(&lanes, edition);
                let mut avx = Block::new(&lanes, edition);
                wide.iterate_portable();
                // SAFETY: AVX2 was found above.
                #[allow(unsafe_code)]
                unsafe {
                    avx2::iterate(&mut avx);
                };
                for (a, b) in [
                    (wide.xn, avx.xn),
                    (wide.xf, avx.xf),
                    (wide.hc, avx.hc),
                    (wide.done, avx.done),
                ] {
                    let bits = |v: Vs| v.map(|x| x.to_array().map(f64::to_bits));
                    assert_eq!(bits(a), bits(b), "block {block}");
                }
                for (hc, hcf) in wide.hc.iter().zip(&wide.hcf) {
                    for (hc, hcf) in hc.to_array().into_iter().zip(hcf.to_array()) {
                        if hc > hcf { natural += 1 } else { forced += 1 }
                    }
                }
            }
        }
        assert!(
            natural > 1000 && forced > 1000,
            "natural {natural}, forced {forced}"
        );
    }
}
