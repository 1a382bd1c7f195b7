//! Grid CSV and map summary.

use mrtmap_radiation::{FieldSummary, MrtField, RasterFile, StdErrorParts, UnseenImpact};

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

/// A standard error's parts for people: "sampling 0.006, surface temperatures 0.002, …, camera
/// level 0.115 K", each to its first digit (at least `min_decimals`).
pub fn parts_line(p: &StdErrorParts, min_decimals: usize) -> String {
    let parts: Vec<String> = p
        .named()
        .iter()
        .map(|(name, v)| format!("{name} {}", uncertainty(*v, min_decimals)))
        .collect();
    format!("{} K", parts.join(", "))
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

/// A surface's raster as a small inline SVG of what the scan saw: seen texels green, texels
/// filled in grey, texels of unseen patches red; row 0 at the bottom (a wall's
/// floor edge). At most 240 × 160 px.
pub fn coverage_svg(r: &RasterFile) -> String {
    let (cols, rows) = (r.cols.max(1), r.rows.max(1));
    let px = (240.0 / cols as f64)
        .min(160.0 / rows as f64)
        .clamp(1.0, 10.0);
    let (w, h) = (cols as f64 * px, rows as f64 * px);
    let mut state = vec![0u8; cols * rows];
    for &i in &r.filled {
        if let Some(s) = state.get_mut(i) {
            *s = 1;
        }
    }
    for p in &r.unseen {
        for &i in &p.texels {
            if let Some(s) = state.get_mut(i) {
                *s = 2;
            }
        }
    }
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" viewBox=\"0 0 {w:.1} {h:.1}\">"
    );
    for (i, t) in r.temperature_c.iter().enumerate().take(cols * rows) {
        if t.is_none() {
            continue;
        }
        let colour = ["#5a8f3a", "#999999", "#d62728"][state[i] as usize];
        let (c, row) = (i % cols, i / cols);
        out.push_str(&format!(
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{px:.1}\" height=\"{px:.1}\" fill=\"{colour}\"/>",
            c as f64 * px,
            h - (row + 1) as f64 * px
        ));
    }
    out.push_str("</svg>");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrtmap_radiation::UnseenPatch;

    #[test]
    fn a_coverage_drawing_colours_each_texel_by_what_was_seen() {
        let r = RasterFile {
            texel_m: 0.15,
            origin: [0.0; 3],
            u: [1.0, 0.0, 0.0],
            v: [0.0, 0.0, 1.0],
            cols: 3,
            rows: 2,
            temperature_c: vec![
                Some(20.0),
                Some(20.0),
                None,
                Some(20.0),
                Some(21.0),
                Some(19.0),
            ],
            filled: vec![1, 4],
            unseen: vec![UnseenPatch {
                texels: vec![4, 5],
                range_c: [19.0, 21.0],
            }],
        };
        let svg = coverage_svg(&r);
        assert_eq!(
            svg.matches("<rect").count(),
            5,
            "the texel off the surface is not drawn"
        );
        assert_eq!(svg.matches("#5a8f3a").count(), 2, "seen: 0 and 3");
        assert_eq!(svg.matches("#999999").count(), 1, "filled only: 1");
        assert_eq!(svg.matches("#d62728").count(), 2, "unseen: 4 and 5");
        // 10 px texels at most; row 0 at the bottom: texel 0 at y = h - px.
        assert!(svg.contains("width=\"30\" height=\"20\""), "{svg}");
        assert!(svg.contains("<rect x=\"0.0\" y=\"10.0\""), "{svg}");
    }
}
