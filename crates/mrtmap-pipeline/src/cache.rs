//! Reusing a stage's outputs while its inputs have not changed.
//!
//! A stage is some work that writes output files. Its [`Fingerprint`] records what the outputs
//! depend on: input files (size and modification time; a folder stands for the files in it) and
//! settings. [`run_or_reuse`] skips the work when the stamp file holds the same fingerprint and
//! every output exists; the stamp is written last, so an interrupted stage runs again.
//!
//! The run's stages, the conversion of a bag or database into a recording, and the demo's
//! simulation all go through here.

use std::path::{Path, PathBuf};
use std::time::{Instant, UNIX_EPOCH};

use mrtmap_io::{Recording, StreamEntry, write_atomic};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// One input file as last seen: missing files stamp as such.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FileStamp {
    /// The path, absolute (canonical where it exists, so that `rec` and `/abs/…/rec` are one
    /// input).
    pub path: String,
    /// Its size, or `None` when it did not exist.
    pub bytes: Option<u64>,
    /// Its modification time (ns since the Unix epoch), when known.
    pub modified_ns: Option<u64>,
}

impl FileStamp {
    /// Stamps `p` now.
    pub fn of(p: &Path) -> Self {
        let m = std::fs::metadata(p).ok();
        let path = std::fs::canonicalize(p)
            .or_else(|_| std::path::absolute(p))
            .unwrap_or_else(|_| p.to_path_buf());
        Self {
            path: path.display().to_string(),
            bytes: m.as_ref().map(std::fs::Metadata::len),
            modified_ns: m
                .and_then(|m| m.modified().ok())
                .and_then(|t| t.duration_since(UNIX_EPOCH).ok())
                .map(|d| d.as_nanos() as u64),
        }
    }
}

/// What a stage's outputs depend on.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Fingerprint {
    /// Input files.
    pub inputs: Vec<FileStamp>,
    /// Settings, by name.
    pub settings: serde_json::Map<String, serde_json::Value>,
}

impl Fingerprint {
    /// A fingerprint of no inputs, made by this version of mrtmap: another version's outputs are
    /// not reused (its algorithms may differ).
    pub fn new() -> Self {
        Self::default().setting("mrtmap_version", &env!("CARGO_PKG_VERSION"))
    }

    /// Adds an input file; a folder adds each file directly in it, in name order.
    pub fn file(mut self, p: &Path) -> Self {
        if p.is_dir() {
            let mut files: Vec<PathBuf> = std::fs::read_dir(p)
                .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
                .unwrap_or_default();
            files.sort();
            self.inputs.extend(files.iter().map(|f| FileStamp::of(f)));
        } else {
            self.inputs.push(FileStamp::of(p));
        }
        self
    }

    /// Adds the frames a list names, as one digest of each file's path, size and modification
    /// time under `name` (thousands of frames make one entry, not thousands): a frame replaced
    /// behind an unchanged list is a changed input (a run reused fusion over new thermal images).
    pub fn frames(self, name: &str, rec: &Recording, frames: &[StreamEntry]) -> Self {
        use std::hash::{Hash, Hasher};
        let mut h = std::hash::DefaultHasher::new();
        for e in frames {
            let p = rec.path_of(e);
            let m = std::fs::metadata(&p).ok();
            p.hash(&mut h);
            m.as_ref().map(std::fs::Metadata::len).hash(&mut h);
            m.and_then(|m| m.modified().ok()).hash(&mut h);
        }
        self.setting(
            name,
            &format!("{} frames, {:016x}", frames.len(), h.finish()),
        )
    }

    /// Adds a small input file by its content (a digest of its bytes) as well as its stamp: a
    /// settings' file (a weather file) rewritten with the same size and time is still a change.
    pub fn file_content(self, p: &Path) -> Self {
        use std::hash::{Hash, Hasher};
        let mut h = std::hash::DefaultHasher::new();
        std::fs::read(p).ok().hash(&mut h);
        let name = format!("content of {}", FileStamp::of(p).path);
        self.file(p).setting(&name, &format!("{:016x}", h.finish()))
    }

    /// Adds an optional input file.
    pub fn maybe_file(self, p: Option<&Path>) -> Self {
        match p {
            Some(p) => self.file(p),
            None => self,
        }
    }

    /// Adds a setting.
    pub fn setting(mut self, name: &str, value: &impl Serialize) -> Self {
        let v = serde_json::to_value(value).unwrap_or(serde_json::Value::Null);
        self.settings.insert(name.to_string(), v);
        self
    }
}

/// A stage: its name for people, where its fingerprint is kept, and the outputs it must leave.
#[derive(Clone, Debug)]
pub struct Stage {
    /// Name for people ("fuse", "map at 1.10 m").
    pub name: String,
    /// The stamp file holding the fingerprint of the last completed run.
    pub stamp: PathBuf,
    /// Files the stage writes; all must exist for a reuse.
    pub outputs: Vec<PathBuf>,
}

#[cfg(test)]
impl Stage {
    /// A stage working in its own folder: stamp `dir/stage.json`, outputs named inside `dir`.
    pub fn in_dir(name: impl Into<String>, dir: &Path, outputs: &[&str]) -> Self {
        Self {
            name: name.into(),
            stamp: crate::layout::stage_json_in(dir),
            outputs: outputs.iter().map(|o| dir.join(o)).collect(),
        }
    }
}

/// What a stage did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StageOutcome {
    /// Stage name.
    pub stage: String,
    /// Skipped: the inputs had not changed.
    pub skipped: bool,
    /// Seconds (of the run that produced the outputs).
    pub secs: f64,
}

