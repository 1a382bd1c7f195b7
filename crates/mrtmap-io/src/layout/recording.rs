//! The recording layout (a folder, version 1): `rig.toml`, stream lists, TUM trajectories,
//! images. See docs/recording.md; what this reader accepts beyond it is in the crate docs.

use std::path::{Path, PathBuf};

use super::files::RecordingFile;
use super::rig::Rig;
use super::streams::{LineSkip, MAX_SKIPPED_SHARE, SkippedLine, StreamEntry, read_stream_list};
use super::trajectory::{InterpolationLimits, Trajectory};
use crate::error::{FileError, FileErrorKind};
use crate::image16::{Image16, read_image16};

/// An opened recording: rig, stream lists and trajectories, checked; images are read on demand.
#[derive(Clone, Debug)]
pub struct Recording {
    /// The folder.
    pub dir: PathBuf,
    /// Cameras and extrinsics.
    pub rig: Rig,
    /// Depth frames.
    pub depth: Vec<StreamEntry>,
    /// Thermal frames.
    pub thermal: Vec<StreamEntry>,
    /// Colour frames (optional stream).
    pub rgb: Vec<StreamEntry>,
    /// Instance-mask frames (optional stream, see [`super::masks`]).
    pub masks: Vec<StreamEntry>,
    /// world_from_depth poses.
    pub trajectory: Trajectory,
    /// True poses, when the recording has them (simulated scans).
    pub groundtruth: Option<Trajectory>,
    /// Inertial samples (`imu.txt`, optional), in the depth camera's frame.
    pub imu: Vec<super::ImuSample>,
    /// Things worth knowing that do not stop a scan from being used.
    pub warnings: Vec<RecordingWarning>,
}

/// Something worth knowing about a recording that does not stop it from being used.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum RecordingWarning {
    /// rig.toml has keys or sections mrtmap does not read (`[section] key`): a misspelt optional
    /// key would otherwise be read past without a word.
    UnknownRigKeys(Vec<String>),
    /// No trajectory.txt: the poses must come from the built-in tracker (the recording has colour).
    NoTrajectory,
    /// depth.txt lists no frames.
    NoDepthFrames,
    /// thermal.txt lists no frames.
    NoThermalFrames,
    /// trajectory.txt has no poses.
    NoPoses,
    /// Lines that repeat the line before them (timestamp and file), left out: a frame listed
    /// twice would count twice.
    RepeatedLines {
        /// The list.
        list: &'static str,
        /// Lines left out.
        count: usize,
        /// The first one (1-based).
        first_line: usize,
    },
    /// Lines left out of a list by the list rules (see [`super::streams`]): not "timestamp
    /// path", back in time, or their file not there; at most a tenth of the list's frame lines.
    SkippedLines {
        /// The list.
        list: &'static str,
        /// Lines left out.
        count: usize,
        /// The first one, and why.
        first: SkippedLine,
    },
    /// Thermal frames whose stamps lie outside the trajectory (as recorded: another clock's
    /// offset may cover them).
    ThermalWithoutPose {
        /// Frames without a pose.
        uncovered: usize,
        /// Thermal frames.
        total: usize,
    },
}

impl std::fmt::Display for RecordingWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::UnknownRigKeys(keys) => write!(
                f,
                "rig.toml has {}, which mrtmap does not read (a misspelt key? the keys are in docs/recording.md)",
                keys.join(", ")
            ),
            Self::NoTrajectory => {
                f.write_str("no trajectory.txt: the poses must come from the built-in tracker")
            }
            Self::NoDepthFrames => f.write_str("depth.txt lists no frames"),
            Self::NoThermalFrames => f.write_str("thermal.txt lists no frames"),
            Self::NoPoses => f.write_str("trajectory.txt has no poses"),
            Self::RepeatedLines {
                list,
                count,
                first_line,
            } => write!(
                f,
                "{list}: {count} line{} repeat{} the line before (the first, line {first_line}) and {} left out",
                if *count == 1 { "" } else { "s" },
                if *count == 1 { "s" } else { "" },
                if *count == 1 { "is" } else { "are" }
            ),
            Self::SkippedLines { list, count, first } => write!(
                f,
                "{list}: {count} line{} left out (the first, line {}: {})",
                if *count == 1 { "" } else { "s" },
                first.line,
                first.why
            ),
            Self::ThermalWithoutPose { uncovered, total } => write!(
                f,
                "{uncovered} of {total} thermal frames have no pose within the trajectory"
            ),
        }
    }
}

