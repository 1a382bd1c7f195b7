//! Segmentation: from the fused thermal cloud to a radiant scene (stage 4 of the seed method).
//!
//! ```text
//!  cloud ─► up (cameras, then floor) ─► planes (RANSAC) ─► floor, ceiling, wall loop, corners
//!        ─► points per surface ─► texels ─► background + thermal features ─► labels ─► scene.json
//! ```

mod envelope;
mod features;
mod furniture;
pub mod labels;
mod outline;
pub mod room;
mod texture;

use std::collections::BTreeMap;

use mrtmap_geometry::PlaneFrame;
use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Unit, Vector3};
use mrtmap_geometry::polygon::{Containment, centroid, point_in_polygon};
use mrtmap_io::{Recording, ThermalCloud};
use mrtmap_physics::ZERO_CELSIUS_K;
use mrtmap_radiation::{
    FeatureFile, FramePose, OccluderFile, RadiantScene, SCENE_FORMAT, SceneError, SceneFile,
    SurfaceFile, SurfaceKind,
};
use serde::{Deserialize, Serialize};

pub use envelope::{Envelope, FoundPlane, PlaneClass, up_from_poses};
pub use labels::{MaskSummary, Votes, WEAK_MAJORITY, rule_label};
pub use texture::{TextureInput, TextureParams, TextureReport};

/// Segmentation settings (all documented in docs/segmentation.md).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SegmentParams {
    /// RANSAC inlier distance (m): the fused surfaces are as thick as the depth noise.
    pub plane_distance_m: f64,
    /// RANSAC normal agreement (degrees).
    pub plane_normal_deg: f64,
    /// Smallest plane (points; at least 0.25 % of the cloud).
    pub min_plane_points: usize,
    /// Planes sought at most.
    pub max_planes: usize,
    /// Planes closer than this in angle (degrees)…
    pub merge_deg: f64,
    /// …and offset (m) are one surface.
    pub merge_distance_m: f64,
    /// Horizontal: normal within this of up (degrees).
    pub horizontal_deg: f64,
    /// Vertical: normal within this of horizontal (degrees).
    pub vertical_deg: f64,
    /// Walls are found from their points this far below the ceiling (m; at least a fifth of the
    /// room's height): walls reach the ceiling, furniture does not.
    pub wall_ceiling_gap_m: f64,
    /// Points within this distance of a surface belong to it (m); more where the surface's fused
    /// points are spread wider (three robust standard deviations, up to 0.35 m).
    pub surface_band_m: f64,
    /// Texel size for the thermal analysis (m).
    pub texel_m: f64,
    /// Texel size of each surface's temperature raster in scene.json (m; a whole number of
    /// analysis texels); 0 for none (each surface at one temperature).
    pub raster_m: f64,
    /// A texel belongs to a feature when it differs from the background by more than this (K).
    pub feature_threshold_k: f64,
    /// Smallest feature (m²).
    pub feature_min_area_m2: f64,
    /// Furniture: points this close to a wall are the wall's (m).
    pub furniture_wall_clearance_m: f64,
    /// Furniture: the smallest group of points.
    pub furniture_min_points: usize,
    /// Seed of RANSAC.
    pub seed: u64,
    /// The floor corner (1-based, in the automatic numbering) at the room frame's origin; `None`
    /// for the rule of [`room`].
    pub origin_corner: Option<usize>,
}

impl Default for SegmentParams {
    fn default() -> Self {
        Self {
            plane_distance_m: 0.12,
            plane_normal_deg: 35.0,
            min_plane_points: 300,
            max_planes: 40,
            merge_deg: 5.0,
            merge_distance_m: 0.25,
            horizontal_deg: 15.0,
            vertical_deg: 15.0,
            wall_ceiling_gap_m: 0.4,
            surface_band_m: 0.10,
            texel_m: 0.03,
            raster_m: 0.15,
            feature_threshold_k: 0.3,
            feature_min_area_m2: 0.04,
            furniture_wall_clearance_m: 0.15,
            furniture_min_points: 200,
            seed: 1,
            origin_corner: None,
        }
    }
}

/// Why segmentation failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SegmentError {
    /// No camera poses to estimate up from.
    #[error("no camera poses to estimate up from (poses.txt of the fusion is empty)")]
    NoPoses,
    /// No horizontal plane below the rest.
    #[error(
        "no floor found: no large horizontal plane; scan again tilting the camera down to the floor every few seconds as you walk (a scan must see the floor, the ceiling and every wall: about one slow loop of the room)"
    )]
    NoFloor,
    /// No ceiling.
    #[error(
        "no ceiling found: no large horizontal plane at least 1.5 m above the floor; scan again tilting the camera up to the ceiling every few seconds as you walk (a scan must see the floor, the ceiling and every wall: about one slow loop of the room)"
    )]
    NoCeiling,
    /// No walls.
    #[error(
        "no walls found: no vertical surface reaches the ceiling around a floor or ceiling seen (did the scan look at the walls up to the ceiling?)"
    )]
    NoWalls,
    /// The walls do not close into a loop.
    #[error(
        "the room's outline does not close: from ({:.2}, {:.2}, {:.2}) to ({:.2}, {:.2}, {:.2}) in the scan's frame ({length_m:.2} m) neither a wall nor the floor's or ceiling's edge was seen; scan that part of the room",
        from[0], from[1], from[2], to[0], to[1], to[2]
    )]
    OpenOutline {
        /// Where the unseen part begins, on the floor (scan's frame).
        from: [f64; 3],
        /// Where it ends.
        to: [f64; 3],
        /// Its length (m).
        length_m: f64,
    },
    /// The origin corner asked for does not exist.
    #[error(
        "origin corner {given} does not exist: the room has {corners} corners, numbered 1…{corners} on the report's map; give one of them or leave it out for the default (a run again reuses its fused cloud)"
    )]
    OriginCorner {
        /// The corner asked for.
        given: usize,
        /// Corners the room has.
        corners: usize,
    },
    /// The scene built breaks a scene rule.
    #[error("the scene built from the cloud is invalid: {0}")]
    Scene(#[from] SceneError),
}

