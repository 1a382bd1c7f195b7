//! Writes the recording layout (docs/recording.md) frame by frame: what `convert` and
//! every reader of another format end in. The folder appears under its final name only when
//! [`LayoutWriter::finish`] succeeds.

use std::path::{Path, PathBuf};

use nalgebra::Isometry3;

use super::files::RecordingFile;
use super::imu::{ImuSample, imu_text};
use super::rig::Rig;
use super::streams::stream_list_text;
use super::trajectory::Trajectory;
use crate::atomic::PartialDir;
use crate::error::FileError;
use crate::image16::{Image16, encode_png16};

/// A recording folder being written.
pub struct LayoutWriter {
    dir: PartialDir,
    depth: Vec<(f64, String)>,
    thermal: Vec<(f64, String)>,
    rgb: Vec<(f64, String)>,
    poses: Vec<(f64, Isometry3<f64>)>,
    imu: Vec<ImuSample>,
    header: String,
}

fn write(dir: &Path, rel: &str, bytes: &[u8]) -> Result<(), FileError> {
    let p = dir.join(rel);
    if let Some(parent) = p.parent() {
        std::fs::create_dir_all(parent).map_err(|e| FileError::io(parent, e))?;
    }
    std::fs::write(&p, bytes).map_err(|e| FileError::io(&p, e))
}

impl LayoutWriter {
    /// Starts `out` (written as `out.partial` until finished); `header` goes atop every list.
    pub fn create(out: &Path, header: &str) -> Result<Self, FileError> {
        Ok(Self {
            dir: PartialDir::create(out)?,
            depth: Vec::new(),
            thermal: Vec::new(),
            rgb: Vec::new(),
            poses: Vec::new(),
            imu: Vec::new(),
            header: header.to_string(),
        })
    }

    /// Adds a 16-bit depth frame.
    pub fn depth(&mut self, t: f64, img: &Image16) -> Result<(), FileError> {
        let rel = format!("depth/{:06}.png", self.depth.len());
        let png =
            encode_png16(img).map_err(|e| FileError::encode(&self.dir.path().join(&rel), e))?;
        write(self.dir.path(), &rel, &png)?;
        self.depth.push((t, rel));
        Ok(())
    }

    /// Adds a 16-bit centikelvin thermal frame.
    pub fn thermal(&mut self, t: f64, img: &Image16) -> Result<(), FileError> {
        let rel = format!("thermal/{:06}.png", self.thermal.len());
        let png =
            encode_png16(img).map_err(|e| FileError::encode(&self.dir.path().join(&rel), e))?;
        write(self.dir.path(), &rel, &png)?;
        self.thermal.push((t, rel));
        Ok(())
    }

    /// Adds an encoded colour frame (`ext` "png" or "jpg").
    pub fn rgb(&mut self, t: f64, bytes: &[u8], ext: &str) -> Result<(), FileError> {
        let rel = format!("rgb/{:06}.{ext}", self.rgb.len());
        write(self.dir.path(), &rel, bytes)?;
        self.rgb.push((t, rel));
        Ok(())
    }

    /// Adds a world_from_depth pose (its quaternion written with w ≥ 0).
    pub fn pose(&mut self, t: f64, mut p: Isometry3<f64>) {
        if p.rotation.w < 0.0 {
            p.rotation = nalgebra::UnitQuaternion::new_unchecked(-p.rotation.into_inner());
        }
        self.poses.push((t, p));
    }

    /// Adds an inertial sample (the depth camera's frame).
    pub fn imu(&mut self, sample: ImuSample) {
        self.imu.push(sample);
    }

    /// Inertial samples so far.
    pub fn imu_count(&self) -> usize {
        self.imu.len()
    }

    /// Frames written so far: (depth, thermal, rgb, poses).
    pub fn counts(&self) -> (usize, usize, usize, usize) {
        (
            self.depth.len(),
            self.thermal.len(),
            self.rgb.len(),
            self.poses.len(),
        )
    }

    /// Writes the lists, trajectory (when there are poses), imu.txt (when there are samples), rig
    /// and `source.json`, then moves the folder into place.
    pub fn finish(mut self, rig: &Rig, source_json: &str) -> Result<PathBuf, FileError> {
        let d = self.dir.path().to_path_buf();
        let sort = |v: &mut Vec<(f64, String)>| v.sort_by(|a, b| a.0.total_cmp(&b.0));
        sort(&mut self.depth);
        sort(&mut self.thermal);
        sort(&mut self.rgb);
        write(
            &d,
            RecordingFile::Depth.name(),
            stream_list_text(&self.header, &self.depth).as_bytes(),
        )?;
        write(
            &d,
            RecordingFile::Thermal.name(),
            stream_list_text(&self.header, &self.thermal).as_bytes(),
        )?;
        if !self.rgb.is_empty() {
            write(
                &d,
                RecordingFile::Rgb.name(),
                stream_list_text(&self.header, &self.rgb).as_bytes(),
            )?;
        }
        self.poses.sort_by(|a, b| a.0.total_cmp(&b.0));
        self.poses.dedup_by(|b, a| b.0 <= a.0);
        let traj = Trajectory {
            stamps: self.poses.iter().map(|p| p.0).collect(),
            poses: self.poses.iter().map(|p| p.1).collect(),
        };
        // No poses (a source without odometry): no trajectory.txt; the recording is tracked.
        if !traj.is_empty() {
            write(
                &d,
                RecordingFile::Trajectory.name(),
                traj.to_tum(&format!(
                    "{}\nworld_from_depth: timestamp tx ty tz qx qy qz qw",
                    self.header
                ))
                .as_bytes(),
            )?;
        }
        if !self.imu.is_empty() {
            self.imu.sort_by(|a, b| a.t.total_cmp(&b.t));
            self.imu.dedup_by(|b, a| b.t <= a.t);
            write(
                &d,
                RecordingFile::Imu.name(),
                imu_text(&self.imu, &self.header).as_bytes(),
            )?;
        }
        write(&d, RecordingFile::Rig.name(), rig.to_toml().as_bytes())?;
        write(&d, "source.json", source_json.as_bytes())?;
        self.dir.finish()
    }
}
