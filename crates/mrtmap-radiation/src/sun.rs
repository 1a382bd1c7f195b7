//! The sun on a person in a scene: how much of the sky the person sees through the glazing
//! (SolarCal's f_svv) and how much of the body the beam reaches (f_bes), by rays cast against the
//! scene. SolarCal itself (ERF, ΔMRT) is `mrtmap_physics::solar_gain`.
//!
//! Glazing is a feature whose label names glazing ([`ElementKind::is_glazing`]: a window, a
//! skylight or roof light, a glazed door, a curtain wall). A ray from a point in the room leaves
//! through the glazing when the first thing it meets is a surface at a point inside a glazing
//! feature, and beyond the glass it meets nothing of the building (a wing of an L-shaped room, a
//! wall): furniture, walls, the ceiling and other features stop it. Only points inside the room
//! send rays, so a ray always meets the glass from the inside.
//!
//! - **f_svv**, the sky-vault view fraction, is counted as the CBE Comfort Tool's form counts it:
//!   directions above the horizon taken uniformly in azimuth (0…360°) and altitude (0…90°), on a
//!   2° grid from the body centre, and the share whose ray leaves through glazing. For a window
//!   straight ahead this is what atan(h/2d)° · atan(w/2d)° / 16200 approximates (that form takes
//!   the window's outline in angles as a rectangle, half of it above the horizon), but traced it
//!   also sees where the window is (above or beside the person) and what stands in the way.
//! - **f_bes**, the fraction of the body in the beam: the body as a vertical rectangle
//!   [`BODY_WIDTH_M`] wide from the floor to the crown (1.3 m seated, 1.75 m standing) through the
//!   body's axis, turned square to the sun, sampled on a 9 × 27 grid; the share of the samples
//!   inside the room whose ray towards the sun leaves through glazing (a body beside a wall is
//!   not lit through the wall by the part of its rectangle that pokes out).
//! - **Whether the beam enters the room at all** ([`SunTracer::beam_enters`]): from some point of
//!   some glazing whose outside faces the sun, 1 mm inside the glass, a ray towards the sun leaves
//!   through that glazing with nothing of the building in the way. Where it does not, SolarCal's floor-reflected beam has no floor patch to come from.

use mrtmap_geometry::RayCaster;
use mrtmap_geometry::nalgebra::{Point3, Vector3};
use mrtmap_geometry::polygon::point_in_polygon_fast;
use mrtmap_physics::Posture;
use serde::{Deserialize, Serialize};

use crate::bounds::RoomBounds;
use crate::scene::RadiantScene;
use crate::vocabulary::ElementKind;

/// The width of the rectangle that stands for the body in the beam (m): about a person's
/// shoulder width.
pub const BODY_WIDTH_M: f64 = 0.4;
/// Samples across and up the body.
const BODY_SAMPLES: (usize, usize) = (9, 27);
/// The sky grid's cell (degrees).
const SKY_STEP_DEG: f64 = 2.0;

/// Where the sun is, in the room's frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunDirection {
    /// Altitude above the floor's plane (degrees).
    pub altitude_deg: f64,
    /// Azimuth in the room's horizontal frame, degrees from +x towards +y (as a person's
    /// facing): 0 puts the sun beyond the +x side of the room.
    pub azimuth_deg: f64,
}

impl SunDirection {
    /// The unit vector towards the sun.
    pub fn towards_sun(&self) -> Vector3<f64> {
        let (alt, az) = (
            self.altitude_deg.to_radians(),
            self.azimuth_deg.to_radians(),
        );
        Vector3::new(alt.cos() * az.cos(), alt.cos() * az.sin(), alt.sin())
    }
}

/// How a person at one place is exposed to the sky and the sun through the scene's windows.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunExposure {
    /// The sky-vault view fraction (0…1).
    pub f_svv: f64,
    /// The fraction of the body in the beam (0…1).
    pub f_bes: f64,
    /// The windows the beam reaches the body through (ids), in scene order.
    pub beam_windows: Vec<String>,
}

enum Owner {
    Surface(usize),
    Occluder,
}

/// The scene made ready for sun rays: its triangles in a BVH and which features are glazing.
pub struct SunTracer<'a> {
    scene: &'a RadiantScene,
    caster: mrtmap_geometry::BvhRayCaster,
    owner: Vec<Owner>,
    /// Per surface, the indices of its features that are glazing.
    windows: Vec<Vec<usize>>,
    /// Where the room is (None for a scene without a floor outline: every point counts).
    bounds: Option<RoomBounds>,
}

