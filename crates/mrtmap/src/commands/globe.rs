//! `mrtmap globe`: globe temperature ↔ MRT.

use mrtmap_pipeline::validation::{Globe, GlobeInput, convert_globe};

use crate::cli::GlobeArgs;
use crate::output::{json, print_lines};

pub fn run(a: &GlobeArgs) -> anyhow::Result<()> {
    let input = match (a.tg, a.tr) {
        (Some(tg), _) => GlobeInput::Globe(tg),
        (None, Some(tr)) => GlobeInput::Mrt(tr),
        (None, None) => {
            anyhow::bail!("give --tg (globe temperature) or --tr (mean radiant temperature)")
        }
    };
    let globe = Globe {
        diameter_m: a.diameter,
        emissivity: a.emissivity,
    };
    let c = convert_globe(input, &globe, a.ta, a.va, a.method.method(a.convection))?;
    if a.json {
        out!("{}", json(&c)?);
    } else {
        print_lines(c.lines());
    }
    Ok(())
}
