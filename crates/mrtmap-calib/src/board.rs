//! The checkerboard: inner-corner grid and square size.

use std::fmt;
use std::str::FromStr;

use mrtmap_geometry::nalgebra::Point3;
use serde::{Deserialize, Serialize};

/// A checkerboard, counted by its inner corners (where four squares meet), as OpenCV counts it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Board {
    /// Inner corners along a row.
    pub cols: u32,
    /// Inner corners along a column.
    pub rows: u32,
    /// Side of one square (m).
    pub square_m: f64,
}

impl Board {
    /// A board; `None` unless both counts are at least 2 and the square is positive.
    pub fn new(cols: u32, rows: u32, square_m: f64) -> Option<Self> {
        (cols >= 2 && rows >= 2 && square_m.is_finite() && square_m > 0.0).then_some(Self {
            cols,
            rows,
            square_m,
        })
    }

    /// Number of inner corners.
    pub fn corners(&self) -> usize {
        (self.cols * self.rows) as usize
    }

    /// The corner with grid label (i, j) in the board frame (z = 0 on the board's face, metres).
    pub fn point(&self, i: i32, j: i32) -> Point3<f64> {
        Point3::new(i as f64 * self.square_m, j as f64 * self.square_m, 0.0)
    }
}

/// The `COLSxROWS` of the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridSize {
    /// Inner corners along a row.
    pub cols: u32,
    /// Inner corners along a column.
    pub rows: u32,
}

impl FromStr for GridSize {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || {
            format!(
                "board size '{s}' is not COLSxROWS of inner corners (two whole numbers ≥ 2, e.g. 9x6)"
            )
        };
        let (c, r) = s.split_once(['x', 'X', '×']).ok_or_else(bad)?;
        let cols: u32 = c.trim().parse().map_err(|_| bad())?;
        let rows: u32 = r.trim().parse().map_err(|_| bad())?;
        if cols < 2 || rows < 2 || cols > 100 || rows > 100 {
            return Err(bad());
        }
        Ok(Self { cols, rows })
    }
}

impl fmt::Display for GridSize {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}", self.cols, self.rows)
    }
}
