//! Scoring a segmented scene against the truth of the simulated recording it came from: planes,
//! corners, features (IoU), temperatures, and the MRT at the validation points.

use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Point2, Point3};
use mrtmap_geometry::polygon::{self, signed_area};
use mrtmap_radiation::{Method, MonteCarlo, RadiantScene, Surface, SurfaceKind};
use serde::{Deserialize, Serialize};

use crate::truth::Truth;

/// A surface compared with its truth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SurfaceScore {
    /// Truth id.
    pub truth_id: String,
    /// Matched id.
    pub id: Option<String>,
    /// Angle between the planes (degrees).
    pub angle_deg: f64,
    /// Distance of the true polygon's centroid from the found plane (m).
    pub offset_m: f64,
    /// Found − true temperature (K).
    pub temperature_error_k: f64,
}

/// A true feature compared with the best-overlapping found feature on its host.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeatureScore {
    /// Truth id.
    pub truth_id: String,
    /// True label.
    pub truth_label: String,
    /// Matched id and label.
    pub found: Option<(String, String)>,
    /// Intersection over union in the host's plane.
    pub iou: f64,
    /// Found − true temperature (K).
    pub temperature_error_k: Option<f64>,
    /// The true feature's area (m²).
    #[serde(default)]
    pub truth_area_m2: f64,
    /// The matched feature's area (m²).
    #[serde(default)]
    pub area_m2: Option<f64>,
}

/// MRT at a validation point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointScore {
    /// Name.
    pub name: String,
    /// Truth (°C).
    pub truth_c: f64,
    /// From the found scene (°C).
    pub found_c: f64,
    /// Difference (K).
    pub error_k: f64,
}

/// Everything compared.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneScore {
    /// Surfaces.
    pub surfaces: Vec<SurfaceScore>,
    /// Largest corner error (m), true floor and ceiling corners to the nearest found ones.
    pub corner_max_error_m: f64,
    /// Features.
    pub features: Vec<FeatureScore>,
    /// Found features matching no true feature.
    pub spurious_features: Vec<String>,
    /// Their areas (m²), in the same order.
    #[serde(default)]
    pub spurious_areas_m2: Vec<f64>,
    /// MRT at the validation points.
    pub points: Vec<PointScore>,
}

/// Area of the intersection of two convex polygons (counter-clockwise).
fn convex_intersection_area(a: &[Point2<f64>], b: &[Point2<f64>]) -> f64 {
    signed_area(&mrtmap_geometry::shape2d::clip_convex(a, b)).abs()
}

fn ccw(mut p: Vec<Point2<f64>>) -> Vec<Point2<f64>> {
    if signed_area(&p) < 0.0 {
        p.reverse();
    }
    p
}

/// The found surface of the same kind whose plane is nearest the true surface's centroid, and how
/// far off it is.
fn surface_score<'a>(ts: &Surface, found: &'a RadiantScene) -> (SurfaceScore, Option<&'a Surface>) {
    let c = polygon::centroid(&ts.polygon);
    let best = found
        .surfaces
        .iter()
        .filter(|s| s.kind == ts.kind && s.frame.normal.dot(&ts.frame.normal).abs() > 0.9)
        .min_by(|a, b| {
            a.frame
                .signed_distance(&c)
                .abs()
                .total_cmp(&b.frame.signed_distance(&c).abs())
        });
    let score = match best {
        None => SurfaceScore {
            truth_id: ts.id.clone(),
            id: None,
            angle_deg: f64::NAN,
            offset_m: f64::NAN,
            temperature_error_k: f64::NAN,
        },
        Some(fs) => SurfaceScore {
            truth_id: ts.id.clone(),
            id: Some(fs.id.clone()),
            angle_deg: fs
                .frame
                .normal
                .dot(&ts.frame.normal)
                .abs()
                .min(1.0)
                .acos()
                .to_degrees(),
            offset_m: fs.frame.signed_distance(&c).abs(),
            temperature_error_k: fs.temperature.kelvin() - ts.temperature.kelvin(),
        },
    };
    (score, best)
}