/// How far beyond the glass the ray is cast on (m), to see whether the building stands in the way.
const BEYOND_GLASS_M: f64 = 1e-4;
/// How far inside the glazing its sample points are taken for [`SunTracer::beam_enters`] (m).
const INSIDE_GLASS_M: f64 = 1e-3;
/// How far from a glazing's centre its sides are told apart (m): past the room's tolerance.
const SIDE_TEST_M: f64 = 0.02;
/// Sample points per side of a glazing's bounds for [`SunTracer::beam_enters`].
const BEAM_GRID: usize = 6;

impl<'a> SunTracer<'a> {
    /// Prepares `scene`.
    pub fn new(scene: &'a RadiantScene) -> Self {
        let mut tris = Vec::new();
        let mut owner = Vec::new();
        for (t, si) in scene.surface_triangles() {
            tris.push(t);
            owner.push(Owner::Surface(si));
        }
        for o in &scene.occluders {
            for t in o.triangles() {
                tris.push(t);
                owner.push(Owner::Occluder);
            }
        }
        let windows = scene
            .surfaces
            .iter()
            .map(|s| {
                (0..s.features.len())
                    .filter(|&f| ElementKind::of_label(&s.features[f].label).is_glazing())
                    .collect()
            })
            .collect();
        Self {
            scene,
            caster: mrtmap_geometry::BvhRayCaster::new(&tris),
            owner,
            windows,
            bounds: RoomBounds::of_scene(scene),
        }
    }

    /// Whether `p` lies in the room (always, for a scene without a floor outline).
    fn inside(&self, p: &Point3<f64>) -> bool {
        self.bounds.as_ref().is_none_or(|b| b.locate(p).is_none())
    }

    /// Whether the scene has any glazing.
    pub fn has_windows(&self) -> bool {
        self.windows.iter().any(|w| !w.is_empty())
    }

    /// The glazing (surface index, feature index) the ray from `p` (in the room) along the unit
    /// vector `d` leaves through, or `None` when something else stops it first, in the room or
    /// beyond the glass.
    fn window_hit(&self, p: &Point3<f64>, d: &Vector3<f64>) -> Option<(usize, usize)> {
        // From inside a closed room a ray always meets something; one that meets nothing slipped
        // through the seam between two triangles (a vertical ray onto a ceiling's diagonal): it is
        // cast again turned by a few microradians (micrometres at a room's distances).
        let hit = self.caster.cast(p, d, f64::INFINITY).or_else(|| {
            let nudged = (d + Vector3::new(3e-6, -2e-6, 1e-6)).normalize();
            self.caster.cast(p, &nudged, f64::INFINITY)
        })?;
        let beyond = p + d * (hit.t + BEYOND_GLASS_M);
        if self.caster.cast(&beyond, d, f64::INFINITY).is_some() {
            return None;
        }
        let Owner::Surface(si) = self.owner[hit.triangle as usize] else {
            return None;
        };
        if self.windows[si].is_empty() {
            return None;
        }
        let s = &self.scene.surfaces[si];
        let q = s.frame.to_2d(&(p + d * hit.t));
        self.windows[si]
            .iter()
            .find(|&&fi| {
                let f = &s.features[fi];
                let (lo, hi) = f.bounds_2d;
                q.x >= lo.x
                    && q.x <= hi.x
                    && q.y >= lo.y
                    && q.y <= hi.y
                    && point_in_polygon_fast(&q, &f.polygon_2d)
            })
            .map(|&fi| (si, fi))
    }

    /// The sky-vault view fraction at `centre`: the share of the directions above the horizon
    /// (uniform in azimuth and altitude, a 2° grid) whose ray leaves through a window.
    pub fn f_svv(&self, centre: &Point3<f64>) -> f64 {
        if !self.has_windows() {
            return 0.0;
        }
        let n_az = (360.0 / SKY_STEP_DEG).round() as usize;
        let n_alt = (90.0 / SKY_STEP_DEG).round() as usize;
        let mut through = 0usize;
        for i in 0..n_az {
            for j in 0..n_alt {
                let d = SunDirection {
                    altitude_deg: (j as f64 + 0.5) * SKY_STEP_DEG,
                    azimuth_deg: (i as f64 + 0.5) * SKY_STEP_DEG,
                }
                .towards_sun();
                if self.window_hit(centre, &d).is_some() {
                    through += 1;
                }
            }
        }
        through as f64 / (n_az * n_alt) as f64
    }

