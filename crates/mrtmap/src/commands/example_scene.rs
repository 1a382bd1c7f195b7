//! `mrtmap example-scene`: the built-in example as scene.json.

use mrtmap_pipeline::points::{EXAMPLE_OFFICE_JSON, write_example_scene};

use crate::cli::ExampleSceneArgs;

pub fn run(args: &ExampleSceneArgs) -> anyhow::Result<()> {
    match &args.out {
        Some(p) => {
            write_example_scene(p)?;
            outln!("wrote {}", p.display());
        }
        None => out!("{EXAMPLE_OFFICE_JSON}"),
    }
    Ok(())
}
