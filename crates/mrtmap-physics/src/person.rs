//! A person instead of a sphere: the projected-area factor fp of a seated or standing body
//! (Fanger 1970; the SolarCal table of ASHRAE 55 App. C, as pythermalcomfort and the CBE tools
//! carry it), the angle-factor fit of ISO 7726 Annex B (Cannistraro et al. 1992) as a check, and
//! ISO 7730's radiant-asymmetry categories.
//!
//! Directions are given by azimuth from the facing direction (0 front, 90 side, 180 back; the body
//! is left/right symmetric) and altitude above the horizontal plane through the body centre. A
//! silhouette seen from opposite directions is the same, so fp(−d) = fp(d): a direction below the
//! horizon is looked up at (azimuth + 180°, −altitude).

use serde::{Deserialize, Serialize};

use crate::comfort::AsymmetryKind;
use crate::error::{PhysicsError, finite, in_range};

/// Seated or standing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Posture {
    /// Seated: body centre 0.6 m above the floor.
    Seated,
    /// Standing: body centre 1.0 m above the floor.
    Standing,
}

impl Posture {
    /// Height of the body centre above the floor for angle factors (m; CBE `mrt.js`).
    pub fn centre_height_m(self) -> f64 {
        match self {
            Self::Seated => 0.6,
            Self::Standing => 1.0,
        }
    }

    /// Height of the top of the head above the floor (m): a 1.75 m standing adult, 1.30 m
    /// seated (ISO 7726's reference heights for the head: 1.7 and 1.1 m, plus the crown).
    pub fn head_height_m(self) -> f64 {
        match self {
            Self::Seated => 1.3,
            Self::Standing => 1.75,
        }
    }

    /// Height at which radiant asymmetry is judged: the abdomen (m; ISO 7726 / ASHRAE 55).
    pub fn abdomen_height_m(self) -> f64 {
        match self {
            Self::Seated => 0.6,
            Self::Standing => 1.1,
        }
    }

    /// The effective radiation area fraction f_eff (Fanger).
    pub fn f_eff(self) -> f64 {
        match self {
            Self::Seated => 0.696,
            Self::Standing => 0.725,
        }
    }

    /// "seated" or "standing".
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Seated => "seated",
            Self::Standing => "standing",
        }
    }
}

/// fp on the 15° grid: rows azimuth 0, 15, …, 180; columns altitude 0, 15, …, 90.
const FP_SEATED: [[f64; 7]; 13] = [
    [0.290, 0.324, 0.305, 0.303, 0.262, 0.224, 0.177],
    [0.292, 0.328, 0.294, 0.288, 0.268, 0.227, 0.177],
    [0.288, 0.332, 0.298, 0.290, 0.264, 0.222, 0.177],
    [0.274, 0.326, 0.294, 0.289, 0.252, 0.214, 0.177],
    [0.254, 0.308, 0.280, 0.276, 0.241, 0.202, 0.177],
    [0.230, 0.282, 0.262, 0.260, 0.233, 0.193, 0.177],
    [0.216, 0.260, 0.248, 0.244, 0.220, 0.186, 0.177],
    [0.234, 0.258, 0.236, 0.227, 0.208, 0.180, 0.177],
    [0.262, 0.260, 0.224, 0.208, 0.196, 0.176, 0.177],
    [0.280, 0.260, 0.210, 0.192, 0.184, 0.170, 0.177],
    [0.298, 0.256, 0.194, 0.174, 0.168, 0.168, 0.177],
    [0.306, 0.250, 0.180, 0.156, 0.156, 0.166, 0.177],
    [0.300, 0.240, 0.168, 0.152, 0.152, 0.164, 0.177],
];