    /// The fraction of the body of a person (`posture`, body centre `centre`) that the beam from
    /// `sun` reaches through a window, and which windows it comes through. No sun above the
    /// horizon, no beam.
    pub fn f_bes(
        &self,
        centre: &Point3<f64>,
        posture: Posture,
        sun: &SunDirection,
    ) -> (f64, Vec<String>) {
        if !self.has_windows() || sun.altitude_deg < 0.0 {
            return (0.0, Vec::new());
        }
        let d = sun.towards_sun();
        let az = sun.azimuth_deg.to_radians();
        let across = Vector3::new(-az.sin(), az.cos(), 0.0);
        let feet = centre.z - posture.centre_height_m();
        let height = posture.head_height_m();
        let (nu, nz) = BODY_SAMPLES;
        let (mut lit, mut body) = (0usize, 0usize);
        let mut through: Vec<(usize, usize)> = Vec::new();
        for i in 0..nu {
            let u = ((i as f64 + 0.5) / nu as f64 - 0.5) * BODY_WIDTH_M;
            for j in 0..nz {
                let z = feet + (j as f64 + 0.5) / nz as f64 * height;
                let p = Point3::new(centre.x, centre.y, z) + across * u;
                if !self.inside(&p) {
                    continue;
                }
                body += 1;
                if let Some(w) = self.window_hit(&p, &d) {
                    lit += 1;
                    if !through.contains(&w) {
                        through.push(w);
                    }
                }
            }
        }
        through.sort_unstable();
        let ids = through
            .iter()
            .map(|&(si, fi)| self.scene.surfaces[si].features[fi].id.clone())
            .collect();
        (lit as f64 / body.max(1) as f64, ids)
    }

    /// Whether the beam from `sun` enters the room through any glazing: from a point of a
    /// glazing that faces the sun (a 6 × 6 grid over it), 1 mm inside the glass, a ray towards
    /// the sun leaves through that glazing. False with the sun below the horizon.
    pub fn beam_enters(&self, sun: &SunDirection) -> bool {
        if sun.altitude_deg < 0.0 {
            return false;
        }
        let d = sun.towards_sun();
        self.windows.iter().enumerate().any(|(si, fs)| {
            let s = &self.scene.surfaces[si];
            fs.iter().any(|&fi| {
                let out = self.outward(si, fi);
                if out.dot(&d) <= 0.0 {
                    return false;
                }
                let f = &s.features[fi];
                let (lo, hi) = f.bounds_2d;
                (0..BEAM_GRID * BEAM_GRID).any(|k| {
                    let q = mrtmap_geometry::nalgebra::Point2::new(
                        lo.x + (hi.x - lo.x) * ((k % BEAM_GRID) as f64 + 0.5) / BEAM_GRID as f64,
                        lo.y + (hi.y - lo.y) * ((k / BEAM_GRID) as f64 + 0.5) / BEAM_GRID as f64,
                    );
                    point_in_polygon_fast(&q, &f.polygon_2d)
                        && self.window_hit(&(s.frame.to_3d(&q) - out * INSIDE_GLASS_M), &d)
                            == Some((si, fi))
                })
            })
        })
    }

    /// The outward normal (away from the room) of glazing `fi` on surface `si`: the side of its
    /// plane that lies outside the room 2 cm from its centre.
    fn outward(&self, si: usize, fi: usize) -> Vector3<f64> {
        let s = &self.scene.surfaces[si];
        let n = s.frame.normal.into_inner();
        let f = &s.features[fi];
        let c = f.polygon.iter().fold(Vector3::zeros(), |a, p| a + p.coords)
            / f.polygon.len().max(1) as f64;
        if self.inside(&Point3::from(c + n * SIDE_TEST_M)) {
            -n
        } else {
            n
        }
    }

    /// The window (its id) through which the beam from `sun` reaches the point `p` (a globe's
    /// centre), or `None` when the point is in shade or the sun below the horizon.
    pub fn beam_at(&self, p: &Point3<f64>, sun: &SunDirection) -> Option<String> {
        if sun.altitude_deg < 0.0 {
            return None;
        }
        let (si, fi) = self.window_hit(p, &sun.towards_sun())?;
        Some(self.scene.surfaces[si].features[fi].id.clone())
    }

