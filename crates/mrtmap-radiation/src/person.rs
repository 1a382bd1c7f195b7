//! A person and a plane element instead of a small sphere.
//!
//! - **Person MRT**: Tr,p⁴ = ∫ fp(d) T(d)⁴ dΩ / ∫ fp(d) dΩ with the projected-area factors fp of a
//!   seated or standing body (`mrtmap_physics::projected_area_factor`), facing a given azimuth or
//!   averaged over all; integrated over the same ray sets the sphere's Monte Carlo casts (a
//!   surface's angle factor is Fᵢ = (4/N) Σ_{rays hitting i} fp(d)).
//! - **Plane radiant temperature** of one face of a small plane element: T_pr⁴ = Σ Fᵢ Tᵢ⁴ with
//!   cosine-weighted factors; exact (Lambert's contour integral over the part of each polygon in
//!   front of the element) for scenes without furniture where no surface hides another, else by
//!   rays weighted 4·max(0, n·d).
//! - **Radiant asymmetry** (ISO 7730): vertical (ceiling side − floor side) and horizontal (the
//!   worst of opposite horizontal faces, every 15°), with the percentage dissatisfied of its kind
//!   and ISO 7730's category.

use mrtmap_geometry::nalgebra::{Point3, Vector3};
use mrtmap_geometry::plane_view_factor;
use mrtmap_physics::{
    AsymmetryKind, Category, Posture, Temperature, projected_area_factor,
    projected_area_factor_averaged, radiant_asymmetry_ppd,
};
use serde::{Deserialize, Serialize};

use crate::engine::{
    ENCLOSURE_TOLERANCE, EXACT_OVERLAP_TOLERANCE, Method, MrtEngine, MrtError, RayFactors, RayHits,
};

/// Which way a person faces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Facing {
    /// Any way: fp averaged over azimuth (an orientation-free answer).
    Any,
    /// This azimuth in degrees in the map's horizontal frame: 0 along +x (u), 90 along +y (v).
    Azimuth(f64),
}

impl Facing {
    /// "any direction" or "facing 90°".
    pub fn describe(self) -> String {
        match self {
            Self::Any => "any direction (fp averaged over azimuth)".into(),
            Self::Azimuth(a) => format!("facing {a}° (from +x towards +y)"),
        }
    }
}

/// A person's mean radiant temperature at one place.
#[derive(Clone, Debug, PartialEq)]
pub struct PersonMrt {
    /// The body centre (0.6 m above the floor seated, 1.0 m standing, for angle factors).
    pub centre: Point3<f64>,
    /// Posture.
    pub posture: Posture,
    /// Facing.
    pub facing: Facing,
    /// Tr,p.
    pub mrt: Temperature,
    /// Standard error (K): ray sampling and surface temperatures combined.
    pub std_error_k: f64,
    /// Angle factor per patch, Fᵢ = (1/π)∫ fp dΩ over what patch i covers (they sum to fp's
    /// closure, about 0.99, not 1; the MRT is normalised by their sum).
    pub angle_factors: Vec<f64>,
    /// Σ Fᵢ.
    pub angle_factor_sum: f64,
    /// Rays cast.
    pub rays: usize,
}

/// The plane radiant temperature of one face of a small plane element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneRadiant {
    /// The face's outward normal.
    pub normal: Vector3<f64>,
    /// T_pr.
    pub temperature: Temperature,
    /// Standard error (K).
    pub std_error_k: f64,
    /// Whether the factors were exact (else rays).
    pub exact: bool,
}

/// One radiant asymmetry and how ISO 7730 judges it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AsymmetryVerdict {
    /// Which of ISO 7730's four situations.
    pub kind: AsymmetryKind,
    /// Δt_pr (K, ≥ 0).
    pub delta_k: f64,
    /// Percentage dissatisfied (%), ISO 7730 clause 6 curve.
    pub pd_pct: f64,
    /// The best category whose limit (Table A.4) holds.
    pub category: Category,
}

impl AsymmetryVerdict {
    fn new(kind: AsymmetryKind, delta_k: f64) -> Self {
        Self {
            kind,
            delta_k,
            pd_pct: radiant_asymmetry_ppd(kind, delta_k.max(0.0)).unwrap_or(f64::NAN),
            category: Category::of_asymmetry(kind, delta_k),
        }
    }
}

