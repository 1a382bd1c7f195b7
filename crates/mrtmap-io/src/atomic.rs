//! Atomic outputs: a file is written to a temporary name in its folder and renamed into place; a
//! folder is built under `NAME.partial` and renamed when complete. An interrupted run leaves no
//! half-written result under the final name.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{FileError, FileErrorKind};

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

/// The file in a folder mrtmap made listing what it wrote there: what a later run may replace.
/// A finished [`PartialDir`] lists every file by its path inside the folder (`thermal/0001.png`);
/// [`claim_dir`] lists whole entries as `name/**` (`fuse/**`: that name and all under it); an
/// empty folder is listed as `name/`.
pub const MADE: &str = ".mrtmap-made";

/// Whether `path` (inside the folder, `/`-separated) is what mrtmap leaves while writing: a
/// temporary file of [`write_atomic`] or a folder `NAME.partial`.
fn is_in_progress(path: &str) -> bool {
    let name = path.rsplit('/').next().unwrap_or(path);
    (name.starts_with(".mrtmap-") && name.ends_with(".tmp")) || name.ends_with(".partial")
}

/// Whether the list `made` covers `path`: named exactly (an empty folder as `name/`), or under an
/// entry `name/**` (the name and all under it).
fn covered(path: &str, made: &std::collections::HashSet<&str>) -> bool {
    made.contains(path)
        || made.iter().any(|e| {
            e.strip_suffix("/**").is_some_and(|stem| {
                path == stem
                    || path
                        .strip_prefix(stem)
                        .is_some_and(|rest| rest.starts_with('/'))
            })
        })
}

/// Every file under `dir`, by its path inside it (`/`-separated), in name order; folders
/// `NAME.partial` and temporary files are passed over.
fn files_under(dir: &Path, prefix: &str, out: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<_> = entries.filter_map(Result::ok).collect();
    entries.sort_by_key(|e| e.file_name());
    for e in entries {
        let path = format!("{prefix}{}", e.file_name().to_string_lossy());
        if is_in_progress(&path) || path == MADE {
            continue;
        }
        if e.file_type().is_ok_and(|t| t.is_dir()) {
            let before = out.len();
            files_under(&e.path(), &format!("{path}/"), out);
            if out.len() == before {
                out.push(format!("{path}/")); // an empty folder is an entry too
            }
        } else {
            out.push(path);
        }
    }
}

/// Refuses `target` when it exists and is not empty, unless [`MADE`] covers every file in it,
/// in its subfolders too (a file a person added inside a folder mrtmap made is theirs).
pub fn check_replaceable(target: &Path) -> Result<(), FileError> {
    if !target.is_dir() {
        return Ok(()); // absent (a file there fails later, named)
    }
    let made = std::fs::read_to_string(target.join(MADE)).unwrap_or_default();
    let made: std::collections::HashSet<&str> = made.lines().filter(|l| !l.is_empty()).collect();
    let mut names = Vec::new();
    files_under(target, "", &mut names);
    let Some(first) = names.iter().find(|n| !covered(n, &made)) else {
        return Ok(());
    };
    let what = if made.is_empty() {
        format!(
            "already exists and holds {} entr{} mrtmap did not write there (the first: {first})",
            names.len(),
            if names.len() == 1 { "y" } else { "ies" }
        )
    } else {
        format!("holds {first}, which mrtmap did not write there")
    };
    Err(FileError::new(
        target,
        None,
        FileErrorKind::Syntax(format!(
            "{what}: give a new or empty folder, or move what is in it (mrtmap replaces only a folder it made)"
        )),
    ))
}

/// Claims the folder `dir` for outputs that mrtmap writes into it in place (a run folder): refuses
/// it when it holds an entry that its [`MADE`] list does not name (a folder of the user's, or a
/// file they put in one of mrtmap's), creates it when missing, and adds `names` (the entries the
/// caller will write) to the list, so that a later run may write them again.
pub fn claim_dir(dir: &Path, names: &[String]) -> Result<(), FileError> {
    check_replaceable(dir)?;
    std::fs::create_dir_all(dir).map_err(|e| FileError::io(dir, e))?;
    let list = dir.join(MADE);
    let old = std::fs::read_to_string(&list).unwrap_or_default();
    let mut all: std::collections::BTreeSet<&str> = old.lines().filter(|l| !l.is_empty()).collect();
    let before = all.len();
    let claimed: Vec<String> = names.iter().map(|n| format!("{n}/**")).collect();
    all.extend(claimed.iter().map(String::as_str));
    if all.len() == before && list.exists() {
        return Ok(());
    }
    let mut text = all.into_iter().collect::<Vec<_>>().join("\n");
    text.push('\n');
    write_atomic(&list, text.as_bytes())
}

/// Adds every file now in `dir` (in its subfolders too) to its [`MADE`] list: for a command that
/// wrote its outputs into a folder [`check_replaceable`] let it use, so that it may write them
/// again next time while a file a person adds later is still theirs.
pub fn record_made(dir: &Path) -> Result<(), FileError> {
    let list = dir.join(MADE);
    let old = std::fs::read_to_string(&list).unwrap_or_default();
    let mut all: std::collections::BTreeSet<String> = old
        .lines()
        .filter(|l| !l.is_empty())
        .map(str::to_string)
        .collect();
    let mut now = Vec::new();
    files_under(dir, "", &mut now);
    all.extend(now);
    let mut text = all.into_iter().collect::<Vec<_>>().join("\n");
    text.push('\n');
    write_atomic(&list, text.as_bytes())
}

