//! Grey rooms: each surface's emissivity and the radiosity it leaves, and the person holding the
//! camera, whom window glass mirrors.
//!
//! A grey diffuse surface at T with emissivity ε receiving irradiance σT_irr⁴ leaves
//! J = εσT⁴ + (1 − ε)σT_irr⁴, the radiosity a thermal camera (set to ε = 1) reads and a person
//! exchanges radiation with. The irradiance comes from the other surfaces' radiosities, so the
//! radiosities are solved by iteration (the radiosity method with one node per surface or feature,
//! as building simulation does it): start from J = σT⁴, compute each element's irradiance from the
//! room's scene at those radiosities ([`mrtmap_radiation::grey::irradiance`], the T⁴ mean over up
//! to nine points on it), update J, three times (each round shrinks the error by 1 − ε, ≤ 0.16).
//!
//! Glass is specular in the long-wave: the thermal camera sees εσT⁴ plus 1 − ε of what the mirrored
//! ray meets, the operator included ([`Operator`](crate::Operator)), while its radiosity for the MRT (and the truth)
//! is the diffuse one above.

use mrtmap_geometry::nalgebra::{Isometry3, Point2, Point3, Vector3};
use mrtmap_physics::ZERO_CELSIUS_K;
use mrtmap_radiation::MrtEngine;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::room::is_glass;
use crate::room::{Room, SurfaceRef};

/// Monte Carlo rays per irradiance point in rooms that need them (furniture, not convex).
pub const IRRADIANCE_RAYS: usize = 20_000;

/// Whether the room's surfaces are black (ε = 1 everywhere unless the room file says otherwise)
/// or grey (window glass 0.84, every other surface and feature drawn from 0.90–0.95 per seed,
/// unless the room file says otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Surfaces {
    /// Black: the camera reads each surface's own temperature.
    Black,
    /// Grey: the camera reads radiosities, glass mirrors the operator.
    Grey,
}

/// Window glass's emissivity in grey rooms: the emissivity table's glass (one value, one place).
pub use mrtmap_radiation::grey::GLASS_EMISSIVITY;
/// Where the other surfaces' emissivities are drawn from in grey rooms (paint, plaster, tiles).
pub const GREY_EMISSIVITY: std::ops::Range<f64> = 0.90..0.95;

/// The room's emissivities and the irradiance on each element (by [`Room::surfaces`] index and
/// feature index).
#[derive(Clone, Debug, PartialEq)]
pub struct Grey {
    /// Emissivity by surface.
    pub surface_emissivity: Vec<f64>,
    /// Emissivity by feature.
    pub feature_emissivity: Vec<f64>,
    /// Irradiance temperature (K) by surface, once solved.
    pub surface_irradiance_k: Vec<f64>,
    /// Irradiance temperature (K) by feature, once solved.
    pub feature_irradiance_k: Vec<f64>,
}

impl Grey {
    /// The emissivities of `room`: the room file's where it gives them, else 1 (black) or, grey,
    /// glass 0.84 and the rest drawn from [`GREY_EMISSIVITY`] with `seed`. Irradiances unsolved.
    pub fn emissivities(room: &Room, surfaces: Surfaces, seed: u64) -> Self {
        if let Some(e) = &room.file.emissivities {
            return Self {
                surface_emissivity: e.surfaces.clone(),
                feature_emissivity: e.features.clone(),
                surface_irradiance_k: Vec::new(),
                feature_irradiance_k: Vec::new(),
            };
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e_e5_11);
        let mut draw = |glass: bool| match surfaces {
            Surfaces::Black => 1.0,
            Surfaces::Grey if glass => GLASS_EMISSIVITY,
            Surfaces::Grey => rng.random_range(GREY_EMISSIVITY),
        };
        let t = &room.file.temperatures;
        let surface_emissivity = room
            .surfaces()
            .into_iter()
            .map(|s| {
                let drawn = draw(false);
                let given = match s {
                    SurfaceRef::Floor => t.floor_emissivity,
                    SurfaceRef::Ceiling => t.ceiling_emissivity,
                    SurfaceRef::Wall(i) => room.wall_emissivity[i].or(t.walls_emissivity),
                };
                given.unwrap_or(drawn)
            })
            .collect();
        let feature_emissivity = room
            .features
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let drawn = draw(is_glass(&f.label));
                room.file.features[k].emissivity.unwrap_or(drawn)
            })
            .collect();
        Self {
            surface_irradiance_k: Vec::new(),
            feature_irradiance_k: Vec::new(),
            surface_emissivity,
            feature_emissivity,
        }
    }

    /// Whether any element is grey.
    pub fn is_grey(&self) -> bool {
        self.surface_emissivity
            .iter()
            .chain(&self.feature_emissivity)
            .any(|e| *e < 1.0)
    }
}

