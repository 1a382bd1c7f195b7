//! Step 4 of docs/segmentation.md, surface membership: each envelope surface's polygon and frame,
//! its band (how far its points may lie from it), and every point given to the nearest surface
//! within its band; points under furniture leave the floor.

use super::*;

pub(super) struct SurfaceGeom {
    pub(super) id: String,
    pub(super) kind: SurfaceKind,
    pub(super) polygon: Vec<Point3<f64>>,
    pub(super) frame: PlaneFrame,
}

/// The cloud as f64 arrays.
pub(super) struct Points {
    pub(super) pos: Vec<Point3<f64>>,
    pub(super) nrm: Vec<Vector3<f64>>,
    pub(super) temp: Vec<f64>,
    pub(super) obs: Vec<u32>,
}

impl Points {
    /// Its points from index `first` on (texturing's samples) as a cloud.
    pub(super) fn cloud_from(&self, first: usize) -> ThermalCloud {
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

    pub(super) fn of(cloud: &ThermalCloud) -> Self {
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
pub(super) fn longest_wall(env: &Envelope) -> Vector3<f64> {
    let n = env.walls.len();
    (0..n)
        .map(|k| env.floor_corners[(k + 1) % n] - env.floor_corners[k])
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .unwrap_or_else(Vector3::x)
}

/// Surface geometry: floor, ceiling, walls in loop order. Floor and ceiling texels run along the
/// longest wall, so features aligned with the room align with the texel grid.
pub(super) fn surface_geometry(env: &Envelope, longest: &Vector3<f64>) -> Vec<SurfaceGeom> {
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
pub(super) fn surface_bands(
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
pub(super) fn assign_points(
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

/// Floor points under a piece of furniture's footprint (grown by [`UNDER_FURNITURE_M`]) are the
/// furniture's own foot, fused into the floor's band: the floor there is hidden, so they leave
/// the floor (unassigned). On the L-shaped room's field walks a bookcase's and a sofa's feet made
/// 0.3-0.7 m² "features" 0.3-1 K warmer than the floor.
pub(super) fn release_under_furniture(
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