    /// f_svv and f_bes together.
    pub fn exposure(
        &self,
        centre: &Point3<f64>,
        posture: Posture,
        sun: &SunDirection,
    ) -> SunExposure {
        let (f_bes, beam_windows) = self.f_bes(centre, posture, sun);
        SunExposure {
            f_svv: self.f_svv(centre),
            f_bes,
            beam_windows,
        }
    }
}

/// Whether `scene`'s up is +z: the frame the sun's altitude and azimuth are given in (a
/// scene with another up, a hand-written y-up one, is refused by the sun's callers rather than
/// lit from the wrong side).
pub fn sun_frame_is_z_up(scene: &RadiantScene) -> bool {
    RoomBounds::of_scene(scene).is_none_or(|b| b.frame.plane.normal.z > 1.0 - 1e-9)
}

impl SunTracer<'_> {
    /// The ids of the glazing whose outside faces the sun (the beam can pass them inwards), with
    /// the sun not below the horizon.
    pub fn glazing_facing(&self, sun: &SunDirection) -> Vec<String> {
        if sun.altitude_deg < 0.0 {
            return Vec::new();
        }
        let d = sun.towards_sun();
        let mut ids = Vec::new();
        for (si, fs) in self.windows.iter().enumerate() {
            for &fi in fs {
                if self.outward(si, fi).dot(&d) > 0.0 {
                    ids.push(self.scene.surfaces[si].features[fi].id.clone());
                }
            }
        }
        ids
    }
}

/// What [`audit_the_beam`] found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BeamAudit {
    /// (sun, body) cases with part of the body in the beam.
    pub lit: usize,
    /// Cases where the beam came through a wall or glazing facing away from the sun, or entered
    /// with no glazing facing it, in words.
    pub violations: Vec<String>,
}

