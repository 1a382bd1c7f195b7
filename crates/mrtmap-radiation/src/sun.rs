//! The sun on a person in a scene: how much of the sky the person sees through the windows
//! (SolarCal's f_svv) and how much of the body the beam reaches (f_bes), by rays cast against the
//! scene. SolarCal itself (ERF, ΔMRT) is `mrtmap_physics::solar_gain`.
//!
//! A window is a feature whose label contains "window" or "glass" (any case). A ray leaves
//! through a window when the first thing it meets is a surface at a point inside a window
//! feature; furniture, walls, the ceiling and other features stop it.
//!
//! - **f_svv**, the sky-vault view fraction, is counted as the CBE Comfort Tool's form counts it:
//!   directions above the horizon taken uniformly in azimuth (0…360°) and altitude (0…90°), on a
//!   2° grid from the body centre, and the share whose ray leaves through a window. For a window
//!   straight ahead this is what atan(h/2d)° · atan(w/2d)° / 16200 approximates (that form takes
//!   the window's outline in angles as a rectangle, half of it above the horizon), but traced it
//!   also sees where the window is (above or beside the person) and what stands in the way.
//! - **f_bes**, the fraction of the body in the beam: the body as a vertical rectangle
//!   [`BODY_WIDTH_M`] wide from the floor to the crown (1.3 m seated, 1.75 m standing) through the
//!   body's axis, turned square to the sun, sampled on a 9 × 27 grid; the share of the samples
//!   whose ray towards the sun leaves through a window.

use mrtmap_geometry::RayCaster;
use mrtmap_geometry::nalgebra::{Point3, Vector3};
use mrtmap_geometry::polygon::point_in_polygon_fast;
use mrtmap_physics::Posture;
use serde::{Deserialize, Serialize};

use crate::scene::RadiantScene;

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

/// The scene made ready for sun rays: its triangles in a BVH and which features are windows.
pub struct SunTracer<'a> {
    scene: &'a RadiantScene,
    caster: mrtmap_geometry::BvhRayCaster,
    owner: Vec<Owner>,
    /// Per surface, the indices of its features that are windows.
    windows: Vec<Vec<usize>>,
}

/// Whether a feature's label makes it a window ("window", "glass", any case).
pub fn is_window_label(label: &str) -> bool {
    let l = label.to_lowercase();
    l.contains("window") || l.contains("glass")
}

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
                    .filter(|&f| is_window_label(&s.features[f].label))
                    .collect()
            })
            .collect();
        Self {
            scene,
            caster: mrtmap_geometry::BvhRayCaster::new(&tris),
            owner,
            windows,
        }
    }

    /// Whether the scene has any window.
    pub fn has_windows(&self) -> bool {
        self.windows.iter().any(|w| !w.is_empty())
    }

    /// The window (surface index, feature index) the ray from `p` along the unit vector `d` leaves
    /// through, or `None` when something else stops it first.
    fn window_hit(&self, p: &Point3<f64>, d: &Vector3<f64>) -> Option<(usize, usize)> {
        let hit = self.caster.cast(p, d, f64::INFINITY)?;
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
        if !self.has_windows() || sun.altitude_deg <= 0.0 {
            return (0.0, Vec::new());
        }
        let d = sun.towards_sun();
        let az = sun.azimuth_deg.to_radians();
        let across = Vector3::new(-az.sin(), az.cos(), 0.0);
        let feet = centre.z - posture.centre_height_m();
        let height = posture.head_height_m();
        let (nu, nz) = BODY_SAMPLES;
        let mut lit = 0usize;
        let mut through: Vec<(usize, usize)> = Vec::new();
        for i in 0..nu {
            let u = ((i as f64 + 0.5) / nu as f64 - 0.5) * BODY_WIDTH_M;
            for j in 0..nz {
                let z = feet + (j as f64 + 0.5) / nz as f64 * height;
                let p = Point3::new(centre.x, centre.y, z) + across * u;
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
        (lit as f64 / (nu * nz) as f64, ids)
    }

    /// The window (its id) through which the beam from `sun` reaches the point `p` (a globe's
    /// centre), or `None` when the point is in shade or the sun below the horizon.
    pub fn beam_at(&self, p: &Point3<f64>, sun: &SunDirection) -> Option<String> {
        if sun.altitude_deg <= 0.0 {
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
