//! The data of the report's 3D view: the room's parts as coloured triangles (`mesh`), the thermal
//! cloud thinned, and each MRT map as a layer of cells at its height, as one JSON document the
//! viewer (`viewer.js`, embedded in report.html) reads.

use mrtmap_radiation::RadiantScene;
use serde::Serialize;
use serde_json::{Value, json};

use crate::mesh::{grid_rgb, scene_mesh, temperature_rgb};

/// Most cloud points the report carries (about 1.5 MB of the file).
pub const MAX_VIEW_POINTS: usize = 40_000;

/// One MRT map as a layer of the 3D view.
#[derive(Clone, Debug, PartialEq)]
pub struct GridLayer {
    /// Its height above the floor (m).
    pub height_m: f64,
    /// Its nodes: x, y, z (scene frame, m) and the MRT (°C).
    pub nodes: Vec<[f64; 4]>,
    /// The map's axes along its columns and rows (unit vectors, scene frame).
    pub u: [f64; 3],
    /// See `u`.
    pub v: [f64; 3],
}

/// The sunlit patch as a layer of the 3D view: orange cells on the floor where the beam reaches a
/// person.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchLayer {
    /// Each cell's centre (scene frame, m).
    pub cells: Vec<[f64; 3]>,
    /// The cells' axes (unit vectors, scene frame).
    pub u: [f64; 3],
    /// See `u`.
    pub v: [f64; 3],
    /// The cells' size along u and v (m).
    pub cell_m: [f64; 2],
}

/// The 3D view's JSON document, ready to embed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct View3d(pub String, pub Layers);

/// Which optional layers a [`View3d`] holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Layers {
    /// The sunlit patch.
    pub sun: bool,
}

fn r3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

fn stops(lo: f64, hi: f64, rgb: fn(f64, f64, f64) -> [u8; 3]) -> Vec<String> {
    (0..=8)
        .map(|k| {
            let c = rgb(lo + (hi - lo) * f64::from(k) / 8.0, lo, hi);
            format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
        })
        .collect()
}

/// `keep` of the indices `0..n`, evenly spaced (all of them when `n ≤ keep`): how a cloud is
/// thinned for the view and for exports.
pub fn evenly_spaced(n: usize, keep: usize) -> Vec<usize> {
    let keep = keep.min(n);
    (0..keep).map(|i| i * n / keep).collect()
}

/// Node spacing along `axis`: the smallest gap between distinct projections.
fn spacing(nodes: &[[f64; 4]], axis: &[f64; 3]) -> f64 {
    let mut s: Vec<f64> = nodes
        .iter()
        .map(|n| n[0] * axis[0] + n[1] * axis[1] + n[2] * axis[2])
        .collect();
    s.sort_by(f64::total_cmp);
    s.windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 1e-6)
        .fold(f64::INFINITY, f64::min)
        .min(1.0)
}