const FP_STANDING: [[f64; 7]; 13] = [
    [0.350, 0.350, 0.314, 0.258, 0.206, 0.144, 0.082],
    [0.342, 0.342, 0.310, 0.252, 0.200, 0.140, 0.082],
    [0.330, 0.330, 0.300, 0.244, 0.190, 0.132, 0.082],
    [0.310, 0.310, 0.275, 0.228, 0.175, 0.124, 0.082],
    [0.283, 0.283, 0.251, 0.208, 0.160, 0.114, 0.082],
    [0.252, 0.252, 0.228, 0.188, 0.150, 0.108, 0.082],
    [0.230, 0.230, 0.214, 0.180, 0.148, 0.108, 0.082],
    [0.242, 0.242, 0.222, 0.180, 0.153, 0.112, 0.082],
    [0.274, 0.274, 0.245, 0.203, 0.165, 0.116, 0.082],
    [0.304, 0.304, 0.270, 0.220, 0.174, 0.121, 0.082],
    [0.328, 0.328, 0.290, 0.234, 0.183, 0.125, 0.082],
    [0.344, 0.344, 0.304, 0.244, 0.190, 0.128, 0.082],
    [0.347, 0.347, 0.308, 0.246, 0.191, 0.128, 0.082],
];

fn table(p: Posture) -> &'static [[f64; 7]; 13] {
    match p {
        Posture::Seated => &FP_SEATED,
        Posture::Standing => &FP_STANDING,
    }
}

/// Folds (azimuth, altitude) in degrees into the table's 0…180 × 0…90.
fn fold(azimuth_deg: f64, altitude_deg: f64) -> (f64, f64) {
    let (mut az, mut alt) = (azimuth_deg, altitude_deg.clamp(-90.0, 90.0));
    if alt < 0.0 {
        az += 180.0;
        alt = -alt;
    }
    let az = az.rem_euclid(360.0);
    let az = if az > 180.0 { 360.0 - az } else { az };
    (az, alt)
}

/// Index and fraction of `x` on a 15° grid with `n` nodes.
fn cell(x: f64, n: usize) -> (usize, f64) {
    let t = (x / 15.0).clamp(0.0, (n - 1) as f64);
    let i = (t.floor() as usize).min(n - 2);
    (i, t - i as f64)
}

/// The projected-area factor fp at an azimuth from the facing direction and an altitude above
/// the horizontal (degrees), bilinear on the 15° table (as pythermalcomfort and CBE interpolate).
pub fn projected_area_factor(posture: Posture, azimuth_deg: f64, altitude_deg: f64) -> f64 {
    let (az, alt) = fold(azimuth_deg, altitude_deg);
    let t = table(posture);
    let (i, fi) = cell(az, 13);
    let (j, fj) = cell(alt, 7);
    let a = t[i][j] * (1.0 - fj) + t[i][j + 1] * fj;
    let b = t[i + 1][j] * (1.0 - fj) + t[i + 1][j + 1] * fj;
    a * (1.0 - fi) + b * fi
}

/// fp averaged over all facing directions (a person who may face any way) at an altitude
/// (degrees): the exact azimuth mean of the bilinear table.
pub fn projected_area_factor_averaged(posture: Posture, altitude_deg: f64) -> f64 {
    let (_, alt) = fold(0.0, altitude_deg);
    let t = table(posture);
    let column = |j: usize| {
        let inner: f64 = (1..12).map(|i| t[i][j]).sum();
        (inner + 0.5 * (t[0][j] + t[12][j])) / 12.0
    };
    let (j, fj) = cell(alt, 7);
    column(j) * (1.0 - fj) + column(j + 1) * fj
}

/// Whether a rectangle in the angle-factor fit is vertical (a wall) or horizontal (floor, ceiling).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RectangleOrientation {
    /// A wall: side a horizontal, side b vertical.
    Vertical,
    /// Floor or ceiling.
    Horizontal,
}