/// Plane radiant temperatures around a point and the radiant asymmetries they make.
#[derive(Clone, Debug, PartialEq)]
pub struct RadiantAsymmetry {
    /// The point.
    pub point: Point3<f64>,
    /// Faces looking up, down, +x, −x, +y, −y (map axes).
    pub six: [PlaneRadiant; 6],
    /// Vertical: the face looking up minus the one looking down (K, signed).
    pub vertical_k: f64,
    /// Horizontal: the largest difference between opposite horizontal faces (K, ≥ 0).
    pub horizontal_k: f64,
    /// The azimuth (degrees from +x towards +y) the warmer of those two faces looks to.
    pub horizontal_warm_azimuth_deg: f64,
    /// The vertical asymmetry judged (warm or cool ceiling).
    pub vertical: AsymmetryVerdict,
    /// The horizontal asymmetry judged (warm or cool wall: which side departs more from the mean).
    pub horizontal: AsymmetryVerdict,
}

impl RadiantAsymmetry {
    /// The verdict with the higher percentage dissatisfied.
    pub fn worst(&self) -> AsymmetryVerdict {
        if self.horizontal.pd_pct > self.vertical.pd_pct {
            self.horizontal
        } else {
            self.vertical
        }
    }
}

/// The map frame's up, +x and +y, or why not.
fn axes(engine: &MrtEngine<'_>) -> Result<[Vector3<f64>; 3], MrtError> {
    let b = engine.bounds().ok_or(MrtError::NeedsFloor {
        what: "a person's or a plane element's radiant temperature",
    })?;
    let f = &b.frame.plane;
    Ok([f.normal.into_inner(), f.u.into_inner(), f.v.into_inner()])
}

/// The spacing of the points along a person's vertical axis checked against furniture (m).
pub const BODY_STEP_M: f64 = 0.05;