/// The view of `scene`, with `cloud` (positions in the scene's frame, °C; thinned evenly to
/// [`MAX_VIEW_POINTS`]), the maps' `grids`, black-globe readings (`globes`; the report adds
/// its named points) and the sunlit patch (`sun`, with `[sun]`).
pub fn view3d(
    scene: &RadiantScene,
    cloud: Option<(&[[f32; 3]], &[f32])>,
    grids: &[GridLayer],
    globes: &[ViewMark],
    sun: Option<&PatchLayer>,
) -> View3d {
    let parts = scene_mesh(scene);
    let (lo, hi) = crate::mesh::colour_range(
        parts
            .iter()
            .flat_map(|p| p.vertex_temperature_c.iter().copied()),
    );
    let mut all = Vec::new();
    let json_parts: Vec<Value> = parts
        .iter()
        .map(|p| {
            all.extend(p.positions.iter().copied());
            json!({
                "id": p.id, "label": p.label, "role": p.role.as_str(), "detail": p.detail,
                "t": p.temperature_c, "std": p.temperature_std_k, "area": p.area_m2,
                "seen": p.observed_fraction,
                "e": p.emissivity,
                "st": p.surface_temperature.map(|x| x.0), "sst": p.surface_temperature.map(|x| x.1),
                "p": p.positions.iter().flat_map(|q| q.map(r3)).collect::<Vec<_>>(),
                "i": p.triangles.iter().flatten().collect::<Vec<_>>(),
                "c": p.vertex_temperature_c.iter().flat_map(|t| temperature_rgb(*t, lo, hi)).collect::<Vec<_>>(),
            })
        })
        .collect();
    let (mut bmin, mut bmax) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in &all {
        for k in 0..3 {
            bmin[k] = bmin[k].min(q[k]);
            bmax[k] = bmax[k].max(q[k]);
        }
    }
    let (centre, size) = if all.is_empty() {
        ([0.0; 3], 5.0)
    } else {
        let c = [0, 1, 2].map(|k| r3(0.5 * (bmin[k] + bmax[k])));
        let d = (0..3)
            .map(|k| (bmax[k] - bmin[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        (c, d.max(1.0))
    };
    let cloud = cloud.filter(|(p, _)| !p.is_empty()).map(|(pos, t)| {
        let n = pos.len();
        let idx = evenly_spaced(n, MAX_VIEW_POINTS);
        json!({
            "p": idx.iter().flat_map(|&i| pos[i].map(|c| r3(f64::from(c)))).collect::<Vec<_>>(),
            "c": idx.iter().flat_map(|&i| temperature_rgb(f64::from(t[i]), lo, hi)).collect::<Vec<_>>(),
        })
    });
    let grids: Vec<Value> = grids
        .iter()
        .filter(|g| !g.nodes.is_empty())
        .map(|g| {
            let (glo, ghi) = crate::mesh::colour_range(g.nodes.iter().map(|n| n[3]));
            json!({
                "height": g.height_m, "range": [glo, ghi], "bar": stops(glo, ghi, grid_rgb),
                "cell": [spacing(&g.nodes, &g.u), spacing(&g.nodes, &g.v)],
                "u": g.u, "v": g.v,
                "n": g.nodes.iter().map(|n| {
                    let c = grid_rgb(n[3], glo, ghi);
                    [r3(n[0]), r3(n[1]), r3(n[2]), r3(n[3]), f64::from(c[0]), f64::from(c[1]), f64::from(c[2])]
                }).collect::<Vec<_>>(),
            })
        })
        .collect();
    // Look first at the wall of the feature that stands out most (a cold window): the camera
    // starts on the far side of the room from it, facing it.
    let look = scene
        .surfaces
        .iter()
        .filter(|s| s.frame.normal.z.abs() < 0.9)
        .flat_map(|s| s.features.iter().map(move |f| (s, f)))
        .max_by(|a, b| {
            let c = |(s, f): &(&mrtmap_radiation::Surface, &mrtmap_radiation::Feature)| {
                (f.temperature.celsius() - s.temperature.celsius()).abs()
            };
            c(a).total_cmp(&c(b))
        })
        .map(|(s, _)| crate::mesh::outward_normal(scene, s))
        .map(|n| [r3(n.x), r3(n.y), r3(n.z)]);
    // 1 cm above the floor, so that the floor does not hide it.
    let sun = sun.filter(|p| !p.cells.is_empty()).map(|p| {
        let up = scene.up().map_or([0.0, 0.0, 1.0], |u| [u.x, u.y, u.z]);
        json!({
            "cells": p.cells.iter().map(|c| [0, 1, 2].map(|k| r3(c[k] + 0.01 * up[k]))).collect::<Vec<_>>(),
            "u": p.u, "v": p.v, "cell": p.cell_m,
        })
    });
    let doc = json!({
        "range": [lo, hi], "bar": stops(lo, hi, temperature_rgb), "centre": centre, "size": size, "look": look,
        "parts": json_parts, "cloud": cloud, "grids": grids, "globes": globes, "sun": sun,
    });
    View3d(
        serde_json::to_string(&doc).unwrap_or_default(),
        Layers {
            sun: !doc["sun"].is_null(),
        },
    )
}

/// A marked point or globe in the 3D view.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ViewMark {
    /// Its label ("P: 20.1 °C").
    pub text: String,
    /// Where (scene frame, m).
    pub xyz: [f64; 3],
    /// "point" or "globe".
    pub kind: &'static str,
}

/// The viewer (JavaScript), embedded in the report.
pub const VIEWER_JS: &str = include_str!("viewer.js");