/// ISO 7726 Annex B: the angle factor between a person (rotated about a vertical axis) and a
/// rectangle with one corner at the foot of the perpendicular from the body centre, sides `a`, `b`
/// and distance `c` (m), by the closed-form fit of Cannistraro et al. (1992). A fit to Fanger's
/// charts: about 5 % low for large surfaces; a check, not what mrtmap integrates.
pub fn angle_factor_fit(
    posture: Posture,
    orientation: RectangleOrientation,
    a: f64,
    b: f64,
    c: f64,
) -> Result<f64, PhysicsError> {
    let a = in_range("rectangle side a (m)", a, 0.0, 1e4)?;
    let b = in_range("rectangle side b (m)", b, 0.0, 1e4)?;
    let c = in_range("distance c (m)", c, 1e-9, 1e4)?;
    let [fmax, ca, cb, cc, cd, ce] = match (posture, orientation) {
        (Posture::Seated, RectangleOrientation::Vertical) => {
            [0.118, 1.216, 0.169, 0.717, 0.087, 0.052]
        }
        (Posture::Seated, RectangleOrientation::Horizontal) => {
            [0.116, 1.396, 0.130, 0.951, 0.080, 0.055]
        }
        (Posture::Standing, RectangleOrientation::Vertical) => {
            [0.120, 1.242, 0.167, 0.616, 0.082, 0.051]
        }
        (Posture::Standing, RectangleOrientation::Horizontal) => {
            [0.116, 1.595, 0.128, 1.226, 0.046, 0.044]
        }
    };
    let (x, y) = (a / c, b / c);
    let tau = ca + cb * x;
    let gamma = cc + cd * y + ce * x;
    Ok(fmax * (1.0 - (-x / tau).exp()) * (1.0 - (-y / gamma).exp()))
}

/// The fit for a rectangle spanning [u1, u2] × [v1, v2] (signed, from the foot of the
/// perpendicular; u along the horizontal or first side) at distance `c`, composed of corner
/// rectangles: F = G(u2, v2) − G(u1, v2) − G(u2, v1) + G(u1, v1), G(u, v) = sgn u · sgn v · F(|u|, |v|).
pub fn angle_factor_fit_rect(
    posture: Posture,
    orientation: RectangleOrientation,
    u: (f64, f64),
    v: (f64, f64),
    c: f64,
) -> Result<f64, PhysicsError> {
    for (name, x) in [("u1", u.0), ("u2", u.1), ("v1", v.0), ("v2", v.1)] {
        finite(name, x)?;
    }
    let g = |a: f64, b: f64| -> Result<f64, PhysicsError> {
        if a == 0.0 || b == 0.0 {
            return Ok(0.0);
        }
        Ok(a.signum() * b.signum() * angle_factor_fit(posture, orientation, a.abs(), b.abs(), c)?)
    };
    Ok(g(u.1, v.1)? - g(u.0, v.1)? - g(u.1, v.0)? + g(u.0, v.0)?)
}

/// ISO 7730:2005 category (Table A.1 / A.4) of a place.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Category {
    /// Category A.
    A,
    /// Category B.
    B,
    /// Category C.
    C,
    /// Outside category C.
    Outside,
}

impl Category {
    /// The best category whose PMV range holds `pmv` (A |PMV| < 0.2, B < 0.5, C < 0.7).
    pub fn of_pmv(pmv: f64) -> Self {
        let a = pmv.abs();
        if a < 0.2 {
            Self::A
        } else if a < 0.5 {
            Self::B
        } else if a < 0.7 {
            Self::C
        } else {
            Self::Outside
        }
    }

    /// The best category whose radiant-asymmetry limit (ISO 7730 Table A.4) holds `delta_k`.
    pub fn of_asymmetry(kind: AsymmetryKind, delta_k: f64) -> Self {
        let (ab, c) = asymmetry_limits_k(kind);
        if delta_k < ab {
            Self::A
        } else if delta_k < c {
            Self::C
        } else {
            Self::Outside
        }
    }

    /// "A", "B", "C" or "outside C".
    pub fn as_str(self) -> &'static str {
        match self {
            Self::A => "A",
            Self::B => "B",
            Self::C => "C",
            Self::Outside => "outside C",
        }
    }
}

/// ISO 7730 Table A.4 limits of radiant asymmetry (K): (categories A and B, category C). The
/// A/B limits are also ASHRAE 55's (PD ≤ 5 %).
pub fn asymmetry_limits_k(kind: AsymmetryKind) -> (f64, f64) {
    match kind {
        AsymmetryKind::WarmCeiling => (5.0, 7.0),
        AsymmetryKind::CoolWall => (10.0, 13.0),
        AsymmetryKind::CoolCeiling => (14.0, 18.0),
        AsymmetryKind::WarmWall => (23.0, 35.0),
    }
}