impl MrtEngine<'_> {
    /// Refuses a point outside the room or inside furniture.
    fn check_place(&self, p: &Point3<f64>) -> Result<(), MrtError> {
        self.check_inside(p)?;
        if let Some(o) = self.scene().occluders.iter().find(|o| o.contains(p)) {
            return Err(MrtError::InsideOccluder {
                point: [p.x, p.y, p.z],
                id: o.id.clone(),
            });
        }
        Ok(())
    }

    /// Refuses a person whose feet (2 cm above them) or crown would lie outside the room, or whose
    /// body (its vertical axis, every [`BODY_STEP_M`]) would pass through furniture.
    fn check_body(
        &self,
        centre: &Point3<f64>,
        posture: Posture,
        up: &Vector3<f64>,
    ) -> Result<(), MrtError> {
        let (below, above) = (
            posture.centre_height_m(),
            posture.head_height_m() - posture.centre_height_m(),
        );
        let posture_name = match posture {
            Posture::Seated => "seated",
            Posture::Standing => "standing",
        };
        for (part, q) in [
            ("feet", centre - up * (below - 0.02)),
            ("head", centre + up * above),
        ] {
            if let Err(MrtError::OutsideRoom { where_, .. }) = self.check_inside(&q) {
                return Err(MrtError::PersonDoesNotFit {
                    point: [centre.x, centre.y, centre.z],
                    posture: posture_name,
                    part,
                    where_,
                    centre_m: below,
                    head_m: above,
                });
            }
        }
        let steps = ((below - 0.02 + above) / BODY_STEP_M).ceil() as usize;
        for k in 0..=steps {
            let h = (-(below - 0.02) + k as f64 * BODY_STEP_M).min(above);
            let q = centre + up * h;
            if let Some(o) = self.scene().occluders.iter().find(|o| o.contains(&q)) {
                return Err(MrtError::PersonThroughOccluder {
                    point: [centre.x, centre.y, centre.z],
                    posture: posture_name,
                    id: o.id.clone(),
                    at_m: below + h,
                    centre_m: below,
                    head_m: above,
                });
            }
        }
        Ok(())
    }

    /// Radiant temperature and its standard error from ray factors; refuses an open scene
    /// (factors short of what a closed room gives) unless open scenes are allowed.
    fn radiant_from_rays(
        &self,
        p: &Point3<f64>,
        r: &RayFactors,
        weight: &dyn Fn(&Vector3<f64>) -> f64,
    ) -> Result<(Temperature, f64), MrtError> {
        let seen: f64 = r.factors.iter().sum();
        let coverage = if r.mean_weight > 0.0 {
            seen / r.mean_weight
        } else {
            0.0
        };
        if !self.answers_open() && (coverage - 1.0).abs() > ENCLOSURE_TOLERANCE {
            return Err(MrtError::NotEnclosed {
                point: [p.x, p.y, p.z],
                sum: coverage,
            });
        }
        let seen = self.seen_temperatures(p, weight);
        let temps = seen.as_ref().map(|s| s.temperatures.as_slice());
        let m = self
            .radiant_of(&r.factors, temps)
            .map_err(|source| MrtError::Physics {
                point: [p.x, p.y, p.z],
                source,
            })?;
        let sampling = self.sampling_error(&r.replicates, temps);
        let (unseen, _) = self.unseen_error(&r.factors, seen.as_ref(), m.temperature);
        Ok((
            m.temperature,
            sampling
                .hypot(m.std_from_temperatures_k)
                .hypot(unseen)
                .hypot(self.scene().temperature_level_std_k),
        ))
    }

    /// The MRT of a person whose body centre is at `centre`; `stream` selects the random stream.
    pub fn person_at(
        &self,
        centre: &Point3<f64>,
        posture: Posture,
        facing: Facing,
        stream: u64,
    ) -> Result<PersonMrt, MrtError> {
        self.check_place(centre)?;
        let [up, x, y] = axes(self)?;
        self.check_body(centre, posture, &up)?;
        let hits = self.ray_hits(centre, &self.ray_settings(), stream);
        let weight = person_weight(posture, facing, up, x, y);
        let r = self.ray_factors(&hits, &weight);
        let (mrt, std_error_k) = self.radiant_from_rays(centre, &r, &weight)?;
        Ok(PersonMrt {
            centre: *centre,
            posture,
            facing,
            mrt,
            std_error_k,
            angle_factor_sum: r.factors.iter().sum(),
            angle_factors: r.factors,
            rays: r.rays,
        })
    }

    /// Exact plane factors per patch, when the scene allows them (no furniture, no surface
    /// hiding another, not forced to Monte Carlo).
    fn exact_plane_factors(&self, p: &Point3<f64>, n: &Vector3<f64>) -> Option<Vec<f64>> {
        if !self.scene().occluders.is_empty() || matches!(self.method(), Method::MonteCarlo(_)) {
            return None;
        }
        let mut f = vec![0.0; self.patch_list().len()];
        for (si, s) in self.scene().surfaces.iter().enumerate() {
            let k = self.surface_patches()[si];
            let mut net = plane_view_factor(p, n, &s.polygon);
            for (fi, feat) in s.features.iter().enumerate() {
                let ff = plane_view_factor(p, n, &feat.polygon);
                f[k + 1 + fi] = ff;
                net -= ff;
            }
            f[k] = net.max(0.0);
        }
        let sum: f64 = f.iter().sum();
        (sum <= 1.0 + EXACT_OVERLAP_TOLERANCE).then_some(f)
    }

    /// Plane radiant temperatures of faces with outward normals `normals` at `p` (one ray set
    /// shared by all faces where rays are needed).
    pub fn plane_radiant(
        &self,
        p: &Point3<f64>,
        normals: &[Vector3<f64>],
        stream: u64,
    ) -> Result<Vec<PlaneRadiant>, MrtError> {
        self.check_place(p)?;
        let mut hits: Option<RayHits> = None;
        normals
            .iter()
            .map(|n| {
                let n = n.normalize();
                if let Some(f) = self.exact_plane_factors(p, &n) {
                    let sum: f64 = f.iter().sum();
                    if !self.answers_open() && (sum - 1.0).abs() > ENCLOSURE_TOLERANCE {
                        return Err(MrtError::NotEnclosed {
                            point: [p.x, p.y, p.z],
                            sum,
                        });
                    }
                    let weight = |d: &Vector3<f64>| 4.0 * n.dot(d).max(0.0);
                    let seen = self.seen_temperatures(p, &weight);
                    let temps = seen.as_ref().map(|s| s.temperatures.as_slice());
                    let m = self
                        .radiant_of(&f, temps)
                        .map_err(|source| MrtError::Physics {
                            point: [p.x, p.y, p.z],
                            source,
                        })?;
                    let (unseen, _) = self.unseen_error(&f, seen.as_ref(), m.temperature);
                    return Ok(PlaneRadiant {
                        normal: n,
                        temperature: m.temperature,
                        std_error_k: m
                            .std_from_temperatures_k
                            .hypot(unseen)
                            .hypot(self.scene().temperature_level_std_k),
                        exact: true,
                    });
                }
                let h = hits.get_or_insert_with(|| self.ray_hits(p, &self.ray_settings(), stream));
                let weight = |d: &Vector3<f64>| 4.0 * n.dot(d).max(0.0);
                let r = self.ray_factors(h, &weight);
                let (t, se) = self.radiant_from_rays(p, &r, &weight)?;
                Ok(PlaneRadiant {
                    normal: n,
                    temperature: t,
                    std_error_k: se,
                    exact: false,
                })
            })
            .collect()
    }

    /// Plane radiant temperatures around `p` and the radiant asymmetries they make.
    pub fn asymmetry_at(&self, p: &Point3<f64>, stream: u64) -> Result<RadiantAsymmetry, MrtError> {
        let [up, x, y] = axes(self)?;
        let horizontal: Vec<Vector3<f64>> = (0..24)
            .map(|k| {
                let a = (15.0 * k as f64).to_radians();
                x * a.cos() + y * a.sin()
            })
            .collect();
        let mut normals = vec![up, -up];
        normals.extend(horizontal.iter().copied());
        let t = self.plane_radiant(p, &normals, stream)?;
        let c = |k: usize| t[k].temperature.celsius();
        let vertical_k = c(0) - c(1);
        // Opposite faces: azimuth k and k + 12 (180° apart).
        let (mut worst, mut warm_az) = (0.0f64, 0.0);
        for k in 0..12 {
            let d = c(2 + k) - c(2 + k + 12);
            if d.abs() > worst {
                worst = d.abs();
                warm_az = if d >= 0.0 {
                    15.0 * k as f64
                } else {
                    15.0 * (k + 12) as f64
                };
            }
        }
        let mean = t.iter().map(|f| f.temperature.celsius()).sum::<f64>() / t.len() as f64;
        let (hot, cold) = {
            let k = (warm_az / 15.0).round() as usize;
            (c(2 + k), c(2 + (k + 12) % 24))
        };
        let wall_kind = if hot - mean > mean - cold {
            AsymmetryKind::WarmWall
        } else {
            AsymmetryKind::CoolWall
        };
        let ceiling_kind = if vertical_k >= 0.0 {
            AsymmetryKind::WarmCeiling
        } else {
            AsymmetryKind::CoolCeiling
        };
        Ok(RadiantAsymmetry {
            point: *p,
            six: [t[0], t[1], t[2], t[2 + 12], t[2 + 6], t[2 + 18]],
            vertical_k,
            horizontal_k: worst,
            horizontal_warm_azimuth_deg: warm_az,
            vertical: AsymmetryVerdict::new(ceiling_kind, vertical_k.abs()),
            horizontal: AsymmetryVerdict::new(wall_kind, worst),
        })
    }
}

/// The person's directional weight 4·fp(d): azimuth from the facing direction, altitude above
/// the horizontal.
fn person_weight(
    posture: Posture,
    facing: Facing,
    up: Vector3<f64>,
    x: Vector3<f64>,
    y: Vector3<f64>,
) -> impl Fn(&Vector3<f64>) -> f64 {
    move |d: &Vector3<f64>| {
        let alt = d.dot(&up).clamp(-1.0, 1.0).asin().to_degrees();
        4.0 * match facing {
            Facing::Any => projected_area_factor_averaged(posture, alt),
            Facing::Azimuth(a) => {
                let az = d.dot(&y).atan2(d.dot(&x)).to_degrees();
                projected_area_factor(posture, az - a, alt)
            }
        }
    }
}
