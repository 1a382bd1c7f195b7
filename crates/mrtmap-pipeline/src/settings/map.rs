//! `[map]` (grid, heights, quantities), `[[points]]` and `[room]`: where the maps and points go.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// `[map]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapSection {
    /// Grid nodes across and along the floor's bounding rectangle.
    #[serde(deserialize_with = "two_counts")]
    pub grid: [usize; 2],
    /// One map per height above the floor (m).
    pub heights_m: Vec<f64>,
    /// Distance kept from the walls (m).
    pub margin_m: f64,
    /// What to map: the sphere's MRT at each height, and a person's quantities.
    pub quantities: Vec<Quantity>,
}

/// Exactly two counts (`[20, 20, 20]` was read as 20 × 20, the third ignored).
fn two_counts<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<[usize; 2], D::Error> {
    let v = Vec::<usize>::deserialize(d)?;
    <[usize; 2]>::try_from(v.as_slice()).map_err(|_| {
        serde::de::Error::custom(format!(
            "grid = {v:?} has {} values where it takes two, nodes across and along: [nx, ny]",
            v.len()
        ))
    })
}

impl Default for MapSection {
    fn default() -> Self {
        Self {
            grid: [20, 20],
            heights_m: vec![1.1],
            margin_m: 0.1,
            quantities: vec![Quantity::Mrt],
        }
    }
}

/// What a map can show (`[map] quantities`, `--quantity`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
#[value(rename_all = "snake_case")]
pub enum Quantity {
    /// The MRT of a small sphere at each map height (ISO 7726).
    Mrt,
    /// The MRT of a seated person (body centre 0.6 m), facing as `[comfort]` says.
    MrtSeated,
    /// The MRT of a standing person (body centre 1.0 m).
    MrtStanding,
    /// The MRT of `[comfort]`'s person with SolarCal's ΔMRT of `[sun]` added (facing the sun
    /// when `[comfort] facing_deg` is unset).
    MrtSun,
    /// The worst radiant temperature asymmetry (K) at the abdomen of `[comfort]`'s posture.
    Asymmetry,
    /// Operative temperature (ISO 7726) of `[comfort]`'s person.
    Operative,
    /// Predicted mean vote (ISO 7730).
    Pmv,
    /// Predicted percentage dissatisfied (ISO 7730).
    Ppd,
}

impl Quantity {
    /// Its name in files ("mrt_seated").
    pub fn name(self) -> &'static str {
        match self {
            Self::Mrt => "mrt",
            Self::MrtSeated => "mrt_seated",
            Self::MrtStanding => "mrt_standing",
            Self::MrtSun => "mrt_sun",
            Self::Asymmetry => "asymmetry",
            Self::Operative => "operative",
            Self::Pmv => "pmv",
            Self::Ppd => "ppd",
        }
    }

    /// The person's quantities among `qs` (all but the sphere's MRT, which every map run draws).
    pub fn person(qs: &[Quantity]) -> Vec<Quantity> {
        qs.iter().copied().filter(|q| *q != Quantity::Mrt).collect()
    }

    /// Whether it needs the air (temperature, humidity…): operative temperature, PMV and PPD.
    pub fn needs_air(self) -> bool {
        matches!(self, Self::Operative | Self::Pmv | Self::Ppd)
    }
}

/// The frame a point is given in: one choice for `--frame` and `[[points]] frame`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum PointFrame {
    /// The room frame: x, y along the floor from the origin corner, z above the floor.
    #[default]
    Room,
    /// The scan's world frame (the frame of trajectory.txt).
    Scan,
}

/// `[[points]]`: a named point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointEntry {
    /// Name.
    pub name: String,
    /// Position (m).
    pub xyz: [f64; 3],
    /// The frame of `xyz`.
    #[serde(default, skip_serializing_if = "is_room")]
    pub frame: PointFrame,
}

fn is_room(f: &PointFrame) -> bool {
    *f == PointFrame::Room
}

/// `[room]`: the room frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RoomSection {
    /// The floor corner at the origin (1-based, as numbered on the report's map); `None` for the
    /// rule (the start of the longest wall with the room at x, y ≥ 0).
    pub origin_corner: Option<usize>,
}

impl RoomSection {
    /// Settings that need no cloud: corners are numbered from 1.
    pub fn check(&self) -> Result<()> {
        if self.origin_corner == Some(0) {
            return Err(Error::setting(
                "--origin-corner 0 ([room] origin_corner)".to_string(),
                "is not a corner: corners are numbered from 1, as on the report's map; leave it out for the default",
            ));
        }
        Ok(())
    }
}