/// One surface of the result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SurfaceSummary {
    /// Id in scene.json.
    pub id: String,
    /// Kind.
    pub kind: SurfaceKind,
    /// Radiant temperature of its background (°C).
    pub temperature_c: Option<f64>,
    /// Standard uncertainty (K).
    pub temperature_std_k: f64,
    /// Observed fraction: seen by the cloud (with depth) or by thermal texturing.
    pub observed_fraction: f64,
    /// The part of it seen by thermal texturing only (no depth there: glass, dark or shiny
    /// surfaces, dropouts, beyond range).
    #[serde(default)]
    pub textured_fraction: f64,
    /// Area (m²).
    pub area_m2: f64,
    /// Cloud points on it.
    pub points: usize,
    /// Background model: level at the surface's centre (°C) and vertical gradient (K/m, walls).
    pub background_c: f64,
    /// Vertical gradient of the background (K/m).
    pub gradient_k_per_m: f64,
}

/// One feature of the result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeatureSummary {
    /// Id in scene.json.
    pub id: String,
    /// Host surface id.
    pub host: String,
    /// Label.
    pub label: String,
    /// "masks", or "rule".
    pub label_source: String,
    /// The votes, with masks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub votes: Option<Votes>,
    /// Radiant temperature (°C).
    pub temperature_c: f64,
    /// Difference from the host's background (K).
    pub contrast_k: f64,
    /// Area (m²).
    pub area_m2: f64,
    /// The part of that area the scan never saw, completed from the shape of what it saw (m²).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub completed_m2: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// A piece of furniture of the result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FurnitureSummary {
    /// Id in scene.json.
    pub id: String,
    /// Label.
    pub label: String,
    /// "masks" or "none".
    pub label_source: String,
    /// The votes, with masks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub votes: Option<Votes>,
    /// Size along, across and up (m).
    pub size_m: [f64; 3],
    /// Radiant temperature (°C).
    pub temperature_c: f64,
    /// Cloud points.
    pub points: usize,
}

/// `segment.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SegmentReport {
    /// Up in the world frame.
    pub up: [f64; 3],
    /// The room frame: p_in_world = world_from_room · p_in_room (scene.json is in the room frame).
    pub world_from_room: FramePose,
    /// How the room frame was chosen.
    pub room: room::RoomFrame,
    /// Planes found: class, normal, offset, points.
    pub planes: Vec<(PlaneClass, [f64; 3], f64, usize)>,
    /// Room corners at the floor in the room frame, numbered from 1 (the first listed):
    /// counter-clockwise from above, corner k starting wall k.
    pub floor_corners: Vec<[f64; 3]>,
    /// Floor-to-ceiling height (m).
    pub height_m: f64,
    /// Surfaces.
    pub surfaces: Vec<SurfaceSummary>,
    /// Features.
    pub features: Vec<FeatureSummary>,
    /// Furniture found (occluders in the scene).
    pub furniture: Vec<FurnitureSummary>,
    /// Fraction of cloud points on no envelope surface (furniture, clutter, noise).
    pub unassigned_fraction: f64,
    /// Features dropped, and why.
    pub dropped: Vec<String>,
    /// Masks, when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub masks: Option<MaskSummary>,
    /// Things to check.
    pub warnings: Vec<String>,
    /// Walls never seen, placed at the edge of the floor and ceiling seen (ids).
    #[serde(default)]
    pub inferred_walls: Vec<String>,
    /// Thermal texturing on the room model, when the frames were given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<TextureReport>,
}

/// The result of segmentation.
pub struct Segmentation {
    /// The scene (world frame of the recording).
    pub scene: RadiantScene,
    /// Surface index of each cloud point (−1 for none).
    pub surface_id: Vec<i32>,
    /// Feature index of each cloud point (−1 for none), counting features over all surfaces.
    pub feature_id: Vec<i32>,
    /// Thermal texturing's samples (texels the cloud left empty), as points: what the camera
    /// saw where the depth camera did not (a contact reading on a window is checked against
    /// these). Empty without texturing.
    pub textured: ThermalCloud,
    /// The report.
    pub report: SegmentReport,
}

/// Masks for labels: a recording with `masks.txt`, and the refined pose at any time.
pub struct MaskInput<'a> {
    /// The recording.
    pub recording: &'a Recording,
    /// world_from_depth at a time.
    pub world_from_depth: &'a (dyn Fn(f64) -> Option<Isometry3<f64>> + Sync),
}

