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
mod membership;
mod outline;
mod outputs;
pub mod room;
mod texture;

use furniture::furniture_of;
use labels::{Vote, vote_labels};
use membership::*;
use outputs::*;
use texture::fill_from_texture;

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
    /// The emissivity taken (set with the level, from project.toml's `[emissivity]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emissivity: Option<f64>,
    /// The true surface temperature (°C) and its ± (K), derived with the level.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_temperature_c: Option<f64>,
    /// Its standard uncertainty (K).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_temperature_std_k: Option<f64>,
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
    /// The emissivity taken (set with the level).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emissivity: Option<f64>,
    /// The true surface temperature (°C), derived with the level.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_temperature_c: Option<f64>,
    /// Its standard uncertainty (K).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_temperature_std_k: Option<f64>,
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

/// The margin of a furniture footprint whose floor points are released (m).
const UNDER_FURNITURE_M: f64 = 0.03;

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
    match segment_textured_until(cloud, camera_poses, masks, texture, p, &|| false)? {
        Some(s) => Ok(s),
        // `stop` never says so.
        None => unreachable!("a segmentation that is never asked to stop stopped"),
    }
}

/// [`segment_textured`], asking `stop` between its steps: `Ok(None)` once it says so (a person
/// pressed Ctrl-C). Long on purpose: one call per step of docs/segmentation.md, in that order, so
/// that the method reads top to bottom here; each step is its own function.
pub fn segment_textured_until(
    cloud: &ThermalCloud,
    camera_poses: &[Isometry3<f64>],
    masks: Option<&MaskInput<'_>>,
    texture: Option<&TextureInput<'_>>,
    p: &SegmentParams,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Option<Segmentation>, SegmentError> {
    let mut pts = Points::of(cloud);
    let cloud_points = pts.pos.len();
    let up0 = up_from_poses(camera_poses).ok_or(SegmentError::NoPoses)?;
    let planes = envelope::find_planes(&pts.pos, &pts.nrm, p);
    if stop() {
        return Ok(None);
    }
    let mut weights: Vec<f64> = pts.obs.iter().map(|&o| o.max(1) as f64).collect();
    let cloud_in = envelope::Cloud {
        points: &pts.pos,
        normals: &pts.nrm,
        weights: &weights,
    };
    let env = envelope::envelope(cloud_in, planes, up0, p)?;
    if stop() {
        return Ok(None);
    }
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
    if stop() {
        return Ok(None);
    }
    let unassigned = surface_id.iter().filter(|s| **s < 0).count();
    let furniture = furniture_of(&env, &longest, &bands, &pts, &surface_id, height_m, p);
    release_under_furniture(&geoms, &furniture, &pts, &mut surface_id, &mut members);
    if stop() {
        return Ok(None);
    }
    let texture_report = texture.map(|t| {
        fill_from_texture(
            t,
            &geoms,
            &polys2,
            &furniture,
            &mut pts,
            &mut weights,
            &mut members,
            &up.into_inner(),
            p,
        )
    });
    let analyses = analyse_surfaces(&geoms, &polys2, &members, (&pts, &weights), p);
    if stop() {
        return Ok(None);
    }
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
    if stop() {
        return Ok(None);
    }
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
    Ok(Some(Segmentation {
        scene,
        surface_id,
        feature_id,
        textured,
        report,
    }))
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