/// The true host's features against the found host's: the best IoU in the true host's plane;
/// found features matched are added to `matched`.
fn feature_scores(
    ts: &Surface,
    fs: &Surface,
    matched: &mut std::collections::HashSet<String>,
) -> Vec<FeatureScore> {
    let frame: &PlaneFrame = &ts.frame;
    let mut out = Vec::new();
    for tf in &ts.features {
        let tpoly = ccw(tf.polygon.iter().map(|p| frame.to_2d(p)).collect());
        let t_area = signed_area(&tpoly).abs();
        let best = fs
            .features
            .iter()
            .map(|ff| {
                let fpoly = ccw(ff.polygon.iter().map(|p| frame.to_2d(p)).collect());
                let inter = convex_intersection_area(&fpoly, &tpoly);
                (inter / (t_area + signed_area(&fpoly).abs() - inter), ff)
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .filter(|(iou, _)| *iou > 0.0);
        if let Some((_, ff)) = best {
            matched.insert(ff.id.clone());
        }
        out.push(FeatureScore {
            truth_id: tf.id.clone(),
            truth_label: tf.label.clone(),
            found: best.map(|(_, ff)| (ff.id.clone(), ff.label.clone())),
            iou: best.map_or(0.0, |b| b.0),
            temperature_error_k: best
                .map(|(_, ff)| ff.temperature.kelvin() - tf.temperature.kelvin()),
            truth_area_m2: t_area,
            area_m2: best.map(|(_, ff)| polygon::area_3d(&ff.polygon)),
        });
    }
    out
}

/// The largest distance from a true floor or ceiling corner to the nearest found one.
fn corner_error(found: &RadiantScene, truth: &RadiantScene) -> f64 {
    let corners = |s: &RadiantScene, k: SurfaceKind| -> Vec<Point3<f64>> {
        s.surfaces
            .iter()
            .filter(|x| x.kind == k)
            .flat_map(|x| x.polygon.clone())
            .collect()
    };
    let mut corner_max = 0.0f64;
    for k in [SurfaceKind::Floor, SurfaceKind::Ceiling] {
        let fc = corners(found, k);
        for tc in corners(truth, k) {
            let d = fc
                .iter()
                .map(|f| (f - tc).norm())
                .fold(f64::INFINITY, f64::min);
            corner_max = corner_max.max(d);
        }
    }
    corner_max
}

/// The found scene's MRT at the truth's validation points.
fn point_scores(found: &RadiantScene, truth: &Truth) -> Result<Vec<PointScore>, crate::SimError> {
    let engine = mrtmap_radiation::enclosure::engine(
        found,
        Method::Auto(MonteCarlo {
            rays: 200_000,
            ..MonteCarlo::default()
        }),
    )?;
    Ok(truth
        .points
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let r = engine.at(&Point3::from(p.xyz_world), k as u64)?;
            Ok(PointScore {
                name: p.name.clone(),
                truth_c: p.mrt_c,
                found_c: r.mrt.celsius(),
                error_k: r.mrt.celsius() - p.mrt_c,
            })
        })
        .collect::<Result<Vec<_>, mrtmap_radiation::MrtError>>()?)
}

/// Scores `found` against `truth`: in the recording's world frame, `found` carried there by its
/// `world_from_room` when it has one.
pub fn score_scene(found: &RadiantScene, truth: &Truth) -> Result<SceneScore, crate::SimError> {
    let in_world;
    let found = match found.world_from_room {
        Some(w) => {
            let mut f = found.to_file().transformed(&w);
            f.world_from_room = None;
            in_world = RadiantScene::new(&f)?;
            &in_world
        }
        None => found,
    };
    let t_scene = RadiantScene::new(&truth.scene)?;
    let mut surfaces = Vec::new();
    let mut features = Vec::new();
    let mut matched_found = std::collections::HashSet::new();
    for ts in &t_scene.surfaces {
        let (score, best) = surface_score(ts, found);
        surfaces.push(score);
        if let Some(fs) = best {
            features.extend(feature_scores(ts, fs, &mut matched_found));
        }
    }
    let (spurious, spurious_areas_m2) = found
        .surfaces
        .iter()
        .flat_map(|s| s.features.iter())
        .filter(|f| !matched_found.contains(&f.id))
        .map(|f| (f.id.clone(), polygon::area_3d(&f.polygon)))
        .unzip();
    Ok(SceneScore {
        surfaces,
        corner_max_error_m: corner_error(found, &t_scene),
        features,
        spurious_features: spurious,
        spurious_areas_m2,
        points: point_scores(found, truth)?,
    })
}