/// Sweeps the sun around the sky (azimuth every 10°, altitudes 5°, 30°, 60°, 85°) over a 7 × 7
/// grid of bodies of `posture` covering the floor to 8 cm from its bounds (inside the room and
/// out of furniture), and checks that every body lit is lit through glazing whose outside faces
/// the sun, and that no beam enters when no glazing faces it: the beam never comes through a
/// wall.
pub fn audit_the_beam(scene: &RadiantScene, posture: Posture) -> BeamAudit {
    let t = SunTracer::new(scene);
    let mut audit = BeamAudit::default();
    let Some(bounds) = RoomBounds::of_scene(scene) else {
        return audit;
    };
    let (lo, hi) = bounds.frame.floor_bounds();
    let mut centres = Vec::new();
    for i in 0..7 {
        for j in 0..7 {
            let u = lo.x + 0.08 + (hi.x - lo.x - 0.16) * i as f64 / 6.0;
            let v = lo.y + 0.08 + (hi.y - lo.y - 0.16) * j as f64 / 6.0;
            let p = bounds.frame.point(
                &mrtmap_geometry::nalgebra::Point2::new(u, v),
                posture.centre_height_m(),
            );
            if bounds.locate(&p).is_none() && !scene.occluders.iter().any(|o| o.contains(&p)) {
                centres.push(p);
            }
        }
    }
    for az in (0..360).step_by(10) {
        for alt in [5.0, 30.0, 60.0, 85.0] {
            let sun = SunDirection {
                altitude_deg: alt,
                azimuth_deg: f64::from(az),
            };
            let facing = t.glazing_facing(&sun);
            let enters = t.beam_enters(&sun);
            if facing.is_empty() && enters {
                audit.violations.push(format!(
                    "sun at {az}°, {alt}° high: the beam enters though no glazing faces it"
                ));
            }
            for c in &centres {
                let (f, ids) = t.f_bes(c, posture, &sun);
                if f <= 0.0 {
                    continue;
                }
                audit.lit += 1;
                if !enters {
                    audit.violations.push(format!(
                        "sun at {az}°, {alt}° high: a body at ({:.2}, {:.2}) is lit though no beam enters",
                        c.x, c.y
                    ));
                }
                for id in ids.iter().filter(|id| !facing.contains(id)) {
                    audit.violations.push(format!(
                        "sun at {az}°, {alt}° high: a body at ({:.2}, {:.2}) is lit through {id}, whose outside faces away",
                        c.x, c.y
                    ));
                }
            }
        }
    }
    audit
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::example_office;

    /// The example office's window is on the +x wall (x = 4.2, y 0.9…2.7, z 0.9…2.2).
    #[test]
    fn the_beam_through_the_example_window() {
        let scene = example_office();
        let t = SunTracer::new(&scene);
        assert!(t.has_windows());
        let sun = SunDirection {
            altitude_deg: 30.0,
            azimuth_deg: 0.0,
        };
        // A globe's centre: in the beam in front of the window, not beside it.
        assert!(t.beam_at(&Point3::new(2.65, 1.8, 1.1), &sun).is_some());
        assert!(t.beam_at(&Point3::new(2.65, 0.3, 1.1), &sun).is_none());
        let night = SunDirection {
            altitude_deg: -5.0,
            azimuth_deg: 0.0,
        };
        assert!(t.beam_at(&Point3::new(2.65, 1.8, 1.1), &night).is_none());
        // Facing the window 1.55 m away, centred on it: the whole body in the beam.
        let (f, ids) = t.f_bes(&Point3::new(2.65, 1.8, 0.6), Posture::Seated, &sun);
        assert!(f > 0.95, "{f}");
        assert_eq!(ids, vec!["window-1".to_string()]);
        // Beside the beam.
        let (f, ids) = t.f_bes(&Point3::new(2.65, 0.3, 0.6), Posture::Seated, &sun);
        assert_eq!(f, 0.0);
        assert!(ids.is_empty());
        // The sun behind the window's wall (azimuth 180: the beam would come from −x) or below
        // the horizon gives no beam.
        for sun in [
            SunDirection {
                altitude_deg: 30.0,
                azimuth_deg: 180.0,
            },
            SunDirection {
                altitude_deg: -5.0,
                azimuth_deg: 0.0,
            },
        ] {
            assert_eq!(
                t.f_bes(&Point3::new(2.65, 1.8, 0.6), Posture::Seated, &sun)
                    .0,
                0.0
            );
        }
        // Half the body: a person standing so that the beam's lower edge crosses them.
        let (f, _) = t.f_bes(&Point3::new(1.0, 1.8, 1.0), Posture::Standing, &sun);
        assert!(f > 0.05 && f < 0.95, "{f}");
    }

    #[test]
    fn no_sun_through_a_wall_in_the_example_office() {
        for posture in [Posture::Seated, Posture::Standing] {
            let audit = audit_the_beam(&example_office(), posture);
            assert!(audit.violations.is_empty(), "{:?}", audit.violations);
            assert!(audit.lit > 0, "the sweep never lit anyone");
        }
        // Issue 63's case: a seated person 0.1 m from the window's wall, the sun behind that wall
        // (azimuth 100°: the beam would come from −x): the body's rectangle reaches past the wall,
        // but no part of it outside the room is lit, and no beam enters the room.
        let scene = example_office();
        let t = SunTracer::new(&scene);
        let sun = SunDirection {
            altitude_deg: 30.0,
            azimuth_deg: 100.0,
        };
        let (f, ids) = t.f_bes(&Point3::new(4.1, 1.8, 0.6), Posture::Seated, &sun);
        assert_eq!((f, ids.len()), (0.0, 0));
        assert!(!t.beam_enters(&sun));
        assert!(t.beam_enters(&SunDirection {
            altitude_deg: 30.0,
            azimuth_deg: 0.0,
        }));
    }

    /// A skylight, a roof light and a glazed door let in what a window of the same polygon lets
    /// in (issue 61).
    #[test]
    fn every_glazing_lets_the_sun_in() {
        let sun = SunDirection {
            altitude_deg: 30.0,
            azimuth_deg: 0.0,
        };
        let at = Point3::new(2.65, 1.8, 0.6);
        let with_label = |label: &str| {
            let mut file = example_office().to_file();
            for s in &mut file.surfaces {
                for f in &mut s.features {
                    if f.label == "window" {
                        f.label = label.into();
                    }
                }
            }
            let scene = RadiantScene::new(&file).unwrap();
            let t = SunTracer::new(&scene);
            (t.f_bes(&at, Posture::Seated, &sun).0, t.f_svv(&at))
        };
        let window = with_label("window");
        assert!(window.0 > 0.9 && window.1 > 0.0, "{window:?}");
        for label in [
            "skylight",
            "roof light",
            "glazed door",
            "Glass Door",
            "curtain wall",
        ] {
            assert_eq!(with_label(label), window, "{label}");
        }
        assert_eq!(with_label("mirror"), (0.0, 0.0));

        // A 0.6 m square in the ceiling (light-2's place) over a seated person, the sun 70° high:
        // as a skylight or a roof light it lets in the beam a "window" there would, as a light
        // none.
        let high = SunDirection {
            altitude_deg: 70.0,
            azimuth_deg: 0.0,
        };
        let under = Point3::new(2.24, 1.0, 0.6);
        let in_ceiling = |label: &str| {
            let mut file = example_office().to_file();
            for s in &mut file.surfaces {
                for f in &mut s.features {
                    if f.id == "light-2" {
                        f.label = label.into();
                    }
                }
            }
            let scene = RadiantScene::new(&file).unwrap();
            let t = SunTracer::new(&scene);
            (
                t.f_bes(&under, Posture::Seated, &high).0,
                t.f_svv(&under),
                t.beam_enters(&high),
            )
        };
        let window = in_ceiling("window");
        assert!(window.0 > 0.05 && window.1 > 0.0 && window.2, "{window:?}");
        for label in ["skylight", "roof light", "rooflight", "roof window"] {
            assert_eq!(in_ceiling(label), window, "{label}");
        }
        let light = in_ceiling("recessed light");
        assert_eq!((light.0, light.2), (0.0, true), "{light:?}");

        // A skylight over the room's centre, which lies on the ceiling's diagonal (the seam of
        // its two triangles): the sun straight overhead lights the whole body, as at 89.999°
        // (rays exactly on the seam slipped through: f_bes 0.89).
        let mut file = example_office().to_file();
        file.surfaces[1].features[0].polygon = vec![
            [1.8, 1.5, 2.7],
            [2.4, 1.5, 2.7],
            [2.4, 2.1, 2.7],
            [1.8, 2.1, 2.7],
        ];
        file.surfaces[1].features[0].label = "skylight".into();
        let scene = RadiantScene::new(&file).unwrap();
        let t = SunTracer::new(&scene);
        for alt in [90.0, 89.999] {
            let (f, _) = t.f_bes(
                &Point3::new(2.1, 1.8, 0.6),
                Posture::Seated,
                &SunDirection {
                    altitude_deg: alt,
                    azimuth_deg: 0.0,
                },
            );
            assert_eq!(f, 1.0, "{alt}");
        }
    }

    #[test]
    fn sky_through_the_example_window() {
        let scene = example_office();
        let t = SunTracer::new(&scene);
        // The window seen from 1.55 m: of the order of the CBE form's 0.042 (the window lies
        // wholly above the seated body centre, so more of it is sky than the form's half).
        let near = t.f_svv(&Point3::new(2.65, 1.8, 0.6));
        assert!(near > 0.03 && near < 0.15, "{near}");
        // Farther away, less; facing away or off to the side does not matter, distance does.
        let far = t.f_svv(&Point3::new(0.5, 1.8, 0.6));
        assert!(far < near, "{far} {near}");
        // A scene without windows sees no sky.
        let mut file = scene.to_file();
        for s in &mut file.surfaces {
            for f in &mut s.features {
                f.label = "painting".into();
            }
        }
        let closed = RadiantScene::new(&file).unwrap();
        assert_eq!(
            SunTracer::new(&closed).f_svv(&Point3::new(2.65, 1.8, 0.6)),
            0.0
        );
    }

    #[test]
    fn a_window_straight_ahead_at_eye_level_is_close_to_the_cbe_form() {
        // A 1.8 × 1.3 m window centred 1.55 m ahead of a standing body centre (1.0 m up): the
        // traced share and atan(h/2d)° · atan(w/2d)° / 16200 count the same directions but for
        // the form's rectangular outline in angles.
        let mut file = example_office().to_file();
        for s in &mut file.surfaces {
            for f in &mut s.features {
                if f.label == "window" {
                    for v in &mut f.polygon {
                        v[2] += 1.0 - 1.55;
                    }
                }
            }
        }
        let scene = RadiantScene::new(&file).unwrap();
        let traced = SunTracer::new(&scene).f_svv(&Point3::new(2.65, 1.8, 1.0));
        let form = mrtmap_physics::f_svv(1.8, 1.3, 1.55).unwrap();
        assert!((traced - form).abs() < 0.1 * form, "{traced} {form}");
    }
}
