//! Atomic outputs: a file is written to a temporary name in its folder and renamed into place; a
//! folder is built under `NAME.partial` and renamed when complete. An interrupted run leaves no
//! half-written result under the final name.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::FileError;

/// Writes `bytes` to `path` atomically (temporary file + rename), creating the folder if needed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir).map_err(|e| FileError::io(dir, e))?;
    let mut builder = tempfile::Builder::new();
    builder.prefix(".mrtmap-").suffix(".tmp");
    // Results are ordinary files (rw-r--r-- before the umask), not private temporaries.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    let mut tmp = builder
        .tempfile_in(dir)
        .map_err(|e| FileError::io(dir, e))?;
    tmp.write_all(bytes).map_err(|e| FileError::io(path, e))?;
    tmp.as_file()
        .sync_all()
        .map_err(|e| FileError::io(path, e))?;
    tmp.persist(path)
        .map_err(|e| FileError::io(path, e.error))?;
    Ok(())
}

/// A folder being built: files go into `FINAL.partial/`; [`PartialDir::finish`] renames it to
/// `FINAL` (replacing an older one). Dropped unfinished, the partial folder stays for inspection
/// and the final name is untouched.
pub struct PartialDir {
    partial: PathBuf,
    target: PathBuf,
}

impl PartialDir {
    /// Starts building `target` (removing a stale partial folder).
    pub fn create(target: &Path) -> Result<Self, FileError> {
        let mut name = target
            .file_name()
            .map(|n| n.to_os_string())
            .unwrap_or_else(|| "out".into());
        name.push(".partial");
        let partial = target.with_file_name(name);
        if partial.exists() {
            std::fs::remove_dir_all(&partial).map_err(|e| FileError::io(&partial, e))?;
        }
        std::fs::create_dir_all(&partial).map_err(|e| FileError::io(&partial, e))?;
        Ok(Self {
            partial,
            target: target.to_path_buf(),
        })
    }

    /// Where to write files now.
    pub fn path(&self) -> &Path {
        &self.partial
    }

    /// Moves the folder to its final name.
    pub fn finish(self) -> Result<PathBuf, FileError> {
        if self.target.exists() {
            std::fs::remove_dir_all(&self.target).map_err(|e| FileError::io(&self.target, e))?;
        }
        std::fs::rename(&self.partial, &self.target).map_err(|e| FileError::io(&self.target, e))?;
        Ok(self.target)
    }
}
