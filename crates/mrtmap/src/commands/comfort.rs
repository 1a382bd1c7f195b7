//! `mrtmap comfort`: operative temperature and PMV/PPD from air and mean radiant temperature.

use anyhow::bail;
use mrtmap_pipeline::comfort::{Air, comfort_csv, comfort_of};

use crate::cli::ComfortArgs;
use crate::output::{json, print_lines};

pub fn run(a: &ComfortArgs) -> anyhow::Result<()> {
    if let Some(path) = &a.csv {
        print_lines(comfort_csv(path)?);
        return Ok(());
    }
    let (Some(ta), Some(tr)) = (a.ta, a.tr) else {
        bail!("give --ta and --tr (°C), or --csv FILE");
    };
    let air = Air {
        temperature_c: ta,
        speed_m_s: a.v,
        relative_humidity_pct: a.rh,
        met: a.met,
        clo: a.clo,
    };
    let answer = comfort_of(air, tr)?;
    if a.json {
        out!("{}", json(&answer)?);
    } else {
        print_lines(answer.lines());
    }
    Ok(())
}