/// The radiant temperature (°C) of an element at `t_c` with emissivity `e` and irradiance
/// temperature `irr_k` (K; none: black).
pub fn radiant_c(t_c: f64, e: f64, irr_k: Option<f64>) -> f64 {
    match irr_k {
        Some(g) if e < 1.0 => {
            let t4 = e * (t_c + ZERO_CELSIUS_K).powi(4) + (1.0 - e) * g.powi(4);
            t4.powf(0.25) - ZERO_CELSIUS_K
        }
        _ => t_c,
    }
}

/// Solves the radiosities of `room` (whose `grey` holds its emissivities): three rounds of
/// irradiance from the scene at the current radiosities. `rays` for rooms that need Monte Carlo.
pub fn solve(room: &mut Room, rays: usize, seed: u64) -> Result<(), crate::SimError> {
    let Some(g) = room.grey.as_ref() else {
        return Ok(());
    };
    if !g.is_grey() {
        return Ok(());
    }
    let method = room.truth_method(rays, seed, 4);
    // Sample points of each element (surface backgrounds without their features; features).
    let mut elements: Vec<(Vec<Point3<f64>>, Vector3<f64>)> = Vec::new();
    for s in room.surfaces() {
        let holes: Vec<&[Point2<f64>]> = room
            .features
            .iter()
            .filter(|f| f.on == s)
            .map(|f| f.polygon_2d.as_slice())
            .collect();
        let pts = mrtmap_radiation::grey::sample_points(&room.surface_polygon_2d(s), &holes, |q| {
            room.on_surface(s, q)
        });
        elements.push((pts, room.inward_normal(s)));
    }
    for f in &room.features {
        let pts =
            mrtmap_radiation::grey::sample_points(&f.polygon_2d, &[], |q| room.on_surface(f.on, q));
        elements.push((pts, room.inward_normal(f.on)));
    }
    let ns = room.surfaces().len();
    for _round in 0..3 {
        let scene = room.scene(&Isometry3::identity(), true)?;
        let engine = MrtEngine::new(&scene, method)?;
        let irr: Vec<f64> = elements
            .iter()
            .enumerate()
            .map(|(k, (pts, n))| {
                mrtmap_radiation::grey::irradiance(&engine, pts, n, 50_000 + k as u64)
                    .map_or(room.file.air_temperature_c + ZERO_CELSIUS_K, |t| {
                        t.0.kelvin()
                    })
            })
            .collect();
        if let Some(g) = room.grey.as_mut() {
            g.surface_irradiance_k = irr[..ns].to_vec();
            g.feature_irradiance_k = irr[ns..].to_vec();
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::Operator;
    use mrtmap_geometry::nalgebra::UnitQuaternion;

    /// A camera 1.4 m up at x = 2, looking along +x: the body stands behind it (x ≈ 1.75); a ray
    /// coming back along −x at chest height meets it, one passing a metre aside or above the head
    /// does not.
    #[test]
    fn the_operator_stands_behind_the_camera() {
        // The camera's +z along the room's +x.
        let rot = UnitQuaternion::rotation_between(&Vector3::z(), &Vector3::x()).unwrap();
        let cam = Isometry3::from_parts(Vector3::new(2.0, 1.0, 1.4).into(), rot);
        let op = Operator::behind(&cam);
        assert!((op.axis.x - 1.75).abs() < 1e-9 && (op.axis.y - 1.0).abs() < 1e-9);
        let back = -Vector3::x();
        let t = op.hit(&Point3::new(4.0, 1.0, 1.2), &back).unwrap();
        assert!((t - (4.0 - 1.95)).abs() < 1e-9, "{t}");
        assert!(op.hit(&Point3::new(4.0, 2.0, 1.2), &back).is_none());
        assert!(op.hit(&Point3::new(4.0, 1.0, 1.8), &back).is_none());
    }

    /// The radiosity of grey rooms: a preset made grey reads the window warmer than it is, walls
    /// within a tenth of a kelvin, and black rooms are unchanged.
    #[test]
    fn grey_rooms_read_radiosities() {
        let room = crate::preset("office").unwrap().unwrap();
        let grey = room
            .clone()
            .with_surfaces(Surfaces::Grey, 1, 2_000)
            .unwrap();
        let k = room
            .features
            .iter()
            .position(|f| f.label == "window")
            .unwrap();
        assert_eq!(grey.feature_emissivity(k), GLASS_EMISSIVITY);
        let seen = grey.feature_radiant_c(k);
        assert!(seen > 12.7 && seen < 13.5, "window reads {seen} °C");
        for s in grey.surfaces() {
            let e = grey.emissivity(s);
            assert!(GREY_EMISSIVITY.contains(&e), "{e}");
            let d = grey.background_radiant_c(s, 1.2) - grey.background_temperature_c(s, 1.2);
            assert!(d.abs() < 0.2, "{s:?}: {d}");
        }
        let black = room
            .clone()
            .with_surfaces(Surfaces::Black, 1, 2_000)
            .unwrap();
        assert!(!black.is_grey());
        assert_eq!(black.feature_radiant_c(k), 11.5);
    }
}