fn arr(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

struct SurfaceGeom {
    id: String,
    kind: SurfaceKind,
    polygon: Vec<Point3<f64>>,
    frame: PlaneFrame,
}

/// The cloud as f64 arrays.
struct Points {
    pos: Vec<Point3<f64>>,
    nrm: Vec<Vector3<f64>>,
    temp: Vec<f64>,
    obs: Vec<u32>,
}

impl Points {
    /// Its points from index `first` on (texturing's samples) as a cloud.
    fn cloud_from(&self, first: usize) -> ThermalCloud {
        let f32x3 = |v: [f64; 3]| [v[0] as f32, v[1] as f32, v[2] as f32];
        ThermalCloud {
            positions: self.pos[first..]
                .iter()
                .map(|q| f32x3([q.x, q.y, q.z]))
                .collect(),
            normals: self.nrm[first..]
                .iter()
                .map(|n| f32x3([n.x, n.y, n.z]))
                .collect(),
            temperature_k: self.temp[first..].iter().map(|t| *t as f32).collect(),
            temperature_std_k: vec![0.0; self.pos.len() - first],
            observations: self.obs[first..].to_vec(),
        }
    }

    fn of(cloud: &ThermalCloud) -> Self {
        Self {
            pos: cloud
                .positions
                .iter()
                .map(|q| Point3::new(q[0] as f64, q[1] as f64, q[2] as f64))
                .collect(),
            nrm: cloud
                .normals
                .iter()
                .map(|n| Vector3::new(n[0] as f64, n[1] as f64, n[2] as f64))
                .collect(),
            temp: cloud.temperature_k.iter().map(|t| *t as f64).collect(),
            obs: cloud.observations.clone(),
        }
    }
}

/// The longest wall's direction along the floor.
fn longest_wall(env: &Envelope) -> Vector3<f64> {
    let n = env.walls.len();
    (0..n)
        .map(|k| env.floor_corners[(k + 1) % n] - env.floor_corners[k])
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .unwrap_or_else(Vector3::x)
}

/// Surface geometry: floor, ceiling, walls in loop order. Floor and ceiling texels run along the
/// longest wall, so features aligned with the room align with the texel grid.
fn surface_geometry(env: &Envelope, longest: &Vector3<f64>) -> Vec<SurfaceGeom> {
    let n = env.walls.len();
    let mut geoms = Vec::with_capacity(n + 2);
    for (id, kind, plane, corners) in [
        ("floor", SurfaceKind::Floor, env.floor, &env.floor_corners),
        (
            "ceiling",
            SurfaceKind::Ceiling,
            env.ceiling,
            &env.ceiling_corners,
        ),
    ] {
        geoms.push(SurfaceGeom {
            id: id.into(),
            kind,
            frame: PlaneFrame::new(centroid(corners), env.planes[plane].plane.normal, longest),
            polygon: corners.clone(),
        });
    }
    for k in 0..n {
        let poly = vec![
            env.floor_corners[k],
            env.floor_corners[(k + 1) % n],
            env.ceiling_corners[(k + 1) % n],
            env.ceiling_corners[k],
        ];
        let wall = &env.planes[env.walls[k]].plane;
        let along = env.floor_corners[(k + 1) % n] - env.floor_corners[k];
        let mut frame = PlaneFrame::new(centroid(&poly), wall.normal, &along);
        if frame.v.dot(&env.up) < 0.0 {
            // Keep v pointing up so the background's slope reads as a vertical gradient.
            frame = PlaneFrame {
                u: -frame.u,
                v: -frame.v,
                ..frame
            };
        }
        geoms.push(SurfaceGeom {
            id: format!("wall-{}", k + 1),
            kind: SurfaceKind::Wall,
            polygon: poly,
            frame,
        });
    }
    geoms
}

/// Each surface's band: three robust standard deviations of the distances of the points near it
/// (the fused surface is as thick as the depth noise), at least `surface_band_m`.
fn surface_bands(
    geoms: &[SurfaceGeom],
    polys2: &[Vec<Point2<f64>>],
    pts: &Points,
    p: &SegmentParams,
) -> Vec<f64> {
    let cos_agree = p.plane_normal_deg.to_radians().cos();
    geoms
        .iter()
        .enumerate()
        .map(|(s, g)| {
            let mut d: Vec<f64> = pts
                .pos
                .iter()
                .zip(&pts.nrm)
                .filter(|(q, n)| {
                    n.dot(&g.frame.normal).abs() >= cos_agree
                        && g.frame.signed_distance(q).abs() < 0.4
                        && point_in_polygon(&g.frame.to_2d(q), &polys2[s], 0.0)
                            == Containment::Inside
                })
                .map(|(q, _)| g.frame.signed_distance(q))
                .collect();
            if d.len() < 100 {
                return p.surface_band_m;
            }
            d.sort_by(f64::total_cmp);
            let med = d[d.len() / 2];
            let mut dev: Vec<f64> = d.iter().map(|x| (x - med).abs()).collect();
            dev.sort_by(f64::total_cmp);
            (3.0 * 1.4826 * dev[dev.len() / 2]).clamp(p.surface_band_m, 0.35)
        })
        .collect()
}

/// Points to surfaces: the nearest surface plane within its band, with an agreeing normal, whose
/// outline (grown by the band) contains the point's projection. Returns each point's surface (−1
/// for none) and each surface's points.
fn assign_points(
    geoms: &[SurfaceGeom],
    polys2: &[Vec<Point2<f64>>],
    bands: &[f64],
    pts: &Points,
    p: &SegmentParams,
) -> (Vec<i32>, Vec<Vec<usize>>) {
    let cos_agree = p.plane_normal_deg.to_radians().cos();
    let mut surface_id = vec![-1i32; pts.pos.len()];
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); geoms.len()];
    for (i, q) in pts.pos.iter().enumerate() {
        let mut best: Option<(f64, usize)> = None;
        for (s, g) in geoms.iter().enumerate() {
            let d = g.frame.signed_distance(q).abs();
            // Normals must agree: the side of a box standing on the floor is not floor.
            if d <= bands[s]
                && best.is_none_or(|b| d < b.0)
                && pts.nrm[i].dot(&g.frame.normal).abs() >= cos_agree
                && point_in_polygon(&g.frame.to_2d(q), &polys2[s], bands[s]) != Containment::Outside
            {
                best = Some((d, s));
            }
        }
        if let Some((_, s)) = best {
            surface_id[i] = s as i32;
            members[s].push(i);
        }
    }
    (surface_id, members)
}

/// Furniture: what stands off the envelope, kept clear of the walls by their band and 5 cm.
fn furniture_of(
    env: &Envelope,
    longest: &Vector3<f64>,
    bands: &[f64],
    pts: &Points,
    surface_id: &[i32],
    height_m: f64,
    p: &SegmentParams,
) -> Vec<furniture::FoundFurniture> {
    let up = env.up;
    let floor_height = up.dot(&env.floor_corners[0].coords);
    let u = (longest - up.as_ref() * longest.dot(&up)).normalize();
    let v = up.cross(&u);
    let floor_2d: Vec<Point2<f64>> = env
        .floor_corners
        .iter()
        .map(|q| Point2::new(u.dot(&q.coords), v.dot(&q.coords)))
        .collect();
    let wall_planes: Vec<(mrtmap_geometry::Plane, f64)> = env
        .walls
        .iter()
        .enumerate()
        .map(|(w, &k)| (env.planes[k].plane, bands[w + 2] + 0.05))
        .collect();
    // Where the floor (surface 0) was seen, in 5 cm cells of the room's axes.
    let c = furniture::FLOOR_CELL_M;
    let floor_seen: std::collections::HashSet<(i32, i32)> = pts
        .pos
        .iter()
        .zip(surface_id)
        .filter(|(_, s)| **s == 0)
        .map(|(q, _)| {
            (
                (u.dot(&q.coords) / c).floor() as i32,
                (v.dot(&q.coords) / c).floor() as i32,
            )
        })
        .collect();
    let room = furniture::Room {
        up,
        along: *longest,
        floor_height,
        room_height: height_m,
        floor_2d: &floor_2d,
        wall_planes: &wall_planes,
        floor_seen: &floor_seen,
    };
    furniture::find_furniture(
        &pts.pos, &pts.nrm, &pts.temp, &pts.obs, surface_id, &room, p,
    )
}

