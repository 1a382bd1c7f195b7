//! `mrtmap rooms`: the preset rooms, or one as TOML.

use anyhow::bail;
use mrtmap_pipeline::simulation::{PRESETS, Room};

use crate::cli::RoomsArgs;

pub fn run(a: &RoomsArgs) -> anyhow::Result<()> {
    match &a.name {
        Some(n) => match PRESETS.iter().find(|p| p.0 == n) {
            Some((_, text)) => out!("{text}"),
            None => bail!("no preset room '{n}' (see `mrtmap rooms`)"),
        },
        None => {
            for (name, text) in PRESETS {
                let room = Room::from_toml(text)?;
                outln!("{name:<16} {}", room.file.description);
            }
        }
    }
    Ok(())
}