/// A list's frames by the list rules, its files checked; the lines left out go to the warnings
/// (repeats and the rest apart). More than [`MAX_SKIPPED_SHARE`] of its frame lines left out
/// (repeats not counted) and the list is refused, naming the first.
fn list(
    dir: &Path,
    file: RecordingFile,
    required: bool,
    warnings: &mut Vec<RecordingWarning>,
) -> Result<Vec<StreamEntry>, FileError> {
    let name = file.name();
    let p = file.path_in(dir);
    if !p.exists() {
        return if required {
            Err(FileError::new(
                &p,
                None,
                FileErrorKind::Missing(format!("{name} (a recording needs it)")),
            ))
        } else {
            Ok(Vec::new())
        };
    }
    let text = std::fs::read_to_string(&p).map_err(|e| FileError::io(&p, e))?;
    let (listed, mut skipped) = read_stream_list(&text);
    let mut entries = Vec::with_capacity(listed.len());
    for e in listed {
        if dir.join(&e.path).is_file() {
            entries.push(e);
        } else {
            skipped.push(SkippedLine {
                line: e.line,
                why: LineSkip::Missing(e.path),
            });
        }
    }
    skipped.sort_by_key(|s| s.line);
    let (repeated, skipped): (Vec<_>, Vec<_>) = skipped
        .into_iter()
        .partition(|s| s.why == LineSkip::Repeated);
    let frame_lines = entries.len() + skipped.len();
    if let Some(first) = skipped.first()
        && skipped.len() as f64 > MAX_SKIPPED_SHARE * frame_lines as f64
    {
        return Err(first.to_error(&p));
    }
    if let Some(first) = repeated.first() {
        warnings.push(RecordingWarning::RepeatedLines {
            list: name,
            count: repeated.len(),
            first_line: first.line,
        });
    }
    if let Some(first) = skipped.first() {
        warnings.push(RecordingWarning::SkippedLines {
            list: name,
            count: skipped.len(),
            first: first.clone(),
        });
    }
    Ok(entries)
}

impl Recording {
    /// Opens and checks a recording folder.
    pub fn open(dir: &Path) -> Result<Self, FileError> {
        if !dir.is_dir() {
            return Err(FileError::new(
                dir,
                None,
                FileErrorKind::Io(std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    "not a recording folder",
                )),
            ));
        }
        let rig_path = RecordingFile::Rig.path_in(dir);
        if !rig_path.exists() {
            return Err(FileError::new(
                &rig_path,
                None,
                FileErrorKind::Missing("rig.toml (a recording needs it)".into()),
            ));
        }
        let rig = Rig::read(&rig_path)?;
        let mut warnings = Vec::new();
        let unknown = std::fs::read_to_string(&rig_path)
            .map(|t| super::rig::unknown_rig_keys(&t))
            .unwrap_or_default();
        if !unknown.is_empty() {
            warnings.push(RecordingWarning::UnknownRigKeys(unknown));
        }
        let depth = list(dir, RecordingFile::Depth, true, &mut warnings)?;
        let thermal = list(dir, RecordingFile::Thermal, true, &mut warnings)?;
        let rgb = list(dir, RecordingFile::Rgb, false, &mut warnings)?;
        let masks = list(dir, RecordingFile::Masks, false, &mut warnings)?;
        let traj_path = RecordingFile::Trajectory.path_in(dir);
        // Without poses, a recording with colour can still be tracked (`mrtmap track`).
        let trajectory = if traj_path.exists() {
            Trajectory::read(&traj_path)?
        } else if !rgb.is_empty() {
            warnings.push(RecordingWarning::NoTrajectory);
            Trajectory::default()
        } else {
            return Err(FileError::new(
                &traj_path,
                None,
                FileErrorKind::Missing(
                    "trajectory.txt (a recording needs it, or colour frames in rgb.txt to track)"
                        .into(),
                ),
            ));
        };
        let gt_path = RecordingFile::Groundtruth.path_in(dir);
        let groundtruth = if gt_path.exists() {
            Some(Trajectory::read(&gt_path)?)
        } else {
            None
        };
        let imu_path = RecordingFile::Imu.path_in(dir);
        let imu = if imu_path.exists() {
            super::read_imu(&imu_path)?
        } else {
            Vec::new()
        };
        if depth.is_empty() {
            warnings.push(RecordingWarning::NoDepthFrames);
        }
        if thermal.is_empty() {
            warnings.push(RecordingWarning::NoThermalFrames);
        }
        if trajectory.is_empty() && traj_path.exists() {
            warnings.push(RecordingWarning::NoPoses);
        }
        let limits = InterpolationLimits::default();
        let uncovered = thermal
            .iter()
            .filter(|e| trajectory.interpolate(e.t, &limits).is_none())
            .count();
        if uncovered > 0 && !trajectory.is_empty() {
            warnings.push(RecordingWarning::ThermalWithoutPose {
                uncovered,
                total: thermal.len(),
            });
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            rig,
            depth,
            thermal,
            rgb,
            masks,
            trajectory,
            groundtruth,
            imu,
            warnings,
        })
    }

    /// Absolute path of a listed frame.
    pub fn path_of(&self, e: &StreamEntry) -> PathBuf {
        self.dir.join(&e.path)
    }

    /// Reads a depth frame (raw units; divide by `rig.depth_scale` for metres), checking its size.
    pub fn read_depth(&self, e: &StreamEntry) -> Result<Image16, FileError> {
        let p = self.path_of(e);
        let img = read_image16(&p)?;
        img.check_size(&p, self.rig.depth.width, self.rig.depth.height)?;
        Ok(img)
    }

    /// Reads a thermal frame (raw; see `rig.thermal_encoding`), checking its size.
    pub fn read_thermal(&self, e: &StreamEntry) -> Result<Image16, FileError> {
        let p = self.path_of(e);
        let img = read_image16(&p)?;
        img.check_size(&p, self.rig.thermal.width, self.rig.thermal.height)?;
        Ok(img)
    }
}
