//! `mrtmap comfort`: operative temperature and PMV/PPD from air and mean radiant temperature.

use anyhow::{Context, bail};
use mrtmap_pipeline::comfort::{Air, PMV_MODEL, thermal};
use serde::Serialize;

use crate::cli::ComfortArgs;
use crate::output::json;

#[derive(Serialize)]
struct Out {
    air: Air,
    mrt_c: f64,
    model: &'static str,
    operative_c: f64,
    pmv: f64,
    ppd_pct: f64,
    within_iso_ranges: bool,
    category: &'static str,
}

pub fn run(a: &ComfortArgs) -> anyhow::Result<()> {
    if let Some(path) = &a.csv {
        return batch(path);
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
    let t = thermal(&air, tr, 0.0)?;
    let out = Out {
        air,
        mrt_c: tr,
        model: PMV_MODEL,
        operative_c: t.operative_c,
        pmv: t.pmv,
        ppd_pct: t.ppd_pct,
        within_iso_ranges: t.within_iso_ranges,
        category: t.category.as_str(),
    };
    if a.json {
        out!("{}", json(&out)?);
        return Ok(());
    }
    outln!("model: {PMV_MODEL}");
    outln!("operative temperature {:.2} °C (ISO 7726)", t.operative_c);
    outln!(
        "PMV {:.3}, PPD {:.1} %: ISO 7730 category {}{}",
        t.pmv,
        t.ppd_pct,
        t.category.as_str(),
        if t.within_iso_ranges {
            ""
        } else {
            " (inputs outside ISO 7730's ranges: indicative only)"
        }
    );
    Ok(())
}

/// One line per row of a CSV with the columns ta,tr,v,rh,met,clo.
fn batch(path: &std::path::Path) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| mrtmap_pipeline::files::FileError::io(path, e))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!(
            "{}: empty: give a header ta,tr,v,rh,met,clo and one row per case",
            path.display()
        );
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = |n: &str| {
        names.iter().position(|h| *h == n).with_context(|| {
            format!(
                "{}:1: the header has no column '{n}' (needs ta,tr,v,rh,met,clo)",
                path.display()
            )
        })
    };
    let idx = [
        col("ta")?,
        col("tr")?,
        col("v")?,
        col("rh")?,
        col("met")?,
        col("clo")?,
    ];
    outln!("{header},operative_c,pmv,ppd");
    for (k, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let num = |i: usize| -> anyhow::Result<f64> {
            cells
                .get(i)
                .and_then(|c| c.parse::<f64>().ok())
                .with_context(|| {
                    format!(
                        "{}:{}: column {} is not a number",
                        path.display(),
                        k + 1,
                        names[i]
                    )
                })
        };
        let air = Air {
            temperature_c: num(idx[0])?,
            speed_m_s: num(idx[2])?,
            relative_humidity_pct: num(idx[3])?,
            met: num(idx[4])?,
            clo: num(idx[5])?,
        };
        match thermal(&air, num(idx[1])?, 0.0) {
            Ok(t) => outln!("{line},{:.6},{:.6},{:.6}", t.operative_c, t.pmv, t.ppd_pct),
            Err(e) => outln!("{line},,,\"{e}\""),
        }
    }
    Ok(())
}