/// Floor points under a piece of furniture's footprint (grown by [`UNDER_FURNITURE_M`]) are the
/// furniture's own foot, fused into the floor's band: the floor there is hidden, so they leave
/// the floor (unassigned). On the L-shaped room's field walks a bookcase's and a sofa's feet made
/// 0.3-0.7 m² "features" 0.3-1 K warmer than the floor.
fn release_under_furniture(
    geoms: &[SurfaceGeom],
    furniture: &[furniture::FoundFurniture],
    pts: &Points,
    surface_id: &mut [i32],
    members: &mut [Vec<usize>],
) {
    let m = UNDER_FURNITURE_M;
    let footprints: Vec<_> = furniture
        .iter()
        .filter_map(|f| {
            let c = f.corners[0];
            let a = (f.corners[1] - c).try_normalize(1e-9)?;
            let b = (f.corners[2] - c).try_normalize(1e-9)?;
            Some((c, a, b, f.size_m[0], f.size_m[1]))
        })
        .collect();
    let under = |q: &Point3<f64>| {
        footprints.iter().any(|(c, a, b, la, lb)| {
            let (s, t) = (a.dot(&(q - c)), b.dot(&(q - c)));
            (-m..=la + m).contains(&s) && (-m..=lb + m).contains(&t)
        })
    };
    for (s, g) in geoms.iter().enumerate() {
        if g.kind != SurfaceKind::Floor {
            continue;
        }
        members[s].retain(|&i| {
            let keep = !under(&pts.pos[i]);
            if !keep {
                surface_id[i] = -1;
            }
            keep
        });
    }
}

/// The margin of a furniture footprint whose floor points are released (m).
const UNDER_FURNITURE_M: f64 = 0.03;

/// A label's vote, if masks gave one.
type Vote = Option<(String, Votes)>;

/// Labels: one pass over the masks for features and furniture; returns their votes (none without
/// masks) and the masks' summary.
fn vote_labels(
    masks: Option<&MaskInput<'_>>,
    features: &[(usize, &features::FoundFeature)],
    furniture: &[furniture::FoundFurniture],
    pos: &[Point3<f64>],
) -> (Vec<Vote>, Vec<Vote>, Option<MaskSummary>) {
    let Some(m) = masks else {
        return (
            vec![None; features.len()],
            vec![None; furniture.len()],
            None,
        );
    };
    let pts: Vec<Vec<Point3<f64>>> = features
        .iter()
        .map(|(_, f)| f.points.iter().map(|&i| pos[i]).collect())
        .chain(
            furniture
                .iter()
                .map(|f| f.points.iter().map(|&i| pos[i]).collect()),
        )
        .collect();
    let (mut voted, summary) = labels::vote(m.recording, m.world_from_depth, &pts);
    let furniture_votes = voted.split_off(features.len());
    (voted, furniture_votes, Some(summary))
}

/// Ids from labels: "window-1", "window-2", "recessed-light-1"…
#[derive(Default)]
struct Ids(BTreeMap<String, usize>);

impl Ids {
    fn next(&mut self, label: &str) -> String {
        let slug = mrtmap_radiation::slug(label);
        let c = self.0.entry(slug.clone()).or_default();
        *c += 1;
        format!("{slug}-{c}")
    }
}

/// Features as written: per surface their scene entries, their summaries, each point's feature.
struct Features {
    per_surface: Vec<Vec<FeatureFile>>,
    summaries: Vec<FeatureSummary>,
    feature_id: Vec<i32>,
}

/// Labels, ids and scene entries of the features (`features` with their surface index).
fn build_features(
    geoms: &[SurfaceGeom],
    features: &[(usize, &features::FoundFeature)],
    votes: Vec<Vote>,
    points: usize,
    ids: &mut Ids,
    warnings: &mut Vec<String>,
) -> Features {
    let mut out = Features {
        per_surface: vec![Vec::new(); geoms.len()],
        summaries: Vec::new(),
        feature_id: vec![-1i32; points],
    };
    for (k, ((s, f), vote)) in features.iter().zip(votes).enumerate() {
        let (label, source, votes) = match vote {
            Some((l, v)) => (l, "masks", Some(v)),
            None => (
                rule_label(geoms[*s].kind, f.contrast_k, f.area_m2).to_string(),
                "rule",
                None,
            ),
        };
        let id = ids.next(&label);
        if let Some(v) = &votes
            && (v.tie || v.weak)
        {
            warnings.push(format!(
                "feature {id}: label '{label}' won only {:.0} % of {} votes{}",
                v.share * 100.0,
                v.votes.values().sum::<usize>(),
                if v.tie { " (a tie)" } else { "" }
            ));
        }
        if f.completed_m2 > 0.0 {
            warnings.push(format!(
                "feature {id} ({label}): completed: {:.2} m² of its {:.2} m² not seen, taken from the shape of what was seen",
                f.completed_m2, f.area_m2
            ));
        }
        for &i in &f.points {
            out.feature_id[i] = k as i32;
        }
        out.per_surface[*s].push(FeatureFile {
            id: id.clone(),
            label: label.clone(),
            polygon: f
                .polygon_2d
                .iter()
                .map(|q| arr(&geoms[*s].frame.to_3d(q)))
                .collect(),
            temperature_c: f.temperature_k - ZERO_CELSIUS_K,
            emissivity: 1.0,
            temperature_std_k: Some(f.temperature_std_k),
        });
        out.summaries.push(FeatureSummary {
            id,
            host: geoms[*s].id.clone(),
            label,
            label_source: source.into(),
            votes,
            temperature_c: f.temperature_k - ZERO_CELSIUS_K,
            contrast_k: f.contrast_k,
            area_m2: f.area_m2,
            completed_m2: f.completed_m2,
        });
    }
    out
}

