//! `mrtmap solar-gain`: the sun on a person behind glass (SolarCal, ASHRAE 55 Appendix C).

use mrtmap_pipeline::comfort::{SolarInputs, solar_gain_of};

use crate::cli::SolarGainArgs;
use crate::output::{json, print_lines};

pub fn run(a: &SolarGainArgs) -> anyhow::Result<()> {
    let answer = solar_gain_of(SolarInputs {
        altitude_deg: a.altitude,
        sharp_deg: a.sharp,
        dni_w_m2: a.dni,
        transmittance: a.transmittance,
        f_svv: a.f_svv,
        f_bes: a.f_bes,
        asw: a.asw,
        posture: a.posture,
        floor_reflectance: a.floor_reflectance,
    })?;
    if a.json {
        out!("{}", json(&answer)?);
    } else {
        print_lines(answer.lines());
    }
    Ok(())
}
