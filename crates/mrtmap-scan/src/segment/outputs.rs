//! The outputs of docs/segmentation.md: features, surfaces and furniture numbered and summarised
//! (segment.json), the radiant scene in the room's frame (scene.json), the planes' table and the
//! warnings about walls that were inferred or seen in part.

use super::*;

/// Ids from labels: "window-1", "window-2", "recessed-light-1"…
#[derive(Default)]
pub(super) struct Ids(pub(super) BTreeMap<String, usize>);

impl Ids {
    pub(super) fn next(&mut self, label: &str) -> String {
        let slug = mrtmap_radiation::slug(label);
        let c = self.0.entry(slug.clone()).or_default();
        *c += 1;
        format!("{slug}-{c}")
    }
}

/// Features as written: per surface their scene entries, their summaries, each point's feature.
pub(super) struct Features {
    pub(super) per_surface: Vec<Vec<FeatureFile>>,
    pub(super) summaries: Vec<FeatureSummary>,
    pub(super) feature_id: Vec<i32>,
}

/// Labels, ids and scene entries of the features (`features` with their surface index).
pub(super) fn build_features(
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
            surface_temperature_c: None,
            surface_temperature_std_k: None,
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
            emissivity: None,
            surface_temperature_c: None,
            surface_temperature_std_k: None,
        });
    }
    out
}

/// The surfaces' scene entries (with their features) and summaries. Surfaces never observed get
/// the mean of the observed ones, and say so.
pub(super) fn build_surfaces(
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
            surface_temperature_c: None,
            surface_temperature_std_k: None,
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
            emissivity: None,
            surface_temperature_c: None,
            surface_temperature_std_k: None,
        });
    }
    (surfaces, summaries)
}

/// The furniture's occluder entries (boxes as meshes) and summaries.
pub(super) fn build_furniture(
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

/// The planes found, as the report lists them.
pub(super) fn plane_rows(env: &Envelope) -> Vec<(PlaneClass, [f64; 3], f64, usize)> {
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

/// The scene in the room's frame, from surfaces and occluders in the world's.
pub(super) fn room_scene(
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
        temperatures: None,
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
pub(super) fn hidden_by_furniture(file: &mut SceneFile, scene: &RadiantScene) -> bool {
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
pub(super) fn wall_warnings(
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