/// The surfaces' scene entries (with their features) and summaries. Surfaces never observed get
/// the mean of the observed ones, and say so.
fn build_surfaces(
    geoms: &[SurfaceGeom],
    analyses: &[features::SurfaceAnalysis],
    members: &[Vec<usize>],
    mut per_surface: Vec<Vec<FeatureFile>>,
    warnings: &mut Vec<String>,
) -> (Vec<SurfaceFile>, Vec<SurfaceSummary>) {
    let observed: Vec<f64> = analyses.iter().filter_map(|a| a.temperature_k).collect();
    let fallback = observed.iter().sum::<f64>() / observed.len().max(1) as f64;
    let mut surfaces = Vec::new();
    let mut summaries = Vec::new();
    for (s, g) in geoms.iter().enumerate() {
        let a = &analyses[s];
        let t = match a.temperature_k {
            Some(t) => t,
            None => {
                warnings.push(format!(
                    "surface {} was not observed: it takes the mean of the others",
                    g.id
                ));
                fallback
            }
        };
        if a.observed_fraction < 0.5 {
            warnings.push(format!(
                "surface {} is only {:.0} % observed",
                g.id,
                a.observed_fraction * 100.0
            ));
        }
        surfaces.push(SurfaceFile {
            id: g.id.clone(),
            kind: g.kind.as_str().into(),
            label: match g.kind {
                SurfaceKind::Wall => "wall".into(),
                k => k.as_str().into(),
            },
            polygon: g.polygon.iter().map(arr).collect(),
            temperature_c: t - ZERO_CELSIUS_K,
            emissivity: 1.0,
            temperature_std_k: Some(a.temperature_std_k),
            observed_fraction: Some(a.observed_fraction),
            features: std::mem::take(&mut per_surface[s]),
            raster: a.raster.clone(),
        });
        summaries.push(SurfaceSummary {
            id: g.id.clone(),
            kind: g.kind,
            temperature_c: a.temperature_k.map(|t| t - ZERO_CELSIUS_K),
            temperature_std_k: a.temperature_std_k,
            observed_fraction: a.observed_fraction,
            textured_fraction: 0.0,
            area_m2: mrtmap_geometry::polygon::area_3d(&g.polygon),
            points: members[s].len(),
            background_c: a.background.a - ZERO_CELSIUS_K,
            gradient_k_per_m: a.background.b,
        });
    }
    (surfaces, summaries)
}

/// The furniture's occluder entries (boxes as meshes) and summaries.
fn build_furniture(
    furniture: &[furniture::FoundFurniture],
    votes: Vec<Vote>,
    ids: &mut Ids,
) -> (Vec<OccluderFile>, Vec<FurnitureSummary>) {
    let mut occluders = Vec::new();
    let mut summaries = Vec::new();
    for (f, vote) in furniture.iter().zip(votes) {
        let (label, source, votes) = match vote {
            Some((l, v)) => (l, "masks", Some(v)),
            None => ("furniture".to_string(), "none", None),
        };
        let id = ids.next(&label);
        occluders.push(OccluderFile {
            id: id.clone(),
            label: label.clone(),
            temperature_c: f.temperature_k - ZERO_CELSIUS_K,
            emissivity: 1.0,
            box_: None,
            vertices: Some(f.corners.iter().map(arr).collect()),
            triangles: Some(mrtmap_geometry::BOX_TRIANGLES.to_vec()),
        });
        summaries.push(FurnitureSummary {
            id,
            label,
            label_source: source.into(),
            votes,
            size_m: f.size_m,
            temperature_c: f.temperature_k - ZERO_CELSIUS_K,
            points: f.points.len(),
        });
    }
    (occluders, summaries)
}

/// The room frame (see [`room`]): the walls described by their length, the features found on
/// them and their temperature.
fn choose_room_frame(
    env: &Envelope,
    analyses: &[features::SurfaceAnalysis],
    p: &SegmentParams,
) -> Result<room::RoomFrame, SegmentError> {
    let n = env.walls.len();
    let observed: Vec<f64> = analyses.iter().filter_map(|a| a.temperature_k).collect();
    let mean = observed.iter().sum::<f64>() / observed.len().max(1) as f64;
    let walls: Vec<room::WallFacts> = (0..n)
        .map(|k| {
            let a = &analyses[k + 2];
            room::WallFacts {
                length_m: (env.floor_corners[(k + 1) % n] - env.floor_corners[k]).norm(),
                feature_area_m2: a.features.iter().map(|f| f.area_m2).sum(),
                temperature_k: a.temperature_k.unwrap_or(mean),
            }
        })
        .collect();
    room::room_frame(&env.floor_corners, &walls, &env.up, p.origin_corner).map_err(|corners| {
        SegmentError::OriginCorner {
            given: p.origin_corner.unwrap_or(0),
            corners,
        }
    })
}

/// Walls get the room frame's numbers: wall k runs from corner k to corner k + 1, corner 1 being
/// the rule's origin; the floor's outline starts at corner 1, so that its k-th vertex is corner k.
fn number_walls(geoms: &mut [SurfaceGeom], frame: &room::RoomFrame) {
    let n = geoms.len() - 2;
    for (k, g) in geoms[2..].iter_mut().enumerate() {
        g.id = format!("wall-{}", (k + n - frame.first_index) % n + 1);
    }
    if geoms[0].polygon.len() == n {
        geoms[0].polygon.rotate_left(frame.first_index);
    }
}

/// The planes found, as the report lists them.
fn plane_rows(env: &Envelope) -> Vec<(PlaneClass, [f64; 3], f64, usize)> {
    env.planes
        .iter()
        .map(|f| {
            (
                f.class,
                [f.plane.normal.x, f.plane.normal.y, f.plane.normal.z],
                f.plane.d,
                f.points,
            )
        })
        .collect()
}