/// The stamp file's content.
#[derive(Serialize, Deserialize)]
struct StampFile {
    fingerprint: Fingerprint,
    secs: f64,
}

/// The fingerprint and time of the last completed run, when the stamp file holds one.
fn last_run(stamp: &Path) -> Option<StampFile> {
    let text = std::fs::read_to_string(stamp).ok()?;
    serde_json::from_str(&text).ok()
}

/// Runs `work` unless the stage's stamp holds `fingerprint` and every output exists (or `force`).
pub fn run_or_reuse(
    stage: &Stage,
    fingerprint: Fingerprint,
    force: bool,
    work: impl FnOnce() -> Result<()>,
) -> Result<StageOutcome> {
    if !force
        && let Some(old) = last_run(&stage.stamp)
        && old.fingerprint == fingerprint
        && stage.outputs.iter().all(|o| o.exists())
    {
        return Ok(StageOutcome {
            stage: stage.name.clone(),
            skipped: true,
            secs: old.secs,
        });
    }
    match std::fs::remove_file(&stage.stamp) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(mrtmap_io::FileError::io(&stage.stamp, e).into());
        }
        _ => {}
    }
    let t0 = Instant::now();
    work()?;
    let secs = t0.elapsed().as_secs_f64();
    write_json(&stage.stamp, &StampFile { fingerprint, secs })?;
    Ok(StageOutcome {
        stage: stage.name.clone(),
        skipped: false,
        secs,
    })
}

/// Pretty JSON with a trailing newline.
pub fn json_text<T: Serialize>(value: &T) -> String {
    // Serialising plain data (maps with string keys, numbers, strings) cannot fail.
    serde_json::to_string_pretty(value).unwrap_or_default() + "\n"
}

/// Writes `value` as pretty JSON to `path`, atomically.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    Ok(write_atomic(path, json_text(value).as_bytes())?)
}

/// Reads JSON the pipeline wrote earlier.
pub fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| mrtmap_io::FileError::io(path, e))?;
    serde_json::from_str(&text).map_err(|source| Error::Json {
        path: path.to_path_buf(),
        source,
    })
}

/// One line per stage: its time, and whether it was reused.
pub fn stage_lines(stages: &[StageOutcome]) -> Vec<String> {
    let mut lines = Vec::new();
    for st in stages {
        lines.push(format!(
            "  {:<14} {:>7.1} s{}",
            st.stage,
            st.secs,
            if st.skipped {
                "  (inputs unchanged: reused)"
            } else {
                ""
            }
        ));
    }
    lines
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_stage_reruns_when_an_input_or_setting_changes_or_an_output_is_gone() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.txt");
        std::fs::write(&input, "a").unwrap();
        let stage = Stage::in_dir("s", dir.path(), &["out.txt"]);
        let fp = |v: i32| Fingerprint::new().file(&input).setting("v", &v);
        let runs = std::cell::Cell::new(0);
        let work = || {
            runs.set(runs.get() + 1);
            std::fs::write(dir.path().join("out.txt"), "x").unwrap();
            Ok(())
        };
        assert!(!run_or_reuse(&stage, fp(1), false, work).unwrap().skipped);
        assert!(run_or_reuse(&stage, fp(1), false, work).unwrap().skipped);
        assert!(!run_or_reuse(&stage, fp(2), false, work).unwrap().skipped);
        std::fs::write(&input, "ab").unwrap();
        assert!(!run_or_reuse(&stage, fp(2), false, work).unwrap().skipped);
        std::fs::remove_file(dir.path().join("out.txt")).unwrap();
        assert!(!run_or_reuse(&stage, fp(2), false, work).unwrap().skipped);
        assert!(!run_or_reuse(&stage, fp(2), true, work).unwrap().skipped);
        assert_eq!(runs.get(), 5);
    }

    #[test]
    fn an_interrupted_stage_leaves_no_stamp_and_runs_again() {
        let dir = tempfile::tempdir().unwrap();
        let stage = Stage::in_dir("s", dir.path(), &[]);
        let failed = run_or_reuse(&stage, Fingerprint::new(), false, || {
            Err(Error::setting("x", "interrupted"))
        });
        assert!(failed.is_err());
        assert!(!stage.stamp.exists());
        let again = run_or_reuse(&stage, Fingerprint::new(), false, || Ok(())).unwrap();
        assert!(!again.skipped);
    }

    /// Issue 54: `rec15` then `/abs/…/rec15` fused again: an input is one input however its path
    /// is written.
    #[test]
    fn a_relative_and_an_absolute_path_are_one_input() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a"), "1").unwrap();
        let absolute = Fingerprint::new().file(&dir.path().join("a"));
        let dotted = Fingerprint::new().file(&dir.path().join(".").join("a"));
        assert_eq!(absolute, dotted);
        let here = std::env::current_dir().unwrap();
        let relative = pathdiff(dir.path(), &here);
        assert_eq!(
            absolute,
            Fingerprint::new().file(&here.join(relative).join("a"))
        );
    }

    /// `to` relative to `from` by `..` steps (both absolute).
    fn pathdiff(to: &Path, from: &Path) -> PathBuf {
        let mut up = PathBuf::new();
        for _ in from.components().skip(1) {
            up.push("..");
        }
        up.join(to.strip_prefix("/").unwrap())
    }

    #[test]
    fn a_folder_stands_for_its_files() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a"), "1").unwrap();
        let before = Fingerprint::new().file(dir.path());
        assert_eq!(before.inputs.len(), 1);
        std::fs::write(dir.path().join("a"), "12").unwrap();
        assert_ne!(before, Fingerprint::new().file(dir.path()));
    }
}
