//! `mrtmap example-scene`: the built-in example as scene.json.

use mrtmap_pipeline::points::EXAMPLE_OFFICE_JSON;

use crate::cli::ExampleSceneArgs;
use mrtmap_pipeline::files::write_atomic;

pub fn run(args: &ExampleSceneArgs) -> anyhow::Result<()> {
    match &args.out {
        Some(p) => {
            write_atomic(p, EXAMPLE_OFFICE_JSON.as_bytes())?;
            outln!("wrote {}", p.display());
        }
        None => out!("{EXAMPLE_OFFICE_JSON}"),
    }
    Ok(())
}