/// Segments a thermal cloud into a radiant scene: up, planes and the envelope; points to surfaces;
/// each surface's background and features; furniture; labels; the scene and its report.
pub fn segment(
    cloud: &ThermalCloud,
    camera_poses: &[Isometry3<f64>],
    masks: Option<&MaskInput<'_>>,
    p: &SegmentParams,
) -> Result<Segmentation, SegmentError> {
    segment_textured(cloud, camera_poses, masks, None, p)
}

/// Texels the cloud's points of a surface cover, in the texel grid of its outline's lower corner.
fn covered_texels(
    g: &SurfaceGeom,
    lo: &Point2<f64>,
    members: &[usize],
    pts: &Points,
    texel_m: f64,
) -> std::collections::HashSet<(i64, i64)> {
    members
        .iter()
        .map(|&i| {
            let q = g.frame.to_2d(&pts.pos[i]);
            (
                ((q.x - lo.x) / texel_m).floor() as i64,
                ((q.y - lo.y) / texel_m).floor() as i64,
            )
        })
        .collect()
}

/// Thermal texturing of the texels the cloud left empty: samples appended to the points (and
/// their weights and the surfaces' members).
#[allow(clippy::too_many_arguments)]
fn fill_from_texture(
    input: &TextureInput<'_>,
    geoms: &[SurfaceGeom],
    polys2: &[Vec<Point2<f64>>],
    furniture: &[furniture::FoundFurniture],
    pts: &mut Points,
    weights: &mut Vec<f64>,
    members: &mut [Vec<usize>],
    p: &SegmentParams,
) -> TextureReport {
    let surfaces: Vec<texture::ModelSurface<'_>> = geoms
        .iter()
        .enumerate()
        .map(|(s, g)| {
            let lo = polys2[s]
                .iter()
                .fold(Point2::new(f64::INFINITY, f64::INFINITY), |a, q| {
                    Point2::new(a.x.min(q.x), a.y.min(q.y))
                });
            texture::ModelSurface {
                frame: &g.frame,
                polygon: &polys2[s],
                texel_origin: lo,
                covered: covered_texels(g, &lo, &members[s], pts, p.texel_m),
            }
        })
        .collect();
    let boxes: Vec<[Point3<f64>; 8]> = furniture.iter().map(|f| f.corners).collect();
    let (tx, report) = texture::texture(
        input,
        &surfaces,
        &boxes,
        p.texel_m,
        &TextureParams::default(),
    );
    for k in 0..tx.surface.len() {
        members[tx.surface[k]].push(pts.pos.len());
        pts.pos.push(tx.pos[k]);
        pts.nrm.push(tx.nrm[k]);
        pts.temp.push(tx.temp_k[k]);
        pts.obs.push(tx.pixels[k]);
        weights.push(f64::from(tx.pixels[k]));
    }
    report
}

/// Segments the cloud into a radiant scene; with `texture`, the thermal frames are also cast onto
/// the room model found, and what the cloud did not cover takes their temperatures. The steps
/// of docs/segmentation.md in their order, one call each.
pub fn segment_textured(
    cloud: &ThermalCloud,
    camera_poses: &[Isometry3<f64>],
    masks: Option<&MaskInput<'_>>,
    texture: Option<&TextureInput<'_>>,
    p: &SegmentParams,
) -> Result<Segmentation, SegmentError> {
    let mut pts = Points::of(cloud);
    let cloud_points = pts.pos.len();
    let up0 = up_from_poses(camera_poses).ok_or(SegmentError::NoPoses)?;
    let planes = envelope::find_planes(&pts.pos, &pts.nrm, p);
    let mut weights: Vec<f64> = pts.obs.iter().map(|&o| o.max(1) as f64).collect();
    let cloud_in = envelope::Cloud {
        points: &pts.pos,
        normals: &pts.nrm,
        weights: &weights,
    };
    let env = envelope::envelope(cloud_in, planes, up0, p)?;
    let up = env.up;
    let height_m = env.planes[env.floor]
        .plane
        .distance(&env.ceiling_corners[0])
        .abs();
    let longest = longest_wall(&env);
    let geoms = surface_geometry(&env, &longest);
    let polys2: Vec<Vec<_>> = geoms
        .iter()
        .map(|g| g.polygon.iter().map(|q| g.frame.to_2d(q)).collect())
        .collect();
    let bands = surface_bands(&geoms, &polys2, &pts, p);
    let (mut surface_id, mut members) = assign_points(&geoms, &polys2, &bands, &pts, p);
    let unassigned = surface_id.iter().filter(|s| **s < 0).count();
    let furniture = furniture_of(&env, &longest, &bands, &pts, &surface_id, height_m, p);
    release_under_furniture(&geoms, &furniture, &pts, &mut surface_id, &mut members);
    let texture_report = texture.map(|t| {
        fill_from_texture(
            t,
            &geoms,
            &polys2,
            &furniture,
            &mut pts,
            &mut weights,
            &mut members,
            p,
        )
    });
    let analyses = analyse_surfaces(&geoms, &polys2, &members, (&pts, &weights), p);
    let all_features: Vec<(usize, &features::FoundFeature)> = analyses
        .iter()
        .enumerate()
        .flat_map(|(s, a)| a.features.iter().map(move |f| (s, f)))
        .collect();
    let frame = choose_room_frame(&env, &analyses, p)?;
    let mut geoms = geoms;
    number_walls(&mut geoms, &frame);
    let (feature_votes, furniture_votes, mask_summary) =
        vote_labels(masks, &all_features, &furniture, &pts.pos);
    let mut ids = Ids::default();
    let mut warnings = Vec::new();
    let found = build_features(
        &geoms,
        &all_features,
        feature_votes,
        pts.pos.len(),
        &mut ids,
        &mut warnings,
    );
    let (surfaces, mut summaries) = build_surfaces(
        &geoms,
        &analyses,
        &members,
        found.per_surface,
        &mut warnings,
    );
    if let Some(t) = &texture_report {
        t.set_fractions(&mut summaries, p.texel_m);
    }
    let mut feature_id = found.feature_id;
    feature_id.truncate(cloud_points);
    let (occluders, furniture_summaries) = build_furniture(&furniture, furniture_votes, &mut ids);
    let world_from_room = frame.world_from_room;
    let scene = room_scene(surfaces, occluders, &up, &world_from_room)?;
    let inferred_walls = wall_warnings(&env, &geoms, &frame, &mut warnings);
    let n = env.floor_corners.len();
    let report = SegmentReport {
        up: [up.x, up.y, up.z],
        world_from_room: FramePose::from_isometry(&world_from_room),
        planes: plane_rows(&env),
        floor_corners: (0..n)
            .map(|k| {
                arr(&(world_from_room.inverse() * env.floor_corners[(frame.first_index + k) % n]))
            })
            .collect(),
        room: frame,
        height_m,
        surfaces: summaries,
        features: found.summaries,
        furniture: furniture_summaries,
        unassigned_fraction: unassigned as f64 / cloud_points.max(1) as f64,
        dropped: analyses
            .iter()
            .flat_map(|a| a.dropped.iter().cloned())
            .collect(),
        masks: mask_summary,
        warnings,
        inferred_walls,
        texture: texture_report,
    };
    let textured = pts.cloud_from(cloud_points);
    Ok(Segmentation {
        scene,
        surface_id,
        feature_id,
        textured,
        report,
    })
}

