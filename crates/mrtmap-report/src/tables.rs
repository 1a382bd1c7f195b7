//! Grid CSV and map summary.

use mrtmap_radiation::{FieldSummary, MrtField, UnseenImpact};

use crate::numbers::{fixed, uncertainty};
use serde::{Deserialize, Serialize};

/// `mrt_grid.csv`: one row per grid node inside the floor: x, y, z (scene frame), mrt_c,
/// std_error_k, then i, j (grid indices) and u_m, v_m (map coordinates), then the standard
/// error's five parts (Monte Carlo sampling, the surfaces' temperatures, placement, unseen areas,
/// the camera's level; they combine in quadrature into std_error_k). A node that could not be
/// computed (inside an occluder) has empty values and the reason in `note`.
pub fn grid_csv(field: &MrtField) -> String {
    let mut s = String::from(
        "x,y,z,mrt_c,std_error_k,i,j,u_m,v_m,sampling_std_error_k,temperature_std_error_k,placement_std_error_k,unseen_std_error_k,level_std_error_k,note\n",
    );
    for n in &field.nodes {
        let (m, e, parts, note) = match &n.result {
            Ok(r) => (
                format!("{:.4}", r.mrt.celsius()),
                format!("{:.4}", r.std_error_k),
                [
                    r.sampling_std_error_k,
                    r.temperature_std_error_k,
                    r.placement_std_error_k,
                    r.unseen_std_error_k,
                    r.level_std_error_k,
                ]
                .map(|x| format!("{x:.4}"))
                .join(","),
                String::new(),
            ),
            Err(err) => (
                String::new(),
                String::new(),
                ",,,,".to_string(),
                format!("\"{}\"", err.to_string().replace('"', "'")),
            ),
        };
        s.push_str(&format!(
            "{:.4},{:.4},{:.4},{m},{e},{},{},{:.4},{:.4},{parts},{note}\n",
            n.point.x, n.point.y, n.point.z, n.i, n.j, n.uv.x, n.uv.y
        ));
    }
    s
}

/// `summary.json` of a map.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapSummary {
    /// Height above the floor (m).
    pub height_m: f64,
    /// Grid nodes along u and v.
    pub grid: [usize; 2],
    /// Margin from the outline (m).
    pub margin_m: f64,
    /// "exact" or "montecarlo".
    pub method: String,
    /// Rays per point (Monte Carlo).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rays: Option<usize>,
    /// Seed (Monte Carlo).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Map axes in scene coordinates: u, v, up.
    pub axes: MapAxes,
    /// Extremes, mean and counts (absent when nothing was computed).
    #[serde(flatten)]
    pub field: Option<FieldSummary>,
    /// Wall-clock time of the computation (s).
    pub compute_secs: f64,
}

/// The map frame's axes in scene coordinates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapAxes {
    /// Origin of map coordinates (on the floor).
    pub origin: [f64; 3],
    /// u axis.
    pub u: [f64; 3],
    /// v axis.
    pub v: [f64; 3],
    /// Up.
    pub up: [f64; 3],
}

impl MapAxes {
    /// The axes of a field's frame.
    pub fn of(field: &MrtField) -> Self {
        let p = &field.frame.plane;
        let a = |v: &mrtmap_geometry::nalgebra::Vector3<f64>| [v.x, v.y, v.z];
        Self {
            origin: [p.origin.x, p.origin.y, p.origin.z],
            u: a(&p.u),
            v: a(&p.v),
            up: a(&p.normal),
        }
    }
}

/// One unseen patch for people: "ceiling, 0.51 m² around (2.10, 3.40, 3.00), 22.4…38.0 °C seen
/// around it: up to 0.20 K at (2.50, 3.00, 1.10)" (the scene's frame; the room's for a scan).
pub fn unseen_line(u: &UnseenImpact) -> String {
    let p = |v: &[f64; 3]| {
        format!(
            "({}, {}, {})",
            fixed(v[0], 2),
            fixed(v[1], 2),
            fixed(v[2], 2)
        )
    };
    format!(
        "{}, {:.2} m² around {}, {:.1}…{:.1} °C seen around it: up to {} K at {}",
        u.surface_id,
        u.area_m2,
        p(&u.centre),
        u.range_c[0],
        u.range_c[1],
        uncertainty(u.max_std_error_k, 2),
        p(&u.at)
    )
}
