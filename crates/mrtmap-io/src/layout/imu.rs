//! `imu.txt` (optional): the rig's inertial unit, one sample per line,
//! `timestamp wx wy wz ax ay az` — angular velocity (rad/s) and specific force (m/s², what an
//! accelerometer reads: gravity's reaction plus the acceleration) in the depth camera's frame
//! (OpenCV axes), on the recording's clock; `#` starts a comment. A D435i's gyro and accelerometer
//! run at their own rates (200/400 and 63/250 Hz); a converter pairs them (ROS's
//! `unite_imu_method`) and turns them into the depth camera's axes.

use std::path::Path;

use mrtmap_geometry::nalgebra::Vector3;

use crate::error::{FileError, FileErrorKind};

/// One inertial sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSample {
    /// Seconds.
    pub t: f64,
    /// Angular velocity in the depth camera's frame (rad/s).
    pub gyro: Vector3<f64>,
    /// Specific force in the depth camera's frame (m/s²).
    pub accel: Vector3<f64>,
}

/// Parses `imu.txt`; errors name the file and line.
pub fn parse_imu(text: &str, path: &Path) -> Result<Vec<ImuSample>, FileError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut out: Vec<ImuSample> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let s = line.trim();
        if s.is_empty() || s.starts_with('#') {
            continue;
        }
        let v: Vec<f64> = s
            .split_whitespace()
            .map(|w| w.parse::<f64>().ok().filter(|x| x.is_finite()))
            .collect::<Option<_>>()
            .filter(|v: &Vec<f64>| v.len() == 7)
            .ok_or_else(|| {
                FileError::syntax(
                    path,
                    n,
                    format!("expected 'timestamp wx wy wz ax ay az' (7 numbers), got '{s}'"),
                )
            })?;
        if let Some(prev) = out.last()
            && v[0] <= prev.t
        {
            return Err(FileError::new(
                path,
                Some(n),
                FileErrorKind::TimestampBackwards {
                    t: v[0],
                    previous: prev.t,
                },
            ));
        }
        out.push(ImuSample {
            t: v[0],
            gyro: Vector3::new(v[1], v[2], v[3]),
            accel: Vector3::new(v[4], v[5], v[6]),
        });
    }
    Ok(out)
}

/// Reads `imu.txt`.
pub fn read_imu(path: &Path) -> Result<Vec<ImuSample>, FileError> {
    let text = std::fs::read_to_string(path).map_err(|e| FileError::io(path, e))?;
    parse_imu(&text, path)
}

/// `imu.txt` text with `header` as comment lines.
pub fn imu_text(samples: &[ImuSample], header: &str) -> String {
    let mut s: String = header.lines().map(|l| format!("# {l}\n")).collect();
    s.push_str("# timestamp wx wy wz (rad/s) ax ay az (m/s^2), depth camera frame\n");
    for m in samples {
        s.push_str(&format!(
            "{:.6} {:.7} {:.7} {:.7} {:.5} {:.5} {:.5}\n",
            m.t, m.gyro.x, m.gyro.y, m.gyro.z, m.accel.x, m.accel.y, m.accel.z
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn imu_text_reads_back_and_bad_lines_are_named() {
        let samples = vec![
            ImuSample {
                t: 1.0,
                gyro: Vector3::new(0.1, -0.2, 0.3),
                accel: Vector3::new(0.0, -9.81, 0.2),
            },
            ImuSample {
                t: 1.005,
                gyro: Vector3::new(0.0, 0.0, 0.01),
                accel: Vector3::new(0.1, -9.8, 0.0),
            },
        ];
        let p = Path::new("imu.txt");
        let back = parse_imu(&imu_text(&samples, "test"), p).unwrap();
        assert_eq!(back.len(), 2);
        assert!((back[1].gyro - samples[1].gyro).norm() < 1e-6);
        assert!((back[0].accel - samples[0].accel).norm() < 1e-4);
        let e = parse_imu("# c\n1.0 0 0 0 0 -9.8\n", p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("imu.txt:2") && e.contains("7 numbers"), "{e}");
        let e = parse_imu("1.0 0 0 0 0 -9.8 0\n0.9 0 0 0 0 -9.8 0\n", p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("imu.txt:2") && e.contains("backwards"), "{e}");
    }
}