/// A folder being built: files go into `FINAL.partial/`; [`PartialDir::finish`] renames it to
/// `FINAL` (replacing an older one). Dropped unfinished, the partial folder stays for inspection
/// and the final name is untouched.
pub struct PartialDir {
    partial: PathBuf,
    target: PathBuf,
}

impl PartialDir {
    /// Starts building `target` (removing a stale partial folder). A `target` that exists must be
    /// empty or a folder this type finished before holding nothing else (its [`MADE`] list names
    /// every entry): a folder of the user's, or one they added files to, is refused, not replaced.
    pub fn create(target: &Path) -> Result<Self, FileError> {
        check_replaceable(target)?;
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

    /// Moves the folder to its final name, listing what it holds in [`MADE`].
    pub fn finish(self) -> Result<PathBuf, FileError> {
        let mut names = Vec::new();
        files_under(&self.partial, "", &mut names);
        names.push(String::new());
        let made = self.partial.join(MADE);
        std::fs::write(&made, names.join("\n")).map_err(|e| FileError::io(&made, e))?;
        if self.target.exists() {
            std::fs::remove_dir_all(&self.target).map_err(|e| FileError::io(&self.target, e))?;
        }
        std::fs::rename(&self.partial, &self.target).map_err(|e| FileError::io(&self.target, e))?;
        Ok(self.target)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn finish_with(target: &Path, files: &[&str]) -> Result<PathBuf, FileError> {
        let dir = PartialDir::create(target)?;
        for f in files {
            std::fs::write(dir.path().join(f), b"x").map_err(|e| FileError::io(target, e))?;
        }
        dir.finish()
    }

    /// A folder of the user's is refused, not replaced (`convert` and `simulate` deleted a
    /// folder's notes and subfolders); a folder mrtmap finished is replaced, until the user puts
    /// something of their own in it.
    #[test]
    fn only_an_empty_folder_or_one_mrtmap_made_is_replaced() -> Result<(), FileError> {
        let tmp = tempfile::tempdir().map_err(|e| FileError::io(Path::new("tmp"), e))?;
        let out = tmp.path().join("out");
        std::fs::create_dir(&out).map_err(|e| FileError::io(&out, e))?;
        finish_with(&out, &["a.txt"])?; // empty: taken
        finish_with(&out, &["b.txt"])?; // made by mrtmap: replaced
        assert!(out.join("b.txt").exists() && !out.join("a.txt").exists());
        std::fs::write(out.join("notes.txt"), b"mine").map_err(|e| FileError::io(&out, e))?;
        let err = finish_with(&out, &["c.txt"]).err().map(|e| e.to_string());
        assert!(
            err.as_deref()
                .is_some_and(|e| e.contains("notes.txt") && e.contains("mrtmap did not write")),
            "{err:?}"
        );
        assert!(out.join("notes.txt").exists() && out.join("b.txt").exists());
        let user = tmp.path().join("precious");
        std::fs::create_dir_all(user.join("sub")).map_err(|e| FileError::io(&user, e))?;
        let err = finish_with(&user, &["d.txt"]).err().map(|e| e.to_string());
        assert!(
            err.as_deref().is_some_and(|e| e.contains("already exists")),
            "{err:?}"
        );
        assert!(user.join("sub").is_dir());
        // A file added inside a subfolder of a folder mrtmap made is the user's too (it was
        // deleted with the folder: the outside campaign of issue 63).
        let nested = tmp.path().join("nested");
        let dir = PartialDir::create(&nested)?;
        std::fs::create_dir_all(dir.path().join("thermal")).map_err(|e| FileError::io(&out, e))?;
        std::fs::write(dir.path().join("thermal/0.png"), b"x")
            .map_err(|e| FileError::io(&out, e))?;
        dir.finish()?;
        finish_with(&nested, &["e.txt"])?; // all its own: replaced
        let dir = PartialDir::create(&nested)?;
        std::fs::create_dir_all(dir.path().join("thermal")).map_err(|e| FileError::io(&out, e))?;
        dir.finish()?;
        std::fs::write(nested.join("thermal/notes.txt"), b"mine")
            .map_err(|e| FileError::io(&out, e))?;
        let err = finish_with(&nested, &["f.txt"])
            .err()
            .map(|e| e.to_string());
        assert!(
            err.as_deref()
                .is_some_and(|e| e.contains("thermal/notes.txt") && e.contains("did not write")),
            "{err:?}"
        );
        assert!(nested.join("thermal/notes.txt").exists());
        // A folder claimed for writing in place covers what is under the names it claimed.
        let run = tmp.path().join("run");
        claim_dir(&run, &["fuse".to_string(), "report.html".to_string()])?;
        std::fs::create_dir_all(run.join("fuse")).map_err(|e| FileError::io(&run, e))?;
        std::fs::write(run.join("fuse/cloud.ply"), b"x").map_err(|e| FileError::io(&run, e))?;
        std::fs::write(run.join("report.html"), b"x").map_err(|e| FileError::io(&run, e))?;
        claim_dir(&run, &["segment".to_string()])?;
        std::fs::write(run.join("mine.txt"), b"x").map_err(|e| FileError::io(&run, e))?;
        let err = claim_dir(&run, &["fuse".to_string()])
            .err()
            .map(|e| e.to_string());
        assert!(
            err.as_deref().is_some_and(|e| e.contains("mine.txt")),
            "{err:?}"
        );
        Ok(())
    }
}
