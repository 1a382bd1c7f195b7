//! `mrtmap map`: MRT over a grid, written as CSV, PNG, SVG and JSON.

use mrtmap_radiation::GridSpec;

use super::{load_scene, resolve_method};
use crate::cli::MapArgs;
use crate::maps::make_map;

pub fn run(a: &MapArgs) -> anyhow::Result<()> {
    let (scene, source) = load_scene(&a.scene)?;
    let method = resolve_method(&a.method, &scene)?;
    let spec = GridSpec {
        nx: a.grid.0,
        ny: a.grid.1,
        height_m: a.height,
        margin_m: a.margin_m,
    };
    let m = make_map(&scene, &source, method, spec, &a.marks, &a.out)?;
    println!("scene: {source}");
    println!("method: {}", m.method);
    print_map(&m.summary);
    println!(
        "computed in {:.3} s; wrote mrt_grid.csv, mrt_map.png, mrt_map.svg, summary.json in {}",
        m.summary.map.compute_secs,
        a.out.display()
    );
    Ok(())
}

/// Prints a map's extremes and marks.
pub(crate) fn print_map(s: &crate::maps::Summary) {
    match &s.map.field {
        Some(f) => {
            println!(
                "MRT at {:.2} m over {} nodes: min {:.2} °C at ({:.2}, {:.2}), max {:.2} °C at ({:.2}, {:.2}), mean {:.2} °C; largest standard error {:.3} K",
                s.map.height_m,
                f.nodes,
                f.min.mrt_c,
                f.min.uv[0],
                f.min.uv[1],
                f.max.mrt_c,
                f.max.uv[0],
                f.max.uv[1],
                f.mean_c,
                f.max_std_error_k
            );
            if f.skipped > 0 {
                println!(
                    "{} nodes skipped (inside occluders or failed): see the note column of mrt_grid.csv",
                    f.skipped
                );
            }
        }
        None => println!("no grid node could be computed"),
    }
    for m in &s.marks {
        println!(
            "  {}: MRT {:.2} °C ± {:.2} K at ({:.2}, {:.2}, {:.2})",
            m.name.as_deref().unwrap_or("?"),
            m.mrt_c,
            m.std_error_k,
            m.xyz[0],
            m.xyz[1],
            m.xyz[2]
        );
    }
}
