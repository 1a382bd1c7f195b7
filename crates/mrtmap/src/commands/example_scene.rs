//! `mrtmap example-scene`: the built-in example as scene.json.

use mrtmap_pipeline::points::{EXAMPLE_OFFICE_JSON, write_example_scene};

use crate::cli::ExampleSceneArgs;

pub fn run(args: &ExampleSceneArgs) -> anyhow::Result<()> {
    match &args.out {
        Some(p) => {
            if p.exists() {
                anyhow::bail!(
                    "{} already exists: give a new file name, or move it away (example-scene does not overwrite a file)",
                    p.display()
                );
            }
            write_example_scene(p)?;
            outln!("wrote {}", p.display());
        }
        None => out!("{EXAMPLE_OFFICE_JSON}"),
    }
    Ok(())
}
