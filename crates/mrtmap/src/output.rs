//! Output helpers for the CLI.

/// JSON text with a trailing newline.
pub fn json<T: serde::Serialize>(value: &T) -> anyhow::Result<String> {
    Ok(serde_json::to_string_pretty(value)? + "\n")
}

/// Writes `bytes` to `path` atomically (see [`mrtmap_io::write_atomic`]).
pub fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> anyhow::Result<()> {
    Ok(mrtmap_io::write_atomic(path, bytes)?)
}
