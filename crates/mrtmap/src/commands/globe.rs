//! `mrtmap globe`: globe temperature ↔ MRT.

use mrtmap_pipeline::validation::{
    Globe, GlobeMethod, GlobeReading, Temperature, globe_temperature, mrt_from_globe,
};
use serde::Serialize;

use crate::cli::{GlobeArgs, GlobeMethodArg};
use crate::output::json;

#[derive(Serialize)]
struct GlobeOut {
    mrt_c: f64,
    globe_c: f64,
    air_c: f64,
    air_speed_m_s: f64,
    diameter_m: f64,
    emissivity: f64,
    formula: mrtmap_pipeline::validation::GlobeFormula,
    formula_description: &'static str,
    h_w_m2k: f64,
    /// "mrt_from_globe" or "globe_from_mrt".
    direction: &'static str,
}

pub fn run(a: &GlobeArgs) -> anyhow::Result<()> {
    let convection = a.convection;
    let method = match a.method {
        GlobeMethodArg::Iso => GlobeMethod::Iso { convection },
        GlobeMethodArg::IsoClosedForm => GlobeMethod::IsoClosedForm { convection },
        GlobeMethodArg::Mixed => GlobeMethod::MixedConvection,
    };
    let globe = Globe {
        diameter_m: a.diameter,
        emissivity: a.emissivity,
    };
    let air = Temperature::from_celsius(a.ta);
    let (tg, direction) = match (a.tg, a.tr) {
        (Some(tg), _) => (Temperature::from_celsius(tg), "mrt_from_globe"),
        (None, Some(tr)) => (
            globe_temperature(&globe, Temperature::from_celsius(tr), air, a.va, method)?,
            "globe_from_mrt",
        ),
        (None, None) => {
            anyhow::bail!("give --tg (globe temperature) or --tr (mean radiant temperature)")
        }
    };
    let r = mrt_from_globe(
        &globe,
        &GlobeReading {
            globe: tg,
            air,
            air_speed_m_s: a.va,
        },
        method,
    )?;
    let out = GlobeOut {
        mrt_c: r.mrt.celsius(),
        globe_c: tg.celsius(),
        air_c: a.ta,
        air_speed_m_s: a.va,
        diameter_m: a.diameter,
        emissivity: a.emissivity,
        formula: r.formula,
        formula_description: r.formula.describe(),
        h_w_m2k: r.h_w_m2k,
        direction,
    };
    if a.json {
        out!("{}", json(&out)?);
    } else if direction == "mrt_from_globe" {
        outln!("MRT {:.2} °C", out.mrt_c);
        outln!(
            "  from globe {:.2} °C, air {:.2} °C, air speed {} m/s, globe {} m, ε {}",
            out.globe_c,
            a.ta,
            a.va,
            a.diameter,
            a.emissivity
        );
        outln!(
            "  formula: {} (h = {:.2} W/m²K)",
            out.formula_description,
            out.h_w_m2k
        );
    } else {
        outln!("globe temperature {:.2} °C", out.globe_c);
        outln!(
            "  at MRT {:.2} °C, air {:.2} °C, air speed {} m/s, globe {} m, ε {}",
            out.mrt_c,
            a.ta,
            a.va,
            a.diameter,
            a.emissivity
        );
        outln!(
            "  formula: {} (h = {:.2} W/m²K), solved numerically",
            out.formula_description,
            out.h_w_m2k
        );
    }
    Ok(())
}
