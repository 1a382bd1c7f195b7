//! Rooms and simulator settings shared by `simulate` and `demo`.

use std::path::Path;

use mrtmap_sim::{PRESETS, Room, SimConfig, preset};

use crate::error::{Error, Result};

/// A preset room by name, or a room TOML file.
pub fn load_room(spec: &str) -> Result<Room> {
    if let Some(r) = preset(spec) {
        return Ok(r?);
    }
    let path = Path::new(spec);
    if !path.exists() {
        let names: Vec<&str> = PRESETS.iter().map(|p| p.0).collect();
        return Err(Error::setting(
            format!("room '{spec}'"),
            format!("is neither a preset room ({}) nor a file", names.join(", ")),
        ));
    }
    let text = std::fs::read_to_string(path).map_err(|e| mrtmap_io::FileError::io(path, e))?;
    Room::from_toml(&text).map_err(|e| Error::source(path, e.to_string()))
}

/// Sets the depth (and colour) image size of `cfg`, scaling the intrinsics; the size must keep
/// the default camera's aspect.
pub fn set_depth_size(cfg: &mut SimConfig, (w, h): (usize, usize)) -> Result<()> {
    let s = w as f64 / cfg.depth_camera.width as f64;
    if (h as f64 / cfg.depth_camera.height as f64 - s).abs() > 1e-9 {
        return Err(Error::setting(
            format!("--depth-size {w}x{h}"),
            format!(
                "must keep the aspect of {}x{}",
                cfg.depth_camera.width, cfg.depth_camera.height
            ),
        ));
    }
    cfg.depth_camera = cfg.depth_camera.scaled(s);
    Ok(())
}