/// Each surface's temperatures and features from its member points ([`features::analyse_surface`]).
fn analyse_surfaces(
    geoms: &[SurfaceGeom],
    polys2: &[Vec<Point2<f64>>],
    members: &[Vec<usize>],
    (pts, weights): (&Points, &[f64]),
    p: &SegmentParams,
) -> Vec<features::SurfaceAnalysis> {
    geoms
        .iter()
        .enumerate()
        .map(|(s, g)| {
            features::analyse_surface(
                &g.frame,
                &polys2[s],
                &members[s],
                (&pts.pos, &pts.temp, weights),
                g.kind == SurfaceKind::Wall,
                p,
            )
        })
        .collect()
}

/// The scene in the room's frame, from surfaces and occluders in the world's.
fn room_scene(
    surfaces: Vec<SurfaceFile>,
    occluders: Vec<OccluderFile>,
    up: &Unit<Vector3<f64>>,
    world_from_room: &Isometry3<f64>,
) -> Result<RadiantScene, SegmentError> {
    let in_world = SceneFile {
        format: SCENE_FORMAT.into(),
        up: Some([up.x, up.y, up.z]),
        world_from_room: None,
        temperature_level_std_k: None,
        surfaces,
        occluders,
    };
    let mut in_room = in_world.transformed(&world_from_room.inverse());
    in_room.up = Some([0.0, 0.0, 1.0]);
    in_room.world_from_room = Some(FramePose::from_isometry(world_from_room));
    let scene = RadiantScene::new(&in_room)?;
    if !hidden_by_furniture(&mut in_room, &scene) {
        return Ok(scene);
    }
    Ok(RadiantScene::new(&in_room)?)
}

/// Leaves out of the rasters' unseen patches the texels that furniture stands in front of (within
/// 15 cm: a bookcase against a wall, a sofa on the floor): no point of the room sees them, so
/// they are no part of any MRT's ±, while the patches' shares count solid angles without
/// occlusion. On the L-shaped room's 60 s walks the wall behind the bookcase (0.58 m² never seen)
/// made up to 0.38–0.42 K of the ± at the node in front of the bookcase (walks 1 and 2). Whether any texel was left out.
fn hidden_by_furniture(file: &mut SceneFile, scene: &RadiantScene) -> bool {
    if scene.occluders.is_empty() {
        return false;
    }
    let mut changed = false;
    for (sf, s) in file.surfaces.iter_mut().zip(&scene.surfaces) {
        let Some(r) = sf.raster.as_mut() else {
            continue;
        };
        if r.unseen.is_empty() {
            continue;
        }
        let (o, u, v) = (
            Point3::from(r.origin),
            Vector3::from(r.u),
            Vector3::from(r.v),
        );
        let n = s.frame.normal.into_inner();
        let (t, cols) = (r.texel_m, r.cols);
        let hidden = |i: usize| {
            let c = o + u * (((i % cols) as f64 + 0.5) * t) + v * (((i / cols) as f64 + 0.5) * t);
            [0.05, 0.15].iter().any(|d| {
                [1.0, -1.0].iter().any(|side| {
                    let q = c + n * (side * d);
                    scene.occluders.iter().any(|oc| oc.contains(&q))
                })
            })
        };
        for patch in &mut r.unseen {
            let before = patch.texels.len();
            patch.texels.retain(|&i| !hidden(i));
            changed |= patch.texels.len() != before;
        }
        r.unseen.retain(|p| !p.texels.is_empty());
    }
    changed
}

/// Walls never seen (inferred) and seen only in part, and corners outside x, y ≥ 0: warnings,
/// each naming where the wall runs; returns the inferred walls' ids.
fn wall_warnings(
    env: &Envelope,
    geoms: &[SurfaceGeom],
    frame: &room::RoomFrame,
    warnings: &mut Vec<String>,
) -> Vec<String> {
    let mut inferred_walls = Vec::new();
    let world_from_room = frame.world_from_room;
    let n_walls = env.floor_corners.len();
    // Where wall k runs, in the room's frame: from corner k to corner k + 1 (numbered as in the
    // report's corner table).
    let span = |k: usize| {
        let at = |j: usize| {
            let q = world_from_room.inverse() * env.floor_corners[j % n_walls];
            let number = (j + n_walls - frame.first_index) % n_walls + 1;
            format!("corner {number} ({:.2}, {:.2})", q.x, q.y)
        };
        format!("from {} to {}", at(k), at(k + 1))
    };
    for (k, seen) in env.seen.iter().enumerate() {
        let id = &geoms[2 + k].id;
        if seen.inferred {
            inferred_walls.push(id.clone());
            warnings.push(format!(
                "{id} ({:.2} m, {}) was not seen as a wall: it is placed at the edge of the floor and ceiling seen; scan it up to the ceiling to place it from its own points",
                seen.length_m,
                span(k)
            ));
        } else if seen.observed < 0.3 && seen.length_m > 0.5 {
            warnings.push(format!(
                "{id} ({:.2} m, {}) was seen along only {:.0} % of its length",
                seen.length_m,
                span(k),
                seen.observed * 100.0
            ));
        }
    }
    if frame.outside_quadrant > 0 {
        warnings.push(format!(
            "with the origin at corner {}, {} corner(s) of the room lie at x < 0 or y < 0",
            frame.origin_corner, frame.outside_quadrant
        ));
    }
    inferred_walls
}

