//! One run at a time per output folder: a run holds an exclusive lock on its `--out` folder while
//! it writes, and a second run into the same folder is refused at once instead of interleaving
//! its files with the first's (issue 54: run A printed its mean and pointed to a report that held
//! B's map). The lock is the operating system's (flock on the folder itself): it needs no file of
//! its own and is released when the process ends, however it ends.

use std::path::Path;

use crate::error::{Error, Result};

/// The lock on a run folder, held until dropped; a folder it created is removed again when the
/// run left it empty (a run that failed at once writes nothing).
#[derive(Debug)]
pub struct OutLock {
    _held: Option<std::fs::File>,
    created: Option<std::path::PathBuf>,
}

impl Drop for OutLock {
    fn drop(&mut self) {
        if let Some(dir) = &self.created
            && std::fs::read_dir(dir).is_ok_and(|mut d| d.next().is_none())
        {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

impl OutLock {
    /// Locks `out` (created when missing); refuses when another process holds it. Where the
    /// folder cannot be locked (a file system without locks, a platform without them) the run
    /// goes on unlocked.
    pub fn take(out: &Path) -> Result<Self> {
        let created = (!out.exists()).then(|| out.to_path_buf());
        std::fs::create_dir_all(out).map_err(|e| mrtmap_io::FileError::io(out, e))?;
        let unlocked = |created| {
            Ok(Self {
                _held: None,
                created,
            })
        };
        let Ok(dir) = std::fs::File::open(out) else {
            return unlocked(created);
        };
        match dir.try_lock() {
            Ok(()) => Ok(Self {
                _held: Some(dir),
                created,
            }),
            Err(std::fs::TryLockError::WouldBlock) => Err(Error::source(
                out,
                "is being written by another mrtmap run: wait for it to finish, or choose another --out",
            )),
            Err(std::fs::TryLockError::Error(_)) => unlocked(created),
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_second_run_into_a_locked_folder_is_refused_until_the_first_ends() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("run");
        let first = OutLock::take(&out).unwrap();
        let e = OutLock::take(&out).unwrap_err().to_string();
        assert!(e.contains("being written by another mrtmap run"), "{e}");
        drop(first);
        // The folder it made, left empty, is gone again; one with files stays.
        assert!(!out.exists());
        let again = OutLock::take(&out).unwrap();
        std::fs::write(out.join("run.json"), "{}").unwrap();
        drop(again);
        assert!(out.join("run.json").exists());
    }
}