/// A unit vector from an array.
pub fn unit(v: [f64; 3]) -> Option<Unit<Vector3<f64>>> {
    Unit::try_new(Vector3::from(v), 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrtmap_geometry::nalgebra::Unit;

    /// A 4 × 3 × 2.5 m room whose south wall (y = 0) has two unseen patches: one behind a
    /// bookcase standing against it (x 1…2, 40 cm deep), one in the open (x 3…3.6). The first is
    /// no part of any MRT's ±: no point of the room sees it.
    #[test]
    fn unseen_texels_behind_furniture_leave_the_patches() {
        let wall = |id: &str, p: [[f64; 3]; 4], raster: Option<serde_json::Value>| {
            let mut v = serde_json::json!({"id": id, "kind": if id == "floor" { "floor" } else if id == "ceiling" { "ceiling" } else { "wall" },
                "temperature_c": 20.0, "polygon": p});
            if let Some(r) = raster {
                v["raster"] = r;
            }
            v
        };
        // 0.2 m texels over the south wall: 20 columns, 13 rows (row 0 at the floor).
        let (cols, rows) = (20usize, 13usize);
        let behind: Vec<usize> = (1..5)
            .flat_map(|r| (5..10).map(move |c| r * cols + c))
            .collect();
        let open: Vec<usize> = (4..7)
            .flat_map(|r| (15..18).map(move |c| r * cols + c))
            .collect();
        let raster = serde_json::json!({"texel_m": 0.2, "origin": [0.0, 0.0, 0.0], "u": [1.0, 0.0, 0.0], "v": [0.0, 0.0, 1.0],
            "cols": cols, "rows": rows, "temperature_c": vec![20.0; cols * rows],
            "unseen": [{"texels": behind, "range_c": [18.0, 22.0]}, {"texels": open, "range_c": [18.0, 22.0]}]});
        let file: SceneFile = serde_json::from_value(serde_json::json!({
            "format": "mrtmap-scene/1",
            "surfaces": [
                wall("floor", [[0.,0.,0.],[4.,0.,0.],[4.,3.,0.],[0.,3.,0.]], None),
                wall("ceiling", [[0.,0.,2.5],[0.,3.,2.5],[4.,3.,2.5],[4.,0.,2.5]], None),
                wall("south", [[0.,0.,0.],[0.,0.,2.5],[4.,0.,2.5],[4.,0.,0.]], Some(raster)),
                wall("east", [[4.,0.,0.],[4.,0.,2.5],[4.,3.,2.5],[4.,3.,0.]], None),
                wall("north", [[4.,3.,0.],[4.,3.,2.5],[0.,3.,2.5],[0.,3.,0.]], None),
                wall("west", [[0.,3.,0.],[0.,3.,2.5],[0.,0.,2.5],[0.,0.,0.]], None),
            ],
            "occluders": [{"id": "bookcase-1", "label": "bookcase", "temperature_c": 20.0,
                "box": {"min": [1.0, 0.02, 0.0], "max": [2.0, 0.42, 1.0]}}]
        }))
        .unwrap();
        let mut file = file;
        let scene = RadiantScene::new(&file).unwrap();
        assert!(hidden_by_furniture(&mut file, &scene));
        let unseen = &file.surfaces[2].raster.as_ref().unwrap().unseen;
        // Rows 1-4 at x 1…2: texel centres at z 0.3…0.9, in front of the 1 m tall bookcase.
        assert_eq!(unseen.len(), 1, "{unseen:?}");
        assert_eq!(unseen[0].texels.len(), 9);
        assert!(RadiantScene::new(&file).is_ok());
        // Nothing to leave out: unchanged.
        let mut again = file.clone();
        assert!(!hidden_by_furniture(
            &mut again,
            &RadiantScene::new(&file).unwrap()
        ));
        assert_eq!(again, file);
    }

    /// A bookcase (x 0.05…0.45, y 3.6…4.9) on a 4 × 5 m floor: the floor points under its
    /// footprint (its foot, fused into the floor's band) leave the floor; those 5 cm in front of
    /// it stay.
    #[test]
    fn floor_points_under_furniture_leave_the_floor() {
        let floor = SurfaceGeom {
            id: "floor".into(),
            kind: SurfaceKind::Floor,
            polygon: vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(4.0, 0.0, 0.0),
                Point3::new(4.0, 5.0, 0.0),
                Point3::new(0.0, 5.0, 0.0),
            ],
            frame: PlaneFrame::new(
                Point3::origin(),
                Unit::new_normalize(Vector3::z()),
                &Vector3::x(),
            ),
        };
        let bookcase = furniture::FoundFurniture {
            corners: mrtmap_geometry::box_corners(
                &Point3::new(0.05, 3.6, 0.0),
                &Point3::new(0.45, 4.9, 1.9),
            ),
            size_m: [0.4, 1.3, 1.9],
            temperature_k: 293.55,
            points: Vec::new(),
        };
        let at = [
            Point3::new(0.25, 4.2, 0.01), // under it
            Point3::new(0.47, 4.2, 0.01), // within the 3 cm margin
            Point3::new(0.50, 4.2, 0.01), // 5 cm in front
            Point3::new(2.0, 2.0, 0.0),   // the open floor
        ];
        let pts = Points {
            pos: at.to_vec(),
            nrm: vec![Vector3::z(); at.len()],
            temp: vec![293.0; at.len()],
            obs: vec![5; at.len()],
        };
        let mut surface_id = vec![0i32; at.len()];
        let mut members = vec![(0..at.len()).collect::<Vec<usize>>()];
        release_under_furniture(
            std::slice::from_ref(&floor),
            std::slice::from_ref(&bookcase),
            &pts,
            &mut surface_id,
            &mut members,
        );
        assert_eq!(members[0], vec![2, 3]);
        assert_eq!(surface_id, vec![-1, -1, 0, 0]);
    }
}
